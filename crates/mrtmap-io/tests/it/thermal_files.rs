//! Thermal files against the real FLIR files in `shared/data/flir-rjpeg` and `flir-fff`: raw
//! statistics and temperatures against the regression values (within 0.01 °C), metadata against
//! exiftool's, plus Lepton raw/PNG/TIFF and float TIFF round trips and corrupt files.

use std::path::{Path, PathBuf};

use mrtmap_io::{
    FileErrorKind, ThermalFileKind, ThermalOptions, decode_thermal, read_thermal_file,
};

fn data_dir(sub: &str) -> Option<PathBuf> {
    let dir = std::env::var_os("MRTMAP_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let d = dir.join(sub);
    d.is_dir().then_some(d)
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn check_against_regression(sub: &str) -> usize {
    let Some(dir) = data_dir(sub) else {
        println!("skipped: shared/data/{sub} not found (set MRTMAP_DATA_DIR)");
        return 0;
    };
    let reg = json(&dir.join("raw2temp_regression_values.json"));
    let files = reg["files"].as_object().unwrap();
    for (name, want) in files {
        let img = read_thermal_file(&dir.join(name), &ThermalOptions::default()).unwrap();
        let shape = want["shape"].as_array().unwrap();
        assert_eq!(img.height as u64, shape[0].as_u64().unwrap(), "{name}");
        assert_eq!(img.width as u64, shape[1].as_u64().unwrap(), "{name}");
        let raw = img.raw.as_ref().unwrap();
        let rmin = *raw.data.iter().min().unwrap() as u64;
        let rmax = *raw.data.iter().max().unwrap() as u64;
        assert_eq!(rmin, want["raw_min"].as_u64().unwrap(), "{name} raw min");
        assert_eq!(rmax, want["raw_max"].as_u64().unwrap(), "{name} raw max");
        assert_eq!(
            raw.data[0] as u64,
            want["raw_00"].as_u64().unwrap(),
            "{name}"
        );
        let c = (img.height / 2 * img.width + img.width / 2) as usize;
        assert_eq!(
            raw.data[c] as u64,
            want["raw_center"].as_u64().unwrap(),
            "{name}"
        );
        let (tmin, tmax, tmean, _) = img.stats().unwrap();
        for (got, key) in [
            (tmin, "T_min_C"),
            (tmax, "T_max_C"),
            (tmean, "T_mean_C"),
            (img.celsius[0], "T_00_C"),
            (img.celsius[c], "T_center_C"),
        ] {
            let w = want[key].as_f64().unwrap();
            assert!((got - w).abs() < 0.01, "{name} {key}: {got} vs {w}");
        }
        // Metadata against exiftool's.
        let mut exif_path = dir.join(format!("{name}.exiftool.json"));
        if !exif_path.exists() {
            exif_path = dir.join(Path::new(name).with_extension("exiftool.json"));
        }
        let exif = json(&exif_path);
        let exif = &exif[0];
        let meta = |k: &str| {
            img.metadata
                .iter()
                .find(|(n, _)| n == k)
                .map(|(_, v)| v.clone())
                .unwrap_or_else(|| panic!("{name}: no {k}"))
        };
        for k in [
            "PlanckR1",
            "PlanckR2",
            "PlanckB",
            "PlanckF",
            "PlanckO",
            "Emissivity",
            "ObjectDistance",
            "ReflectedApparentTemperature",
            "RelativeHumidity",
            "RawValueMedian",
            "RawValueRange",
            "FieldOfView",
        ] {
            let got: f64 = meta(k).parse().unwrap();
            let w = exif[format!("FLIR:{k}")].as_f64().unwrap();
            assert!(
                (got - w).abs() <= 1e-4 * w.abs().max(1.0),
                "{name} {k}: {got} vs {w}"
            );
        }
        let model = exif["FLIR:CameraModel"].as_str().unwrap();
        let got_model = img.metadata.iter().find(|(n, _)| n == "CameraModel");
        assert_eq!(got_model.map_or("", |(_, v)| v.as_str()), model, "{name}");
        let kind = if name.ends_with(".jpg") {
            ThermalFileKind::FlirJpeg
        } else {
            ThermalFileKind::FlirFff
        };
        assert_eq!(img.kind, kind);
    }
    files.len()
}

#[test]
fn flir_rjpeg_matches_regression_values_and_exiftool() {
    let n = check_against_regression("flir-rjpeg");
    assert!(n == 0 || n == 3);
}

#[test]
fn flir_fff_both_byte_orders_match_regression_values_and_exiftool() {
    let n = check_against_regression("flir-fff");
    assert!(n == 0 || n == 2);
}

#[test]
fn overrides_change_the_temperature_the_right_way() {
    let Some(dir) = data_dir("flir-rjpeg") else {
        return;
    };
    let p = dir.join("zenmuse_xtr.jpg");
    let base = read_thermal_file(&p, &ThermalOptions::default()).unwrap();
    let mut o = ThermalOptions::default();
    o.flir.emissivity = Some(0.95);
    let e95 = read_thermal_file(&p, &o).unwrap();
    // The scene is warmer than the 22 °C reflected temperature: a higher emissivity reads cooler.
    let (_, _, m0, _) = base.stats().unwrap();
    let (_, _, m1, _) = e95.stats().unwrap();
    assert!(m1 < m0 - 1.0, "{m0} → {m1}");
    assert!(e95.notes.iter().any(|n| n.contains("overridden")));
}

#[test]
fn duo_pro_radiometric_tiff_reads_at_0_04_kelvin_per_count() {
    let Some(dir) = data_dir("flir-fff") else {
        return;
    };
    let img = read_thermal_file(
        &dir.join("example_radiometric.tiff"),
        &ThermalOptions::default(),
    )
    .unwrap();
    assert_eq!(
        (img.width, img.height, img.kind),
        (640, 512, ThermalFileKind::Tiff16)
    );
    let (lo, hi, _, med) = img.stats().unwrap();
    // Raw 6743…7077, median 6994 → ×0.04 K.
    assert!((lo - (6743.0 * 0.04 - 273.15)).abs() < 1e-9);
    assert!((hi - (7077.0 * 0.04 - 273.15)).abs() < 1e-9);
    assert!((med - (6994.0 * 0.04 - 273.15)).abs() < 1e-9);
    assert!(img.notes[0].contains("0.04"), "{:?}", img.notes);
    let forced = read_thermal_file(
        &dir.join("example_radiometric.tiff"),
        &ThermalOptions {
            scale_k: Some(0.01),
            ..Default::default()
        },
    )
    .unwrap();
    assert!(forced.stats().unwrap().0 < -200.0);
}

fn lepton_frame() -> Vec<u16> {
    (0..160 * 120)
        .map(|i| 29_315 + (i % 160) as u16 * 3)
        .collect()
}

#[test]
fn lepton_raw_png_and_tiff_agree() {
    let dir = tempfile::tempdir().unwrap();
    let data = lepton_frame();
    let raw: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.path().join("f.y16"), &raw).unwrap();
    let img16 = mrtmap_io::Image16 {
        width: 160,
        height: 120,
        data: data.clone(),
    };
    std::fs::write(
        dir.path().join("f.png"),
        mrtmap_io::encode_png16(&img16).unwrap(),
    )
    .unwrap();
    image::ImageBuffer::<image::Luma<u16>, _>::from_raw(160, 120, data.clone())
        .unwrap()
        .save(dir.path().join("f.tiff"))
        .unwrap();
    let o = ThermalOptions::default();
    let a = read_thermal_file(&dir.path().join("f.y16"), &o).unwrap();
    let b = read_thermal_file(&dir.path().join("f.png"), &o).unwrap();
    let c = read_thermal_file(&dir.path().join("f.tiff"), &o).unwrap();
    assert_eq!(a.kind, ThermalFileKind::Raw16);
    assert_eq!(b.kind, ThermalFileKind::Png16);
    assert_eq!(c.kind, ThermalFileKind::Tiff16);
    assert!((a.celsius[0] - 20.0).abs() < 1e-9);
    assert_eq!(a.celsius, b.celsius);
    assert_eq!(a.celsius, c.celsius);
    assert_eq!(a.centikelvin().data, data);
    // A raw file of another size needs --size; a cut one names the offset.
    let e = decode_thermal(Path::new("g.bin"), &raw[..1000], &o).unwrap_err();
    assert!(e.to_string().contains("--size"), "{e}");
    let sized = ThermalOptions {
        size: Some((160, 120)),
        ..Default::default()
    };
    let e = decode_thermal(Path::new("g.bin"), &raw[..1000], &sized).unwrap_err();
    assert!(
        matches!(e.kind, FileErrorKind::Corrupt { offset: 1000, .. }),
        "{e}"
    );
}

#[test]
fn float_tiff_in_celsius_or_kelvin() {
    let dir = tempfile::tempdir().unwrap();
    for (name, add) in [("c.tiff", 0.0f32), ("k.tiff", 273.15)] {
        let v: Vec<f32> = (0..64 * 48)
            .map(|i| 18.0 + (i % 64) as f32 * 0.1 + add)
            .collect();
        let p = dir.path().join(name);
        let f = std::fs::File::create(&p).unwrap();
        let mut enc = tiff::encoder::TiffEncoder::new(f).unwrap();
        enc.write_image::<tiff::encoder::colortype::Gray32Float>(64, 48, &v)
            .unwrap();
        let img = read_thermal_file(&p, &ThermalOptions::default()).unwrap();
        assert_eq!(img.kind, ThermalFileKind::TiffFloat);
        assert!(
            (img.celsius[0] - 18.0).abs() < 1e-4,
            "{name}: {}",
            img.celsius[0]
        );
        assert!((img.celsius[63] - 24.3).abs() < 1e-4);
    }
}

#[test]
fn cut_or_foreign_files_name_the_file_and_offset() {
    let Some(dir) = data_dir("flir-rjpeg") else {
        return;
    };
    let bytes = std::fs::read(dir.join("ax8.jpg")).unwrap();
    let o = ThermalOptions::default();
    for cut in [100usize, 2_000, 30_000, bytes.len() / 2] {
        let e = decode_thermal(Path::new("ax8-cut.jpg"), &bytes[..cut], &o).unwrap_err();
        let s = e.to_string();
        assert!(s.starts_with("ax8-cut.jpg: "), "{s}");
        assert!(s.contains("byte") || s.contains("FLIR"), "{s}");
    }
    let e = decode_thermal(Path::new("x.jpg"), b"\xFF\xD8\xFF\xD9", &o).unwrap_err();
    assert!(e.to_string().contains("no temperatures"), "{e}");
    let e = decode_thermal(Path::new("x.txt"), b"hello", &o).unwrap_err();
    assert!(e.to_string().contains("unknown thermal format"), "{e}");
}

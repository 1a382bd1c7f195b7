//! Synthetic boards with known intrinsics, distortion and extrinsic: the calibration recovers
//! them (focal lengths within 0.5 %, translation within 2 mm, rotation within 0.2°).

use mrtmap_calib::synth::{SynthOptions, SynthRig, render_pairs};
use mrtmap_calib::{
    DetectOptions, Gray, PairInput, PairStatus, StereoOptions, calibrate_stereo, detect,
};

#[test]
fn stereo_calibration_recovers_the_synthetic_rig() {
    let rig = SynthRig::default();
    let seed: u64 = std::env::var("SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(7);
    let o = SynthOptions {
        seed,
        ..SynthOptions::default()
    };
    let pairs = render_pairs(&rig, &o);
    assert_eq!(pairs.len(), o.pairs);
    let max = (o.board.cols, o.board.rows);
    let opts = DetectOptions::default();
    let dets: Vec<_> = pairs
        .iter()
        .map(|p| {
            let g = Gray::from_dynamic(&image::DynamicImage::ImageRgb8(p.rgb.clone()));
            let t = Gray::from_u16(p.thermal.width, p.thermal.height, &p.thermal.data);
            (detect(&g, max, &opts), detect(&t, max, &opts))
        })
        .collect();
    let found_rgb = dets.iter().filter(|d| d.0.is_some()).count();
    let found_th = dets.iter().filter(|d| d.1.is_some()).count();
    println!(
        "detected: colour {found_rgb}/{}, thermal {found_th}/{}",
        o.pairs, o.pairs
    );
    let inputs: Vec<PairInput> = dets
        .iter()
        .map(|d| PairInput {
            rgb: d.0.as_ref(),
            thermal: d.1.as_ref(),
        })
        .collect();
    let r = calibrate_stereo(
        &o.board,
        (640, 480),
        (160, 120),
        &inputs,
        &StereoOptions::default(),
    )
    .expect("calibration");
    let used = r
        .pairs
        .iter()
        .filter(|p| p.status == PairStatus::Used)
        .count();
    for (k, p) in r.pairs.iter().enumerate() {
        println!(
            "pair {k}: {:?} rgb {} th {} {:?} {:?}",
            p.status,
            p.rgb_corners,
            p.thermal_corners,
            p.rgb_error.map(|e| e.rms_px),
            p.thermal_error.map(|e| e.rms_px)
        );
    }
    let rel = |a: f64, b: f64| (a - b).abs() / b;
    let dt =
        (r.rgb_from_thermal.translation.vector - rig.rgb_from_thermal.translation.vector).norm();
    let dr = (r.rgb_from_thermal.rotation.inverse() * rig.rgb_from_thermal.rotation)
        .angle()
        .to_degrees();
    println!(
        "used {used}; rgb fx {:.3} fy {:.3} (truth {} {}), thermal fx {:.3} fy {:.3} cx {:.2} cy {:.2} (truth {} {} {} {}); k {:?}",
        r.rgb.fx,
        r.rgb.fy,
        rig.rgb.fx,
        rig.rgb.fy,
        r.thermal.fx,
        r.thermal.fy,
        r.thermal.cx,
        r.thermal.cy,
        rig.thermal.fx,
        rig.thermal.fy,
        rig.thermal.cx,
        rig.thermal.cy,
        r.thermal.distortion
    );
    println!(
        "translation error {:.2} mm, rotation error {:.3}°; MRE colour {:.3} px thermal {:.3} px",
        dt * 1e3,
        dr,
        r.rgb_error.mean_px,
        r.thermal_error.mean_px
    );
    // A right calibration raises no warning; the same with the thermal camera moved 40 cm does.
    assert_eq!(mrtmap_calib::plausibility(&r), Vec::<String>::new());
    let mut far = r.clone();
    far.rgb_from_thermal.translation.vector.z += 0.4;
    let w = mrtmap_calib::plausibility(&far);
    assert!(
        w.len() == 1 && w[0].contains("from the colour camera"),
        "{w:?}"
    );
    let mut loose = r.clone();
    if let Some(s) = loose.std.as_mut() {
        s[21] = 0.05;
    }
    assert!(mrtmap_calib::plausibility(&loose)[0].contains("poorly constrained"));
    assert!(used >= 15, "only {used} pairs used");
    // The convention: rgb_from_thermal carries thermal-frame points into the colour frame, so its
    // translation is the thermal camera's centre seen from the colour camera. The board seen by
    // the colour camera, carried into the thermal frame by its inverse, lands on the thermal
    // corners; the transform the other way round would miss them by the baseline (45 mm, about
    // 8 px at these distances).
    let thermal_from_rgb = r.rgb_from_thermal.inverse();
    let centre = r.rgb_from_thermal * mrtmap_geometry::nalgebra::Point3::origin();
    assert!(
        (centre - rig.rgb_from_thermal * mrtmap_geometry::nalgebra::Point3::origin()).norm()
            < 0.002
    );
    let (mut sum, mut wrong, mut n) = (0.0, 0.0, 0usize);
    for (k, p) in r.pairs.iter().enumerate() {
        let (Some(pose), Some(th)) = (r.rgb_alone.poses[k], r.thermal_labels[k].as_ref()) else {
            continue;
        };
        if p.status != PairStatus::Used {
            continue;
        }
        for c in th {
            let q = pose * o.board.point(c.i, c.j);
            if let (Some(a), Some(b)) = (
                r.thermal.project(&(thermal_from_rgb * q)),
                r.thermal.project(&(r.rgb_from_thermal * q)),
            ) {
                sum += (a.x - c.x).hypot(a.y - c.y);
                wrong += (b.x - c.x).hypot(b.y - c.y);
                n += 1;
            }
        }
    }
    let (mean, mean_wrong) = (sum / n as f64, wrong / n as f64);
    println!(
        "colour board into the thermal image: {mean:.3} px (the inverse convention: {mean_wrong:.1} px)"
    );
    assert!(n > 500 && mean < 0.5, "{n} corners, mean {mean:.3} px");
    assert!(
        mean_wrong > 3.0,
        "the inverse convention fits too: {mean_wrong:.2} px"
    );
    assert!(rel(r.rgb.fx, rig.rgb.fx) < 0.005);
    assert!(rel(r.rgb.fy, rig.rgb.fy) < 0.005);
    assert!(rel(r.thermal.fx, rig.thermal.fx) < 0.005);
    assert!(rel(r.thermal.fy, rig.thermal.fy) < 0.005);
    assert!(dt < 0.002, "translation off by {:.2} mm", dt * 1e3);
    assert!(dr < 0.2, "rotation off by {dr:.3}°");
}

/// 8-bit colour-mapped thermal images (iron palette, as many cameras export) give the same corners
/// as the 16-bit radiometric ones.
#[test]
fn colour_mapped_thermal_gives_the_same_corners() {
    let rig = SynthRig::default();
    let o = SynthOptions {
        pairs: 4,
        partial: 0,
        ..SynthOptions::default()
    };
    let pairs = render_pairs(&rig, &o);
    let max = (o.board.cols, o.board.rows);
    let opts = DetectOptions::default();
    for p in &pairs {
        let g16 = Gray::from_u16(p.thermal.width, p.thermal.height, &p.thermal.data);
        let iron = image::RgbImage::from_fn(p.thermal.width, p.thermal.height, |x, y| {
            image::Rgb(mrtmap_io::iron(
                g16.data[(y * p.thermal.width + x) as usize],
            ))
        });
        let g8 = Gray::from_dynamic(&image::DynamicImage::ImageRgb8(iron));
        let a = detect(&g16, max, &opts).expect("16-bit board");
        let b = detect(&g8, max, &opts).expect("colour-mapped board");
        assert_eq!(a.corners.len(), 48);
        assert_eq!(b.corners.len(), 48);
        for c in &a.corners {
            let d = b
                .corners
                .iter()
                .map(|e| (e.x - c.x).hypot(e.y - c.y))
                .fold(f64::INFINITY, f64::min);
            assert!(d < 0.15, "corner moved {d:.3} px");
        }
    }
}

/// The false-colour and layout variants real thermal exports come in: a rainbow palette (found in
/// its hue), grey inverted (white-cold), a portrait image (the camera mounted on its side) and a
/// blurred one all give the whole board, at the 16-bit image's corners (portrait: transposed
/// back).
#[test]
fn palettes_inversion_portrait_and_blur_give_the_same_corners() {
    let rig = SynthRig::default();
    let o = SynthOptions {
        pairs: 3,
        partial: 0,
        ..SynthOptions::default()
    };
    let pairs = render_pairs(&rig, &o);
    let max = (o.board.cols, o.board.rows);
    let opts = DetectOptions::default();
    // A rainbow: hue from blue (cold) through green to red (warm).
    let rainbow = |v: f32| {
        let h = (1.0 - v.clamp(0.0, 1.0)) * 240.0;
        let x = 1.0 - ((h / 60.0) % 2.0 - 1.0).abs();
        let (r, g, b) = match (h / 60.0) as u32 {
            0 => (1.0, x, 0.0),
            1 => (x, 1.0, 0.0),
            2 => (0.0, 1.0, x),
            _ => (0.0, x, 1.0),
        };
        image::Rgb([(r * 255.0) as u8, (g * 255.0) as u8, (b * 255.0) as u8])
    };
    for p in &pairs {
        let (w, h) = (p.thermal.width, p.thermal.height);
        let g16 = Gray::from_u16(w, h, &p.thermal.data);
        let v = |x: u32, y: u32| g16.data[(y * w + x) as usize];
        let a = detect(&g16, max, &opts).expect("16-bit board");
        assert_eq!(a.corners.len(), 48);
        let variants: Vec<(&str, Gray, bool)> = vec![
            (
                "grey inverted",
                Gray::from_dynamic(&image::DynamicImage::ImageLuma8(image::GrayImage::from_fn(
                    w,
                    h,
                    |x, y| image::Luma([255 - (v(x, y).clamp(0.0, 1.0) * 255.0) as u8]),
                ))),
                false,
            ),
            (
                "portrait",
                Gray::from_dynamic(&image::DynamicImage::ImageLuma8(image::GrayImage::from_fn(
                    h,
                    w,
                    |x, y| image::Luma([(v(y, x).clamp(0.0, 1.0) * 255.0) as u8]),
                ))),
                true,
            ),
            (
                "blurred",
                Gray::from_dynamic(&image::DynamicImage::ImageLuma8(image::imageops::blur(
                    &image::GrayImage::from_fn(w, h, |x, y| {
                        image::Luma([(v(x, y).clamp(0.0, 1.0) * 255.0) as u8])
                    }),
                    1.0,
                ))),
                false,
            ),
        ];
        // A rainbow's luminance is not monotonic in temperature: the board is found in its hue.
        let rainbow_img =
            image::DynamicImage::ImageRgb8(image::RgbImage::from_fn(w, h, |x, y| rainbow(v(x, y))));
        let luminance_only =
            detect(&Gray::from_dynamic(&rainbow_img), max, &opts).map_or(0, |d| d.corners.len());
        let (k, b) = mrtmap_calib::detect_variants(&Gray::variants(&rainbow_img), max, &opts)
            .expect("rainbow: no board");
        println!(
            "rainbow: {luminance_only} corners from its luminance, {} from variant {k}",
            b.corners.len()
        );
        assert_eq!(b.corners.len(), 48, "rainbow");
        let worst = a
            .corners
            .iter()
            .map(|c| {
                b.corners
                    .iter()
                    .map(|e| (e.x - c.x).hypot(e.y - c.y))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max);
        assert!(worst < 0.25, "rainbow: a corner moved {worst:.3} px");
        for (name, g, transposed) in variants {
            let b = detect(&g, max, &opts).unwrap_or_else(|| panic!("{name}: no board"));
            assert_eq!(b.corners.len(), 48, "{name}");
            let mut worst: f64 = 0.0;
            for c in &a.corners {
                let (cx, cy) = if transposed { (c.y, c.x) } else { (c.x, c.y) };
                let d = b
                    .corners
                    .iter()
                    .map(|e| (e.x - cx).hypot(e.y - cy))
                    .fold(f64::INFINITY, f64::min);
                worst = worst.max(d);
            }
            println!("{name}: corners within {worst:.3} px of the 16-bit image's");
            assert!(worst < 0.25, "{name}: a corner moved {worst:.3} px");
        }
    }
}

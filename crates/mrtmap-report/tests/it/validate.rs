//! globe.csv reading, validation rows and their CSV and JSON forms.

use mrtmap_report::{
    GLOBE_COLUMNS, GlobeRow, ISO_DESIRED_K, ISO_REQUIRED_K, parse_globe_csv, validate,
    validation_csv,
};

fn err(text: &str) -> String {
    parse_globe_csv(text, "globe.csv")
        .expect_err("an error")
        .to_string()
}

#[test]
fn header_columns_are_found_by_name_in_any_order() {
    let text = "# rig 2, morning\n\
                time,emissivity,location,z,y,x,diameter_m,va_m_s,ta_c,tg_c,notes\n\
                \n\
                09:00,0.95,\"desk, north\",1.1,0.5,2.0,0.15,0.1,21.0,20.5,ok\n\
                09:20,0.95,door,1.1,0.6,0.4,0.05,0.2,21.5,22.0,\n";
    let rows = parse_globe_csv(text, "globe.csv").unwrap();
    assert_eq!(
        rows,
        vec![
            GlobeRow {
                label: "desk, north".into(),
                xyz: [2.0, 0.5, 1.1],
                tg_c: 20.5,
                ta_c: 21.0,
                va_m_s: 0.1,
                diameter_m: 0.15,
                emissivity: 0.95,
                line: 4,
            },
            GlobeRow {
                label: "door".into(),
                xyz: [0.4, 0.6, 1.1],
                tg_c: 22.0,
                ta_c: 21.5,
                va_m_s: 0.2,
                diameter_m: 0.05,
                emissivity: 0.95,
                line: 5,
            },
        ]
    );
}

#[test]
fn without_a_header_the_nine_columns_come_in_order() {
    let rows = parse_globe_csv("P1, 1, 2, 3, 24, 22, 0.1, 0.15, 0.95\n", "g.csv").unwrap();
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0].label, "P1");
    assert_eq!(rows[0].xyz, [1.0, 2.0, 3.0]);
    assert_eq!((rows[0].tg_c, rows[0].emissivity), (24.0, 0.95));
    assert_eq!(GLOBE_COLUMNS.len(), 9);
}

#[test]
fn bad_files_name_the_file_line_and_column() {
    let header = GLOBE_COLUMNS.join(",");
    assert_eq!(
        err(&format!("{header}\nA,0,0,1,warm,21,0.1,0.15,0.95\n")),
        "globe.csv:2: tg_c 'warm' is not a number"
    );
    assert_eq!(
        err(&format!("# comment\n{header}\nA,0,0,1,20,21,,0.15,0.95\n")),
        "globe.csv:3: va_m_s is missing"
    );
    assert_eq!(
        err(&format!("{header}\nA,0,0,1,20,21,0.1,0.15,inf\n")),
        "globe.csv:2: emissivity 'inf' is not a number"
    );
    assert!(
        err("label,x,y,z,tg_c,ta_c,va_m_s,diameter_m\n")
            .starts_with("globe.csv:1: the header has no column 'emissivity'")
    );
    assert!(err("A,0,0,1,20,21,0.1\n").starts_with("globe.csv:1: expected 9 columns"));
    assert_eq!(
        err(&format!("{header}\n# nothing yet\n")),
        "globe.csv: no readings"
    );
    assert_eq!(err(""), "globe.csv: no readings");
}

fn row(label: &str, tg: f64, ta: f64, v: f64, d: f64) -> GlobeRow {
    GlobeRow {
        label: label.into(),
        xyz: [0.0, 0.0, 1.1],
        tg_c: tg,
        ta_c: ta,
        va_m_s: v,
        diameter_m: d,
        emissivity: 0.95,
        line: 0,
    }
}

/// The globe conversions reproduce pythermalcomfort's published values (shared/reference,
/// physics.md) and the differences and ISO 7726 classes follow from ours − ISO.
#[test]
fn rows_convert_the_globe_and_classify_the_difference() {
    let rows = [
        row("iso-1", 53.2, 30.0, 0.3, 0.1),
        row("iso-2", 55.0, 30.0, 0.1, 0.1),
        row("mixed", 25.42, 26.10, 0.1931, 0.1),
        row("ping-pong", 25.0, 22.0, 0.1, 0.038),
    ];
    // Ours: the published ISO value plus an offset chosen per row.
    let offsets = [0.15, -1.5, 2.5, 0.0];
    let published_iso = [74.8, 71.9];
    let v = validate(&rows, &|_: &[f64; 3]| Ok((0.0, 0.01)));
    assert!((v[0].mrt_iso_c.as_ref().unwrap() - published_iso[0]).abs() < 0.1);
    assert!((v[1].mrt_iso_c.as_ref().unwrap() - published_iso[1]).abs() < 0.1);
    assert!((v[2].mrt_mixed_c.as_ref().unwrap() - 24.2).abs() < 0.1);
    assert!(
        v[3].mrt_mixed_c
            .as_ref()
            .is_err_and(|e| e.to_string().contains("0.038") && e.to_string().contains("0.04")),
        "{:?}",
        v[3].mrt_mixed_c
    );
    // Now put ours at ISO + offset, row by row (the points differ in x).
    let rows: Vec<GlobeRow> = rows
        .iter()
        .enumerate()
        .map(|(k, r)| GlobeRow {
            xyz: [k as f64, 0.0, 1.1],
            ..r.clone()
        })
        .collect();
    let iso: Vec<f64> = v.iter().map(|r| *r.mrt_iso_c.as_ref().unwrap()).collect();
    let v = validate(&rows, &|xyz: &[f64; 3]| {
        let k = xyz[0] as usize;
        Ok((iso[k] + offsets[k], 0.01))
    });
    for (k, r) in v.iter().enumerate() {
        let d = r.diff_iso_k.unwrap();
        assert!((d - offsets[k]).abs() < 1e-9, "row {k}: {d}");
        assert_eq!(r.meets_desired, Some(offsets[k].abs() <= ISO_DESIRED_K));
        assert_eq!(r.meets_required, Some(offsets[k].abs() <= ISO_REQUIRED_K));
    }
    assert_eq!(v[3].diff_mixed_k, None);
    // No map value: no differences, no class.
    let v = validate(&rows[..1], &|_: &[f64; 3]| {
        Err(mrtmap_radiation::MrtError::OutsideRoom {
            point: [0.0, 0.0, 1.1],
            where_: "outside the walls".into(),
            room: "a test room".into(),
        })
    });
    assert_eq!(
        (v[0].diff_iso_k, v[0].meets_required, v[0].meets_desired),
        (None, None, None)
    );
}

#[test]
fn csv_and_json_forms_are_flat_and_quote_labels() {
    let rows = [
        row("desk, north", 25.0, 22.0, 0.1, 0.15),
        row("pp", 25.0, 22.0, 0.1, 0.038),
    ];
    let v = validate(&rows, &|_: &[f64; 3]| Ok((26.5, 0.02)));
    let csv = validation_csv(&v).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 3);
    assert_eq!(lines[0].split(',').count(), 19);
    assert!(lines[0].ends_with(",calibrates,in_sun"));
    assert!(lines[1].starts_with("\"desk, north\",0,0,1.1,25,22,0.1,0.15,0.95,"));
    // The mixed convection columns are blank for the 38 mm globe.
    let cells: Vec<&str> = lines[2].split(',').collect();
    assert_eq!(cells.len(), 19);
    assert_eq!((cells[10], cells[14]), ("", ""));
    assert_eq!(cells[11], "26.500");
    let json = serde_json::to_value(&v).unwrap();
    assert!(json[0]["mrt_iso_c"].is_f64() && json[0]["mrt_mixed_c"].is_f64());
    assert!(json[0].get("mrt_mixed_note").is_none());
    assert_eq!(json[1]["mrt_mixed_c"], serde_json::Value::Null);
    assert!(
        json[1]["mrt_mixed_note"]
            .as_str()
            .unwrap()
            .contains("0.038")
    );
    assert_eq!(json[1]["ours_c"], 26.5);
    assert_eq!(json[1]["ours_std_error_k"], 0.02);
}

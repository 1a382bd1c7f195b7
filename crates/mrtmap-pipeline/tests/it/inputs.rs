//! Property tests of the hand-written inputs (issue 41): references.csv, globe.csv and
//! project.toml, from cells and keys drawn among the values people and programs get wrong (NaN,
//! infinities, overflowing exponents, empty cells, units, commas, non-ASCII digits). Whatever the
//! text, parsing answers or refuses naming the line; nothing panics; what is accepted is finite
//! and in range.

use std::path::Path;

use mrtmap_pipeline::Project;
use mrtmap_pipeline::settings::Reference;
use proptest::prelude::*;

fn cell() -> impl Strategy<Value = String> {
    prop_oneof![
        (-1e4f64..1e4).prop_map(|v| format!("{v}")),
        (-50i32..80).prop_map(|v| v.to_string()),
        prop::sample::select(vec![
            "", "NaN", "nan", "inf", "-inf", "1e999", "-1e999", "1e308", "-0", "0.1", "20,5",
            "20.5 °C", "٣", "room", "scan", "world", "\"x\"", "  ", "0x10", "1_000", "+3",
        ])
        .prop_map(String::from),
        "[a-z ]{0,8}",
    ]
}

fn csv_text(columns: &'static [&'static str]) -> impl Strategy<Value = String> {
    (
        prop::sample::subsequence(columns.to_vec(), 0..=columns.len()).prop_shuffle(),
        prop::collection::vec(prop::collection::vec(cell(), 0..10), 0..6),
        any::<bool>(),
    )
        .prop_map(|(header, rows, comment)| {
            let mut t = String::new();
            if comment {
                t += "# readings\n";
            }
            t += &header.join(",");
            t += "\n";
            for r in rows {
                t += &r.join(",");
                t += "\n";
            }
            t
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn references_csv_answers_or_names_the_line(
        text in csv_text(&["label", "x", "y", "z", "temperature_c", "std_k", "frame", "notes"])
    ) {
        match Reference::parse_csv(&text, Path::new("references.csv")) {
            Ok(refs) => {
                for r in refs {
                    prop_assert!(r.xyz.iter().all(|v| v.is_finite()));
                    prop_assert!(r.temperature_c.is_finite());
                    prop_assert!(r.std_k > 0.0 && r.std_k < 50.0);
                }
            }
            Err(e) => {
                let m = e.to_string();
                prop_assert!(m.contains("references.csv:"), "{m}");
            }
        }
    }

    #[test]
    fn globe_csv_answers_or_names_the_line(
        text in csv_text(&["label", "x", "y", "z", "globe_c", "air_c", "air_speed_m_s", "diameter_m", "emissivity", "time"])
    ) {
        if let Err(e) = mrtmap_report::parse_globe_csv(&text, "globe.csv") {
            let m = e.to_string();
            prop_assert!(m.contains("globe.csv"), "{m}");
        }
    }

    #[test]
    fn project_toml_answers_or_refuses(
        entries in prop::collection::vec(
            (
                prop::sample::select(vec![
                    ("air", "temperature_c"), ("air", "speed_m_s"), ("comfort", "met"),
                    ("comfort", "clo"), ("comfort", "facing_deg"), ("comfort", "relative_humidity_pct"),
                    ("map", "heights_m"), ("map", "grid"), ("segment", "raster_m"),
                    ("room", "origin_corner"), ("fuse", "voxel_m"), ("mrt", "rays"),
                    ("thermal", "absolute_accuracy_k"), ("map", "nope"),
                ]),
                prop_oneof![
                    (-1e3f64..1e3).prop_map(|v| format!("{v:?}")),
                    (-5i64..100_000).prop_map(|v| v.to_string()),
                    prop::sample::select(vec![
                        "nan", "inf", "-inf", "\"20\"", "[]", "[1.1, nan]", "[0, 0]", "[20, 20]",
                        "[1.1]", "true", "1e400", "0",
                    ]).prop_map(String::from),
                ],
            ),
            0..6,
        )
    ) {
        let mut by_table: std::collections::BTreeMap<&str, Vec<String>> = Default::default();
        for ((table, key), value) in &entries {
            by_table.entry(table).or_default().push(format!("{key} = {value}"));
        }
        let text: String = by_table
            .iter()
            .map(|(t, kv)| format!("[{t}]\n{}\n", kv.join("\n")))
            .collect();
        if let Ok(p) = Project::parse(&text) {
            // Checking answers or refuses; it never panics.
            let _ = p.check();
        }
    }
}

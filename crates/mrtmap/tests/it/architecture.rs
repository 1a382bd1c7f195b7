//! ARCHITECTURE.md's crate table is the map of the code: it must list every workspace crate, and
//! each row's "uses" column must name exactly the crates that crate depends on.

use std::collections::BTreeSet;
use std::path::Path;

/// The mrtmap crates named in a "uses" cell (`—` for none; words in parentheses are remarks).
fn named(cell: &str) -> BTreeSet<String> {
    let mut text = String::new();
    let mut depth = 0;
    for c in cell.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            _ if depth == 0 => text.push(c),
            _ => {}
        }
    }
    text.split(',')
        .map(|w| w.trim().trim_matches('`').to_string())
        .filter(|w| !w.is_empty() && w != "—")
        .map(|w| w.trim_start_matches("mrtmap-").to_string())
        .collect()
}

/// The mrtmap crates a crate's Cargo.toml lists under [dependencies] (`mrtmap` is the CLI).
fn dependencies(manifest: &Path) -> BTreeSet<String> {
    let text = std::fs::read_to_string(manifest).unwrap();
    let mut in_deps = false;
    let mut out = BTreeSet::new();
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with('[') {
            in_deps = line == "[dependencies]";
            continue;
        }
        if in_deps && (line.starts_with("mrtmap ") || line.starts_with("mrtmap.")) {
            out.insert("mrtmap".to_string());
        } else if in_deps && let Some(rest) = line.strip_prefix("mrtmap-") {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
                .collect();
            out.insert(name);
        }
    }
    out
}

#[test]
fn the_crate_table_lists_every_crate_and_what_it_uses() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let doc = std::fs::read_to_string(root.join("ARCHITECTURE.md")).unwrap();
    let mut rows = std::collections::BTreeMap::new();
    for line in doc.lines().filter(|l| l.starts_with("| `mrtmap")) {
        let cells: Vec<&str> = line.split(" | ").collect();
        let name = cells[0]
            .trim_start_matches("| ")
            .trim_matches('`')
            .to_string();
        let uses = cells.last().unwrap().trim_end_matches('|').trim();
        rows.insert(name, named(uses));
    }
    let mut crates = BTreeSet::new();
    for entry in std::fs::read_dir(root.join("crates")).unwrap() {
        let dir = entry.unwrap().path();
        if !dir.join("Cargo.toml").is_file() {
            continue;
        }
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let deps = dependencies(&dir.join("Cargo.toml"));
        let listed = rows
            .get(&name)
            .unwrap_or_else(|| panic!("ARCHITECTURE.md's crate table has no row for {name}"));
        assert_eq!(
            listed, &deps,
            "ARCHITECTURE.md says {name} uses {listed:?}; its Cargo.toml says {deps:?}"
        );
        crates.insert(name);
    }
    let extra: Vec<_> = rows.keys().filter(|k| !crates.contains(*k)).collect();
    assert!(
        extra.is_empty(),
        "ARCHITECTURE.md lists crates the workspace lacks: {extra:?}"
    );
    assert!(crates.len() >= 12, "{crates:?}");
}

/// The paths in a "file" cell of the method's table (backticked names with a file extension or a
/// trailing slash; function names are left out).
fn paths_in(cell: &str) -> Vec<String> {
    cell.split('`')
        .skip(1)
        .step_by(2)
        .filter(|w| w.ends_with('/') || [".rs", ".js", ".py"].iter().any(|e| w.ends_with(e)))
        .map(str::to_string)
        .collect()
}

/// Every file that "Where each step of the method lives" names exists, so that a reader who
/// follows it lands on the code. A full path starts with a crate (under `crates/`) or `python/`;
/// a shorter one (`board.rs`, `rtabmap/convert.rs`) is beside, or under a folder above, a full
/// path of the same cell, up to that crate.
#[test]
fn the_method_table_names_files_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let doc = std::fs::read_to_string(root.join("ARCHITECTURE.md")).unwrap();
    let section = doc
        .split("## Where each step of the method lives")
        .nth(1)
        .and_then(|s| s.split("\n## ").next())
        .expect("ARCHITECTURE.md has a section \"Where each step of the method lives\"");
    let mut checked = 0;
    for line in section.lines().filter(|l| l.starts_with('|')) {
        let cells: Vec<&str> = line.split(" | ").collect();
        let Some(cell) = cells.last().filter(|_| cells.len() >= 2) else {
            continue;
        };
        let paths = paths_in(cell);
        let full: Vec<std::path::PathBuf> = paths
            .iter()
            .filter_map(|p| {
                if p.starts_with("mrtmap-") {
                    Some(root.join("crates").join(p))
                } else if p.starts_with("python/") {
                    Some(root.join(p))
                } else {
                    None
                }
            })
            .collect();
        for p in &paths {
            let found = if p.starts_with("mrtmap-") || p.starts_with("python/") {
                full.iter()
                    .any(|f| f.ends_with(p.trim_end_matches('/')) && f.exists())
            } else {
                // Beside a full path of the cell, or under one of its folders up to the crate.
                full.iter().any(|f| {
                    f.ancestors()
                        .skip(1)
                        .take_while(|a| *a != root.join("crates") && *a != root)
                        .any(|a| a.join(p).exists())
                })
            };
            assert!(
                found,
                "ARCHITECTURE.md's method table names {p} in \"{}\", which is not there",
                cells[0].trim_start_matches("| ")
            );
            checked += 1;
        }
    }
    assert!(checked >= 40, "only {checked} paths in the method table");
}

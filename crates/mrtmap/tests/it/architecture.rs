//! ARCHITECTURE.md's crate table is the map of the code: it must list every workspace crate, and
//! each row's "uses" column must name exactly the crates that crate depends on.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

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
    let mut rows = BTreeMap::new();
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
        let full: Vec<PathBuf> = paths
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

/// `text` without its test code: each item under a `#[cfg(test)]` (a `mod tests { … }` block, a
/// `use …;`) left out, wherever it is in the file, and what comes after it kept.
fn without_tests(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(k) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..k]);
        let after = &rest[k + "#[cfg(test)]".len()..];
        let (brace, semi) = (after.find('{'), after.find(';'));
        rest = match (brace, semi) {
            (_, Some(s)) if brace.is_none_or(|b| s < b) => &after[s + 1..],
            (Some(b), _) => {
                let mut depth = 0usize;
                let mut end = after.len();
                for (i, c) in after[b..].char_indices() {
                    match c {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                end = b + i + 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                }
                &after[end..]
            }
            _ => "",
        };
    }
    out.push_str(rest);
    out
}

#[test]
fn test_code_is_left_out_wherever_it_is() {
    let text = "fn a() {}\n#[cfg(test)]\nuse x::y;\nfn b() {}\n#[cfg(test)]\nmod tests {\n    fn t() { let s = 1; }\n}\nfn after() {}\n";
    assert_eq!(
        without_tests(text),
        "fn a() {}\n\nfn b() {}\n\nfn after() {}\n"
    );
}

/// The code of a module file that is not test code, comments dropped.
fn code_of(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let text = without_tests(&text);
    text.lines()
        .map(|l| l.split("//").next().unwrap_or_default())
        .collect::<Vec<_>>()
        .join("\n")
}

/// The crate's modules (files and folders directly in `src/`) and the others each one names as
/// `crate::x`, in a `use crate::{…}` group, or (from a file directly in `src/`) as `super::x`.
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    for e in std::fs::read_dir(src).unwrap().map(Result::unwrap) {
        let p = e.path();
        let name = p.file_stem().unwrap().to_string_lossy().to_string();
        if p.is_dir() {
            let mut all = Vec::new();
            let mut stack = vec![p];
            while let Some(d) = stack.pop() {
                for f in std::fs::read_dir(d).unwrap().map(|e| e.unwrap().path()) {
                    if f.is_dir() {
                        stack.push(f);
                    } else if f.extension().is_some_and(|x| x == "rs") {
                        all.push(f);
                    }
                }
            }
            files.entry(name).or_default().extend(all);
        } else if p.extension().is_some_and(|x| x == "rs") && name != "lib" && name != "main" {
            files.entry(name).or_default().push(p);
        }
    }
    let names: BTreeSet<String> = files.keys().cloned().collect();
    let word = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    files
        .iter()
        .map(|(m, fs)| {
            let mut uses = BTreeSet::new();
            for f in fs {
                let code = code_of(f);
                let top = f.parent() == Some(src);
                let mut names_after = |prefix: &str| {
                    for part in code.split(prefix).skip(1) {
                        if let Some(group) = part.strip_prefix('{') {
                            let group = group.split('}').next().unwrap_or_default();
                            uses.extend(group.split(',').map(|g| word(g.trim())));
                        } else {
                            uses.insert(word(part));
                        }
                    }
                };
                names_after("crate::");
                if top {
                    names_after("super::");
                }
            }
            uses.retain(|u| u != m && names.contains(u));
            (m.clone(), uses)
        })
        .collect()
}

/// A cycle in `g`, if there is one.
fn a_cycle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        g: &BTreeMap<String, BTreeSet<String>>,
        m: &str,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(k) = path.iter().position(|p| p == m) {
            let mut c = path[k..].to_vec();
            c.push(m.to_string());
            return Some(c);
        }
        if done.contains(m) {
            return None;
        }
        path.push(m.to_string());
        for n in g.get(m).into_iter().flatten() {
            if let Some(c) = visit(g, n, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(m.to_string());
        None
    }
    let mut done = BTreeSet::new();
    g.keys()
        .find_map(|m| visit(g, m, &mut Vec::new(), &mut done))
}

/// Issue 53: ARCHITECTURE.md said no crate's modules form a cycle while four did.
#[test]
fn no_crates_modules_form_a_cycle() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut found = Vec::new();
    for e in std::fs::read_dir(&crates).unwrap().map(Result::unwrap) {
        let src = e.path().join("src");
        if src.is_dir()
            && let Some(c) = a_cycle(&module_graph(&src))
        {
            found.push(format!(
                "{}: {}",
                e.file_name().to_string_lossy(),
                c.join(" → ")
            ));
        }
    }
    found.sort();
    assert!(found.is_empty(), "module cycles:\n{}", found.join("\n"));
}

#[test]
fn the_cycle_check_sees_a_cycle() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::write(src.join("lib.rs"), "mod a;\nmod b;\n").unwrap();
    std::fs::write(src.join("a.rs"), "use crate::b::X;\n// crate::c\n").unwrap();
    std::fs::create_dir(src.join("b")).unwrap();
    std::fs::write(src.join("b/mod.rs"), "mod inner;\n").unwrap();
    std::fs::write(src.join("b/inner.rs"), "use crate::{a::Y, b};\n").unwrap();
    let g = module_graph(src);
    assert_eq!(a_cycle(&g), Some(vec!["a".into(), "b".into(), "a".into()]));
    std::fs::write(src.join("b/inner.rs"), "#[cfg(test)]\nuse crate::a::Y;\n").unwrap();
    assert_eq!(a_cycle(&module_graph(src)), None);
}

/// The file of module `name` declared in `file` (`name.rs` or `name/mod.rs` beside a `lib.rs` or
/// `mod.rs`, else in the folder named after `file`).
fn module_file(file: &Path, name: &str) -> Option<PathBuf> {
    let parent = file.parent()?;
    let stem = file.file_stem()?.to_string_lossy();
    let dir = if stem == "lib" || stem == "mod" {
        parent.to_path_buf()
    } else {
        parent.join(stem.as_ref())
    };
    [
        dir.join(format!("{name}.rs")),
        dir.join(name).join("mod.rs"),
    ]
    .into_iter()
    .find(|p| p.is_file())
}

/// The names a `pub use` statement (the text after `pub use`, up to its `;`) re-exports: one per
/// leaf of its tree (`a::{B, c::{D, E}}` is three; `X as Y` is one).
fn use_leaves(tree: &str) -> Vec<String> {
    tree.replace(['{', '}'], "")
        .split(',')
        .map(|leaf| leaf.split_whitespace().collect::<Vec<_>>().join(" "))
        .filter(|leaf| !leaf.is_empty())
        .collect()
}

/// The public items of the module in `file`, named under `path`, pushed onto `items`. The rule
/// (issue 53's count of a crate's API): from `lib.rs`, every file of a `pub mod`, followed down (a
/// `mod` without `pub` is private and not read); in each, the items that start a line (not
/// indented: methods, fields and variants belong to their type) declared `pub` (not `pub(crate)`):
/// fn, struct, enum, const, static, trait, type, union, mod; each name a `pub use` re-exports
/// (`pub use m::*` counts the public items of the child module `m` as its own); an inline `pub mod x { … }`
/// counts itself and its items indented once; its `#[cfg(test)]` items left out (what comes after
/// them counted).
fn public_items(file: &Path, path: &str, items: &mut Vec<String>) {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let code = without_tests(&text);
    let code = code.as_str();
    let lines: Vec<&str> = code.lines().collect();
    let mut inline: Option<String> = None;
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        i += 1;
        let (item, within) = match &inline {
            Some(_) if line == "}" => {
                inline = None;
                continue;
            }
            Some(m) => match line.strip_prefix("    ") {
                Some(l) if !l.starts_with(' ') => (l, format!("{path}::{m}")),
                _ => continue,
            },
            None if line.starts_with(char::is_whitespace) => continue,
            None => (line, path.to_string()),
        };
        let Some(rest) = item.strip_prefix("pub ") else {
            continue;
        };
        let words: Vec<&str> = rest.split_whitespace().collect();
        let mut k = 0;
        while k + 1 < words.len()
            && (["unsafe", "async", "extern", "\"C\""].contains(&words[k])
                || (words[k] == "const" && words[k + 1] == "fn"))
        {
            k += 1;
        }
        let kind = words.get(k).copied().unwrap_or("");
        if kind == "use" {
            let mut statement = rest.trim_start_matches("use").to_string();
            while !statement.contains(';') && i < lines.len() {
                statement.push_str(lines[i]);
                i += 1;
            }
            let tree = statement.split(';').next().unwrap_or("");
            for leaf in use_leaves(tree) {
                if let Some(module) = leaf.strip_suffix("::*") {
                    let child = module_file(file, module.trim()).unwrap_or_else(|| {
                        panic!("{}: cannot count `pub use {leaf}`", file.display())
                    });
                    public_items(&child, &within, items);
                } else {
                    let name = leaf.rsplit([' ', ':']).next().unwrap_or("");
                    items.push(format!("{within}::{name}"));
                }
            }
            continue;
        }
        let name: String = words
            .get(k + 1)
            .unwrap_or(&"")
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        items.push(format!("{within}::{name}"));
        if kind == "mod" {
            if rest.trim_end().ends_with('{') {
                inline = Some(name);
            } else if let Some(child) = module_file(file, &name) {
                public_items(&child, &format!("{within}::{name}"), items);
            }
        }
    }
}

/// The counting rule on a small crate: what it reads and what it leaves out.
#[test]
fn the_public_item_count_follows_its_rule() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    std::fs::create_dir_all(src.join("b")).unwrap();
    std::fs::write(
        src.join("lib.rs"),
        "pub mod a;\nmod b;\nmod c;\npub use b::{X, y::{Z, W as V}};\npub use c::*;\n\
         pub(crate) fn hidden() {}\npub mod files {\n    pub use std::fs::{read, write};\n}\n\
         pub const N: usize = 1;\n",
    )
    .unwrap();
    std::fs::write(
        src.join("a.rs"),
        "pub fn f() {}\npub struct S {\n    pub field: u8,\n}\nimpl S {\n    pub fn m() {}\n}\n\
         pub(crate) struct T;\n#[cfg(test)]\nmod tests {\n    pub fn t() {}\n}\npub fn after_tests() {}\n",
    )
    .unwrap();
    std::fs::write(src.join("b/mod.rs"), "pub fn private_module() {}\n").unwrap();
    std::fs::write(src.join("c.rs"), "pub enum E {}\npub(crate) fn g() {}\n").unwrap();
    let mut items = Vec::new();
    public_items(&src.join("lib.rs"), "crate", &mut items);
    assert_eq!(
        items,
        [
            "crate::a",
            "crate::a::f",
            "crate::a::S",
            "crate::a::after_tests",
            "crate::X",
            "crate::Z",
            "crate::V",
            "crate::E",
            "crate::files",
            "crate::files::read",
            "crate::files::write",
            "crate::N",
        ]
    );
}

/// Issue 53: mrtmap-pipeline's API grew to some 350 public items (every stage function, every
/// library type a module used); a front end needs the front door (`Pipeline`), the settings and
/// the types its results carry. At most 150, counted by `public_items`'s rule.
#[test]
fn the_pipelines_public_api_stays_small() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut items = Vec::new();
    public_items(
        &root.join("crates/mrtmap-pipeline/src/lib.rs"),
        "mrtmap_pipeline",
        &mut items,
    );
    assert!(
        items.iter().any(|i| i == "mrtmap_pipeline::Pipeline"),
        "the count found no Pipeline: {items:#?}"
    );
    assert!(
        items.len() <= 150,
        "mrtmap-pipeline has {} public items, at most 150 (issue 53): make what no front end uses pub(crate)\n{items:#?}",
        items.len()
    );
}

/// The Rust files under `dir`, recursively.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Issue 53: no source file is longer than 1,250 lines without its tests (its `#[cfg(test)]`
/// items, wherever they are: issue 61 found a file counted only up to a test function near its
/// top); a longer one is split at its seams.
#[test]
fn no_source_file_is_longer_than_1250_lines_without_its_tests() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut files = Vec::new();
    for dir in ["crates", "fuzz"] {
        rust_files(&root.join(dir), &mut files);
    }
    assert!(files.len() > 100, "found only {} files", files.len());
    let long: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let text = std::fs::read_to_string(f).unwrap();
            let n = without_tests(&text).lines().count();
            (n > 1250).then(|| format!("{} ({n} lines)", f.display()))
        })
        .collect();
    assert!(long.is_empty(), "longer than 1,250 lines: {long:?}");
}

/// Issue 61: no program decides by comparing a message's or a label's words: errors carry their
/// kind, labels go through the vocabulary (`mrtmap_radiation::ElementKind`), the recording's file
/// names through `mrtmap_io::RecordingFile`. A comparison with a string literal, or a message cut
/// at ": ", is allowed only where a file format's own words are read (its field names, keywords
/// and encodings), in the files named here with why.
#[test]
fn no_program_decides_by_comparing_text() {
    const FORMAT_READERS: &[(&str, &str)] = &[
        (
            "crates/mrtmap-sources/src/",
            "ROS, MCAP and RTAB-Map fields and encodings",
        ),
        (
            "crates/mrtmap-export/src/hbjson.rs",
            "Honeybee's face types and keys, a CSV header",
        ),
        (
            "crates/mrtmap-export/src/lib.rs",
            "a number's printed text (-0 as 0)",
        ),
        (
            "crates/mrtmap-radiation/src/scene/read.rs",
            "serde's path of a JSON field",
        ),
        (
            "crates/mrtmap-pipeline/src/export.rs",
            "a scene file's own name",
        ),
    ];
    const SIGNS: [&str; 6] = [
        "== \"",
        "!= \"",
        ".to_string().contains(",
        "split(\": \")",
        "rsplit(\": \")",
        "split_once(\": \")",
    ];
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut files = Vec::new();
    rust_files(&root.join("crates"), &mut files);
    let mut found = Vec::new();
    let mut read = 0;
    for f in &files {
        let rel = f
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        let in_src = rel.split('/').nth(2) == Some("src");
        if !in_src || FORMAT_READERS.iter().any(|(p, _)| rel.starts_with(p)) {
            continue;
        }
        read += 1;
        let code = without_tests(&std::fs::read_to_string(f).unwrap());
        for (n, line) in code.lines().enumerate() {
            let c = line.split("//").next().unwrap_or_default();
            if SIGNS.iter().any(|s| c.contains(s)) {
                found.push(format!("{rel}: {}", c.trim()));
                let _ = n;
            }
        }
    }
    assert!(read > 100, "read only {read} files");
    assert!(found.is_empty(), "text compared:\n{}", found.join("\n"));
}

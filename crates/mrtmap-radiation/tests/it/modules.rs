//! ARCHITECTURE.md says no crate's modules form a cycle: this crate's top-level modules do not, and
//! neither do mrtmap-scan's (checked from here, with the same function, on its sources).
//!
//! A top-level module is a file `src/x.rs` or a folder `src/x/` (all the files under it). It uses
//! another when its text names it: `crate::y` (also in paths such as `crate::y::Item` and doc
//! links), each first name of a `crate::{y, z::Item}` group, and `super::` paths that climb, from
//! the file's place under `src/`, up to the crate's root (`super::y` in `src/x/mod.rs`). A `super::`
//! inside an inline module (`mod tests { use super::*; }`) is read as if in the file itself, which
//! only ever climbs less far than it does.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Which top-level modules each top-level module uses, from the crate's source files given as
/// (path under `src/` with `/` separators, text).
fn module_graph(files: &[(String, String)]) -> BTreeMap<String, BTreeSet<String>> {
    // `x.rs` and everything under `x/` are module `x`; `lib.rs` and `main.rs` are the root.
    let top = |path: &str| -> Option<String> {
        match path.split_once('/') {
            Some((dir, _)) => Some(dir.to_string()),
            None => path
                .strip_suffix(".rs")
                .filter(|name| !["lib", "main"].contains(name))
                .map(str::to_string),
        }
    };
    let modules: BTreeSet<String> = files.iter().filter_map(|(p, _)| top(p)).collect();
    let mut graph: BTreeMap<String, BTreeSet<String>> = modules
        .iter()
        .map(|m| (m.clone(), BTreeSet::new()))
        .collect();
    for (path, text) in files {
        let Some(from) = top(path) else { continue };
        // The file's depth below the crate's root: `x.rs` and `x/mod.rs` are 1, `x/a.rs` is 2.
        let parts: Vec<&str> = path.split('/').collect();
        let depth = parts.len() - usize::from(parts.last() == Some(&"mod.rs"));
        for name in referenced_roots(text, depth) {
            if name != from
                && modules.contains(&name)
                && let Some(uses) = graph.get_mut(&from)
            {
                uses.insert(name);
            }
        }
    }
    graph
}

/// The names a file's text reaches at the crate's root: after `crate::`, and after as many
/// `super::` as the file's `depth`.
fn referenced_roots(text: &str, depth: usize) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let bytes = text.as_bytes();
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut i = 0;
    while i < bytes.len() {
        let starts_word = i == 0 || !(ident(bytes[i - 1]) || bytes[i - 1] == b':');
        let rest = &bytes[i..];
        let after = if starts_word && rest.starts_with(b"crate::") {
            Some(i + "crate::".len())
        } else if starts_word && rest.starts_with(b"super::") {
            let mut j = i;
            let mut climbs = 0;
            while bytes[j..].starts_with(b"super::") {
                j += "super::".len();
                climbs += 1;
            }
            (climbs == depth).then_some(j)
        } else {
            None
        };
        let Some(at) = after else {
            i += 1;
            continue;
        };
        if bytes.get(at) == Some(&b'{') {
            // A group: the first name of each item at its own level.
            let mut level = 0;
            let mut item_start = true;
            for (k, &c) in bytes[at..].iter().enumerate() {
                match c {
                    b'{' => {
                        level += 1;
                        item_start = level == 1;
                    }
                    b'}' => {
                        level -= 1;
                        if level == 0 {
                            break;
                        }
                    }
                    b',' if level == 1 => item_start = true,
                    c if item_start && level == 1 && ident(c) => {
                        let name: String = bytes[at + k..]
                            .iter()
                            .take_while(|&&c| ident(c))
                            .map(|&c| char::from(c))
                            .collect();
                        out.insert(name);
                        item_start = false;
                    }
                    _ => {}
                }
            }
        } else {
            let name: String = bytes[at..]
                .iter()
                .take_while(|&&c| ident(c))
                .map(|&c| char::from(c))
                .collect();
            if !name.is_empty() {
                out.insert(name);
            }
        }
        i = at;
    }
    out
}

/// A cycle of `graph`, as the modules along it with the first repeated at the end.
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        New,
        OnPath,
        Done,
    }
    fn visit(
        m: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        marks: &mut BTreeMap<String, Mark>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        marks.insert(m.to_string(), Mark::OnPath);
        path.push(m.to_string());
        for next in graph.get(m).into_iter().flatten() {
            match marks.get(next).copied().unwrap_or(Mark::New) {
                Mark::OnPath => {
                    let from = path.iter().position(|p| p == next).unwrap();
                    let mut cycle = path[from..].to_vec();
                    cycle.push(next.clone());
                    return Some(cycle);
                }
                Mark::New => {
                    if let Some(cycle) = visit(next, graph, marks, path) {
                        return Some(cycle);
                    }
                }
                Mark::Done => {}
            }
        }
        path.pop();
        marks.insert(m.to_string(), Mark::Done);
        None
    }
    let mut marks = BTreeMap::new();
    for m in graph.keys() {
        if marks.get(m).copied().unwrap_or(Mark::New) == Mark::New
            && let Some(cycle) = visit(m, graph, &mut marks, &mut Vec::new())
        {
            return Some(cycle);
        }
    }
    None
}

/// Every `.rs` file under `src` as (path under `src`, text).
fn sources(src: &Path) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut dirs = vec![src.to_path_buf()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(src).unwrap();
                let rel: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                out.push((rel.join("/"), std::fs::read_to_string(&path).unwrap()));
            }
        }
    }
    out.sort();
    out
}

/// Asserts that the top-level modules of the crate in `crate_dir` form no cycle.
fn assert_no_module_cycle(crate_dir: &Path) {
    let graph = module_graph(&sources(&crate_dir.join("src")));
    assert!(graph.len() >= 5, "{graph:?}");
    if let Some(cycle) = find_cycle(&graph) {
        panic!(
            "the top-level modules of {} form a cycle: {} (each uses the next: move what they \
             share to the module it belongs to)\nall uses: {graph:#?}",
            crate_dir.display(),
            cycle.join(" → ")
        );
    }
}

#[test]
fn this_crates_top_level_modules_form_no_cycle() {
    assert_no_module_cycle(Path::new(env!("CARGO_MANIFEST_DIR")));
}

#[test]
fn mrtmap_scans_top_level_modules_form_no_cycle() {
    assert_no_module_cycle(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../mrtmap-scan"));
}

/// The cycles an outside review found in this crate (`raster` ↔ `scene`, and `bounds` → `field`
/// → `engine` → `bounds`), written as the modules then used each other, are found.
#[test]
fn a_cycle_through_modules_is_found_and_named() {
    let file = |path: &str, text: &str| (path.to_string(), text.to_string());
    let files = [
        file(
            "lib.rs",
            "mod bounds; mod engine; pub use bounds::RoomBounds;",
        ),
        file("bounds.rs", "use crate::field::{FieldError, MapFrame};"),
        file(
            "field.rs",
            "use crate::bounds::RoomBounds;\nuse crate::engine::MrtEngine;",
        ),
        file("engine.rs", "use crate::bounds::RoomBounds;"),
        file(
            "grey.rs",
            "/// See [`crate::engine::MrtEngine`].\nuse crate::engine::MrtEngine;",
        ),
    ];
    let graph = module_graph(&files);
    assert!(!graph.contains_key("lib"), "{graph:?}");
    assert_eq!(
        find_cycle(&graph),
        Some(vec!["bounds".into(), "field".into(), "bounds".into()])
    );
    let files = [
        file(
            "raster.rs",
            "use crate::scene::{SceneError, TEMPERATURE_RANGE_C};",
        ),
        file("scene.rs", "use crate::raster::{Raster, RasterFile};"),
        file("sun.rs", "use crate::scene::RadiantScene;"),
    ];
    assert_eq!(
        find_cycle(&module_graph(&files)),
        Some(vec!["raster".into(), "scene".into(), "raster".into()])
    );
    // Without the way back, no cycle.
    let files = [
        file("bounds.rs", "use crate::map_frame::{FieldError, MapFrame};"),
        file(
            "field.rs",
            "use crate::{bounds::RoomBounds, engine::{MrtEngine, PointMrt}};",
        ),
        file("engine.rs", "use crate::bounds::RoomBounds;"),
        file("map_frame.rs", "use crate::scene::RadiantScene;"),
        file("scene/mod.rs", "mod raster;\npub use raster::Raster;"),
        file("scene/raster.rs", "use super::error::SceneError;"),
    ];
    let graph = module_graph(&files);
    assert_eq!(find_cycle(&graph), None, "{graph:?}");
    assert_eq!(
        graph["field"],
        BTreeSet::from(["bounds".to_string(), "engine".to_string()])
    );
    assert!(graph["scene"].is_empty(), "{graph:?}");
}

/// `use crate::{a, b::{c, d}}` names `a` and `b`; `super::` reaches the root from a folder's
/// `mod.rs` in one step and from a file beside it in two; a word that merely ends in `crate` or
/// `super` is no path.
#[test]
fn groups_and_climbing_super_paths_are_references() {
    let roots = |text: &str, depth: usize| -> Vec<String> {
        referenced_roots(text, depth).into_iter().collect()
    };
    assert_eq!(
        roots("use crate::{field::{A, B}, engine, scene::X};", 1),
        ["engine", "field", "scene"]
    );
    assert_eq!(roots("use super::engine::X;", 1), ["engine"]);
    assert_eq!(roots("use super::engine::X;", 2), Vec::<String>::new());
    assert_eq!(
        roots("use super::super::{engine, field};", 2),
        ["engine", "field"]
    );
    assert_eq!(
        roots("my_crate::engine; notsuper::field", 1),
        Vec::<String>::new()
    );
}

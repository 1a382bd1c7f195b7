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

/// Every module of the crate in `src` by its path (`a`, `a::b` for `a/b.rs` or `a/b/mod.rs`; the
/// crate root is ""), with its file.
fn module_files(src: &Path) -> BTreeMap<String, PathBuf> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    files
        .into_iter()
        .map(|f| {
            let rel = f.strip_prefix(src).unwrap().with_extension("");
            let mut parts: Vec<String> = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().to_string())
                .collect();
            if parts
                .last()
                .is_some_and(|l| l == "mod" || l == "lib" || l == "main")
            {
                parts.pop();
            }
            (parts.join("::"), f)
        })
        .collect()
}

/// The paths `code` names from `crate::`, `super::` or `self::`, and, with `relative`, from a
/// name of its own child modules: each as (its head, its segments), a `{…}` group expanded one
/// level deep (a nested group's leading path is kept).
fn named_paths(code: &str, children: &BTreeSet<String>) -> Vec<(String, Vec<String>)> {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let mut out = Vec::new();
    let bytes: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < bytes.len() {
        if !ident(bytes[i]) || (i > 0 && (ident(bytes[i - 1]) || bytes[i - 1] == ':')) {
            i += 1;
            continue;
        }
        // A path starting here: idents separated by `::`, maybe ending in a group.
        let mut segs: Vec<String> = Vec::new();
        let mut j = i;
        let mut group: Option<String> = None;
        loop {
            let start = j;
            while j < bytes.len() && ident(bytes[j]) {
                j += 1;
            }
            segs.push(bytes[start..j].iter().collect());
            if bytes.get(j) == Some(&':') && bytes.get(j + 1) == Some(&':') {
                j += 2;
                if bytes.get(j) == Some(&'{') {
                    let mut depth = 0;
                    let open = j;
                    while j < bytes.len() {
                        match bytes[j] {
                            '{' => depth += 1,
                            '}' => {
                                depth -= 1;
                                if depth == 0 {
                                    break;
                                }
                            }
                            _ => {}
                        }
                        j += 1;
                    }
                    group = Some(bytes[open + 1..j.min(bytes.len())].iter().collect());
                    break;
                }
                if j < bytes.len() && ident(bytes[j]) {
                    continue;
                }
            }
            break;
        }
        let head = segs[0].clone();
        if matches!(head.as_str(), "crate" | "super" | "self") || children.contains(&head) {
            let base: Vec<String> = segs[1..].to_vec();
            match group {
                Some(g) => {
                    let mut depth = 0;
                    let mut cur = String::new();
                    let mut parts = Vec::new();
                    for c in g.chars() {
                        match c {
                            '{' => depth += 1,
                            '}' => depth -= 1,
                            ',' if depth == 0 => parts.push(std::mem::take(&mut cur)),
                            _ => {}
                        }
                        if !(c == ',' && depth == 0) {
                            cur.push(c);
                        }
                    }
                    parts.push(cur);
                    for part in parts {
                        let lead: Vec<String> = part
                            .trim()
                            .split("::")
                            .map(|x| x.chars().take_while(|c| ident(*c)).collect::<String>())
                            .take_while(|x| !x.is_empty())
                            .collect();
                        if !lead.is_empty() {
                            out.push((head.clone(), [base.clone(), lead].concat()));
                        }
                    }
                }
                None => out.push((head, base)),
            }
        }
        i = j.max(i + 1);
    }
    out
}

/// The module a path names from module `at`: the longest prefix that is a module, followed
/// through that module's re-exports (`pub use child::X`) to where the name is declared.
fn resolve_module(
    modules: &BTreeMap<String, PathBuf>,
    reexports: &BTreeMap<(String, String), String>,
    at: &str,
    head: &str,
    segs: &[String],
) -> Option<String> {
    let here: Vec<String> = if at.is_empty() {
        Vec::new()
    } else {
        at.split("::").map(String::from).collect()
    };
    let full: Vec<String> = match head {
        "crate" => segs.to_vec(),
        "super" => [here[..here.len().saturating_sub(1)].to_vec(), segs.to_vec()].concat(),
        "self" => [here.clone(), segs.to_vec()].concat(),
        child => [here.clone(), vec![child.to_string()], segs.to_vec()].concat(),
    };
    let k = (0..=full.len())
        .rev()
        .find(|&k| modules.contains_key(&full[..k].join("::")))?;
    let module = full[..k].join("::");
    match full.get(k) {
        Some(name) => match reexports.get(&(module.clone(), name.clone())) {
            Some(m) if *m != module => Some(m.clone()),
            _ => Some(module),
        },
        None => Some(module),
    }
}

/// The crate's modules, each with the others it names (through re-exports to the module that
/// declares the name), leaving out a module's own ancestors and descendants (a parent declares and
/// re-exports its children, and a child may use its parent's items: that is nesting, not a cycle).
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let modules = module_files(src);
    let code: BTreeMap<String, String> = modules
        .iter()
        .map(|(m, f)| (m.clone(), code_of(f)))
        .collect();
    let children = |m: &str| -> BTreeSet<String> {
        modules
            .keys()
            .filter_map(|k| {
                let rest = if m.is_empty() {
                    Some(k.as_str())
                } else {
                    k.strip_prefix(m).and_then(|r| r.strip_prefix("::"))
                };
                rest.filter(|r| !r.is_empty() && !r.contains("::"))
                    .map(String::from)
            })
            .collect()
    };
    // Re-exports: (module, name) → the module the name comes from, resolved in passes so that a
    // chain of re-exports is followed.
    let mut reexports: BTreeMap<(String, String), String> = BTreeMap::new();
    for _ in 0..4 {
        for (m, c) in &code {
            let kids = children(m);
            for stmt in c.split(';') {
                let Some(k) = stmt.find("use ") else { continue };
                if !stmt[..k].trim().starts_with("pub") {
                    continue;
                }
                for (head, segs) in named_paths(&stmt[k + 4..], &kids) {
                    let (Some(name), Some(target)) = (
                        segs.last(),
                        resolve_module(&modules, &reexports, m, &head, &segs),
                    ) else {
                        continue;
                    };
                    if target != *m {
                        reexports.insert((m.clone(), name.clone()), target);
                    }
                }
            }
        }
    }
    code.iter()
        .map(|(m, c)| {
            let kids = children(m);
            let uses: BTreeSet<String> = named_paths(c, &kids)
                .into_iter()
                .filter_map(|(head, segs)| resolve_module(&modules, &reexports, m, &head, &segs))
                .filter(|t| {
                    let nested =
                        |a: &str, b: &str| a.is_empty() || b.starts_with(&format!("{a}::"));
                    t != m && !nested(t, m) && !nested(m, t)
                })
                .collect();
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
    std::fs::write(src.join("b/mod.rs"), "mod inner;\npub use inner::X;\n").unwrap();
    std::fs::write(
        src.join("b/inner.rs"),
        "use crate::{a::Y, b};\npub struct X;\n",
    )
    .unwrap();
    let g = module_graph(src);
    // Through b's re-export, a uses b::inner, which uses a.
    assert_eq!(
        a_cycle(&g),
        Some(vec!["a".into(), "b::inner".into(), "a".into()])
    );
    std::fs::write(
        src.join("b/inner.rs"),
        "#[cfg(test)]\nuse crate::a::Y;\npub struct X;\n",
    )
    .unwrap();
    assert_eq!(a_cycle(&module_graph(src)), None);
    // Siblings inside a folder.
    std::fs::write(
        src.join("b/mod.rs"),
        "mod inner;\nmod other;\npub use inner::X;\n",
    )
    .unwrap();
    std::fs::write(
        src.join("b/inner.rs"),
        "use super::other::Z;\npub struct X;\n",
    )
    .unwrap();
    std::fs::write(
        src.join("b/other.rs"),
        "use super::inner::X;\npub struct Z;\n",
    )
    .unwrap();
    assert_eq!(
        a_cycle(&module_graph(src)),
        Some(vec![
            "b::inner".into(),
            "b::other".into(),
            "b::inner".into()
        ])
    );
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

/// Issue 61: `[mrt]`'s keys are spelled in Python's wrapper, its stub, the extension's signatures
/// and the keyword list that turns them into the project's keys; a key added to `MrtSection` (or
/// renamed) and not to each of them fails here.
#[test]
fn the_mrt_keys_are_the_same_in_every_front_end() {
    let section = serde_json::to_value(mrtmap_pipeline::MrtSection::default()).unwrap();
    let keys: Vec<String> = section.as_object().unwrap().keys().cloned().collect();
    assert_eq!(keys.len(), 7, "{keys:?}");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let read = |f: &str| std::fs::read_to_string(root.join(f)).unwrap();
    // (file, how a key is spelled there, how many times: one per Scene method taking [mrt])
    let places = [
        ("python/mrtmap/__init__.py", "{k}: Optional[", 4),
        ("python/mrtmap/_mrtmap.pyi", "{k}: Optional[", 4),
        ("crates/mrtmap-py/src/scene.rs", "{k}=None", 4),
        ("crates/mrtmap-py/src/lib.rs", "\"mrt.{k}\"", 1),
    ];
    for (file, form, n) in places {
        let text = read(file);
        for k in &keys {
            let spelled = form.replace("{k}", k);
            assert!(
                text.matches(&spelled).count() >= n,
                "{file} spells [mrt] {k} as {spelled} fewer than {n} times"
            );
        }
    }
}

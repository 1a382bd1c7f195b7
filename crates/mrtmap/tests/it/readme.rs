//! README.md is a guide, not a lab notebook: short, undated, and each figure with the command that
//! reproduces it (the dated history lives in docs/measurement-log.md).

fn readme() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../README.md")).unwrap()
}

/// Whether `w` at the start of `s` looks like an ISO date (2026-12-07 or 2026-12).
fn starts_with_date(s: &[u8]) -> bool {
    let digits =
        |r: std::ops::Range<usize>| r.clone().all(|i| s.get(i).is_some_and(u8::is_ascii_digit));
    digits(0..4) && s.get(4) == Some(&b'-') && digits(5..7) && s[0] == b'2' && s[1] == b'0'
}

#[test]
fn the_readme_has_no_date() {
    let text = readme();
    for (n, line) in text.lines().enumerate() {
        let b = line.as_bytes();
        let dated = (0..b.len())
            .any(|i| (i == 0 || !b[i - 1].is_ascii_digit()) && starts_with_date(&b[i..]));
        assert!(
            !dated,
            "README.md line {}: a date (dated figures go to docs/measurement-log.md): {line}",
            n + 1
        );
    }
}

#[test]
fn the_readme_is_at_most_2000_words() {
    let words = readme().split_whitespace().count();
    assert!(
        words <= 2000,
        "README.md has {words} words: keep it a guide (at most 2,000)"
    );
}

#[test]
fn every_figure_in_the_readmes_accuracy_table_names_its_bench_command() {
    let text = readme();
    let table = text
        .split("## How accurate and how fast")
        .nth(1)
        .expect("README.md has its figures section")
        .split("\n## ")
        .next()
        .unwrap_or_default();
    let rows: Vec<&str> = table
        .lines()
        .filter(|l| l.starts_with('|') && !l.starts_with("| what") && !l.starts_with("|---"))
        .collect();
    assert!(rows.len() >= 5, "{rows:?}");
    for row in rows {
        assert!(
            row.contains("`bench/run "),
            "a figure without its bench/run command: {row}"
        );
    }
}

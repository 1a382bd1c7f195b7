//! CLI round trips: run the built binary and check what it prints and writes.
#![allow(clippy::unwrap_used)]

mod architecture;
mod calibrate;
mod cli;
mod export;
mod live;
mod pipeline;
mod readme;
mod refusals;
mod sources;
mod stages;
mod sun;

/// Runs the built binary.
fn mrtmap(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_mrtmap"))
        .args(args)
        .output()
        .unwrap()
}

/// Runs it, asserts success, returns stdout.
fn ok(args: &[&str]) -> String {
    let o = mrtmap(args);
    assert!(
        o.status.success(),
        "mrtmap {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

/// Runs it, asserts success, returns stdout read as JSON.
fn ok_json(args: &[&str]) -> serde_json::Value {
    let out = mrtmap(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Runs it, asserts failure with `needle` in stderr, and no panic.
fn fails_with(args: &[&str], needle: &str) {
    let out = mrtmap(args);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(needle), "stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

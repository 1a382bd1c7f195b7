//! CLI round trips: run the built binary and check what it prints and writes.
#![allow(clippy::unwrap_used)]

mod architecture;
mod calibrate;
mod cli;
mod live;
mod pipeline;
mod readme;
mod sources;

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

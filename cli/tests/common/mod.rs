//! What the `snapgen` binary's tests share: running it, checking it succeeded, scratch paths.
#![allow(dead_code)] // each test file uses its own subset

use std::path::PathBuf;
use std::process::{Command, Output};

/// Runs the built `snapgen` with `args`.
pub fn snapgen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_snapgen"))
        .args(args)
        .output()
        .expect("run snapgen")
}

/// Fails the test, showing what `snapgen` wrote, unless it exited with success.
pub fn assert_ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `snapgen args`, asserted to succeed.
pub fn snapgen_ok(args: &[&str]) -> Output {
    let out = snapgen(args);
    assert_ok(&out);
    out
}

/// A scratch path `name` in this test process's own folder under `group`.
pub fn tmp(group: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("snapgen-{group}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Runs `verilator --lint-only -Wall` on `files` with top `top`: no warning, no error.
pub fn lint_clean(dir: &std::path::Path, top: &str, files: &[String]) {
    let lint = Command::new("verilator")
        .current_dir(dir)
        .args(["--lint-only", "-Wall", "--top-module", top])
        .args(files)
        .output()
        .expect("verilator is installed by the test command");
    let text = String::from_utf8_lossy(&lint.stderr);
    assert!(
        lint.status.success() && !text.contains("%Warning"),
        "{top}: {text}"
    );
}

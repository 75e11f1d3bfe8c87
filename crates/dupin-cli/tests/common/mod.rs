//! Helpers shared by the CLI end-to-end tests: run the built `dupin`, name temp files, read
//! JSON reports.
#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};
use std::process::Command;

/// A file name in the temp directory, unique per test process.
pub fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("dupin-test-{}-{name}", std::process::id()))
}

/// Runs the `dupin` binary of this build.
pub fn dupin(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_dupin"))
        .args(args)
        .output()
        .expect("dupin runs")
}

/// Reads a JSON file.
pub fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// The names `dupin COMMAND --list-scenes` prints, one a line (asserting that it succeeds).
pub fn listed_scenes(command: &str) -> Vec<String> {
    let o = dupin(&[command, "--list-scenes"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(String::from)
        .collect()
}

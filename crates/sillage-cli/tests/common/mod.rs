//! Helpers shared by the end-to-end tests: run the `sillage` binary and read what it says.

use std::path::Path;
use std::process::{Command, Output};

/// Runs the `sillage` binary with `args` and collects its output.
pub fn sillage(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sillage"))
        .args(args)
        .output()
        .expect("the sillage binary runs")
}

/// The binary's standard error as text.
pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// A path as a command-line argument (the tests' paths are UTF-8).
pub fn path_str(path: &Path) -> &str {
    path.to_str().expect("utf-8 path")
}

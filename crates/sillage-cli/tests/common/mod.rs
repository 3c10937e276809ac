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

/// Runs a command that must succeed and returns its standard output.
#[allow(dead_code)] // not every test file runs commands through it
pub fn run_ok(args: &[&str]) -> String {
    let output = sillage(args);
    assert!(output.status.success(), "{}", stderr(&output));
    String::from_utf8(output.stdout).expect("utf-8 output")
}

/// Runs a command that must fail as a user error (exit 1) and returns its message.
#[allow(dead_code)] // not every test file runs commands through it
pub fn run_user_error(args: &[&str]) -> String {
    let output = sillage(args);
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    stderr(&output)
}

/// Writes `frames` frames of the TracTrac vortex (`sillage synth vortex`) with `particles`
/// particles on `width`×`height` px into `out`, with the generator's `extra` options.
#[allow(dead_code)] // not every test file needs the vortex
pub fn synth_vortex(
    out: &Path,
    frames: u64,
    particles: u64,
    (width, height): (u64, u64),
    extra: &[&str],
) {
    let (frames, particles) = (frames.to_string(), particles.to_string());
    let (width, height) = (width.to_string(), height.to_string());
    let mut args = vec![
        "synth",
        "vortex",
        "--out",
        path_str(out),
        "--frames",
        &frames,
        "--particles",
        &particles,
        "--width",
        &width,
        "--height",
        &height,
    ];
    args.extend_from_slice(extra);
    run_ok(&args);
}

/// Writes generated walkers of `scenario` (`sillage synth walkers`), `frames` long, into `seq`
/// (img1/, gt/gt.txt, seqinfo.ini).
#[allow(dead_code)] // not every test file needs walkers
pub fn synth_walkers(seq: &Path, scenario: &str, frames: u64) {
    run_ok(&[
        "synth",
        "walkers",
        "--scenario",
        scenario,
        "--frames",
        &frames.to_string(),
        "--out",
        path_str(seq),
    ]);
}

//! `sillage ptv --window W --overlap O --jobs J`: a sequence tracked in time windows on local
//! threads and stitched; the output does not depend on `--jobs`, and bad plans are refused.

use std::fs;

mod common;
use common::{path_str, run_ok, run_user_error, sillage, stderr};

#[test]
fn windows_give_the_same_file_whatever_the_jobs() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("vortex");
    common::synth_vortex(&frames, 70, 300, (256, 256), &[]);
    let run = |jobs: &str| {
        let out = dir.path().join(format!("tracks_{jobs}.csv"));
        let json = run_ok(&[
            "ptv",
            path_str(&frames),
            "--out",
            path_str(&out),
            "--window",
            "30",
            "--overlap",
            "8",
            "--jobs",
            jobs,
            "--json",
        ]);
        (fs::read(&out).unwrap(), json)
    };
    let (one, json) = run("1");
    let (three, _) = run("3");
    assert_eq!(one, three, "the file does not depend on --jobs");
    let summary: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(summary["windows"]["windows"], 3, "{summary}");
    assert_eq!(summary["windows"]["seams"].as_array().unwrap().len(), 2);
    let joined = summary["windows"]["seams"][0]["joined"].as_u64().unwrap();
    assert!(joined > 200, "{summary}");
    let rows = String::from_utf8(one).unwrap().lines().count() as u64 - 1;
    assert_eq!(summary["rows"].as_u64(), Some(rows));
}

#[test]
fn bad_windows_are_refused_with_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("vortex");
    common::synth_vortex(&frames, 12, 50, (64, 64), &[]);
    let out = dir.path().join("tracks.csv");
    let ptv = |extra: &[&str]| {
        let mut args = vec!["ptv", path_str(&frames), "--out", path_str(&out)];
        args.extend_from_slice(extra);
        run_user_error(&args)
    };
    let message = ptv(&["--window", "8", "--overlap", "8"]);
    assert!(
        message.contains("overlap") && message.contains("shorter than the window"),
        "{message}"
    );
    let message = ptv(&["--window", "2", "--overlap", "1"]);
    assert!(message.contains("at least 3 frames"), "{message}");
    let message = ptv(&["--window", "10", "--overlap", "2"]);
    assert!(message.contains("at least 4"), "{message}");
    assert!(!out.exists(), "nothing written");
    // Windows and checkpoints do not mix: refused by the argument parser.
    let refused = sillage(&[
        "ptv",
        path_str(&frames),
        "--out",
        path_str(&out),
        "--window",
        "8",
        "--overlap",
        "4",
        "--checkpoint-every",
        "5",
    ]);
    assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
    assert!(
        stderr(&refused).contains("--checkpoint-every"),
        "{}",
        stderr(&refused)
    );
}

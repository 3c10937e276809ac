//! End-to-end tests of `sillage track siftpf` and `sillage bench siftpf` on a generated
//! walkers crossing: the results file and the JSON summary agree, the bench scores ETISEO
//! M1–M3 as the paper defines them, and bad options or folders are user errors naming the
//! problem.

use std::collections::BTreeSet;
use std::fs;

mod common;
use common::{path_str, run_ok, run_user_error, synth_walkers};
use sillage::io::read_mot_rows;

const FRAMES: u64 = 60;

#[test]
fn a_walkers_crossing_is_tracked_and_benched() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("crossing");
    synth_walkers(&seq, "crossing", FRAMES);
    let out = dir.path().join("t.txt");
    let summary = run_ok(&[
        "track",
        "siftpf",
        path_str(&seq.join("img1")),
        "--out",
        path_str(&out),
        "--json",
    ]);
    let summary: serde_json::Value = serde_json::from_str(&summary).unwrap();
    let rows = read_mot_rows(&out).unwrap();
    let ids: BTreeSet<u64> = rows.iter().map(|r| r.id.unwrap()).collect();
    assert!(!ids.is_empty(), "no identity in {}", out.display());
    assert!(
        rows.iter().all(|r| r.frame < FRAMES),
        "a row beyond the sequence"
    );
    assert!(
        rows.iter().all(|r| r.width_px > 0.0 && r.height_px > 0.0),
        "an empty box"
    );
    assert_eq!(summary["selection"], "reliability");
    assert_eq!(summary["frames"].as_u64(), Some(FRAMES));
    assert_eq!(summary["rows"].as_u64(), Some(rows.len() as u64));
    assert_eq!(summary["tracks"].as_u64(), Some(ids.len() as u64));
    assert_eq!(summary["out"].as_str(), Some(path_str(&out)));

    let report = run_ok(&[
        "bench",
        "siftpf",
        path_str(&seq),
        "--selections",
        "reliability",
        "--json",
    ]);
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    let sequences = report["sequences"].as_array().unwrap();
    assert_eq!(sequences.len(), 1, "{report}");
    let row = &sequences[0];
    assert_eq!(row["sequence"], "crossing");
    assert_eq!(row["selection"], "reliability");
    assert_eq!(row["frames"].as_u64(), Some(FRAMES));
    // The same seed tracks the same way.
    assert_eq!(row["tracks"].as_u64(), Some(ids.len() as u64));
    let score = |key: &str| row[key].as_f64().unwrap_or_else(|| panic!("{key}: {row}"));
    let m = [
        score("tracking_time"),
        score("id_persistence"),
        score("id_confusion"),
    ];
    assert!(m.iter().all(|v| (0.0..=1.0).contains(v)), "{row}");
    assert!(
        (score("mean") - (m[0] + m[1] + m[2]) / 3.0).abs() < 1e-12,
        "{row}"
    );
    for key in ["mota", "idf1", "hota", "tracking_ms_per_frame", "fps"] {
        assert!(score(key).is_finite(), "{key}: {row}");
    }
    // One sequence: the combination is that sequence.
    let combined = report["combined"].as_array().unwrap();
    assert_eq!(combined.len(), 1, "{report}");
    assert_eq!(combined[0]["sequence"], "COMBINED");
    for key in [
        "tracking_time",
        "id_persistence",
        "id_confusion",
        "mean",
        "mota",
    ] {
        assert_eq!(combined[0][key], row[key], "{key}");
    }
}

#[test]
fn several_runs_give_the_median_of_each_score_and_count_the_best_selection() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("crossing");
    synth_walkers(&seq, "crossing", FRAMES);
    let bench = |extra: &[&str]| {
        let mut args = vec![
            "bench",
            "siftpf",
            path_str(&seq),
            "--selections",
            "whole-object,reliability",
            "--json",
        ];
        args.extend_from_slice(extra);
        let report: serde_json::Value = serde_json::from_str(&run_ok(&args)).unwrap();
        report["sequences"].as_array().unwrap().clone()
    };
    let seed1 = bench(&["--seed", "1"]);
    let seed2 = bench(&["--seed", "2"]);
    let both = bench(&["--seed", "1", "--runs", "2"]);
    assert_eq!(both.len(), 2);
    let value = |row: &serde_json::Value, key: &str| row[key].as_f64().unwrap();
    for k in 0..2 {
        assert_eq!(both[k]["runs"].as_u64(), Some(2));
        // The median of two runs is their mean.
        for key in ["mean", "mota", "idf1", "hota"] {
            let expected = 0.5 * (value(&seed1[k], key) + value(&seed2[k], key));
            assert!(
                (value(&both[k], key) - expected).abs() < 1e-9,
                "{key}: {} against {expected}",
                both[k][key]
            );
        }
        let wins =
            seed1[k]["best_mean_in"].as_u64().unwrap() + seed2[k]["best_mean_in"].as_u64().unwrap();
        assert_eq!(both[k]["best_mean_in"].as_u64(), Some(wins));
    }
    // In each run, at least one selection has the best M̄.
    for rows in [&seed1, &seed2] {
        assert!(rows.iter().any(|r| r["best_mean_in"].as_u64() == Some(1)));
    }
}

#[test]
fn bad_options_and_folders_are_refused_with_the_problem_named() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.txt");
    let empty = dir.path().join("empty");
    fs::create_dir(&empty).unwrap();
    let track = |extra: &[&str]| {
        let mut args = vec!["track", "siftpf", path_str(&empty), "--out", path_str(&out)];
        args.extend_from_slice(extra);
        run_user_error(&args)
    };

    let message = track(&["--selection", "best"]);
    assert!(
        message.contains("best")
            && message.contains("whole-object")
            && message.contains("detection-order")
            && message.contains("reliability"),
        "{message}"
    );
    let message = track(&["--set", "tracker.filter.particles=0"]);
    assert!(message.contains("tracker.filter.particles"), "{message}");
    let message = run_user_error(&[
        "bench",
        "siftpf",
        path_str(&empty),
        "--seed",
        "18446744073709551615",
        "--runs",
        "2",
    ]);
    assert!(message.contains("--seed"), "{message}");
    let message = run_user_error(&["bench", "siftpf", path_str(&empty), "--selections", "best"]);
    assert!(
        message.contains("best") && message.contains("reliability"),
        "{message}"
    );

    // A sequence folder with its truth but no frames.
    let seq = dir.path().join("no-frames");
    fs::create_dir_all(seq.join("gt")).unwrap();
    fs::write(seq.join("gt/gt.txt"), "1,1,10,20,30,60,1,1,1\n").unwrap();
    let message = run_user_error(&["bench", "siftpf", path_str(&seq)]);
    assert!(
        message.contains("no-frames") && message.contains("img1/") && message.contains("video"),
        "{message}"
    );
    assert!(!out.exists(), "a failed run wrote {}", out.display());
}

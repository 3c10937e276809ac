//! `sillage track bedload` end to end: detections and candidates from CSV, trajectories in
//! BeadTracking's layout, scored against the truth by `sillage eval mot`, and clear errors.

mod common;

use std::fmt::Write as _;
use std::path::Path;

use common::{path_str, sillage, stderr};

const FRAMES: u64 = 30;

/// A bed of 20 resting black beads and 5 transparent beads rolling at 4 px/frame, bead 0
/// missed in frames 10-13 (a weak candidate left there); writes the detections, candidates
/// and the truth (BeadTracking layout, 1-based) into `dir`.
fn write_scene(dir: &Path) {
    let mut detections = String::from("frame,x,y,class,score\n");
    let mut candidates = String::from("frame,x,y,class,score\n");
    let mut truth = String::from("frame,id,x,y,category,vx,vy,motion_state\n");
    for f in 0..FRAMES {
        for i in 0..20 {
            let x = 15.0 + 30.0 * i as f64;
            writeln!(detections, "{f},{x},300,0,1").unwrap();
            writeln!(truth, "{},{},{},301,0,0,0,0", f + 1, i + 1, x + 1.0).unwrap();
        }
        for b in 0..5u64 {
            let x = 900.0 - 4.0 * f as f64 - 100.0 * b as f64;
            let jitter = ((f * 31 + b * 17) % 7) as f64 / 10.0 - 0.3;
            let line = format!("{f},{},{},1,", x + jitter, 278.0 - jitter);
            if b == 0 && (10..14).contains(&f) {
                writeln!(candidates, "{line}0.22").unwrap();
            } else {
                writeln!(detections, "{line}0.5").unwrap();
                writeln!(candidates, "{line}0.5").unwrap();
            }
            writeln!(
                truth,
                "{},{},{x_1},279,1,-4,0,1",
                f + 1,
                21 + b,
                x_1 = x + 1.0
            )
            .unwrap();
        }
    }
    std::fs::write(dir.join("det.csv"), detections).unwrap();
    std::fs::write(dir.join("cand.csv"), candidates).unwrap();
    std::fs::write(dir.join("truth.csv"), truth).unwrap();
    // Bead sizes for the disc matching of `eval mot` (6 and 4 mm at 2e-4 m/px: r = 15, 10).
    std::fs::write(
        dir.join("sequence_param.txt"),
        "diamBlackBead\t0.006\tm\ndiamTransBead\t0.004\tm\nmByPx\t0.0002\tm/px\n",
    )
    .unwrap();
}

fn track(dir: &Path, tracker: &str) -> serde_json::Value {
    let out = dir.join(format!("tracks_{tracker}.csv"));
    let output = sillage(&[
        "track",
        "bedload",
        "--detections",
        path_str(&dir.join("det.csv")),
        "--candidates",
        path_str(&dir.join("cand.csv")),
        "--out",
        path_str(&out),
        "--tracker",
        tracker,
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    serde_json::from_slice(&output.stdout).unwrap()
}

fn score(dir: &Path, tracker: &str) -> serde_json::Value {
    let output = sillage(&[
        "eval",
        "mot",
        "--gt",
        path_str(&dir.join("truth.csv")),
        "--pred",
        path_str(&dir.join(format!("tracks_{tracker}.csv"))),
        "--match",
        "disc:0.43",
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    serde_json::from_slice(&output.stdout).unwrap()
}

/// The first number found under `key` anywhere in `value`.
fn find(value: &serde_json::Value, key: &str) -> Option<f64> {
    match value {
        serde_json::Value::Object(map) => map
            .get(key)
            .and_then(serde_json::Value::as_f64)
            .or_else(|| map.values().find_map(|v| find(v, key))),
        serde_json::Value::Array(items) => items.iter().find_map(|v| find(v, key)),
        _ => None,
    }
}

#[test]
fn mmpf_plus_bridges_the_misses_that_break_det() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path());
    let mmpf = track(dir.path(), "mmpf-plus");
    assert_eq!(mmpf["tracks"], 25, "{mmpf}");
    assert_eq!(mmpf["coasted_points"], 4, "{mmpf}");
    let det = track(dir.path(), "det");
    assert_eq!(det["tracks"], 26, "{det}");
    let mmpf_scores = score(dir.path(), "mmpf-plus");
    let det_scores = score(dir.path(), "det");
    let id_switches = |s: &serde_json::Value| find(s, "id_switches");
    let fn_count = |s: &serde_json::Value| find(s, "false_negatives");
    // MMPF+ finds the missed bead in the four frames; DET does not.
    assert_eq!(fn_count(&mmpf_scores), Some(0.0), "{mmpf_scores}");
    assert_eq!(fn_count(&det_scores), Some(4.0), "{det_scores}");
    assert_eq!(id_switches(&mmpf_scores), Some(0.0), "{mmpf_scores}");
}

#[test]
fn every_tracker_runs_and_the_output_is_reproducible() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path());
    for tracker in ["mmpf-plus", "mmpf", "pf", "imm", "det"] {
        let summary = track(dir.path(), tracker);
        assert!(summary["tracks"].as_u64().unwrap() >= 25, "{summary}");
    }
    let first = std::fs::read_to_string(dir.path().join("tracks_mmpf-plus.csv")).unwrap();
    track(dir.path(), "mmpf-plus");
    let second = std::fs::read_to_string(dir.path().join("tracks_mmpf-plus.csv")).unwrap();
    if first != second {
        let diff: Vec<_> = first
            .lines()
            .zip(second.lines())
            .filter(|(a, b)| a != b)
            .take(3)
            .collect();
        panic!("runs differ: {diff:?}");
    }
}

/// `eval mot --papers` of `pred` against the scene's truth, without the file names.
fn paper_scores(dir: &Path, pred: &Path) -> serde_json::Value {
    let output = sillage(&[
        "eval",
        "mot",
        "--gt",
        path_str(&dir.join("truth.csv")),
        "--pred",
        path_str(pred),
        "--match",
        "disc:0.43",
        "--papers",
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let scores: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    scores["sequences"][0]["papers"].clone()
}

#[test]
fn every_output_format_carries_the_motion_states() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path());
    track(dir.path(), "mmpf-plus");
    let beads = paper_scores(dir.path(), &dir.path().join("tracks_mmpf-plus.csv"));
    assert!(
        find(&beads["motion_states"], "f_score").is_some(),
        "{beads}"
    );
    let mut outputs = vec![("csv", "tracks.csv"), ("parquet", "tracks.parquet")];
    if cfg!(feature = "hdf5") {
        outputs.push(("hdf5", "tracks.h5"));
    }
    for (format, name) in outputs {
        let out = dir.path().join(name);
        let output = sillage(&[
            "track",
            "bedload",
            "--detections",
            path_str(&dir.path().join("det.csv")),
            "--candidates",
            path_str(&dir.path().join("cand.csv")),
            "--out",
            path_str(&out),
            "--format",
            format,
        ]);
        assert!(output.status.success(), "{}", stderr(&output));
        // The same tracks, categories and states as BeadTracking's layout.
        assert_eq!(paper_scores(dir.path(), &out), beads, "{format}");
    }
    let text = std::fs::read_to_string(dir.path().join("tracks.csv")).unwrap();
    assert!(text.starts_with(
        "frame,particle,x,y,vx,vy,ax,ay,vx_pred,vy_pred,log_err,class,motion_state,spread_px\n"
    ));
    assert!(text.contains(",1,rolling,"), "transparent beads rolling");
    // TracTrac's layout has no state columns: refused, nothing written.
    let txt = dir.path().join("tracks_track.txt");
    let output = sillage(&[
        "track",
        "bedload",
        "--detections",
        path_str(&dir.path().join("det.csv")),
        "--out",
        path_str(&txt),
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        stderr(&output).contains("motion states"),
        "{}",
        stderr(&output)
    );
    assert!(!txt.exists());
}

#[test]
fn bad_inputs_and_parameters_fail_with_clear_messages() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path());
    let out = dir.path().join("o.csv");
    let run = |extra: &[&str]| {
        let mut args = vec!["track", "bedload", "--out", path_str(&out)];
        args.extend_from_slice(extra);
        sillage(&args)
    };
    let det = dir.path().join("det.csv");
    let cases: [(Vec<&str>, &str); 4] = [
        (vec!["--detections", "missing.csv"], "missing.csv"),
        (
            vec![
                "--detections",
                path_str(&det),
                "--set",
                "filter.particles=0",
            ],
            "filter.particles",
        ),
        (
            vec![
                "--detections",
                path_str(&det),
                "--set",
                "motion.transition=[[0.9,0.2,0],[0.1,0.8,0.1],[0.05,0.15,0.8]]",
            ],
            "motion.transition",
        ),
        (
            vec![
                "--detections",
                path_str(&det),
                "--set",
                "motion.salt_pos_noise.var_x=-2",
            ],
            "motion.salt_pos_noise",
        ),
    ];
    for (args, expected) in cases {
        let output = run(&args);
        assert_eq!(output.status.code(), Some(1), "{args:?}");
        assert!(stderr(&output).contains(expected), "{}", stderr(&output));
    }
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "frame,x,y,class,score\n0,1,2,0,1\n1,nan,2,0,1\n").unwrap();
    let output = run(&["--detections", path_str(&bad)]);
    assert_eq!(output.status.code(), Some(1));
    assert!(stderr(&output).contains("bad.csv:3"), "{}", stderr(&output));
    assert!(!out.exists(), "nothing written for unreadable input");
    // Writing over an input is refused before anything is read or written.
    let before = std::fs::read(&det).unwrap();
    let output = sillage(&[
        "track",
        "bedload",
        "--detections",
        path_str(&det),
        "--out",
        path_str(&det),
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        stderr(&output).contains("would overwrite"),
        "{}",
        stderr(&output)
    );
    assert_eq!(std::fs::read(&det).unwrap(), before);
}

#[test]
fn synthetic_sequence_to_tracks_to_scores() {
    let dir = tempfile::tempdir().unwrap();
    let beads = dir.path().join("beads");
    let output = sillage(&[
        "synth",
        "bedload",
        "--out",
        path_str(&beads),
        "--frames",
        "20",
        // Fewer transparent beads lodge in the bed, so it needs more black ones (≥ 314).
        "--black",
        "330",
        "--transparent",
        "40",
        "--seed",
        "4",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    for file in [
        "truth.csv",
        "detections.csv",
        "candidates.csv",
        "sequence_param.txt",
    ] {
        assert!(beads.join(file).exists(), "{file}");
    }
    let tracks = beads.join("tracks.csv");
    let output = sillage(&[
        "track",
        "bedload",
        "--detections",
        path_str(&beads.join("detections.csv")),
        "--candidates",
        path_str(&beads.join("candidates.csv")),
        "--out",
        path_str(&tracks),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let output = sillage(&[
        "eval",
        "mot",
        "--gt",
        path_str(&beads.join("truth.csv")),
        "--pred",
        path_str(&tracks),
        "--match",
        "disc:0.43",
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let scores: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let mota = find(&scores, "mota").unwrap();
    assert!(mota > 0.9, "MOTA {mota}");
}

#[test]
fn bench_bedload_prints_table1_and_the_sweep_and_draws_the_figures() {
    let dir = tempfile::tempdir().unwrap();
    let plots = dir.path().join("plots");
    let output = sillage(&[
        "bench",
        "bedload",
        "--frames",
        "8",
        "--thresholds",
        "0.2,0.3",
        "--plots",
        path_str(&plots),
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let rows: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    // Table 1 (every bead at τ_t = 0.25), then the sweep (transparent beads), five trackers each.
    assert_eq!(rows.len(), 15);
    let field = |row: &serde_json::Value, key: &str| row[key].as_str().unwrap().to_string();
    let trackers: Vec<_> = rows[..5].iter().map(|r| field(r, "tracker")).collect();
    assert_eq!(trackers, ["mmpf_plus", "mmpf", "pf", "imm", "det"]);
    assert!(rows[..5].iter().all(|r| field(r, "scope") == "all_beads"));
    assert!(rows[5..].iter().all(|r| field(r, "scope") == "transparent"));
    let taus: Vec<f64> = rows[5..]
        .iter()
        .map(|r| r["transparent_threshold"].as_f64().unwrap())
        .collect();
    assert_eq!(taus, [[0.2; 5], [0.3; 5]].concat());
    for row in rows {
        let mota = find(&row["scores"], "mota").unwrap();
        assert!(mota <= 1.0, "{row}");
    }
    // One panel (no real sequence) per figure, PNG and SVG.
    for name in ["fig6_tau_sweep", "fig7_state_f_scores"] {
        let png = image::open(plots.join(format!("{name}.png"))).unwrap();
        assert_eq!((png.width(), png.height()), (760, 460), "{name}");
        let svg = std::fs::read_to_string(plots.join(format!("{name}.svg"))).unwrap();
        assert!(svg.contains("MMPF+") && svg.contains("synthetic"), "{name}");
    }
    let bad = sillage(&["bench", "bedload", "--frames", "2", "--thresholds", "1.5"]);
    assert_eq!(bad.status.code(), Some(1));
    assert!(stderr(&bad).contains("between 0 and 1"), "{}", stderr(&bad));
}

#[test]
fn demo_bedload_renders_detects_tracks_and_scores() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    let output = sillage(&[
        "demo",
        "bedload",
        "--out",
        path_str(&out),
        "--frames",
        "8",
        "--overlays",
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let summary: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(summary["frames"], 8);
    for file in [
        "truth.csv",
        "tracks.csv",
        "sequence_param.txt",
        "frames/frame_00007.png",
        "overlays/overlay_00000.png",
        "overlays/overlay_00007.png",
    ] {
        assert!(out.join(file).exists(), "{file}");
    }
    // Beads kept apart at contact distance, as in the flume: found and followed.
    let mota = find(&summary["scores"], "mota").unwrap();
    assert!(mota > 0.95, "{summary}");
}

//! End-to-end test of `sillage detect motion` on generated walkers: the blobs are written as
//! MOTChallenge detections that land on the true walkers, and bad options are user errors
//! naming the key.

mod common;
use common::{path_str, run_ok, run_user_error, synth_walkers};
use sillage::io::{MotRow, read_mot_rows};

const FRAMES: u64 = 60;

/// Box intersection over union.
fn iou(a: &MotRow, b: &MotRow) -> f64 {
    let w = (a.left_px + a.width_px).min(b.left_px + b.width_px) - a.left_px.max(b.left_px);
    let h = (a.top_px + a.height_px).min(b.top_px + b.height_px) - a.top_px.max(b.top_px);
    let inter = w.max(0.0) * h.max(0.0);
    inter / (a.width_px * a.height_px + b.width_px * b.height_px - inter)
}

#[test]
fn motion_blobs_are_written_as_detections_on_the_walkers() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("crossing");
    synth_walkers(&seq, "crossing", FRAMES);
    let out = dir.path().join("det.txt");
    let summary = run_ok(&[
        "detect",
        "motion",
        path_str(&seq.join("img1")),
        "--out",
        path_str(&out),
        "--json",
    ]);
    let summary: serde_json::Value = serde_json::from_str(&summary).unwrap();
    let rows = read_mot_rows(&out).unwrap();
    assert_eq!(summary["frames"].as_u64(), Some(FRAMES));
    assert_eq!(summary["blobs"].as_u64(), Some(rows.len() as u64));
    assert!(rows.iter().all(|r| r.id.is_none()), "detections have no id");
    assert!(
        rows.iter()
            .all(|r| r.confidence.is_some_and(|c| c > 0.0 && c <= 1.0)),
        "the confidence is a share of the box"
    );
    // The first frame only starts the background model; after it, the walkers are found.
    assert!(rows.iter().all(|r| r.frame >= 1 && r.frame < FRAMES));
    let truth = read_mot_rows(seq.join("gt/gt.txt")).unwrap();
    let found = truth
        .iter()
        .filter(|t| t.frame >= 1)
        .filter(|t| rows.iter().any(|r| r.frame == t.frame && iou(r, t) >= 0.5))
        .count();
    let scored = truth.iter().filter(|t| t.frame >= 1).count();
    let recall = found as f64 / scored as f64;
    assert!(recall >= 0.7, "{found} of {scored} true boxes found");
}

#[test]
fn bad_motion_detector_options_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("crossing");
    synth_walkers(&seq, "crossing", FRAMES);
    let out = dir.path().join("det.txt");
    let input = seq.join("img1");
    let err = run_user_error(&[
        "detect",
        "motion",
        path_str(&input),
        "--out",
        path_str(&out),
        "--detector-set",
        "min_blob_px=1",
    ]);
    assert!(err.contains("min_blob_px"), "{err}");
    let err = run_user_error(&[
        "detect",
        "motion",
        path_str(&dir.path().join("missing")),
        "--out",
        path_str(&out),
    ]);
    assert!(err.contains("missing"), "{err}");
    assert!(!out.exists(), "nothing written on a bad input");
}

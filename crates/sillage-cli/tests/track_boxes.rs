//! `sillage track boxes` (SORT, ByteTrack) on the shared MOT15 detections: the scores of the
//! references on the same detections — the authors' SORT (`sort-tracker-py` 1.0.2) and
//! `supervision` 0.30.9's ByteTrack (`tools/box_trackers_compare.py`) — and bad detection files
//! refused naming the file.

use std::fs;

mod common;
use common::{path_str, run_ok, run_user_error};

const MOT15: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/mot15_train_gt_det"
);

/// MOTA and IDF1 of `sillage eval mot` on `pred` against the sequence's truth.
fn scores(sequence: &str, pred: &str) -> (f64, f64) {
    let gt = format!("{MOT15}/{sequence}/gt/gt.txt");
    let out = run_ok(&["eval", "mot", "--gt", &gt, "--pred", pred, "--json"]);
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let metrics = &json["combined"]["metrics"];
    (
        metrics["clear"]["mota"].as_f64().unwrap(),
        metrics["identity"]["idf1"].as_f64().unwrap(),
    )
}

#[test]
fn sort_and_bytetrack_score_what_the_references_score() {
    let dir = tempfile::tempdir().unwrap();
    // The references on the same detections (tools/box_trackers_compare.py), scored the same
    // way.
    for (tracker, sequence, mota, idf1) in [
        ("sort", "TUD-Campus", 0.6267, 0.6065),
        ("sort", "TUD-Stadtmitte", 0.7171, 0.7347),
        ("sort", "ETH-Bahnhof", 0.4464, 0.6094),
        ("bytetrack", "TUD-Campus", 0.5961, 0.6656),
        ("bytetrack", "TUD-Stadtmitte", 0.7093, 0.6776),
        ("bytetrack", "KITTI-17", 0.5974, 0.6912),
    ] {
        let out = dir.path().join(format!("{tracker}_{sequence}.txt"));
        run_ok(&[
            "track",
            "boxes",
            "--tracker",
            tracker,
            "--detections",
            &format!("{MOT15}/{sequence}/det/det.txt"),
            "--out",
            path_str(&out),
        ]);
        let (m, i) = scores(sequence, path_str(&out));
        assert!(
            (m - mota).abs() < 1e-4,
            "{sequence}: MOTA {m} against {mota}"
        );
        assert!(
            (i - idf1).abs() < 1e-4,
            "{sequence}: IDF1 {i} against {idf1}"
        );
    }
}

#[test]
fn bad_detection_files_are_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.txt");
    let negative = dir.path().join("negative.txt");
    fs::write(&negative, "1,-1,10,10,-5,20,0.9\n").unwrap();
    let message = run_user_error(&[
        "track",
        "boxes",
        "--detections",
        path_str(&negative),
        "--out",
        path_str(&out),
    ]);
    assert!(message.contains("negative.txt"), "{message}");
    assert!(!out.exists());
}

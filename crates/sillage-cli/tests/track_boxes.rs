//! `sillage track boxes` (SORT) on the shared MOT15 detections: the scores of the authors'
//! SORT (`sort-tracker-py` 1.0.2 on the same detections, `tools/sort_compare.py`), and bad
//! detection files refused naming the file.

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
fn sort_scores_what_the_authors_sort_scores() {
    let dir = tempfile::tempdir().unwrap();
    // The authors' SORT on the same detections (tools/sort_compare.py), scored the same way.
    for (sequence, mota, idf1) in [
        ("TUD-Campus", 0.6267, 0.6065),
        ("TUD-Stadtmitte", 0.7171, 0.7347),
        ("ETH-Bahnhof", 0.4464, 0.6094),
    ] {
        let out = dir.path().join(format!("{sequence}.txt"));
        run_ok(&[
            "track",
            "boxes",
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

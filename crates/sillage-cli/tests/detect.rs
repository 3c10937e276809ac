//! `sillage detect bead` on the ten real flume frames of the MMPF+ paper's authors, then
//! `sillage track bedload` and `sillage eval mot` against their hand-edited truth: the whole
//! bedload workflow from images to scores.

mod common;

use common::{path_str, sillage, stderr};

const DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/bedload_beads_lafaye2018"
);
const MASK: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/bedload_beads_lafaye2018/sequence_base_mask.tif"
);

#[test]
fn real_frames_to_detections_to_tracks_to_scores() {
    let dir = tempfile::tempdir().unwrap();
    let (det, cand) = (dir.path().join("det.csv"), dir.path().join("cand.csv"));
    let output = sillage(&[
        "detect",
        "bead",
        &format!("{DATA}/images"),
        "--sequence-params",
        &format!("{DATA}/sequence_param.txt"),
        "--mask",
        MASK,
        "--template",
        &format!("{DATA}/template_transparent_bead_rOut10_rIn6.csv"),
        "--out",
        path_str(&det),
        "--candidates",
        path_str(&cand),
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let summary: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(summary["frames"], 10);
    // The truth holds 3,962 beads over the ten frames.
    let found = summary["black"].as_u64().unwrap() + summary["transparent"].as_u64().unwrap();
    assert!((3900..=4000).contains(&found), "{summary}");
    let tracks = dir.path().join("tracks.csv");
    let output = sillage(&[
        "track",
        "bedload",
        "--detections",
        path_str(&det),
        "--candidates",
        path_str(&cand),
        "--out",
        path_str(&tracks),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    std::fs::copy(
        format!("{DATA}/sequence_param.txt"),
        dir.path().join("sequence_param.txt"),
    )
    .unwrap();
    let truth = dir.path().join("truth.csv");
    std::fs::copy(format!("{DATA}/ground_truth/trackdatatruth.csv"), &truth).unwrap();
    let output = sillage(&[
        "eval",
        "mot",
        "--gt",
        path_str(&truth),
        "--pred",
        path_str(&tracks),
        "--match",
        "disc:0.43",
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let scores = String::from_utf8(output.stdout).unwrap();
    let value = |key: &str| -> f64 {
        let at = scores.find(&format!("\"{key}\":")).unwrap() + key.len() + 3;
        let end = scores[at..].find([',', '}']).unwrap();
        scores[at..at + end].trim().parse().unwrap()
    };
    assert!(value("mota") > 0.99, "{scores}");
    assert_eq!(value("id_switches"), 0.0);
}

#[test]
fn bad_detector_input_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("det.csv");
    let output = sillage(&[
        "detect",
        "bead",
        &format!("{DATA}/images"),
        "--detector-set",
        "transparent_threshold=2",
        "--out",
        path_str(&out),
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        stderr(&output).contains("transparent_threshold"),
        "{}",
        stderr(&output)
    );
    let output = sillage(&["detect", "bead", "no/such/folder", "--out", path_str(&out)]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        stderr(&output).contains("no/such/folder"),
        "{}",
        stderr(&output)
    );
}

#[test]
fn track_bedload_detects_frames_itself() {
    let dir = tempfile::tempdir().unwrap();
    let tracks = dir.path().join("tracks.csv");
    let overlays = dir.path().join("overlays");
    let output = sillage(&[
        "track",
        "bedload",
        &format!("{DATA}/images"),
        "--sequence-params",
        &format!("{DATA}/sequence_param.txt"),
        "--mask",
        MASK,
        "--out",
        path_str(&tracks),
        "--overlay",
        path_str(&overlays),
        "--overlay-tail",
        "5",
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let summary: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    assert_eq!(summary["frames"], 10);
    let tracks_found = summary["tracks"].as_u64().unwrap();
    // 397 true beads in the ten frames.
    assert!((390..=405).contains(&tracks_found), "{summary}");
    // One overlay per frame, the frame's size, with the beads' heads in their state's
    // colour: mostly resting, some rolling or saltating.
    assert_eq!(std::fs::read_dir(&overlays).unwrap().count(), 10);
    let last = image::open(overlays.join("overlay_00009.png"))
        .unwrap()
        .to_rgb8();
    assert_eq!(last.dimensions(), (1280, 320));
    let count = |state| {
        let rgb = sillage::viz::state_rgb(state);
        last.pixels().filter(|p| p.0 == rgb).count()
    };
    use sillage::core::MotionState::{Resting, Rolling, Saltating};
    assert!(count(Resting) > 300 * 9, "resting {}", count(Resting));
    assert!(count(Rolling) + count(Saltating) > 20);
    let output = sillage(&["track", "bedload", "--out", path_str(&tracks)]);
    assert_eq!(
        output.status.code(),
        Some(2),
        "frames or --detections are required"
    );
}

//! `sillage track immpf --overlay DIR` end to end on the first frames of the shared
//! PETS09-S2L1 sequence: one PNG per frame, named by its 1-based frame number, at the frame's
//! size, with the people's boxes drawn; and the option refused without frames.

mod common;

use std::path::PathBuf;

use common::{path_str, sillage, stderr};

const PETS_FRAMES: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/pets09_s2l1/img1"
);

/// The colour of the boxes on pedestrian overlays.
const BOX_RGB: [u8; 3] = [255, 215, 0];

/// `sillage track immpf` on the first 12 PETS frames with `extra` options, overlays
/// requested: the folder (kept alive by the returned temporary folder), and the results.
fn track_with_overlays(extra: &[&str]) -> (tempfile::TempDir, PathBuf, String) {
    let dir = tempfile::tempdir().unwrap();
    let overlays = dir.path().join("overlays");
    let results = dir.path().join("results.txt");
    let mut args = vec!["track", "immpf", PETS_FRAMES, "--max-frames", "12"];
    args.extend_from_slice(extra);
    args.extend([
        "--out",
        path_str(&results),
        "--overlay",
        path_str(&overlays),
    ]);
    let output = sillage(&args);
    assert!(output.status.success(), "{}", stderr(&output));
    let rows = std::fs::read_to_string(&results).unwrap();
    (dir, overlays, rows)
}

#[test]
fn overlays_of_the_first_pets_frames_are_written_one_per_frame() {
    let (_dir, overlays, rows) = track_with_overlays(&["--models", "CP_CV_CA"]);
    let mut names: Vec<String> = std::fs::read_dir(&overlays)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let expected: Vec<String> = (1..=12).map(|f| format!("overlay_{f:05}.png")).collect();
    assert_eq!(names, expected);
    for name in &names {
        let picture = image::open(overlays.join(name)).unwrap().to_rgb8();
        assert_eq!(picture.dimensions(), (768, 576), "{name}");
    }
    // The frames with result rows show boxes; the legend's black strip is in the corner.
    let last = image::open(overlays.join("overlay_00012.png"))
        .unwrap()
        .to_rgb8();
    let box_pixels = last.pixels().filter(|p| p.0 == BOX_RGB).count();
    let tracked_at_12 = rows.lines().any(|l| l.starts_with("12,"));
    assert_eq!(
        box_pixels > 100,
        tracked_at_12,
        "{box_pixels} box pixels\n{rows}"
    );
    assert_eq!(last.get_pixel(760, 8).0, [0, 0, 0]);
}

/// With detections beside the frames the boxes are smoothed and written four frames late
/// (`detection.smooth_frames`): the overlays wait for them, so every frame with result rows,
/// the last ones included (written when the input ends), shows its boxes.
#[test]
fn overlays_wait_for_the_smoothed_boxes() {
    let detections = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/pets09_s2l1/det/det.txt"
    );
    let (_dir, overlays, rows) = track_with_overlays(&["--detections", detections]);
    let mut frames_with_rows = 0;
    for f in 1..=12 {
        let picture = image::open(overlays.join(format!("overlay_{f:05}.png")))
            .unwrap()
            .to_rgb8();
        let box_pixels = picture.pixels().filter(|p| p.0 == BOX_RGB).count();
        let tracked = rows.lines().any(|l| l.starts_with(&format!("{f},")));
        frames_with_rows += usize::from(tracked);
        assert_eq!(
            box_pixels > 100,
            tracked,
            "frame {f}: {box_pixels} box pixels"
        );
    }
    assert!(frames_with_rows >= 6, "{rows}");
}

#[test]
fn overlays_need_frames() {
    let dir = tempfile::tempdir().unwrap();
    let detections = dir.path().join("det.txt");
    std::fs::write(&detections, "1,-1,10,10,20,40,1\n").unwrap();
    let output = sillage(&[
        "track",
        "immpf",
        "--detections",
        path_str(&detections),
        "--size",
        "100x100",
        "--out",
        path_str(&dir.path().join("out.txt")),
        "--overlay",
        path_str(&dir.path().join("ov")),
    ]);
    assert!(!output.status.success());
    assert!(stderr(&output).contains("<INPUT>"), "{}", stderr(&output));
    assert!(!dir.path().join("ov").exists());
}

//! End-to-end tests of `sillage fit motion-prior` and `sillage fit homography` on the shared
//! PETS09-S2L1 ground truth (frames 1-150, MOT15 world coordinates), and bad inputs with exit
//! code 1 and a message naming the file.

use std::fs;
use std::path::Path;

mod common;
use common::{path_str, run_ok, run_user_error};

use serde::Deserialize;
use sillage::core::{Homography, PedestrianSize, Point2};
use sillage::filter::MotionPrior;

const PETS: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/pets09_s2l1"
);

/// Bound on the RMS reprojection error of the PETS homography, px. Measured: 0.44 px over
/// the 873 foot points. The MOT15 world coordinates were computed from the image positions
/// through the calibrated PETS camera, so foot points and world points agree up to the
/// rounding of the published numbers and the camera model's departure from a pure
/// homography; 1 px (2.3 times the measure) fails when the fit or the foot point goes wrong
/// (the box centre instead of the foot point gives 1.87 px).
const PETS_RMS_BOUND_PX: f64 = 1.0;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct HomographyFile {
    homography: Homography,
    pedestrian: Option<PedestrianSize>,
    fit: FitTable,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FitTable {
    source: String,
    pairs: usize,
    rms_reprojection_px: f64,
}

fn read_homography(path: &Path) -> HomographyFile {
    let text = fs::read_to_string(path).unwrap();
    toml::from_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

#[test]
fn homography_of_pets_reprojects_within_a_few_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ground.toml");
    let gt = format!("{PETS}/gt/gt.txt");
    let stdout = run_ok(&["fit", "homography", &gt, "--out", path_str(&out)]);
    assert!(stdout.contains("873 pairs"), "{stdout}");
    assert!(stdout.contains("RMS reprojection error"), "{stdout}");
    let file = read_homography(&out);
    assert_eq!(file.fit.pairs, 873);
    assert!(file.fit.source.ends_with("gt.txt"));
    let rms = file.fit.rms_reprojection_px;
    assert!(rms > 0.0 && rms < PETS_RMS_BOUND_PX, "RMS {rms} px");
    // The first row of gt.txt: foot (514.515, 233.17) ↔ (−4.1554, −7.3591) m.
    let foot = file
        .homography
        .image_from_ground(Point2::new(-4.1554, -7.3591))
        .unwrap();
    assert!(
        foot.distance(Point2::new(514.515, 233.17)) < 10.0,
        "{foot:?}"
    );
    // An adult: 1.5 to 2.1 m tall (MOT boxes include some margin), 0.4 to 1 m wide.
    let adult = file
        .pedestrian
        .expect("[pedestrian] from ground truth boxes");
    adult.validate().unwrap();
    assert!((1.5..2.1).contains(&adult.height_m), "{adult:?}");
    assert!((0.4..1.0).contains(&adult.width_m), "{adult:?}");
    // Only the output is left behind.
    let names: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1);
}

#[test]
fn homography_from_four_point_pairs() {
    let dir = tempfile::tempdir().unwrap();
    let points = dir.path().join("points.txt");
    // 40 px per metre, origin at (100, 50), plus a comment and a blank line.
    fs::write(
        &points,
        "# u,v,x,y\n100,50,0,0\n140 50 1 0\n\n100,130,0,2\n180,130,2,2\n",
    )
    .unwrap();
    let out = dir.path().join("h.toml");
    let stdout = run_ok(&[
        "fit",
        "homography",
        "--points",
        path_str(&points),
        "--out",
        path_str(&out),
    ]);
    assert!(stdout.contains("4 pairs"), "{stdout}");
    let file = read_homography(&out);
    assert!(file.pedestrian.is_none());
    assert!(file.fit.rms_reprojection_px < 1e-9);
    let p = file
        .homography
        .image_from_ground(Point2::new(1.0, 1.0))
        .unwrap();
    assert!(p.distance(Point2::new(140.0, 90.0)) < 1e-9, "{p:?}");
}

#[test]
fn bad_point_sets_exit_1_with_a_clear_message() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("h.toml");
    let three = dir.path().join("three.txt");
    fs::write(&three, "100,50,0,0\n140,50,1,0\n100,130,0,2\n").unwrap();
    let err = run_user_error(&[
        "fit",
        "homography",
        "--points",
        path_str(&three),
        "--out",
        path_str(&out),
    ]);
    assert!(
        err.contains("three.txt") && err.contains("3 point pair(s)") && err.contains("at least 4"),
        "{err}"
    );
    // Four ground points on one line: no homography.
    let collinear = dir.path().join("collinear.txt");
    fs::write(
        &collinear,
        "100,50,0,0\n140,60,1,0\n180,75,2,0\n220,95,3,0\n",
    )
    .unwrap();
    let err = run_user_error(&[
        "fit",
        "homography",
        "--points",
        path_str(&collinear),
        "--out",
        path_str(&out),
    ]);
    assert!(
        err.contains("collinear.txt") && err.contains("one line"),
        "{err}"
    );
    let malformed = dir.path().join("malformed.txt");
    fs::write(&malformed, "100,50,0,0\n140,50,one,0\n").unwrap();
    let err = run_user_error(&[
        "fit",
        "homography",
        "--points",
        path_str(&malformed),
        "--out",
        path_str(&out),
    ]);
    assert!(err.contains("malformed.txt:2:"), "{err}");
    // Ground truth without world coordinates (MOT15 TUD-Campus).
    let tud = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/mot15_train_gt_det/TUD-Campus/gt/gt.txt"
    );
    let err = run_user_error(&["fit", "homography", tud, "--out", path_str(&out)]);
    assert!(
        err.contains("gt.txt") && err.contains("no row has world coordinates"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn motion_prior_of_pets_is_written_and_loads() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("prior.json");
    let gt = format!("{PETS}/gt/gt.txt");
    // The image size comes from PETS's seqinfo.ini (768 × 576).
    let stdout = run_ok(&["fit", "motion-prior", &gt, "--out", path_str(&out)]);
    assert!(stdout.contains("4 rows with flag 0 ignored"), "{stdout}");
    assert!(stdout.contains("cells with data"), "{stdout}");
    let prior = MotionPrior::from_json(&out, &fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(prior.image_size_px(), (768, 576));
    assert_eq!(prior.grid_size(), (26, 20));
    assert!(stdout.contains(&format!("{} cells with data", prior.cells_with_data())));
    assert!(prior.cells_with_data() > 40, "{}", prior.cells_with_data());
    assert!(prior.moves() > 800, "{}", prior.moves());
    // --width/--height and --cell override.
    run_ok(&[
        "fit",
        "motion-prior",
        &gt,
        "--width",
        "800",
        "--height",
        "600",
        "--cell",
        "40",
        "--out",
        path_str(&out),
    ]);
    let prior = MotionPrior::from_json(&out, &fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(prior.grid_size(), (20, 15));
}

#[test]
fn motion_prior_bad_inputs_exit_1() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("prior.json");
    // Detections have no track ids.
    let det = format!("{PETS}/det/det.txt");
    let err = run_user_error(&["fit", "motion-prior", &det, "--out", path_str(&out)]);
    assert!(
        err.contains("det.txt") && err.contains("no track id"),
        "{err}"
    );
    // No seqinfo.ini and no --width.
    let lone = dir.path().join("tracks.txt");
    fs::write(
        &lone,
        "1,1,10,10,5,20,1,-1,-1,-1\n2,1,12,10,5,20,1,-1,-1,-1\n",
    )
    .unwrap();
    let err = run_user_error(&[
        "fit",
        "motion-prior",
        path_str(&lone),
        "--out",
        path_str(&out),
    ]);
    assert!(
        err.contains("tracks.txt") && err.contains("--width"),
        "{err}"
    );
    let err = run_user_error(&[
        "fit",
        "motion-prior",
        path_str(&lone),
        "--width",
        "100",
        "--height",
        "100",
        "--cell",
        "0",
        "--out",
        path_str(&out),
    ]);
    assert!(err.contains("cell_px"), "{err}");
    assert!(!out.exists());
}

//! End-to-end tests of `sillage track immpf` and `sillage bench immpf`: real PETS 2009 frames
//! scored against their truth, the detections-only mode, reproducibility whatever the number
//! of threads, and bad inputs (a singular homography, a detections file with a negative size,
//! frames whose size changes) refused with exit code 1 and a message naming the file.

use std::fs;
use std::path::Path;
use std::process::Command;

mod common;
use common::{path_str, run_ok, run_user_error, stderr};

const PETS: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/pets09_s2l1"
);

/// The ground plane of PETS fitted from its truth (`sillage fit homography`).
fn ground_plane(dir: &Path) -> String {
    let ground = dir.join("ground.toml");
    run_ok(&[
        "fit",
        "homography",
        &format!("{PETS}/gt/gt.txt"),
        "--out",
        path_str(&ground),
    ]);
    path_str(&ground).to_string()
}

#[test]
fn pets_frames_are_tracked_scored_and_repeat_with_the_seed_on_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let ground = ground_plane(dir.path());
    let out = dir.path().join("pets.txt");
    let weights = dir.path().join("weights.csv");
    let track = |out: &Path, threads: &str| {
        let output = Command::new(env!("CARGO_BIN_EXE_sillage"))
            .env("RAYON_NUM_THREADS", threads)
            .args([
                "track",
                "immpf",
                &format!("{PETS}/img1"),
                "--ground-plane",
                &ground,
                "--max-frames",
                "40",
                "--seed",
                "7",
                "--out",
                path_str(out),
                "--model-weights",
                path_str(&weights),
            ])
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", stderr(&output));
        fs::read_to_string(out).unwrap()
    };
    let results = track(&out, "2");
    let single = track(&dir.path().join("one.txt"), "1");
    assert_eq!(results, single, "one and two threads give the same tracks");
    let rows = results.lines().count();
    // 163 true boxes in frames 1-40.
    assert!((100..=400).contains(&rows), "{rows} rows");
    let header = fs::read_to_string(&weights).unwrap();
    assert!(header.starts_with("frame,id,CV,CA\n"), "{header}");
    assert_eq!(header.lines().count(), rows + 1);

    // Scored against the truth of the same frames: most boxes are on people.
    let gt = dir.path().join("gt.txt");
    let truth: String = fs::read_to_string(format!("{PETS}/gt/gt.txt"))
        .unwrap()
        .lines()
        .filter(|l| l.split(',').next().unwrap().parse::<u32>().unwrap() <= 40)
        .map(|l| format!("{l}\n"))
        .collect();
    fs::write(&gt, truth).unwrap();
    let scores = run_ok(&[
        "eval",
        "mot",
        "--gt",
        path_str(&gt),
        "--pred",
        path_str(&out),
        "--json",
    ]);
    let json: serde_json::Value = serde_json::from_str(&scores).unwrap();
    let text = json.to_string();
    let precision = find_number(&json, "precision").unwrap_or_else(|| panic!("{text}"));
    let recall = find_number(&json, "recall").unwrap_or_else(|| panic!("{text}"));
    // Measured 2026-11-23 on these 40 frames, seed 7: precision 0.51, recall 0.44 (IoU ≥ 0.5;
    // the motion detector needs a few frames before its first blobs).
    assert!(
        precision > 0.45 && recall > 0.38,
        "precision {precision}, recall {recall}"
    );
}

/// The first number under a key named `key` anywhere in `value`.
fn find_number(value: &serde_json::Value, key: &str) -> Option<f64> {
    match value {
        serde_json::Value::Object(map) => map.iter().find_map(|(k, v)| {
            if k == key {
                v.as_f64()
            } else {
                find_number(v, key)
            }
        }),
        serde_json::Value::Array(items) => items.iter().find_map(|v| find_number(v, key)),
        _ => None,
    }
}

#[test]
fn detections_alone_are_tracked_and_benched() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("det_only.txt");
    // The size comes from seqinfo.ini beside det/.
    let summary = run_ok(&[
        "track",
        "immpf",
        "--detections",
        &format!("{PETS}/det/det.txt"),
        "--out",
        path_str(&out),
        "--json",
    ]);
    let rows = fs::read_to_string(&out).unwrap().lines().count();
    assert!(rows > 500, "{rows} rows");
    // The summary counts the rows written, and those of them interpolated over gaps: people
    // the detector misses for a few frames are there (12 rows on these frames, seed 1).
    let summary: serde_json::Value = serde_json::from_str(&summary).unwrap();
    assert_eq!(summary["rows"].as_u64(), Some(rows as u64), "{summary}");
    let gap_rows = summary["gap_rows"]
        .as_u64()
        .unwrap_or_else(|| panic!("{summary}"));
    assert!(gap_rows > 0 && gap_rows < rows as u64 / 10, "{summary}");
    // Without frames there is no colour to weigh: the colour weight changes nothing, row for
    // row. (It once widened the assignment's cost bound even so, which changed this seed's
    // rows.)
    let with_weight = |weight: &str, name: &str| {
        let path = dir.path().join(name);
        run_ok(&[
            "track",
            "immpf",
            "--detections",
            &format!("{PETS}/det/det.txt"),
            "--seed",
            "2",
            "--set",
            &format!("tracker.detection.colour_weight={weight}"),
            "--out",
            path_str(&path),
        ]);
        fs::read_to_string(&path).unwrap()
    };
    assert_eq!(with_weight("0", "w0.txt"), with_weight("6", "w6.txt"));
    let table = run_ok(&[
        "bench",
        "immpf",
        PETS,
        "--detections-only",
        "--runs",
        "2",
        "--models",
        "CV,CV_CA",
        "--json",
    ]);
    let rows: serde_json::Value = serde_json::from_str(&table).unwrap();
    let rows = rows.as_array().unwrap();
    // The two combinations, then the SORT and ByteTrack baselines on the same detections.
    let labels: Vec<&str> = rows.iter().map(|r| r["models"].as_str().unwrap()).collect();
    assert_eq!(labels, ["CV", "CV_CA", "SORT", "ByteTrack"]);
    for row in rows {
        let mota = row["median"]["mota"].as_f64().unwrap();
        // Measured (2026-11-28): 44-46 % MOTA for the IMM-PF (5 seeds), 48.7 % SORT,
        // 40.3 % ByteTrack with the public ACF detections of frames 1-150, whose own MODA
        // is 41 %; a tracker that lost the detections falls below 0.
        assert!(mota > 10.0, "{row}");
    }
}

const TUD: [&str; 2] = [
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/mot15_train_gt_det/TUD-Campus"
    ),
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/mot15_train_gt_det/TUD-Stadtmitte"
    ),
];

/// `bench immpf --detections-only --models CV_CA --runs 1` on `sequences` with `extra`
/// options, as JSON.
fn bench_detections(sequences: &[&str], extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "bench",
        "immpf",
        "--detections-only",
        "--models",
        "CV_CA",
        "--runs",
        "1",
        "--json",
    ];
    args.extend(sequences);
    args.extend(extra);
    serde_json::from_str(&run_ok(&args)).unwrap()
}

#[test]
fn settings_are_chosen_on_the_other_sequences_and_reported_on_the_one_left_out() {
    let sequences = [TUD[0], TUD[1], PETS];
    let grid = ["--grid", "tracker.detection.min_hits=3,5"];
    let rows = bench_detections(&sequences, &grid);
    let rows = rows.as_array().unwrap();
    let names: Vec<&str> = rows
        .iter()
        .map(|r| r["sequence"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["TUD-Campus", "TUD-Stadtmitte", "pets09_s2l1"]);
    for (row, folder) in rows.iter().zip(sequences) {
        let name = row["sequence"].as_str().unwrap();
        let tuned_on: Vec<&str> = row["tuned_on"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap())
            .collect();
        assert_eq!(tuned_on.len(), 2);
        assert!(!tuned_on.contains(&name), "{row}");
        // The reported scores are the chosen setting's own on the held-out sequence.
        let chosen = row["chosen"][0].as_str().unwrap();
        assert!(
            chosen.starts_with("tracker.detection.min_hits="),
            "{chosen}"
        );
        let alone = bench_detections(&[folder], &["--set", chosen]);
        assert_eq!(alone[0]["median"]["mota"], row["held_out"]["mota"], "{row}");
        assert_eq!(
            alone[2]["median"]["idf1"], row["bytetrack"]["idf1"],
            "{row}"
        );
    }
    // One choice on PETS, reported on the two TUD sequences.
    let tuned = bench_detections(&sequences, &[grid[0], grid[1], "--tune-on", "pets09_s2l1"]);
    let tuned = tuned.as_array().unwrap();
    assert_eq!(tuned.len(), 2);
    assert!(
        tuned
            .iter()
            .all(|r| r["tuned_on"] == serde_json::json!(["pets09_s2l1"]))
    );
    // A sequence not benched, a malformed grid, two model combinations.
    let mut args = vec!["bench", "immpf", "--detections-only", "--runs", "1"];
    args.extend(sequences);
    let message =
        run_user_error(&[&args[..], &["--models", "CV_CA", "--tune-on", "KITTI-13"]].concat());
    assert!(message.contains("--tune-on KITTI-13"), "{message}");
    let message = run_user_error(
        &[
            &args[..],
            &["--models", "CV_CA", "--grid", "tracker.detection.min_hits"],
        ]
        .concat(),
    );
    assert!(message.contains("KEY=V1,V2"), "{message}");
    let message =
        run_user_error(&[&args[..], &["--models", "CV,CV_CA", "--grid", grid[1]]].concat());
    assert!(message.contains("one model combination"), "{message}");
}

#[test]
fn a_sequence_whose_frames_are_a_video_is_benched_from_pixels() {
    // TUD-Campus has no img1/, only video/TUD-Campus.mp4 (decoded by ffmpeg).
    let table = run_ok(&[
        "bench",
        "immpf",
        TUD[0],
        "--models",
        "CV",
        "--runs",
        "1",
        "--max-frames",
        "20",
        "--json",
    ]);
    let rows: serde_json::Value = serde_json::from_str(&table).unwrap();
    let labels: Vec<&str> = rows
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["models"].as_str().unwrap())
        .collect();
    assert_eq!(labels, ["CV", "SORT", "ByteTrack"]);
    assert!(
        rows[0]["median"]["tracks"].as_f64().unwrap() > 0.0,
        "{rows}"
    );
}

#[test]
fn bad_inputs_are_refused_with_the_file_named() {
    let dir = tempfile::tempdir().unwrap();
    let singular = dir.path().join("singular.toml");
    fs::write(
        &singular,
        "[homography]\nimage_from_ground = [[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]]\n\
         [pedestrian]\nheight_m = 1.7\nwidth_m = 0.5\n",
    )
    .unwrap();
    let out = dir.path().join("out.txt");
    let message = run_user_error(&[
        "track",
        "immpf",
        "--detections",
        &format!("{PETS}/det/det.txt"),
        "--ground-plane",
        path_str(&singular),
        "--out",
        path_str(&out),
    ]);
    assert!(
        message.contains("singular.toml") && message.contains("singular"),
        "{message}"
    );

    let negative = dir.path().join("det.txt");
    fs::write(&negative, "1,-1,10,20,30,60,0.9\n2,-1,10,20,-30,60,0.9\n").unwrap();
    let message = run_user_error(&[
        "track",
        "immpf",
        "--detections",
        path_str(&negative),
        "--size",
        "640x480",
        "--out",
        path_str(&out),
    ]);
    assert!(message.contains("det.txt:2"), "{message}");
    assert!(
        message.contains("-30") && message.contains("must be ≥ 0"),
        "{message}"
    );

    // Frames whose size changes mid-sequence.
    let frames = dir.path().join("frames");
    fs::create_dir(&frames).unwrap();
    fs::copy(format!("{PETS}/img1/000001.jpg"), frames.join("000001.jpg")).unwrap();
    fs::copy(format!("{PETS}/img1/000002.jpg"), frames.join("000002.jpg")).unwrap();
    let small = image::RgbImage::from_pixel(64, 48, image::Rgb([90, 90, 90]));
    small.save(frames.join("000003.png")).unwrap();
    let message = run_user_error(&["track", "immpf", path_str(&frames), "--out", path_str(&out)]);
    assert!(message.contains("000003.png"), "{message}");
    assert!(!out.exists(), "no result file from a failed run");

    let message = run_user_error(&[
        "track",
        "immpf",
        "--detections",
        &format!("{PETS}/det/det.txt"),
        "--models",
        "CV_MP",
        "--out",
        path_str(&out),
    ]);
    assert!(message.contains("motion prior"), "{message}");
}

/// Detections beside the frames drive the trackers (`tracker.detection.with_frames`, default
/// `measurements`): with the default colour weight 0 the result file is the one of the
/// detections alone; `births` gives the image mode; an unknown role is refused by name.
#[test]
fn detections_beside_frames_are_measurements_by_default() {
    let dir = tempfile::tempdir().unwrap();
    let (beside, alone, births) = (
        dir.path().join("beside.txt"),
        dir.path().join("alone.txt"),
        dir.path().join("births.txt"),
    );
    let detections = format!("{PETS}/det/det.txt");
    let frames = format!("{PETS}/img1");
    let common = ["--detections", &detections, "--max-frames", "30"];
    run_ok(
        &[
            &["track", "immpf", &frames][..],
            &common,
            &["--out", path_str(&beside)],
        ]
        .concat(),
    );
    run_ok(
        &[
            &["track", "immpf"][..],
            &common,
            &["--out", path_str(&alone)],
        ]
        .concat(),
    );
    let beside_rows = fs::read_to_string(&beside).unwrap();
    assert!(beside_rows.lines().count() > 50, "{beside_rows}");
    assert_eq!(beside_rows, fs::read_to_string(&alone).unwrap());
    let as_births = ["--set", "tracker.detection.with_frames=births"];
    run_ok(
        &[
            &["track", "immpf", &frames][..],
            &common,
            &as_births,
            &["--out", path_str(&births)],
        ]
        .concat(),
    );
    assert_ne!(beside_rows, fs::read_to_string(&births).unwrap());
    let message = run_user_error(
        &[
            &["track", "immpf", &frames][..],
            &common,
            &[
                "--set",
                "tracker.detection.with_frames=sideways",
                "--out",
                path_str(&births),
            ],
        ]
        .concat(),
    );
    assert!(
        message.contains("with_frames") || message.contains("sideways"),
        "{message}"
    );
}

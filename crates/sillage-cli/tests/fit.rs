//! End-to-end tests of `sillage fit bedload`: the shared real ground truth, a generated CSV
//! whose Eq. (3) residuals are known exactly, and bad inputs with exit code 1 and a message
//! naming the file.

use std::fmt::Write as _;
use std::fs;
use std::path::Path;

mod common;
use common::{path_str, sillage, stderr};

use serde::Deserialize;
use sillage::filter::{BedloadParams, apply_min_probability};

const TRUTH: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/bedload_beads_lafaye2018/ground_truth/trackdatatruth.csv"
);

/// The written config: only the `[motion]` table, read back as the trackers will.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConfigFile {
    motion: BedloadParams,
}

fn read_motion(path: &Path) -> (String, BedloadParams) {
    let text = fs::read_to_string(path).unwrap();
    let config: ConfigFile = toml::from_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    config.motion.validate().unwrap();
    (text, config.motion)
}

/// Runs `sillage fit bedload` and returns its stdout; panics unless it succeeds.
fn fit(truth: &str, out: &Path, extra: &[&str]) -> String {
    let mut args = vec!["fit", "bedload", "--truth", truth, "--out", path_str(out)];
    args.extend_from_slice(extra);
    let output = sillage(&args);
    assert!(output.status.success(), "{}", stderr(&output));
    String::from_utf8(output.stdout).unwrap()
}

#[test]
fn fits_the_shared_real_ground_truth() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("motion.toml");
    let stdout = fit(TRUTH, &out, &[]);
    assert!(
        stdout.contains("fitted on frames 0..=4 of 0..=9"),
        "{stdout}"
    );
    let (text, motion) = read_motion(&out);
    // The comments say where the values come from.
    for expected in [
        "# source: ",
        "trackdatatruth.csv",
        "trained on 0..=4 (--train-fraction 0.5)",
        "#   resting   [755, 13, 0]",
        "#   rolling   [20, 371, 1]",
        "#   saltating [0, 3, 25]",
        "kept from the defaults (fewer than 30 samples): transition[2], salt_pos_noise, \
         salt_vel_noise",
    ] {
        assert!(text.contains(expected), "{expected:?} not in\n{text}");
    }
    // Rows with enough transitions are their frequencies, floored at 0.05; saltating's 28
    // transitions and 26 residuals are too few: the defaults stay.
    let defaults = BedloadParams::default();
    let expected_rest = apply_min_probability([755.0 / 768.0, 13.0 / 768.0, 0.0], 0.05);
    for (got, want) in motion.transition[0].iter().zip(expected_rest) {
        assert!((got - want).abs() < 1e-12, "{:?}", motion.transition);
    }
    assert_eq!(motion.transition[2], defaults.transition[2]);
    assert_eq!(motion.salt_pos_noise, defaults.salt_pos_noise);
    assert_ne!(motion.roll_pos_noise, defaults.roll_pos_noise);
    assert_eq!(motion.roll_vel_noise, motion.roll_pos_noise);
    assert_eq!(motion.flow_vel_px_per_frame, defaults.flow_vel_px_per_frame);
    // Nothing is left behind but the config.
    let names: Vec<_> = fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["motion.toml"]);

    // --json carries the same parameters and the report; more options fit saltating too.
    let stdout = fit(
        TRUTH,
        &out,
        &["--json", "--min-samples", "10", "--train-fraction", "1"],
    );
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(json["report"]["training_frames"], serde_json::json!([0, 9]));
    assert_eq!(json["report"]["kept"], serde_json::json!([]));
    let (_, motion) = read_motion(&out);
    let from_json: BedloadParams = serde_json::from_value(json["motion"].clone()).unwrap();
    // serde_json's float parsing may differ from the written value in the last bit.
    let pairs = from_json
        .transition
        .iter()
        .flatten()
        .zip(motion.transition.iter().flatten());
    let noises = [
        (from_json.rest_pos_noise, motion.rest_pos_noise),
        (from_json.roll_pos_noise, motion.roll_pos_noise),
        (from_json.salt_pos_noise, motion.salt_pos_noise),
    ];
    let noise_pairs = noises
        .iter()
        .flat_map(|(a, b)| [(a.var_x, b.var_x), (a.var_y, b.var_y), (a.cov_xy, b.cov_xy)]);
    for (a, b) in pairs.map(|(a, b)| (*a, *b)).chain(noise_pairs) {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{a} vs {b}");
    }
    assert_ne!(motion.salt_pos_noise, defaults.salt_pos_noise);
}

/// Bead `k` of a generated sequence: 18 frames, the first unknown, then always `state`.
/// Every step's Eq. (3) residual is ±`residual` (the sign alternating), so the second moment
/// of the state's residuals is known exactly; frames 9..=17 (the second half) are garbage.
fn write_bead(csv: &mut String, id: u64, state: u8, residual: (f64, f64)) {
    let mut pos = (500.0 + 40.0 * id as f64, 150.0);
    let mut vel: (f64, f64) = if state == 2 {
        (-10.0, 8.0)
    } else {
        (-5.0, 0.0)
    };
    for frame in 0..18u64 {
        let label = if frame == 0 { 3 } else { state };
        if frame > 0 {
            let sign = if frame % 2 == 0 { 1.0 } else { -1.0 };
            let (rx, ry) = (sign * residual.0, sign * residual.1);
            let predicted = match state {
                0 => (0.0, 0.0),
                1 => (vel.0, 0.0),
                // Saltating: a rebound every third step.
                _ if frame % 3 == 0 => (vel.0, -vel.1),
                _ => vel,
            };
            // Rolling and saltating have no velocity before frame 1: a plain first move.
            let step = if frame == 1 && state != 0 {
                vel
            } else if frame >= 9 {
                (37.0 * frame as f64, -11.0)
            } else {
                (predicted.0 + rx, predicted.1 + ry)
            };
            pos = (pos.0 + step.0, pos.1 + step.1);
            vel = step;
        }
        let label = if frame >= 9 { (label + 1) % 3 } else { label };
        writeln!(
            csv,
            "{},{id},{},{},0,{},{},{label}",
            frame + 1,
            pos.0,
            pos.1,
            vel.0,
            vel.1
        )
        .unwrap();
    }
}

#[test]
fn recovers_known_dynamics_from_a_generated_csv() {
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("frame,id,x,y,category,vx,vy,motion_state\n");
    // Six beads per state, three residual shapes each (two for resting).
    let shapes = [
        vec![(1.0, 0.0), (0.0, 1.0)],
        vec![(2.0, 0.0), (0.0, 1.0), (1.0, 1.0)],
        vec![(1.0, 0.0), (0.0, 1.0), (1.0, -1.0)],
    ];
    let mut id = 1;
    for (state, shapes) in shapes.iter().enumerate() {
        for k in 0..6 {
            write_bead(&mut csv, id, state as u8, shapes[k % shapes.len()]);
            id += 1;
        }
    }
    let truth = dir.path().join("beads.csv");
    fs::write(&truth, csv).unwrap();
    let out = dir.path().join("fitted.toml");
    fit(path_str(&truth), &out, &["--min-probability", "0"]);
    let (text, motion) = read_motion(&out);
    // Training frames 0..=8: 7 transitions per bead (frame 0 is unknown), all staying put.
    assert!(text.contains("#   resting   [42, 0, 0]"), "{text}");
    assert!(text.contains("#   saltating [0, 0, 42]"), "{text}");
    assert!(text.contains("kept from the defaults: none"), "{text}");
    assert_eq!(
        motion.transition,
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    );
    // Second moments about zero: the mean of (rx², ry², rx·ry) over the shapes.
    let close = |got: f64, want: f64| assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    let rest = motion.rest_pos_noise;
    close(rest.var_x, 0.5);
    close(rest.var_y, 0.5);
    close(rest.cov_xy, 0.0);
    let roll = motion.roll_pos_noise;
    close(roll.var_x, 5.0 / 3.0);
    close(roll.var_y, 2.0 / 3.0);
    close(roll.cov_xy, 1.0 / 3.0);
    let salt = motion.salt_pos_noise;
    close(salt.var_x, 2.0 / 3.0);
    close(salt.var_y, 2.0 / 3.0);
    close(salt.cov_xy, -1.0 / 3.0);
    assert_eq!(motion.salt_vel_noise, salt);
}

#[test]
fn bad_inputs_exit_1_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("motion.toml");
    let run = |truth: &Path, extra: &[&str]| {
        let mut args = vec![
            "fit",
            "bedload",
            "--truth",
            path_str(truth),
            "--out",
            path_str(&out),
        ];
        args.extend_from_slice(extra);
        let output = sillage(&args);
        assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
        stderr(&output)
    };
    let missing = dir.path().join("missing.csv");
    let message = run(&missing, &[]);
    assert!(
        message.contains("missing.csv") && message.contains("--truth"),
        "{message}"
    );

    let unlabelled = dir.path().join("unlabelled.csv");
    fs::write(&unlabelled, "frame,id,x,y,category\n1,1,5,5,0\n2,1,6,5,0\n").unwrap();
    let message = run(&unlabelled, &[]);
    assert!(
        message.contains("unlabelled.csv") && message.contains("motion_state"),
        "{message}"
    );

    let twice = dir.path().join("twice.csv");
    fs::write(
        &twice,
        "frame,id,x,y,category,vx,vy,motion_state\n1,4,5,5,0,0,0,0\n1,4,6,5,0,0,0,0\n",
    )
    .unwrap();
    let message = run(&twice, &[]);
    assert!(
        message.contains("twice.csv") && message.contains("bead id 4 appears twice in frame 1"),
        "{message}"
    );

    let real = Path::new(TRUTH);
    let message = run(real, &["--min-samples", "100000"]);
    assert!(
        message.contains("trackdatatruth.csv") && message.contains("`min_samples`"),
        "{message}"
    );
    let message = run(real, &["--train-fraction", "1.5"]);
    assert!(
        message.contains("--train-fraction") && message.contains("`train_fraction`"),
        "{message}"
    );
    assert!(!out.exists());
    let nowhere = dir.path().join("no/such/folder/motion.toml");
    let output = sillage(&[
        "fit",
        "bedload",
        "--truth",
        TRUTH,
        "--out",
        path_str(&nowhere),
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert!(stderr(&output).contains("no/such/folder/motion.toml"));
}

/// `--tracks`: the motion-state smoother's evidence learnt from a tracker's output paired
/// with the truth, written under `[smoother.emission]`, which `track bedload` reads back; a
/// lag not shorter than the sequence is refused.
#[test]
fn fits_the_smoother_evidence_and_the_tracker_reads_it() {
    let dir = tempfile::tempdir().unwrap();
    let tracks = dir.path().join("tracks.csv");
    let track = |extra: &[&str]| {
        let mut args = vec![
            "track",
            "bedload",
            concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../../shared/data/bedload_beads_lafaye2018/images"
            ),
            "--mask",
            concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../../shared/data/bedload_beads_lafaye2018/sequence_base_mask.tif"
            ),
            "--out",
            path_str(&tracks),
        ];
        args.extend_from_slice(extra);
        sillage(&args)
    };
    let output = track(&[]);
    assert!(output.status.success(), "{}", stderr(&output));
    let out = dir.path().join("fit.toml");
    let stdout = fit(TRUTH, &out, &["--tracks", path_str(&tracks)]);
    assert!(stdout.contains("motion-state evidence from"), "{stdout}");
    let text = fs::read_to_string(&out).unwrap();
    assert!(
        text.contains("[smoother.emission.rolling.log_speed]"),
        "{text}"
    );
    let config: sillage::track::bedload::BedloadTrackerParams = toml::from_str(&text).unwrap();
    config.validate().unwrap();
    let e = &config.smoother.emission;
    // Resting beads barely move, saltating ones fly: the learnt speeds are ordered.
    assert!(e.resting.log_speed.mean < e.rolling.log_speed.mean);
    assert!(e.rolling.log_speed.mean < e.saltating.log_speed.mean);
    // The saltation threshold is learnt too, between the rolling and the saltating speeds.
    assert!(stdout.contains("saltating at or above"), "{stdout}");
    assert!(text.contains("saltation_speed_m_per_s"), "{text}");
    let threshold = e.saltation_speed_m_per_s.ln();
    assert!(e.rolling.log_speed.mean < threshold && threshold < e.saltating.log_speed.mean);
    assert_ne!(
        e.saltation_speed_m_per_s,
        sillage::track::bedload::EmissionParams::default().saltation_speed_m_per_s
    );
    // The window the evidence was learnt over is written beside it; a narrower one averages
    // a resting bead's jitter less, so its learnt speed is higher.
    assert_eq!(config.smoother.half_window, 2);
    let narrow = dir.path().join("fit0.toml");
    let stdout = fit(
        TRUTH,
        &narrow,
        &[
            "--tracks",
            path_str(&tracks),
            "--half-window",
            "0",
            "--json",
        ],
    );
    let summary: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(summary["half_window"], 0);
    let narrow: sillage::track::bedload::BedloadTrackerParams =
        toml::from_str(&fs::read_to_string(&narrow).unwrap()).unwrap();
    assert_eq!(narrow.smoother.half_window, 0);
    assert!(narrow.smoother.emission.resting.log_speed.mean > e.resting.log_speed.mean);
    let output = track(&["--config", path_str(&out)]);
    assert!(output.status.success(), "{}", stderr(&output));
    // Ten frames cannot hold a lag of ten.
    let output = track(&["--set", "smoother.lag=10"]);
    assert_eq!(output.status.code(), Some(1));
    let message = stderr(&output);
    assert!(
        message.contains("`smoother.lag`") && message.contains("10 frames"),
        "{message}"
    );
}

//! End-to-end tests of the `sillage` binary on generated data in temporary folders: the happy
//! path, TracTrac compatibility, and every kind of bad input with its exit code and message.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::{path_str, sillage, stderr};

use sillage_core::Point2;
use sillage_synth::{Noise, NoiseKind, render_spots};

/// Writes `n` 16-bit TIFF frames of spots drifting right by 1.5 px per frame.
fn write_tiff_frames(dir: &Path, n: usize, width: usize, height: usize) -> Vec<PathBuf> {
    fs::create_dir_all(dir).unwrap();
    (0..n)
        .map(|i| {
            let spots: Vec<_> = (0..40)
                .map(|k| {
                    let base =
                        Point2::new(20.0 + (k % 8) as f64 * 25.0, 20.0 + (k / 8) as f64 * 25.0);
                    (Point2::new(base.x + 1.5 * i as f64, base.y), 0.6, 2.0)
                })
                .collect();
            let image = render_spots(
                width,
                height,
                &spots,
                Noise::new(NoiseKind::Uniform, 0.05),
                i as u64,
            )
            .unwrap();
            let pixels: Vec<u16> = image
                .as_slice()
                .iter()
                .map(|v| (v.clamp(0.0, 1.0) * 65535.0).round() as u16)
                .collect();
            let path = dir.join(format!("img_{i:03}.tif"));
            let file = fs::File::create(&path).unwrap();
            let mut encoder = tiff::encoder::TiffEncoder::new(file).unwrap();
            encoder
                .write_image::<tiff::encoder::colortype::Gray16>(
                    width as u32,
                    height as u32,
                    &pixels,
                )
                .unwrap();
            path
        })
        .collect()
}

/// `sillage synth vortex` into `dir`: square frames of `side` px.
fn synth_vortex(dir: &Path, frames: usize, particles: usize, side: usize, snr: u32) {
    let args = [
        "synth".to_string(),
        "vortex".into(),
        "--out".into(),
        path_str(dir).into(),
        "--frames".into(),
        frames.to_string(),
        "--particles".into(),
        particles.to_string(),
        "--width".into(),
        side.to_string(),
        "--height".into(),
        side.to_string(),
        "--snr".into(),
        snr.to_string(),
    ];
    let out = sillage(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn synth_track_and_eval_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("vortex");
    synth_vortex(&frames, 8, 100, 256, 8);
    let tracks = dir.path().join("vortex_track.txt");
    let out = sillage(&[
        "ptv",
        path_str(&frames),
        "--out",
        path_str(&tracks),
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let summary: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("--json prints JSON");
    assert_eq!(summary["frames"], 8);
    let density = summary["detector"]["measured"]["source_density"]
        .as_f64()
        .expect("the measured source density in --json");
    assert!(density > 0.0 && density < 0.1, "source density {density}");
    // The points written because their trajectories vouch for them are counted among all.
    let restored = summary["restored_points"]
        .as_u64()
        .expect("the restored points in --json");
    assert!(restored <= summary["points"].as_u64().unwrap(), "{summary}");
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
    let text = fs::read_to_string(&tracks).unwrap();
    let header: Vec<&str> = text.lines().take(3).collect();
    assert!(header[0].starts_with("# TracTrac"), "{}", header[0]);
    assert_eq!(
        header[2],
        "#  Frame ID x y Vx Vy Ax Ay Vx(prediction) Vy(prediction) Error(prediction)"
    );
    let row = text.lines().nth(3).expect("at least one track row");
    assert_eq!(row.split_whitespace().count(), 11, "{row}");

    let out = sillage(&[
        "eval",
        "ptv",
        "--truth",
        path_str(&frames.join("truth.csv")),
        "--tracks",
        path_str(&tracks),
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let accuracy: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let true_rate = accuracy["true_recovery_rate"].as_f64().unwrap();
    let false_rate = accuracy["false_recovery_rate"].as_f64().unwrap();
    assert!(true_rate > 0.8, "true recovery {true_rate}");
    assert!(false_rate < 0.1, "false recovery {false_rate}");
}

#[test]
fn particle_images_too_dense_for_ptv_are_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("dense");
    // 0.05 particles per pixel: the images of the vortex's particles cover the frame.
    synth_vortex(&frames, 3, 3000, 256, 4);
    let tracks = dir.path().join("dense_track.txt");
    let out = sillage(&["ptv", path_str(&frames), "--out", path_str(&tracks)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let message = stderr(&out);
    assert!(
        message.contains("warning: the particle images cover the frame (source density"),
        "{message}"
    );
    let header = fs::read_to_string(&tracks).unwrap();
    assert!(
        header.contains("detector.measured.source_density"),
        "{}",
        header.lines().take(5).collect::<Vec<_>>().join("\n")
    );
}

/// OpenPIV's real image pair (8-bit BMP, `../shared/data/piv_openpiv_test1`): read, measured,
/// and told that two frames form no track.
#[test]
fn a_piv_image_pair_in_bmp_is_read_and_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let data = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/piv_openpiv_test1"
    );
    let tracks = dir.path().join("pair_track.txt");
    let pattern = format!("{data}/exp1_001_*.bmp");
    let out = sillage(&["ptv", &pattern, "--out", path_str(&tracks)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let message = stderr(&out);
    assert!(
        message.contains("particle images measured on the first frame"),
        "{message}"
    );
    assert!(
        message.contains("warning: 2 frame(s): PTV links each particle over 3 frames"),
        "{message}"
    );
    assert!(message.contains("2 frames, "), "{message}");
}

#[test]
fn a_tractrac_par_file_and_a_tractrac_track_file_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("frames");
    write_tiff_frames(&frames, 6, 240, 160);
    let par = dir.path().join("tifseq_par.txt");
    fs::write(
        &par,
        "# TracTrac parameters\nvid_loop 1\nBG 0\nnoise 0\npeak_th_auto 1 # automatic\npeak_neigh 1\npeak_conv 1\n\
         peak_conv_size 2.0\npeak_subpix 1\npeak_minima 0\nmotion 1\nmotion_av 5\nmotion_it 0\nfilter 1\n\
         filter_std 1.5\nfilter_time 1.0\nplot 0\n",
    )
    .unwrap();
    let out = sillage(&["config", "--tractrac-par", path_str(&par)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let config = String::from_utf8_lossy(&out.stdout);
    assert!(config.contains("motion_av = 5"), "{config}");
    assert!(config.contains("training_passes = 1"), "{config}");

    let csv = dir.path().join("tracks.csv");
    let out = sillage(&[
        "ptv",
        path_str(&frames),
        "--tractrac-par",
        path_str(&par),
        "--out",
        path_str(&csv),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let rows = fs::read_to_string(&csv).unwrap();
    assert!(rows.starts_with("frame,particle,x,y,vx,vy,ax,ay,vx_pred,vy_pred,log_err"));
    assert!(rows.lines().count() > 40, "{rows}");

    // A file as TracTrac writes it (header of numpy.savetxt, %d/%.3f/%.5f/%.4f columns).
    let tractrac = dir.path().join("tifseq_track.txt");
    fs::write(
        &tractrac,
        "# TracTrac v3.0 \n#  Parameters: {'vid_loop': 2, 'peak_conv': 1}\n\
         #  Frame ID x y Vx Vy Ax Ay Vx(prediction) Vy(prediction) Error(prediction)\n\
         1 0 21.500 20.000 1.50000 0.00000 0.0000 0.0000 1.5000 0.0000 -1.000\n\
         2 0 23.000 20.000 1.50000 0.00000 0.0000 0.0000 1.5000 0.0000 -1.000\n",
    )
    .unwrap();
    let truth = dir.path().join("truth.csv");
    fs::write(
        &truth,
        "frame,track_id,x,y,vx,vy\n1,7,21.5,20.0,1.5,0.0\n2,7,23.0,20.0,1.5,0.0\n",
    )
    .unwrap();
    let out = sillage(&[
        "eval",
        "ptv",
        "--truth",
        path_str(&truth),
        "--tracks",
        path_str(&tractrac),
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let accuracy: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(accuracy["true_recovery_rate"].as_f64(), Some(1.0));
}

#[test]
fn a_missing_or_empty_folder_is_a_user_error() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nowhere");
    let out = sillage(&[
        "ptv",
        path_str(&missing),
        "--out",
        path_str(&dir.path().join("t.csv")),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("nowhere"), "{}", stderr(&out));

    let empty = dir.path().join("empty");
    fs::create_dir(&empty).unwrap();
    let out = sillage(&[
        "ptv",
        path_str(&empty),
        "--out",
        path_str(&dir.path().join("t.csv")),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("no frames"), "{}", stderr(&out));
}

#[test]
fn a_corrupt_tiff_mid_sequence_names_the_file_and_keeps_earlier_rows() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("frames");
    let paths = write_tiff_frames(&frames, 8, 240, 160);
    fs::write(&paths[5], b"II*\0this is not a TIFF any more").unwrap();
    let csv = dir.path().join("tracks.csv");
    let out = sillage(&["ptv", path_str(&frames), "--out", path_str(&csv)]);
    assert_eq!(out.status.code(), Some(1));
    let message = stderr(&out);
    assert!(
        message.contains("img_005.tif") && message.contains("frame 5"),
        "{message}"
    );
    let rows = fs::read_to_string(&csv).expect("rows written before the error are kept");
    let frames_written: Vec<u64> = rows
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert!(!frames_written.is_empty());
    assert!(frames_written.iter().all(|&f| f < 5), "{frames_written:?}");
    for line in rows.lines().skip(1) {
        assert_eq!(line.split(',').count(), 11, "incomplete row {line}");
    }
}

#[test]
fn frames_of_different_sizes_are_a_user_error() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("frames");
    write_tiff_frames(&frames, 3, 240, 160);
    let odd = dir.path().join("odd");
    let odd_paths = write_tiff_frames(&odd, 4, 200, 160);
    fs::rename(&odd_paths[3], frames.join("img_003.tif")).unwrap();
    let out = sillage(&[
        "ptv",
        path_str(&frames),
        "--out",
        path_str(&dir.path().join("t.csv")),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let message = stderr(&out);
    assert!(
        message.contains("img_003.tif") && message.contains("200"),
        "{message}"
    );
}

#[test]
fn par_files_with_unknown_keys_or_bad_values_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let par = dir.path().join("bad_par.txt");
    fs::write(&par, "motion_av 5\npeak_treshold 0.1\n").unwrap();
    let out = sillage(&["config", "--tractrac-par", path_str(&par)]);
    assert_eq!(out.status.code(), Some(1));
    let message = stderr(&out);
    assert!(
        message.contains("bad_par.txt:2") && message.contains("peak_treshold"),
        "{message}"
    );

    fs::write(&par, "motion_av -3\n").unwrap();
    let out = sillage(&["config", "--tractrac-par", path_str(&par)]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("motion_av"), "{}", stderr(&out));

    fs::write(&par, "peak_conv 3\n").unwrap();
    let out = sillage(&["config", "--tractrac-par", path_str(&par)]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("peak_conv"), "{}", stderr(&out));
}

#[test]
fn nan_in_a_truth_file_names_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let truth = dir.path().join("truth.csv");
    fs::write(&truth, "frame,track_id,x,y\n0,1,3.0,4.0\n1,1,NaN,4.0\n").unwrap();
    let tracks = dir.path().join("tracks.csv");
    fs::write(&tracks, "frame,particle,x,y\n0,1,3.0,4.0\n").unwrap();
    let out = sillage(&[
        "eval",
        "ptv",
        "--truth",
        path_str(&truth),
        "--tracks",
        path_str(&tracks),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("truth.csv:3"), "{}", stderr(&out));
}

#[test]
fn bad_command_lines_exit_with_2_and_bad_overrides_with_1() {
    assert_eq!(sillage(&["ptv"]).status.code(), Some(2));
    assert_eq!(sillage(&["frobnicate"]).status.code(), Some(2));
    let out = sillage(&["config", "--set", "tracker.motion_av=0"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("motion_av"), "{}", stderr(&out));
}

#[test]
fn one_thread_and_the_default_write_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("vortex");
    synth_vortex(&frames, 6, 400, 320, 4);
    let run = |threads: Option<&str>, name: &str| {
        let path = dir.path().join(name);
        let mut command = Command::new(env!("CARGO_BIN_EXE_sillage"));
        command.args(["ptv", path_str(&frames), "--out", path_str(&path)]);
        match threads {
            Some(n) => command.env("RAYON_NUM_THREADS", n),
            None => command.env_remove("RAYON_NUM_THREADS"),
        };
        let out = command.output().unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        fs::read(path).unwrap()
    };
    let one = run(Some("1"), "one_track.txt");
    assert!(one.len() > 1000);
    assert_eq!(one, run(None, "default_track.txt"));
    assert_eq!(run(Some("1"), "one.csv"), run(None, "default.csv"));
}

#[test]
fn bench_ptv_accuracy_runs_the_moderate_family() {
    let output = sillage(&[
        "bench",
        "ptv-accuracy",
        "--family",
        "moderate",
        "--half",
        "tune",
        "--size",
        "128",
        "--frames",
        "4",
        "--no-search",
        "--json",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let rows: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 24);
    for row in rows {
        assert_eq!(row["case"]["half"], "tune");
        assert!(
            row["case"]["name"].as_str().unwrap().contains("-m"),
            "{row}"
        );
        let true_pct = row["defaults"]["true_pct"].as_f64().unwrap();
        assert!((0.0..=100.0).contains(&true_pct), "{row}");
    }
}

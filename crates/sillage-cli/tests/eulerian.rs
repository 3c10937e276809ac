//! `sillage eulerian` end to end: the mean velocity field of the TracTrac paper's vortex
//! flow against the analytic field, units and rotation, output formats and errors.

mod common;

use std::collections::HashMap;
use std::path::Path;

use common::{path_str, run_ok, run_user_error};
use sillage_core::Vec2;
use sillage_synth::vortex_map;

/// The rows of a CSV written by `sillage eulerian`, as column name → value (NaN if empty).
fn read_stats(path: &Path) -> Vec<HashMap<String, f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|line| {
            header
                .iter()
                .cloned()
                .zip(line.split(',').map(|v| v.parse().unwrap_or(f64::NAN)))
                .collect()
        })
        .collect()
}

/// The position one frame before `c` under the map of frame `n` (the map is a small
/// perturbation of the identity, so the fixed-point iteration converges fast).
fn inverse_map(c: Vec2, n: u64, delta: f64) -> Vec2 {
    let mut before = c;
    for _ in 0..60 {
        before = before + (c - vortex_map(before, n, delta));
    }
    before
}

/// The central-difference velocity `(x(n+1) − x(n−1)) / 2` of the flow at `c` (relative
/// to the image centre), frame `n`: what a three-frame tracker measures.
fn analytic_velocity(c: Vec2, n: u64, delta: f64) -> Vec2 {
    (vortex_map(c, n, delta) - inverse_map(c, n - 1, delta)) * 0.5
}

#[test]
fn vortex_mean_velocity_matches_the_analytic_field() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("vortex");
    let tracks = dir.path().join("tracks.csv");
    let stats = dir.path().join("stats.csv");
    let plots = dir.path().join("plots");
    // The paper's flow and image (1024², SNR 4, 100 frames), 8000 particles so that each
    // 128-px bin holds ~6000 samples: the sampling error of the bin means stays near 1 %.
    run_ok(&[
        "synth",
        "vortex",
        "--out",
        path_str(&frames),
        "--frames",
        "100",
        "--particles",
        "8000",
    ]);
    run_ok(&["ptv", path_str(&frames), "--out", path_str(&tracks)]);
    run_ok(&[
        "eulerian",
        path_str(&tracks),
        "--bin",
        "128",
        "--out",
        path_str(&stats),
        "--profile",
        "x,y",
        "--plots",
        path_str(&plots),
    ]);
    let bins = read_stats(&stats);
    assert_eq!(bins.len(), 64, "an 8×8 grid over the 1024² image");
    // Frames that carry velocities in the tracks: the analytic field is averaged over them.
    let tracked_frames: Vec<u64> = {
        let text = std::fs::read_to_string(&tracks).unwrap();
        let mut frames: Vec<u64> = text
            .lines()
            .skip(1)
            .filter(|l| l.split(',').nth(4).is_some_and(|v| !v.is_empty()))
            .map(|l| l.split(',').next().unwrap().parse().unwrap())
            .collect();
        frames.sort_unstable();
        frames.dedup();
        frames
    };
    let centre = Vec2::new(511.5, 511.5);
    let (mut error2, mut reference2) = (0.0, 0.0);
    for bin in &bins {
        let (column, row) = (bin["column"], bin["row"]);
        // The analytic field averaged over an 8×8 sub-grid of the bin and the frames.
        let mut sum = Vec2::ZERO;
        let mut samples = 0.0;
        for &n in &tracked_frames {
            for a in 0..8 {
                for b in 0..8 {
                    let x = (column + (a as f64 + 0.5) / 8.0) * 128.0;
                    let y = (row + (b as f64 + 0.5) / 8.0) * 128.0;
                    sum = sum + analytic_velocity(Vec2::new(x, y) - centre, n, 0.01);
                    samples += 1.0;
                }
            }
        }
        let analytic = sum * (1.0 / samples);
        let measured = Vec2::new(bin["u"], bin["v"]);
        error2 += (measured - analytic).norm().powi(2);
        reference2 += analytic.norm().powi(2);
    }
    let relative_rms = (error2 / reference2).sqrt();
    assert!(
        relative_rms < 0.02,
        "mean velocity field off the analytic one by {:.2} % RMS",
        100.0 * relative_rms
    );
    for axis in ["x", "y"] {
        let profile = read_stats(&dir.path().join(format!("stats_profile_{axis}.csv")));
        assert_eq!(profile.len(), 8, "profile along {axis}");
        let points: f64 = profile.iter().map(|p| p["points"]).sum();
        let all: f64 = bins.iter().map(|b| b["points"]).sum();
        assert_eq!(points, all, "a profile pools every point");
    }
    for name in [
        "points",
        "speed",
        "u",
        "v",
        "tke",
        "uv",
        "profile_x_velocity",
        "profile_x_stresses",
        "profile_y_velocity",
        "profile_y_stresses",
    ] {
        let png = plots.join(format!("eulerian_{name}.png"));
        let picture = image::open(&png).unwrap();
        assert_eq!((picture.width(), picture.height()), (720, 600), "{name}");
    }
}

/// A table of one track moving at (2, 0) px/frame, then one at (0, 1) px/frame in another
/// bin.
fn uniform_tracks(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("uniform.csv");
    let mut text = String::from("frame,particle,x,y,vx,vy,ax,ay,vx_pred,vy_pred,log_err\n");
    for frame in 0..10 {
        let x = 5.0 + 2.0 * frame as f64;
        text += &format!("{frame},1,{x},5,2,0,,,,,-1\n");
        text += &format!("{frame},2,45,{},0,1,,,,,\n", 5.0 + frame as f64);
    }
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn calibration_and_rotation_set_the_units_and_the_components() {
    let dir = tempfile::tempdir().unwrap();
    let tracks = uniform_tracks(dir.path());
    let stats = dir.path().join("stats.csv");
    // 1 mm per px, 50 fps: 2 px/frame = 0.1 m/s. The grid turned 90° counter-clockwise on
    // the image: its x axis points up the image, its y axis along the image's x.
    run_ok(&[
        "eulerian",
        path_str(&tracks),
        "--bin",
        "0.04m",
        "--calibration",
        "0.001,50",
        "--rotate",
        "90",
        "--out",
        path_str(&stats),
    ]);
    let bins = read_stats(&stats);
    let first = bins.iter().find(|b| b["v"] > 0.09).expect("track 1's bins");
    assert!(first["u"].abs() < 1e-12, "{first:?}");
    assert!((first["v"] - 0.1).abs() < 1e-12, "{first:?}");
    assert!((first["log10_pred_err"] + 1.0).abs() < 1e-12);
    let second = bins
        .iter()
        .find(|b| b["u"] < -0.04)
        .expect("track 2's bins");
    assert!((second["u"] + 0.05).abs() < 1e-12, "{second:?}");
    assert!(
        second["log10_pred_err"].is_nan(),
        "no prediction errors in track 2"
    );
    // Bins of 4 cm = 40 px: positions (5..23, 5) and (45, 5..14) in px.
    assert!(bins.iter().all(|b| (b["x"] / 0.02).fract().abs() < 1e-9));
}

#[test]
fn npy_and_parquet_outputs_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let tracks = uniform_tracks(dir.path());
    for (name, magic) in [("stats.npy", &b"\x93NUMPY"[..]), ("stats.parquet", b"PAR1")] {
        let out = dir.path().join(name);
        run_ok(&["eulerian", path_str(&tracks), "--out", path_str(&out)]);
        let bytes = std::fs::read(&out).unwrap();
        assert!(bytes.starts_with(magic), "{name}");
    }
    let npy = std::fs::read(dir.path().join("stats.npy")).unwrap();
    let header_len = u16::from_le_bytes([npy[8], npy[9]]) as usize;
    let header = std::str::from_utf8(&npy[10..10 + header_len]).unwrap();
    assert!(header.contains("('u', '<f8')") && header.contains("('points', '<i8')"));
    let rows: usize = header
        .split("'shape': (")
        .nth(1)
        .and_then(|s| s.split(',').next())
        .unwrap()
        .parse()
        .unwrap();
    // 15 fields of 8 bytes per bin.
    assert_eq!(npy.len() - 10 - header_len, rows * 15 * 8);
}

#[test]
fn bad_input_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let tracks = uniform_tracks(dir.path());
    let out = dir.path().join("stats.csv");
    let message = run_user_error(&[
        "eulerian",
        path_str(&tracks),
        "--bin",
        "0.01m",
        "--out",
        path_str(&out),
    ]);
    assert!(message.contains("--calibration"), "{message}");
    let message = run_user_error(&[
        "eulerian",
        path_str(&tracks),
        "--out",
        path_str(&dir.path().join("stats.xlsx")),
    ]);
    assert!(
        message.contains("stats.xlsx") && message.contains(".npy"),
        "{message}"
    );
    let broken = dir.path().join("broken.csv");
    std::fs::write(&broken, "frame,particle,x,y\n0,1,3,4\n1,1,oops,4\n").unwrap();
    let message = run_user_error(&["eulerian", path_str(&broken), "--out", path_str(&out)]);
    assert!(
        message.contains("broken.csv:3") && message.contains("oops"),
        "{message}"
    );
    let empty = dir.path().join("empty.csv");
    std::fs::write(&empty, "frame,particle,x,y\n").unwrap();
    let message = run_user_error(&["eulerian", path_str(&empty), "--out", path_str(&out)]);
    assert!(message.contains("no rows"), "{message}");
    assert!(!out.exists(), "nothing written on errors");
}

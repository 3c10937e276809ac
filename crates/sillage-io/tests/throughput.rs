//! Throughput of the writers and the frame reader (slow; run with
//! `cargo test -p sillage-io --release --all-features --test throughput -- --ignored --nocapture`).

use std::time::Instant;

use sillage_core::{GrayImage, Point2, TrackPoint, Vec2};
use sillage_io::{
    FrameOptions, TrackFileHeader, TrackFormat, create_track_writer, open_frames, read_tracks,
    write_png16,
};

#[test]
#[ignore = "slow: prints timings for BENCHMARKS.md"]
fn writers_and_readers_on_one_million_rows() {
    let dir = tempfile::tempdir().unwrap();
    let points: Vec<TrackPoint> = (0..1_000_000u64)
        .map(|i| {
            let mut p = TrackPoint::at(
                i / 1000,
                i % 1000,
                Point2::new(i as f64 * 0.37 % 2048.0, i as f64 * 0.11 % 2048.0),
            );
            p.vel_px_per_frame = Some(Vec2::new(0.5, -0.25));
            p.acc_px_per_frame2 = Some(Vec2::new(0.01, 0.0));
            p.vel_pred_px_per_frame = Some(Vec2::new(0.49, -0.26));
            p.log10_pred_err = Some(-1.5);
            p
        })
        .collect();
    for format in TrackFormat::ALL {
        let path = dir.path().join(format!(
            "tracks.{}",
            match format {
                TrackFormat::Tractrac => "txt",
                TrackFormat::Csv => "csv",
                TrackFormat::Parquet => "parquet",
                TrackFormat::Hdf5 => "h5",
            }
        ));
        let start = Instant::now();
        let Ok(mut writer) = create_track_writer(&path, format, &TrackFileHeader::default()) else {
            println!("{format}: not built");
            continue;
        };
        for frame in points.chunks(1000) {
            writer.accept(frame).unwrap();
        }
        writer.finish().unwrap();
        let written = start.elapsed();
        let start = Instant::now();
        let back = read_tracks(&path, format).unwrap();
        let read = start.elapsed();
        assert_eq!(back.len(), points.len());
        let size = std::fs::metadata(&path).unwrap().len();
        println!(
            "{format:>8}: write {:>6.0} ms, read {:>6.0} ms, {:>6.1} MB for 1M rows",
            written.as_secs_f64() * 1e3,
            read.as_secs_f64() * 1e3,
            size as f64 / 1e6
        );
    }
}

#[test]
#[ignore = "slow: prints timings for BENCHMARKS.md"]
fn frame_reader_on_png16_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h, n) = (1024, 1024, 50);
    let image =
        GrayImage::from_vec(w, h, (0..w * h).map(|i| (i % 977) as f32 / 977.0).collect()).unwrap();
    let start = Instant::now();
    for i in 0..n {
        write_png16(dir.path().join(format!("f{i:04}.png")), &image).unwrap();
    }
    let written = start.elapsed();
    let start = Instant::now();
    let count = open_frames(dir.path().to_str().unwrap(), &FrameOptions::default())
        .unwrap()
        .inspect(|f| assert!(f.is_ok()))
        .count();
    let read = start.elapsed();
    assert_eq!(count, n);
    println!(
        "png16 {w}x{h}: write {:.1} ms/frame, read {:.1} ms/frame",
        written.as_secs_f64() * 1e3 / n as f64,
        read.as_secs_f64() * 1e3 / n as f64
    );
}

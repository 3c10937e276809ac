//! `sillage bench eulerian`: the time and peak memory of binning track tables of growing
//! length (10⁵ to 10⁷ rows by default). The statistics stream row by row, so the peak
//! memory must stay flat while the time grows linearly.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use serde::Serialize;
use sillage::core::{Point2, TrackPoint, Vec2};
use sillage::eval::eulerian::GridParams;
use sillage::io::{TrackFileHeader, TrackFormat, create_track_writer};

use crate::bench::{peak_rss_mib, reset_peak_rss};
use crate::cli::BenchEulerianArgs;
use crate::eulerian::accumulate;
use crate::ptv::output_format;

/// Points per generated frame.
const POINTS_PER_FRAME: u64 = 1000;

/// One row of the table.
#[derive(Serialize)]
struct BenchRow {
    rows: u64,
    format: String,
    file_mib: f64,
    seconds: f64,
    million_rows_per_s: f64,
    bins: usize,
    peak_rss_mib: Option<f64>,
}

/// Runs `sillage bench eulerian`.
pub fn run(args: &BenchEulerianArgs) -> Result<()> {
    let format = output_format(Some(args.format), Path::new("."))?;
    if !args.json {
        println!(
            "{:>10} {:>8} {:>9} {:>9} {:>10} {:>6} {:>14}",
            "rows", "format", "file MiB", "time s", "Mrows/s", "bins", "peak RSS MiB"
        );
    }
    for &rows in &args.rows {
        let path = args.dir.join(format!(
            "sillage_bench_eulerian_{rows}.{}",
            extension(format)
        ));
        write_table(&path, format, rows)?;
        let file_mib = std::fs::metadata(&path)?.len() as f64 / (1 << 20) as f64;
        let peak_measured = reset_peak_rss();
        let start = Instant::now();
        let grid = accumulate(&path, format, GridParams::default());
        let seconds = start.elapsed().as_secs_f64();
        let peak = peak_rss_mib().filter(|_| peak_measured);
        std::fs::remove_file(&path).with_context(|| format!("cannot remove {}", path.display()))?;
        let row = BenchRow {
            rows,
            format: format.name().into(),
            file_mib,
            seconds,
            million_rows_per_s: rows as f64 / seconds / 1e6,
            bins: grid?.accumulators().len(),
            peak_rss_mib: peak,
        };
        if args.json {
            println!("{}", serde_json::to_string(&row)?);
        } else {
            println!(
                "{:>10} {:>8} {:>9.1} {:>9.2} {:>10.2} {:>6} {:>14}",
                row.rows,
                row.format,
                row.file_mib,
                row.seconds,
                row.million_rows_per_s,
                row.bins,
                row.peak_rss_mib.map_or("n/a".into(), |m| format!("{m:.1}")),
            );
        }
    }
    Ok(())
}

fn extension(format: TrackFormat) -> &'static str {
    match format {
        TrackFormat::Tractrac => "txt",
        TrackFormat::Csv => "csv",
        TrackFormat::Parquet => "parquet",
        TrackFormat::Hdf5 => "h5",
    }
}

/// SplitMix64: a fixed, dependency-free stream of well-mixed numbers for the generated rows.
fn mix(index: u64) -> u64 {
    let mut z = index.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A number in [0, 1) from `index`.
fn unit(index: u64) -> f64 {
    (mix(index) >> 11) as f64 / (1u64 << 53) as f64
}

/// Writes `rows` rows: `POINTS_PER_FRAME` points per frame spread over a 1024² image, with
/// velocities and prediction errors.
fn write_table(path: &Path, format: TrackFormat, rows: u64) -> Result<()> {
    let mut writer = create_track_writer(path, format, &TrackFileHeader::default())?;
    let mut batch = Vec::with_capacity(POINTS_PER_FRAME as usize);
    for start in (0..rows).step_by(POINTS_PER_FRAME as usize) {
        batch.clear();
        for i in start..(start + POINTS_PER_FRAME).min(rows) {
            let (frame, particle) = (i / POINTS_PER_FRAME, i % POINTS_PER_FRAME);
            let mut point = TrackPoint::at(
                frame,
                particle,
                Point2::new(1024.0 * unit(4 * i), 1024.0 * unit(4 * i + 1)),
            );
            point.vel_px_per_frame = Some(Vec2::new(unit(4 * i + 2) - 0.5, unit(4 * i + 3)));
            point.log10_pred_err = Some(-unit(i ^ 0x5555));
            batch.push(point);
        }
        writer.accept(&batch)?;
    }
    writer.finish()?;
    Ok(())
}

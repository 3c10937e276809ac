//! `sillage bench eulerian`: the time and peak memory of binning a generated track table. The
//! statistics stream row by row, so the peak memory must stay flat while the time grows
//! linearly with the rows.

use std::path::Path;
use std::time::Instant;

use serde::Serialize;
use sillage_core::{Error, Point2, Result, TrackPoint, Vec2};
use sillage_eval::eulerian::GridParams;
use sillage_io::{TrackFileHeader, TrackFormat, create_track_writer};

use crate::eulerian::accumulate;
use crate::process_memory::{peak_rss_mib, reset_peak_rss};

/// Points per generated frame.
const POINTS_PER_FRAME: u64 = 1000;

/// One row of the table.
#[derive(Debug, Clone, Serialize)]
pub struct EulerianBenchRow {
    /// Rows of the generated table.
    pub rows: u64,
    /// Its format's name.
    pub format: String,
    /// Its size, MiB.
    pub file_mib: f64,
    /// Time to bin it, s.
    pub seconds: f64,
    /// Binning throughput, millions of rows per second.
    pub million_rows_per_s: f64,
    /// Bins with at least one point.
    pub bins: usize,
    /// Peak resident memory while binning, MiB (Linux only).
    pub peak_rss_mib: Option<f64>,
}

/// Writes a table of `rows` rows in `format` into `dir`, bins it with the default grid (timed,
/// its peak memory measured), removes it; `on_row` is called for each row binned.
pub fn bench_eulerian_case(
    dir: &Path,
    format: TrackFormat,
    rows: u64,
    on_row: &mut dyn FnMut(),
) -> Result<EulerianBenchRow> {
    let path = dir.join(format!(
        "sillage_bench_eulerian_{rows}.{}",
        extension(format)
    ));
    write_table(&path, format, rows)?;
    let file_mib = std::fs::metadata(&path)
        .map_err(|e| Error::io(&path, e))?
        .len() as f64
        / (1 << 20) as f64;
    let peak_measured = reset_peak_rss();
    let start = Instant::now();
    let grid = accumulate(&path, format, GridParams::default(), on_row);
    let seconds = start.elapsed().as_secs_f64();
    let peak = peak_rss_mib().filter(|_| peak_measured);
    std::fs::remove_file(&path)
        .map_err(|e| Error::input(format!("cannot remove {}: {e}", path.display())))?;
    Ok(EulerianBenchRow {
        rows,
        format: format.name().into(),
        file_mib,
        seconds,
        million_rows_per_s: rows as f64 / seconds / 1e6,
        bins: grid?.accumulators().len(),
        peak_rss_mib: peak,
    })
}

/// The file extension of `format`.
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_generated_table_is_binned_then_removed() {
        let dir = tempfile::tempdir().unwrap();
        let mut rows_binned = 0;
        let row = bench_eulerian_case(dir.path(), TrackFormat::Csv, 2500, &mut || rows_binned += 1)
            .unwrap();
        assert_eq!(
            (row.rows, rows_binned, row.format.as_str()),
            (2500, 2500, "csv")
        );
        assert!(row.bins > 0 && row.file_mib > 0.0, "{row:?}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}

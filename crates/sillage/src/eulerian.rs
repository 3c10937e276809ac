//! `sillage eulerian`: track tables binned on a grid in one streaming pass (memory independent
//! of the number of rows) — per bin the count, concentration, mean velocity, Reynolds-stress
//! terms, turbulent kinetic energy, mean speed and mean log prediction error (the TracTrac
//! paper's §4, Fig. 6) — written as CSV, Parquet or NPY, with optional profiles and heatmaps.

use std::path::{Path, PathBuf};

use sillage_core::{Calibration, Error, Point2, Result};
use sillage_eval::eulerian::{BinStats, EulerianGrid, GridParams, ProfileAxis};
use sillage_io::{
    ColumnValues, NumericTable, TrackFormat, for_each_track_point, write_numeric_table,
};

use crate::eulerian_plots::write_eulerian_plots;

/// The side of a bin, in pixels or, with a calibration, in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BinSize {
    /// In pixels.
    Px(f64),
    /// In metres.
    Metres(f64),
}

/// The grid of bins of `bin` side, origin and rotation (degrees); lengths and velocities are
/// in m and m/s with a `calibration`, else in px and px/frame. Validated.
pub fn grid_params(
    bin: BinSize,
    origin_px: Point2,
    rotation_deg: f64,
    calibration: Option<Calibration>,
) -> Result<GridParams> {
    let bin_size = match (bin, calibration) {
        (BinSize::Px(px), None) => px,
        (BinSize::Px(px), Some(c)) => px * c.m_per_px,
        (BinSize::Metres(m), Some(_)) => m,
        (BinSize::Metres(m), None) => {
            return Err(Error::input(format!(
                "--bin {m}m is in metres but no --calibration M_PER_PX,FPS was given; give one, \
                 or a bin size in px"
            )));
        }
    };
    let params = GridParams {
        bin_size,
        origin_px,
        rotation_deg,
        calibration,
    };
    params.validate()?;
    Ok(params)
}

/// One pass over the rows of the track table at `path`; `on_row` is called for each row
/// (progress spinners).
pub fn accumulate(
    path: &Path,
    format: TrackFormat,
    params: GridParams,
    on_row: &mut dyn FnMut(),
) -> Result<EulerianGrid> {
    let mut grid = EulerianGrid::new(params)?;
    for_each_track_point(path, format, |point| {
        on_row();
        grid.push(&point)
    })
    .map_err(|e| Error::input(format!("reading {}: {e}", path.display())))?;
    Ok(grid)
}

/// What [`write_eulerian`] binned and wrote.
#[derive(Debug, Clone)]
pub struct EulerianReport {
    /// Rows read.
    pub rows: u64,
    /// First and last frame of the table (0-based).
    pub frames: (u64, u64),
    /// Bins with at least one point.
    pub bins: usize,
    /// The side of a bin, in [`EulerianReport::units`].
    pub bin_size: f64,
    /// `"px, px/frame"`, or `"m, m/s"` with a calibration.
    pub units: &'static str,
    /// Every file written: the statistics, the profiles, the plots.
    pub written: Vec<PathBuf>,
}

/// Bins the track table `tracks` with `params` and writes the statistics per bin to `out`,
/// the profiles along each of `profiles` beside it (`OUT_profile_x.EXT`) and, with `plots`,
/// the heatmaps and profile charts into that folder; `on_row` is called for each row read.
pub fn write_eulerian(
    tracks: &Path,
    format: TrackFormat,
    params: GridParams,
    out: &Path,
    profiles: &[ProfileAxis],
    plots: Option<&Path>,
    on_row: &mut dyn FnMut(),
) -> Result<EulerianReport> {
    let grid = accumulate(tracks, format, params, on_row)?;
    if grid.rows() == 0 {
        return Err(Error::input(format!(
            "{}: the table has no rows; nothing to bin",
            tracks.display()
        )));
    }
    let bins = grid.bins();
    write_numeric_table(out, &stats_table(&bins)?)?;
    let mut written = vec![out.to_path_buf()];
    let mut profile_stats = Vec::new();
    for &axis in profiles {
        let path = profile_path(out, axis);
        let profile = grid.profile(axis);
        write_numeric_table(&path, &stats_table(&profile)?)?;
        written.push(path);
        profile_stats.push((axis, profile));
    }
    if let Some(dir) = plots {
        written.extend(write_eulerian_plots(dir, &grid, &bins, &profile_stats)?);
    }
    let units = if grid.params().calibration.is_some() {
        "m, m/s"
    } else {
        "px, px/frame"
    };
    Ok(EulerianReport {
        rows: grid.rows(),
        frames: grid.frame_span().unwrap_or((0, 0)),
        bins: bins.len(),
        bin_size: grid.params().bin_size,
        units,
        written,
    })
}

/// `OUT_profile_x.EXT` beside `out`.
fn profile_path(out: &Path, axis: ProfileAxis) -> PathBuf {
    let stem = out
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("eulerian");
    let extension = out.extension().and_then(|e| e.to_str()).unwrap_or("csv");
    let axis = match axis {
        ProfileAxis::X => "x",
        ProfileAxis::Y => "y",
    };
    out.with_file_name(format!("{stem}_profile_{axis}.{extension}"))
}

/// The columns written per bin (units: px and px/frame, or m and m/s with a calibration).
pub const STATS_COLUMNS: [&str; 15] = [
    "column",
    "row",
    "x",
    "y",
    "points",
    "concentration",
    "velocities",
    "u",
    "v",
    "uu",
    "vv",
    "uv",
    "tke",
    "speed",
    "log10_pred_err",
];

/// The statistics of `bins` as a table of [`STATS_COLUMNS`].
fn stats_table(bins: &[BinStats]) -> Result<NumericTable> {
    let ints = |f: fn(&BinStats) -> i64| ColumnValues::Int(bins.iter().map(f).collect());
    let floats = |f: fn(&BinStats) -> f64| ColumnValues::Float(bins.iter().map(f).collect());
    let columns = [
        ints(|b| b.column),
        ints(|b| b.row),
        floats(|b| b.centre.x),
        floats(|b| b.centre.y),
        ints(|b| b.points as i64),
        floats(|b| b.concentration),
        ints(|b| b.velocities as i64),
        floats(|b| b.mean_velocity.x),
        floats(|b| b.mean_velocity.y),
        floats(|b| b.stresses[0]),
        floats(|b| b.stresses[1]),
        floats(|b| b.stresses[2]),
        floats(|b| b.turbulent_kinetic_energy),
        floats(|b| b.mean_speed),
        floats(|b| b.mean_log10_pred_err),
    ];
    let mut table = NumericTable::default();
    for (name, values) in STATS_COLUMNS.into_iter().zip(columns) {
        table.push(name, values)?;
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_in_metres_need_a_calibration_and_px_bins_are_scaled() {
        let origin = Point2::new(0.0, 0.0);
        let err = grid_params(BinSize::Metres(0.01), origin, 0.0, None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("--calibration"), "{err}");
        let calibration = Calibration::new(0.001, 50.0).unwrap();
        let params = grid_params(BinSize::Px(16.0), origin, 0.0, Some(calibration)).unwrap();
        assert!((params.bin_size - 0.016).abs() < 1e-12);
        assert_eq!(
            profile_path(Path::new("out/stats.parquet"), ProfileAxis::Y),
            PathBuf::from("out/stats_profile_y.parquet")
        );
    }
}

//! `sillage eulerian`: tracks binned on a grid in one streaming pass (memory independent of
//! the number of rows) — per bin the count, concentration, mean velocity, Reynolds-stress
//! terms, turbulent kinetic energy, mean speed and mean log prediction error — written as
//! CSV, Parquet or NPY, with optional profiles and PNG heatmaps.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use sillage::core::{Calibration, Point2};
use sillage::eval::eulerian::{BinStats, EulerianGrid, GridParams, ProfileAxis};
use sillage::io::{
    ColumnValues, NumericTable, TrackFormat, for_each_track_point, write_numeric_table,
};

use crate::cli::{AxisArg, BinSizeArg, EulerianArgs};
use crate::progress::RowProgress;
use crate::ptv::output_format;

/// Runs `sillage eulerian`.
pub fn run(args: &EulerianArgs) -> Result<()> {
    let params = grid_params(args)?;
    let format = output_format(args.format, &args.tracks)?;
    let grid = accumulate(&args.tracks, format, params)?;
    if grid.rows() == 0 {
        bail!(
            "{}: the table has no rows; nothing to bin",
            args.tracks.display()
        );
    }
    let bins = grid.bins();
    write_numeric_table(&args.out, &stats_table(&bins)?)?;
    let mut written = vec![args.out.clone()];
    let mut profiles = Vec::new();
    for &axis in &args.profile {
        let path = profile_path(&args.out, axis);
        let axis = match axis {
            AxisArg::X => ProfileAxis::X,
            AxisArg::Y => ProfileAxis::Y,
        };
        let profile = grid.profile(axis);
        write_numeric_table(&path, &stats_table(&profile)?)?;
        written.push(path);
        profiles.push((axis, profile));
    }
    if let Some(dir) = &args.plots {
        written.extend(crate::eulerian_plots::write(dir, &grid, &bins, &profiles)?);
    }
    report(args, &grid, bins.len(), &written);
    Ok(())
}

fn grid_params(args: &EulerianArgs) -> Result<GridParams> {
    let calibration = args
        .calibration
        .map(|(m_per_px, fps)| Calibration::new(m_per_px, fps))
        .transpose()
        .context("--calibration M_PER_PX,FPS")?;
    let bin_size = match (args.bin, calibration) {
        (BinSizeArg::Px(px), None) => px,
        (BinSizeArg::Px(px), Some(c)) => px * c.m_per_px,
        (BinSizeArg::Metres(m), Some(_)) => m,
        (BinSizeArg::Metres(m), None) => bail!(
            "--bin {m}m is in metres but no --calibration M_PER_PX,FPS was given; give one, or \
             a bin size in px"
        ),
    };
    let params = GridParams {
        bin_size,
        origin_px: Point2::new(args.origin.0, args.origin.1),
        rotation_deg: args.rotate,
        calibration,
    };
    params.validate()?;
    Ok(params)
}

/// One pass over the rows of the track table at `path`.
pub(crate) fn accumulate(
    path: &Path,
    format: TrackFormat,
    params: GridParams,
) -> Result<EulerianGrid> {
    let mut grid = EulerianGrid::new(params)?;
    let mut progress = RowProgress::new("binning");
    for_each_track_point(path, format, |point| {
        progress.tick();
        grid.push(&point)
    })
    .with_context(|| format!("reading {}", path.display()))?;
    progress.finish();
    Ok(grid)
}

/// `OUT_profile_x.EXT` beside `out`.
fn profile_path(out: &Path, axis: AxisArg) -> PathBuf {
    let stem = out
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("eulerian");
    let extension = out.extension().and_then(|e| e.to_str()).unwrap_or("csv");
    let axis = match axis {
        AxisArg::X => "x",
        AxisArg::Y => "y",
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

fn report(args: &EulerianArgs, grid: &EulerianGrid, bins: usize, written: &[PathBuf]) {
    let units = if grid.params().calibration.is_some() {
        "m, m/s"
    } else {
        "px, px/frame"
    };
    let (first, last) = grid.frame_span().unwrap_or((0, 0));
    if args.json {
        let files: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
        let summary = serde_json::json!({
            "rows": grid.rows(),
            "frames": [first, last],
            "bins": bins,
            "bin_size": grid.params().bin_size,
            "units": units,
            "written": files,
        });
        println!("{summary}");
    } else {
        eprintln!(
            "{} rows (frames {first}-{last}) in {bins} bins of {} ({units}); wrote {}",
            grid.rows(),
            grid.params().bin_size,
            written
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
}

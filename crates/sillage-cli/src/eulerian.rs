//! `sillage eulerian`: tracks binned on a grid in one streaming pass (memory independent of
//! the number of rows) — per bin the count, concentration, mean velocity, Reynolds-stress
//! terms, turbulent kinetic energy, mean speed and mean log prediction error — written as
//! CSV, Parquet or NPY, with optional profiles and PNG heatmaps.

use anyhow::{Context, Result};
use sillage::core::{Calibration, Point2};
use sillage::eulerian::{BinSize, EulerianReport, grid_params, write_eulerian};
use sillage::eval::eulerian::{GridParams, ProfileAxis};

use crate::cli::{AxisArg, BinSizeArg, EulerianArgs};
use crate::progress::RowProgress;
use crate::ptv::output_format;

/// Runs `sillage eulerian`.
pub fn run(args: &EulerianArgs) -> Result<()> {
    let params = params(args)?;
    let format = output_format(args.format, &args.tracks)?;
    let profiles: Vec<ProfileAxis> = args
        .profile
        .iter()
        .map(|axis| match axis {
            AxisArg::X => ProfileAxis::X,
            AxisArg::Y => ProfileAxis::Y,
        })
        .collect();
    let mut progress = RowProgress::new("binning");
    let report = write_eulerian(
        &args.tracks,
        format,
        params,
        &args.out,
        &profiles,
        args.plots.as_deref(),
        &mut || progress.tick(),
    );
    progress.finish();
    print_report(args.json, &report?);
    Ok(())
}

/// The grid of `--bin`, `--origin`, `--rotate` and `--calibration`.
fn params(args: &EulerianArgs) -> Result<GridParams> {
    let calibration = args
        .calibration
        .map(|(m_per_px, fps)| Calibration::new(m_per_px, fps))
        .transpose()
        .context("--calibration M_PER_PX,FPS")?;
    let bin = match args.bin {
        BinSizeArg::Px(px) => BinSize::Px(px),
        BinSizeArg::Metres(m) => BinSize::Metres(m),
    };
    let origin = Point2::new(args.origin.0, args.origin.1);
    Ok(grid_params(bin, origin, args.rotate, calibration)?)
}

fn print_report(json: bool, report: &EulerianReport) {
    let (first, last) = report.frames;
    let files: Vec<String> = report
        .written
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    if json {
        let summary = serde_json::json!({
            "rows": report.rows,
            "frames": [first, last],
            "bins": report.bins,
            "bin_size": report.bin_size,
            "units": report.units,
            "written": files,
        });
        println!("{summary}");
    } else {
        eprintln!(
            "{} rows (frames {first}-{last}) in {} bins of {} ({}); wrote {}",
            report.rows,
            report.bins,
            report.bin_size,
            report.units,
            files.join(", ")
        );
    }
}

//! `sillage eulerian`: tracks binned on a grid in one streaming pass (memory independent of
//! the number of rows) — per bin the count, concentration, mean velocity, Reynolds-stress
//! terms, turbulent kinetic energy, mean speed and mean log prediction error — written as
//! CSV, Parquet or NPY, with optional profiles and PNG heatmaps.

use std::path::PathBuf;
use std::str::FromStr;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use sillage::core::{Calibration, Point2};
use sillage::eulerian::{BinSize, EulerianReport, grid_params, write_eulerian};
use sillage::eval::eulerian::{GridParams, ProfileAxis};

use crate::progress::RowProgress;
use crate::ptv::output_format;
use crate::shared_args::{FormatArg, JsonArg};

/// `sillage eulerian`.
#[derive(Debug, Args)]
pub struct EulerianArgs {
    /// Tracks to bin: TracTrac _track.txt, CSV or Parquet (read row by row).
    pub tracks: PathBuf,
    /// Format of TRACKS (default: from its extension).
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
    /// Statistics per bin: .csv, .parquet or .npy (a numpy structured array).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Bin side: px (`16`, `16px`) or metres (`0.002m`, needs --calibration).
    #[arg(long, value_name = "SIZE", default_value = "16")]
    pub bin: BinSizeArg,
    /// Pixel size and frame rate, `M_PER_PX,FPS`: positions in m, velocities in m/s.
    #[arg(long, value_name = "M_PER_PX,FPS", value_parser = parse_number_pair)]
    pub calibration: Option<(f64, f64)>,
    /// Grid origin and rotation pivot in the image, px, `X,Y`.
    #[arg(long, value_name = "X,Y", value_parser = parse_number_pair, default_value = "0,0")]
    pub origin: (f64, f64),
    /// Rotation of the grid's x axis, degrees counter-clockwise on the image (u along it).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub rotate: f64,
    /// Also write profiles along these axes (rows or columns of bins pooled), as
    /// `<out stem>_profile_<axis>.<ext>` beside --out.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub profile: Vec<AxisArg>,
    /// Folder for PNG heatmaps (count, mean speed, u, v, TKE, <u'v'>) and profile plots.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// A bin size with its unit, from `--bin`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BinSizeArg {
    /// In pixels.
    Px(f64),
    /// In metres.
    Metres(f64),
}

impl FromStr for BinSizeArg {
    type Err = String;

    /// Parses `16`, `16px` or `0.002m`.
    fn from_str(text: &str) -> Result<Self, String> {
        let text = text.trim();
        let (number, metres) = if let Some(n) = text.strip_suffix("px") {
            (n, false)
        } else if let Some(n) = text.strip_suffix('m') {
            (n, true)
        } else {
            (text, false)
        };
        let size = number
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| format!("`{text}` is not a bin size > 0, e.g. 16, 16px or 0.002m"))?;
        Ok(if metres {
            Self::Metres(size)
        } else {
            Self::Px(size)
        })
    }
}

/// Parses `A,B` as two finite numbers.
fn parse_number_pair(text: &str) -> Result<(f64, f64), String> {
    let numbers: Vec<f64> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("`{text}` is not two numbers separated by a comma"))?;
    match numbers[..] {
        [a, b] => Ok((a, b)),
        _ => Err(format!("`{text}` is not two numbers separated by a comma")),
    }
}

/// An image axis, for profiles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AxisArg {
    /// Along x: each column of bins pooled.
    X,
    /// Along y: each row of bins pooled.
    Y,
}

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
    print_report(args.json.enabled, &report?);
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

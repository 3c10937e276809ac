//! `sillage fit motion-prior` and `sillage fit homography`: what the pedestrian IMM particle
//! filter of Madrigal & Hayet learns before tracking, from MOTChallenge files. The learned
//! motion prior (§5.1) is written as JSON; the image ↔ ground homography and the adult's box
//! size in metres (§4) as TOML (`sillage::pedestrian::{motion_prior, homography}`).

use std::path::Path;
use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;
use serde::Serialize;
use sillage::filter::MotionPriorParams;
use sillage::pedestrian::homography::{HomographySource, fit_homography};
use sillage::pedestrian::motion_prior::{fit_motion_prior, write_motion_prior};

use crate::shared_args::JsonArg;

/// `sillage fit motion-prior`.
#[derive(Debug, Args)]
pub struct FitMotionPriorArgs {
    /// Trajectories in MOTChallenge format (`gt.txt` or tracker output; rows with flag 0 are
    /// ignored), or a sequence folder holding `gt/gt.txt`.
    #[arg(value_name = "TRACKS")]
    pub tracks: PathBuf,
    /// Image width, px; default `imWidth` of the `seqinfo.ini` beside the file or above it.
    #[arg(long, value_name = "PX")]
    pub width: Option<u32>,
    /// Image height, px; default `imHeight` of that `seqinfo.ini`.
    #[arg(long, value_name = "PX")]
    pub height: Option<u32>,
    /// Cell side, px (§5.1 uses 30).
    #[arg(long, value_name = "PX", default_value_t = MotionPriorParams::default().cell_px)]
    pub cell: f64,
    /// Steps slower than this count as "stay", px/frame.
    #[arg(long, value_name = "PX", default_value_t = MotionPriorParams::default().min_speed_px_per_frame)]
    pub min_speed: f64,
    /// Dirichlet pseudo-count added to every bin of every cell.
    #[arg(long, value_name = "N", default_value_t = MotionPriorParams::default().smoothing)]
    pub smoothing: f64,
    /// JSON file to write.
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// `sillage fit homography`.
#[derive(Debug, Args)]
pub struct FitHomographyArgs {
    /// MOT15 ground truth with world coordinates
    /// (`frame,id,bb_left,bb_top,bb_width,bb_height,flag,world_x,world_y,world_z`).
    #[arg(
        value_name = "GT",
        required_unless_present = "points",
        conflicts_with = "points"
    )]
    pub gt: Option<PathBuf>,
    /// Instead of ground truth: a text file of 4 or more `u,v,x,y` lines (image px, ground m).
    #[arg(long, value_name = "FILE")]
    pub points: Option<PathBuf>,
    /// TOML file to write: `[homography]` (image_from_ground), `[pedestrian]` (from ground
    /// truth only) and `[fit]`.
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// `--json` of `fit motion-prior`.
#[derive(Serialize)]
struct MotionPriorSummary<'a> {
    tracks_file: &'a Path,
    out: &'a Path,
    width_px: u32,
    height_px: u32,
    params: MotionPriorParams,
    tracks: usize,
    moves: u64,
    cells: usize,
    cells_with_data: usize,
    ignored_rows: usize,
}

/// `sillage fit motion-prior TRACKS --out prior.json`.
pub fn run_motion_prior(args: &FitMotionPriorArgs) -> Result<()> {
    let params = MotionPriorParams {
        cell_px: args.cell,
        min_speed_px_per_frame: args.min_speed,
        smoothing: args.smoothing,
    };
    let fit = fit_motion_prior(&args.tracks, args.width, args.height, &params)?;
    write_motion_prior(&args.out, &fit.prior)?;
    let (columns, rows) = fit.prior.grid_size();
    let (width, height) = (fit.width_px, fit.height_px);
    let path = &fit.tracks_file;
    let summary = MotionPriorSummary {
        tracks_file: path,
        out: &args.out,
        width_px: width,
        height_px: height,
        params,
        tracks: fit.tracks,
        moves: fit.prior.moves(),
        cells: columns * rows,
        cells_with_data: fit.prior.cells_with_data(),
        ignored_rows: fit.ignored_rows,
    };
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        println!(
            "{} tracks, {} moves ({} rows with flag 0 ignored) from {} → {}",
            summary.tracks,
            summary.moves,
            fit.ignored_rows,
            path.display(),
            args.out.display()
        );
        println!(
            "{width} × {height} px in {columns} × {rows} cells of {} px: {} cells with data",
            params.cell_px, summary.cells_with_data
        );
    }
    Ok(())
}

/// `sillage fit homography (GT | --points FILE) --out ground.toml`.
pub fn run_homography(args: &FitHomographyArgs) -> Result<()> {
    let source = match (&args.gt, &args.points) {
        (_, Some(points)) => HomographySource::Points(points),
        (Some(gt), None) => HomographySource::GroundTruth(gt),
        (None, None) => bail!("give a ground truth file or --points FILE"),
    };
    let fit = fit_homography(source)?;
    fit.file.write(&args.out)?;
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&fit.file)?);
    } else if let Some(table) = &fit.file.fit {
        println!(
            "{} pairs from {} → {}",
            table.pairs,
            table.source,
            args.out.display()
        );
        println!(
            "RMS reprojection error: {:.3} px",
            table.rms_reprojection_px
        );
        if let Some(p) = fit.file.pedestrian {
            println!(
                "adult box (median over {} boxes): height {:.3} m, width {:.3} m",
                fit.boxes, p.height_m, p.width_m
            );
        }
    }
    Ok(())
}

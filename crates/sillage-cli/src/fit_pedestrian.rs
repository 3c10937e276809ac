//! `sillage fit motion-prior` and `sillage fit homography`: what the pedestrian IMM particle
//! filter of Madrigal & Hayet learns before tracking, from MOTChallenge files. The learned
//! motion prior (§5.1) is written as JSON; the image ↔ ground homography and the adult's box
//! size in metres (§4) as TOML (`sillage::pedestrian::{motion_prior, homography}`).

use std::path::Path;

use anyhow::{Result, bail};
use serde::Serialize;
use sillage::filter::MotionPriorParams;
use sillage::pedestrian::homography::{HomographySource, fit_homography};
use sillage::pedestrian::motion_prior::{fit_motion_prior, write_motion_prior};

use crate::cli::{FitHomographyArgs, FitMotionPriorArgs};

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
    if args.json {
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
    if args.json {
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

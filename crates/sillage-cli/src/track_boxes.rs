//! `sillage track boxes`: SORT (Bewley et al. 2016) on a MOTChallenge detection file, the
//! baseline the pedestrian trackers are compared with; writes MOTChallenge results.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use serde::Serialize;
use sillage::io::write_mot_results;
use sillage::pedestrian::sort::track_boxes_with_sort;
use sillage::track::sort::SortParams;

use crate::shared_args::JsonArg;

/// `sillage track boxes`.
#[derive(Debug, Args)]
pub struct TrackBoxesArgs {
    /// MOTChallenge detections (`det.txt`: frame,-1,left,top,width,height,score,...).
    #[arg(long, value_name = "FILE")]
    pub detections: PathBuf,
    /// MOTChallenge results to write (1-based frames).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Frames a track may go unmatched before it ends.
    #[arg(long, default_value_t = SortParams::default().max_age)]
    pub max_age: u32,
    /// Consecutive matches before a track is written.
    #[arg(long, default_value_t = SortParams::default().min_hits)]
    pub min_hits: u32,
    /// Smallest IoU of a match.
    #[arg(long, default_value_t = SortParams::default().iou_threshold)]
    pub iou_threshold: f64,
    /// Drop detections scoring below this.
    #[arg(long, value_name = "S")]
    pub min_score: Option<f64>,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// What a run did.
#[derive(Debug, Serialize)]
struct Summary {
    tracker: &'static str,
    rows: usize,
    tracks: usize,
    frames_per_second: f64,
    out: String,
}

/// `sillage track boxes --detections det.txt --out FILE`.
pub fn run(args: &TrackBoxesArgs) -> Result<()> {
    let params = SortParams {
        max_age: args.max_age,
        min_hits: args.min_hits,
        iou_threshold: args.iou_threshold,
    };
    let start = Instant::now();
    let rows = track_boxes_with_sort(&args.detections, params, args.min_score)
        .context("cannot track the boxes of --detections")?;
    let seconds = start.elapsed().as_secs_f64();
    write_mot_results(&args.out, &rows)
        .with_context(|| format!("{}: cannot write the results", args.out.display()))?;
    let frames = rows.iter().map(|r| r.frame + 1).max().unwrap_or(0);
    let mut ids: Vec<u64> = rows.iter().filter_map(|r| r.id).collect();
    ids.sort_unstable();
    ids.dedup();
    let summary = Summary {
        tracker: "sort",
        rows: rows.len(),
        tracks: ids.len(),
        frames_per_second: frames as f64 / seconds.max(1e-9),
        out: args.out.display().to_string(),
    };
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        eprintln!(
            "sort: {} tracks, {} rows → {} ({:.0} frames/s)",
            summary.tracks, summary.rows, summary.out, summary.frames_per_second
        );
    }
    Ok(())
}

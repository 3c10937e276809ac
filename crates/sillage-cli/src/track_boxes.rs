//! `sillage track boxes`: SORT (Bewley et al. 2016) or ByteTrack (Zhang et al. 2022) on a
//! MOTChallenge detection file, the baselines the pedestrian trackers are compared with;
//! writes MOTChallenge results.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use serde::Serialize;
use sillage::io::write_mot_results;
use sillage::pedestrian::boxes::{BoxTracker, track_boxes};
use sillage::track::bytetrack::ByteTrackParams;
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
    /// `sort` (the filters' boxes written) or `bytetrack` (as `supervision` 0.30.9: the
    /// detections matched to tracks written; its defaults: activation 0.25, lost buffer 30
    /// frames, matching 0.8).
    #[arg(long, default_value = "sort", value_parser = ["sort", "bytetrack"])]
    pub tracker: String,
    /// SORT: frames a track may go unmatched before it ends.
    #[arg(long, default_value_t = SortParams::default().max_age)]
    pub max_age: u32,
    /// SORT: consecutive matches before a track is written.
    #[arg(long, default_value_t = SortParams::default().min_hits)]
    pub min_hits: u32,
    /// SORT: smallest IoU of a match.
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
    let tracker = match args.tracker.as_str() {
        "bytetrack" => BoxTracker::ByteTrack(ByteTrackParams::default()),
        _ => BoxTracker::Sort(SortParams {
            max_age: args.max_age,
            min_hits: args.min_hits,
            iou_threshold: args.iou_threshold,
        }),
    };
    let start = Instant::now();
    let rows = track_boxes(&args.detections, tracker, args.min_score)
        .context("cannot track the boxes of --detections")?;
    let seconds = start.elapsed().as_secs_f64();
    write_mot_results(&args.out, &rows)
        .with_context(|| format!("{}: cannot write the results", args.out.display()))?;
    let frames = rows.iter().map(|r| r.frame + 1).max().unwrap_or(0);
    let mut ids: Vec<u64> = rows.iter().filter_map(|r| r.id).collect();
    ids.sort_unstable();
    ids.dedup();
    let summary = Summary {
        tracker: tracker.name(),
        rows: rows.len(),
        tracks: ids.len(),
        frames_per_second: frames as f64 / seconds.max(1e-9),
        out: args.out.display().to_string(),
    };
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        eprintln!(
            "{}: {} tracks, {} rows → {} ({:.0} frames/s)",
            summary.tracker, summary.tracks, summary.rows, summary.out, summary.frames_per_second
        );
    }
    Ok(())
}

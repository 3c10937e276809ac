//! `sillage track siftpf`: surveillance objects found by motion detection and followed by
//! their SIFT features' particle filters (Souded et al. 2011); writes MOTChallenge results.

use std::time::Duration;

use anyhow::Result;
use serde::Serialize;
use sillage::io::MotResultsWriter;
use sillage::pedestrian::siftpf::track_siftpf;
use sillage::pedestrian::{GroundPlaneFile, SiftPfSettings};

use crate::cli::TrackSiftpfArgs;
use crate::progress::FrameProgress;

/// What a run did (`--json`: as JSON on stdout).
#[derive(Debug, Serialize)]
struct Summary {
    selection: String,
    frames: u64,
    tracks: usize,
    rows: usize,
    ms_per_frame: f64,
    tracking_ms_per_frame: f64,
    out: String,
}

/// `sillage track siftpf FRAMES --out FILE`.
pub fn run(args: &TrackSiftpfArgs) -> Result<()> {
    let settings = SiftPfSettings::load(
        args.config.as_deref(),
        &args.overrides,
        args.selection.as_deref(),
    )?;
    let homography = args
        .ground_plane
        .as_deref()
        .map(GroundPlaneFile::read_homography)
        .transpose()?;
    let mut progress = None;
    let run = track_siftpf(
        &args.input,
        &settings,
        homography,
        args.seed,
        args.max_frames,
        &mut |expected| {
            progress
                .get_or_insert_with(|| FrameProgress::new(expected, "tracking"))
                .tick()
        },
    );
    if let Some(p) = progress {
        p.finish();
    }
    let run = run?;
    let mut writer = MotResultsWriter::create(&args.out)?;
    writer.push(&run.rows)?;
    writer.finish()?;
    let per_frame = |d: Duration| 1e3 * d.as_secs_f64() / run.frames as f64;
    let summary = Summary {
        selection: settings.tracker.selection.label().to_string(),
        frames: run.frames,
        tracks: run.track_count(),
        rows: run.rows.len(),
        ms_per_frame: per_frame(run.total),
        tracking_ms_per_frame: per_frame(run.tracking),
        out: args.out.display().to_string(),
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        eprintln!(
            "{} frames, {} tracks, {} rows ({} selection) → {} ({:.1} ms/frame, tracking {:.1} ms/frame)",
            summary.frames,
            summary.tracks,
            summary.rows,
            summary.selection,
            summary.out,
            summary.ms_per_frame,
            summary.tracking_ms_per_frame
        );
    }
    Ok(())
}

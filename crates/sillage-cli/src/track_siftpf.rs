//! `sillage track siftpf`: surveillance objects found by motion detection and followed by
//! their SIFT features' particle filters (Souded et al. 2011); writes MOTChallenge results.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Result;
use clap::Args;
use serde::Serialize;
use sillage::io::{FrameOptions, MotResultsWriter};
use sillage::pedestrian::siftpf::track_siftpf;
use sillage::pedestrian::{GroundPlaneFile, SiftPfSettings};

use crate::progress::FrameProgress;
use crate::shared_args::{ConfigFileArgs, JsonArg};

/// `sillage track siftpf`.
#[derive(Debug, Args)]
pub struct TrackSiftpfArgs {
    /// Colour frames (a folder, a quoted glob, a multi-page TIFF or a video).
    pub input: String,
    /// MOTChallenge results to write (1-based frames).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Feature selection, the paper's configurations of §3.1.1: whole-object (1),
    /// detection-order (2), reliability (3, the default).
    #[arg(long, value_name = "NAME")]
    pub selection: Option<String>,
    /// Ground plane (TOML with `[homography]`, from `sillage fit homography`): sizes and
    /// speeds learned in metres for resuming occluded objects (§2.4); pixels without it.
    #[arg(long, value_name = "FILE")]
    pub ground_plane: Option<PathBuf>,
    /// `--config FILE` and `--set KEY=VALUE`: the parameters.
    #[command(flatten)]
    pub params: ConfigFileArgs,
    /// Random seed of the particles.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Stop after this many frames.
    #[arg(long, value_name = "N")]
    pub max_frames: Option<usize>,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

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
        args.params.config.as_deref(),
        &args.params.overrides,
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
        &FrameOptions {
            max_frames: args.max_frames,
            ..FrameOptions::default()
        },
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
    writer.push(&run.rows())?;
    writer.finish()?;
    let per_frame = |d: Duration| 1e3 * d.as_secs_f64() / run.frames as f64;
    let summary = Summary {
        selection: settings.tracker.selection.label().to_string(),
        frames: run.frames,
        tracks: run.track_count(),
        rows: run.estimates.len(),
        ms_per_frame: per_frame(run.total),
        tracking_ms_per_frame: per_frame(run.tracking),
        out: args.out.display().to_string(),
    };
    if args.json.enabled {
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

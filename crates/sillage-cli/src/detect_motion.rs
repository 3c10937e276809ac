//! `sillage detect motion`: the motion detector the pedestrian and surveillance trackers use
//! (adaptive Gaussian-mixture background, morphology, blobs), its blobs written as
//! MOTChallenge detections, to look at what the trackers are given or to feed another
//! tracker.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use serde::Serialize;
use sillage::detect::motion::MotionParams;
use sillage::io::MotResultsWriter;
use sillage::pedestrian::motion::MotionDetection;
use sillage::toml_config::load;

use crate::progress::FrameProgress;
use crate::shared_args::JsonArg;

/// `sillage detect motion`.
#[derive(Debug, Args)]
pub struct DetectMotionArgs {
    /// Frames: a folder, a quoted glob pattern, a multi-page TIFF or a video file.
    pub input: String,
    /// MOTChallenge detections to write (`frame,-1,left,top,width,height,conf,-1,-1,-1`;
    /// frames 1-based, conf the share of motion pixels in the box).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// TOML motion-detector parameters (the `[motion_detector]` table of the trackers'
    /// configurations, without its header).
    #[arg(long, value_name = "FILE")]
    pub detector_config: Option<PathBuf>,
    /// Override one detector key, e.g. `--detector-set open_radius_px=2` (repeatable).
    #[arg(long = "detector-set", value_name = "KEY=VALUE")]
    pub detector_overrides: Vec<String>,
    /// Stop after this many frames.
    #[arg(long, value_name = "N")]
    pub max_frames: Option<usize>,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// What a run found (`--json`: as JSON on stdout).
#[derive(Debug, Serialize)]
struct Summary {
    frames: u64,
    blobs: usize,
    ms_per_frame: f64,
    out: String,
}

/// `sillage detect motion INPUT --out det.txt`: one MOTChallenge row per blob (id `-1`,
/// confidence the blob's share of motion pixels in its box).
pub fn run_motion(args: &DetectMotionArgs) -> Result<()> {
    let params: MotionParams = load(args.detector_config.as_deref(), &args.detector_overrides)?;
    let detection = MotionDetection::open(&args.input, &params, args.max_frames)?;
    let mut writer = MotResultsWriter::create(&args.out)?;
    let mut progress = FrameProgress::new(detection.frames_expected(), "detecting");
    let outcome = detection.run(&mut |rows| -> Result<()> {
        writer.push(rows)?;
        progress.tick();
        Ok(())
    });
    progress.finish();
    // Rows written before an error stay valid: the file is completed either way.
    writer.finish()?;
    let run = outcome?;
    let summary = Summary {
        frames: run.frames,
        blobs: run.blobs,
        ms_per_frame: 1e3 * run.total.as_secs_f64() / run.frames as f64,
        out: args.out.display().to_string(),
    };
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        eprintln!(
            "{} frames: {} blobs → {} ({:.1} ms/frame)",
            summary.frames, summary.blobs, summary.out, summary.ms_per_frame
        );
    }
    Ok(())
}

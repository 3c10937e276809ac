//! `sillage detect bead`: the MMPF+ paper's bead detector over a sequence of frames, its
//! detections and detector-confidence candidates written as CSV for `sillage track bedload`.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use serde::Serialize;
use sillage::bedload::detector::{BeadCounts, BeadDetectorSources, write_bead_detections};
use sillage::io::{FrameOptions, open_frames};

use crate::progress::FrameProgress;
use crate::shared_args::{BeadDetectorArgs, JsonArg};

/// `sillage detect bead`.
#[derive(Debug, Args)]
pub struct DetectBeadArgs {
    /// Frames: a folder, a quoted glob pattern, a multi-page TIFF or a video file.
    pub input: String,
    /// Detections CSV to write (`frame,x,y,class,score`; class 0 black, 1 transparent).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Candidates CSV to write (every correlation maximum above `candidate_threshold`).
    #[arg(long, value_name = "FILE")]
    pub candidates: Option<PathBuf>,
    /// The detector.
    #[command(flatten)]
    pub detector: BeadDetectorArgs,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

impl From<&BeadDetectorArgs> for BeadDetectorSources {
    fn from(args: &BeadDetectorArgs) -> Self {
        Self {
            config: args.detector_config.clone(),
            sequence_params: args.sequence_params.clone(),
            overrides: args.detector_overrides.clone(),
            base_mask: args.mask.clone(),
            template: args.template.clone(),
        }
    }
}

/// What a run found, printed at the end (`--json`: as JSON).
#[derive(Debug, Serialize)]
struct DetectSummary {
    #[serde(flatten)]
    counts: BeadCounts,
    ms_per_frame: f64,
}

/// `sillage detect bead INPUT --out FILE [--candidates FILE]`.
pub fn run_bead(args: &DetectBeadArgs) -> Result<()> {
    let mut detector = BeadDetectorSources::from(&args.detector).load()?.build()?;
    let frames = open_frames(&args.input, &FrameOptions::default())?;
    let mut progress = FrameProgress::new(frames.len(), "detecting");
    let start = Instant::now();
    let outcome = write_bead_detections(
        frames,
        &mut detector,
        &args.out,
        args.candidates.as_deref(),
        &mut || progress.tick(),
    );
    progress.finish();
    let counts = outcome?;
    let summary = DetectSummary {
        ms_per_frame: 1e3 * start.elapsed().as_secs_f64() / counts.frames.max(1) as f64,
        counts,
    };
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        let c = &summary.counts;
        eprintln!(
            "{} frames: {} black and {} transparent beads, {} candidates → {} ({:.1} ms/frame)",
            c.frames,
            c.black,
            c.transparent,
            c.candidates,
            args.out.display(),
            summary.ms_per_frame
        );
    }
    Ok(())
}

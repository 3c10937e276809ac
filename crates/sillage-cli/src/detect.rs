//! `sillage detect bead`: the MMPF+ paper's bead detector over a sequence of frames, its
//! detections and detector-confidence candidates written as CSV for `sillage track bedload`.

use std::time::Instant;

use anyhow::Result;
use serde::Serialize;
use sillage::bedload::detector::{BeadCounts, BeadDetectorSources, write_bead_detections};
use sillage::io::{FrameOptions, open_frames};

use crate::cli::{BeadDetectorArgs, DetectBeadArgs};
use crate::progress::FrameProgress;

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
    if args.json {
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

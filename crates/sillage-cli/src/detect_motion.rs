//! `sillage detect motion`: the motion detector the pedestrian and surveillance trackers use
//! (adaptive Gaussian-mixture background, morphology, blobs), its blobs written as
//! MOTChallenge detections, to look at what the trackers are given or to feed another
//! tracker.

use anyhow::Result;
use serde::Serialize;
use sillage::detect::motion::MotionParams;
use sillage::io::MotResultsWriter;
use sillage::pedestrian::motion::MotionDetection;
use sillage::toml_config::load;

use crate::cli::DetectMotionArgs;
use crate::progress::FrameProgress;

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
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        eprintln!(
            "{} frames: {} blobs → {} ({:.1} ms/frame)",
            summary.frames, summary.blobs, summary.out, summary.ms_per_frame
        );
    }
    Ok(())
}

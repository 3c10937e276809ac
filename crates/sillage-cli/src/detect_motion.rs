//! `sillage detect motion`: the motion detector the pedestrian and surveillance trackers use
//! (adaptive Gaussian-mixture background, morphology, blobs), its blobs written as
//! MOTChallenge detections, to look at what the trackers are given or to feed another
//! tracker.

use std::time::Instant;

use anyhow::{Context, Result, ensure};
use serde::Serialize;
use sillage::detect::motion::{MotionDetector, MotionParams};
use sillage::io::{FrameOptions, MotResultsWriter, MotRow, open_frames};
use sillage::toml_config::{read_toml_file, set_key};

use crate::cli::DetectMotionArgs;
use crate::progress::FrameProgress;

/// Defaults, then `--detector-config`, then `--detector-set`; validated.
fn load_params(args: &DetectMotionArgs) -> Result<MotionParams> {
    let mut params: MotionParams = match &args.detector_config {
        Some(path) => read_toml_file(path)?,
        None => MotionParams::default(),
    };
    for assignment in &args.detector_overrides {
        set_key(&mut params, assignment)?;
    }
    params.validate()?;
    Ok(params)
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
    let params = load_params(args)?;
    let options = FrameOptions {
        max_frames: args.max_frames,
        ..FrameOptions::default()
    };
    let mut frames = open_frames(&args.input, &options)?;
    let (width, height) = frames.dimensions();
    let mut detector = MotionDetector::new(&params, width, height)?;
    let mut writer = MotResultsWriter::create(&args.out)?;
    let mut progress = FrameProgress::new(frames.len(), "detecting");
    let (mut blobs, mut rows) = (Vec::new(), Vec::new());
    let mut summary = Summary {
        frames: 0,
        blobs: 0,
        ms_per_frame: 0.0,
        out: args.out.display().to_string(),
    };
    let start = Instant::now();
    let mut outcome: Result<()> = Ok(());
    for frame in &mut frames {
        let step = frame.map_err(anyhow::Error::from).and_then(|frame| {
            detector
                .detect(&frame.image, &mut blobs)
                .with_context(|| format!("{}: frame {}", frame.path.display(), frame.index + 1))?;
            rows.clear();
            rows.extend(blobs.iter().map(|b| {
                let (w, h) = (b.bbox.width(), b.bbox.height());
                MotRow {
                    frame: frame.index,
                    id: None,
                    left_px: b.bbox.x0 as f64,
                    top_px: b.bbox.y0 as f64,
                    width_px: w as f64,
                    height_px: h as f64,
                    confidence: Some(b.area as f64 / (w * h).max(1) as f64),
                    class: None,
                    visibility: None,
                    world: None,
                }
            }));
            writer.push(&rows)?;
            Ok(())
        });
        if let Err(e) = step {
            outcome = Err(e);
            break;
        }
        summary.frames += 1;
        summary.blobs += blobs.len();
        progress.tick();
    }
    progress.finish();
    // Rows written before an error stay valid: the file is completed either way.
    writer.finish()?;
    outcome?;
    ensure!(
        summary.frames > 0,
        "{}: the input holds no frame",
        args.input
    );
    summary.ms_per_frame = 1e3 * start.elapsed().as_secs_f64() / summary.frames as f64;
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

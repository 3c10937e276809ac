//! `sillage detect bead`: the MMPF+ paper's bead detector over a sequence of frames, its
//! detections and detector-confidence candidates written as CSV for `sillage track bedload`.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use serde::Serialize;
use sillage::core::GrayImage;
use sillage::detect::{BeadDetections, BeadDetector, BeadParams};
use sillage::io::{
    DetectionsCsvWriter, Frame, FrameOptions, open_frames, read_bead_sequence_params, read_image,
    read_matrix_csv,
};
use sillage::toml_config::{read_toml_file, set_key};

use crate::cli::{BeadDetectorArgs, DetectBeadArgs};
use crate::progress::FrameProgress;

/// Defaults, then `--detector-config`, then the sizes of `--sequence-params`, then
/// `--detector-set`; validated.
fn load_params(args: &BeadDetectorArgs) -> Result<BeadParams> {
    let mut params: BeadParams = match &args.detector_config {
        Some(path) => read_toml_file(path)?,
        None => BeadParams::default(),
    };
    if let Some(path) = &args.sequence_params {
        let sequence = read_bead_sequence_params(path)?;
        params.m_per_px = sequence.m_per_px;
        params.black_diameter_m = sequence.black_diameter_m;
        params.transparent_diameter_m = sequence.transparent_diameter_m;
    }
    for assignment in &args.detector_overrides {
        set_key(&mut params, assignment)?;
    }
    params.geometry()?;
    Ok(params)
}

/// The bead detector of the command line: parameters, base mask and ring template.
pub fn build_detector(args: &BeadDetectorArgs) -> Result<BeadDetector> {
    let mut detector = BeadDetector::new(load_params(args)?)?;
    if let Some(path) = &args.mask {
        detector = detector.with_base_mask(&read_image(path)?);
    }
    if let Some(path) = &args.template {
        detector = detector
            .with_ring_template(&read_template(path)?)
            .with_context(|| format!("in {}", path.display()))?;
    }
    Ok(detector)
}

/// Detects the beads of one frame into `beads`; the error names the frame and its file.
pub fn detect_frame(
    detector: &mut BeadDetector,
    frame: &Frame,
    beads: &mut BeadDetections,
) -> Result<()> {
    detector
        .detect_beads(&frame.image, beads)
        .with_context(|| format!("frame {} ({})", frame.index, frame.path.display()))
}

/// A ring template from a CSV matrix (BeadTracking's exported `.mat`) or an image.
fn read_template(path: &Path) -> Result<GrayImage> {
    let is_csv = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    Ok(if is_csv {
        read_matrix_csv(path)?
    } else {
        read_image(path)?
    })
}

/// What a run found, printed at the end (`--json`: as JSON).
#[derive(Debug, Serialize)]
struct DetectSummary {
    frames: u64,
    black: usize,
    transparent: usize,
    candidates: usize,
    ms_per_frame: f64,
}

/// `sillage detect bead INPUT --out FILE [--candidates FILE]`.
pub fn run_bead(args: &DetectBeadArgs) -> Result<()> {
    let mut detector = build_detector(&args.detector)?;
    let frames = open_frames(&args.input, &FrameOptions::default())?;
    let mut progress = FrameProgress::new(frames.len(), "detecting");
    let mut detections = DetectionsCsvWriter::create(&args.out)?;
    let mut candidates = match &args.candidates {
        Some(path) => Some(DetectionsCsvWriter::create(path)?),
        None => None,
    };
    let mut beads = BeadDetections::default();
    let mut both = Vec::new();
    let mut summary = DetectSummary {
        frames: 0,
        black: 0,
        transparent: 0,
        candidates: 0,
        ms_per_frame: 0.0,
    };
    let start = Instant::now();
    let mut outcome: Result<()> = Ok(());
    for frame in frames {
        let step = frame.map_err(anyhow::Error::from).and_then(|frame| {
            detect_frame(&mut detector, &frame, &mut beads)?;
            both.clear();
            both.extend_from_slice(&beads.black);
            both.extend_from_slice(&beads.transparent);
            detections.push(frame.index, &both)?;
            if let Some(writer) = &mut candidates {
                writer.push(frame.index, &beads.candidates)?;
            }
            Ok(())
        });
        if let Err(e) = step {
            outcome = Err(e);
            break;
        }
        summary.frames += 1;
        summary.black += beads.black.len();
        summary.transparent += beads.transparent.len();
        summary.candidates += beads.candidates.len();
        progress.tick();
    }
    progress.finish();
    summary.ms_per_frame = 1e3 * start.elapsed().as_secs_f64() / summary.frames.max(1) as f64;
    // Rows written before an error stay valid: the files are completed either way.
    detections.finish()?;
    if let Some(writer) = candidates {
        writer.finish()?;
    }
    outcome?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        eprintln!(
            "{} frames: {} black and {} transparent beads, {} candidates → {} ({:.1} ms/frame)",
            summary.frames,
            summary.black,
            summary.transparent,
            summary.candidates,
            args.out.display(),
            summary.ms_per_frame
        );
    }
    Ok(())
}

//! `sillage track bedload`: the bedload trackers (MMPF+ and the baselines of its Table 1) on
//! detections read from CSV, or on frames through the bead detector; trajectories written in
//! BeadTracking's layout or as a track table with motion states.

use std::collections::BTreeMap;
use std::time::Instant;

use anyhow::{Context, Result};
use serde::Serialize;
use sillage::core::{Detection, FrameIndex, FrameObservations, Tracker};
use sillage::detect::BeadDetections;
use sillage::io::{FrameOptions, open_frames, read_detections_csv};
use sillage::toml_config::{read_toml_file, set_key};
use sillage::track::bedload::{BedloadTracker, BedloadTrackerParams};
use sillage::viz::OverlayStyle;

use crate::bead_output::BeadTrackOutput;
use crate::cli::TrackBedloadArgs;
use crate::detect::{build_detector, detect_frame};
use crate::overlay::{DetectionsByFrame, write_overlays};
use crate::progress::FrameProgress;

/// Defaults, then `--config`, then `--set`, then `--tracker` and `--seed`; validated.
pub fn load_bedload_params(args: &TrackBedloadArgs) -> Result<BedloadTrackerParams> {
    let mut params: BedloadTrackerParams = match &args.config {
        Some(path) => read_toml_file(path)?,
        None => BedloadTrackerParams::default(),
    };
    for assignment in &args.overrides {
        set_key(&mut params, assignment)?;
    }
    if let Some(kind) = args.tracker {
        params.tracker = kind.into();
    }
    if let Some(seed) = args.seed {
        params.seed = seed;
    }
    params.validate()?;
    Ok(params)
}

/// What a run did, printed at the end (`--json`: as JSON).
#[derive(Debug, Serialize)]
struct TrackSummary {
    tracker: &'static str,
    frames: u64,
    detections: usize,
    candidates: usize,
    tracks: u64,
    points: u64,
    coasted_points: u64,
    weight_recoveries: u64,
    ms_per_frame: f64,
    out: String,
}

/// The detections and candidates of each frame, in frame order.
type FrameInputs = BTreeMap<FrameIndex, (Vec<Detection>, Vec<Detection>)>;

fn read_inputs(args: &TrackBedloadArgs, detections: &std::path::Path) -> Result<FrameInputs> {
    let inputs = std::iter::once(detections).chain(args.candidates.as_deref());
    for input in inputs {
        let same = match (input.canonicalize(), args.out.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        };
        anyhow::ensure!(
            !same,
            "--out {} would overwrite the input {}; write the tracks to another file",
            args.out.display(),
            input.display()
        );
    }
    let mut frames = FrameInputs::new();
    for (frame, found) in read_detections_csv(detections)? {
        frames.entry(frame).or_default().0 = found;
    }
    if let Some(path) = &args.candidates {
        for (frame, candidates) in read_detections_csv(path)? {
            frames.entry(frame).or_default().1 = candidates;
        }
    }
    anyhow::ensure!(
        !frames.is_empty(),
        "{} holds no detection; give a file with rows `frame,x,y,class,score`",
        detections.display()
    );
    Ok(frames)
}

/// One frame of input: its index, detections and candidates.
type FrameInput = (FrameIndex, Vec<Detection>, Vec<Detection>);

/// The frames to track (their number when known) and the input of each.
type FrameStream = (Option<usize>, Box<dyn Iterator<Item = Result<FrameInput>>>);

/// The frames of `input`, each detected by the bead detector of the command line.
fn detected_frames(args: &TrackBedloadArgs, input: &str) -> Result<FrameStream> {
    let mut detector = build_detector(&args.detector)?;
    let frames = open_frames(input, &FrameOptions::default())?;
    let total = frames.len();
    let mut beads = BeadDetections::default();
    let detected = frames.map(move |frame| {
        let frame = frame?;
        detect_frame(&mut detector, &frame, &mut beads)?;
        let mut found = beads.black.clone();
        found.extend_from_slice(&beads.transparent);
        Ok((frame.index, found, beads.candidates.clone()))
    });
    Ok((total, Box::new(detected)))
}

/// `sillage track bedload --detections FILE --out FILE`.
pub fn run_bedload(args: &TrackBedloadArgs) -> Result<()> {
    let params = load_bedload_params(args)?;
    let (total, frames): FrameStream = match (&args.input, &args.detections) {
        (Some(input), _) => detected_frames(args, input)?,
        (None, Some(detections)) => {
            let inputs = read_inputs(args, detections)?;
            let total = inputs.len();
            let frames = inputs.into_iter().map(|(f, (d, c))| Ok((f, d, c)));
            (Some(total), Box::new(frames))
        }
        (None, None) => anyhow::bail!("give frames to detect beads in, or --detections FILE"),
    };
    let mut tracker = BedloadTracker::new(&params)?;
    let mut writer = BeadTrackOutput::create(&args.out, args.format, &params)?;
    let kind = writer.kind();
    let mut progress = FrameProgress::new(total, "tracking");
    let start = Instant::now();
    let mut outcome = Ok(());
    let (mut n_detections, mut n_candidates) = (0, 0);
    let mut kept = DetectionsByFrame::new();
    for input in frames {
        let step = input.and_then(|(frame, detections, candidates)| {
            n_detections += detections.len();
            n_candidates += candidates.len();
            if args.overlay.is_some() {
                kept.insert(frame, detections.clone());
            }
            let observations = FrameObservations {
                candidates: &candidates,
                ..FrameObservations::from_detections(frame, &detections)
            };
            Ok(tracker.step(&observations, &mut writer)?)
        });
        if let Err(e) = step {
            outcome = Err(e);
            break;
        }
        progress.tick();
    }
    if outcome.is_ok() {
        outcome = tracker.finish(&mut writer).map_err(anyhow::Error::from);
    }
    progress.finish();
    let elapsed = start.elapsed().as_secs_f64();
    // Rows written before an error stay valid: the file is completed either way.
    let written = writer.finish()?;
    let source = match (&args.input, &args.detections) {
        (Some(input), _) => input.clone(),
        (None, Some(path)) => path.display().to_string(),
        (None, None) => String::new(),
    };
    outcome.with_context(|| format!("while tracking {source}"))?;
    if let (Some(dir), Some(input)) = (&args.overlay, &args.input) {
        let tracks = kind.read(&written.path)?;
        let style = OverlayStyle {
            tail_frames: args.overlay_tail,
            detection_radius_px: params.radius_px.clone(),
            ..OverlayStyle::default()
        };
        let n = write_overlays(input, dir, &kept, tracks, &style, None)?;
        eprintln!("{n} overlays → {}", dir.display());
    }
    let stats = tracker.stats();
    let summary = TrackSummary {
        tracker: params.tracker.name(),
        frames: stats.frames,
        detections: n_detections,
        candidates: n_candidates,
        tracks: stats.tracks,
        points: written.rows,
        coasted_points: stats.coasted,
        weight_recoveries: stats.weight_recoveries,
        ms_per_frame: 1e3 * elapsed / stats.frames.max(1) as f64,
        out: written.path.display().to_string(),
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        eprintln!(
            "{}: {} frames, {} detections → {} tracks, {} points ({} predicted through misses) \
             → {} ({:.2} ms/frame)",
            summary.tracker,
            summary.frames,
            summary.detections,
            summary.tracks,
            summary.points,
            summary.coasted_points,
            summary.out,
            summary.ms_per_frame
        );
    }
    Ok(())
}

//! `sillage track bedload`: the bedload trackers (MMPF+ and the baselines of its Table 1) on
//! detections read from CSV, trajectories written in BeadTracking's layout.

use std::collections::BTreeMap;
use std::time::Instant;

use anyhow::{Context, Result};
use serde::Serialize;
use sillage::core::{Detection, FrameIndex, FrameObservations, Tracker};
use sillage::io::{BeadCsvWriter, read_detections_csv};
use sillage::toml_config::{read_toml_file, set_key};
use sillage::track::bedload::{BedloadTracker, BedloadTrackerParams};

use crate::cli::TrackBedloadArgs;
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

fn read_inputs(args: &TrackBedloadArgs) -> Result<FrameInputs> {
    let inputs = std::iter::once(&args.detections).chain(&args.candidates);
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
    for (frame, detections) in read_detections_csv(&args.detections)? {
        frames.entry(frame).or_default().0 = detections;
    }
    if let Some(path) = &args.candidates {
        for (frame, candidates) in read_detections_csv(path)? {
            frames.entry(frame).or_default().1 = candidates;
        }
    }
    anyhow::ensure!(
        !frames.is_empty(),
        "{} holds no detection; give a file with rows `frame,x,y,class,score`",
        args.detections.display()
    );
    Ok(frames)
}

/// `sillage track bedload --detections FILE --out FILE`.
pub fn run_bedload(args: &TrackBedloadArgs) -> Result<()> {
    let params = load_bedload_params(args)?;
    let inputs = read_inputs(args)?;
    let mut tracker = BedloadTracker::new(&params)?;
    let mut writer = BeadCsvWriter::create(&args.out)?;
    let mut progress = FrameProgress::new(Some(inputs.len()), "tracking");
    let start = Instant::now();
    let mut outcome = Ok(());
    for (&frame, (detections, candidates)) in &inputs {
        let observations = FrameObservations {
            candidates,
            ..FrameObservations::from_detections(frame, detections)
        };
        outcome = tracker.step(&observations, &mut writer);
        if outcome.is_err() {
            break;
        }
        progress.tick();
    }
    if outcome.is_ok() {
        outcome = tracker.finish(&mut writer);
    }
    progress.finish();
    let elapsed = start.elapsed().as_secs_f64();
    // Rows written before an error stay valid: the file is completed either way.
    let written = writer.finish()?;
    outcome.with_context(|| format!("while tracking {}", args.detections.display()))?;
    let stats = tracker.stats();
    let summary = TrackSummary {
        tracker: params.tracker.name(),
        frames: stats.frames,
        detections: inputs.values().map(|(d, _)| d.len()).sum(),
        candidates: inputs.values().map(|(_, c)| c.len()).sum(),
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

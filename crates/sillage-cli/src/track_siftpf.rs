//! `sillage track siftpf`: surveillance objects found by motion detection and followed by
//! their SIFT features' particle filters (Souded et al. 2011); writes MOTChallenge results.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, ensure};
use serde::{Deserialize, Serialize};
use sillage::core::Homography;
use sillage::detect::motion::{MotionDetector, MotionParams};
use sillage::io::{FrameOptions, MotResultsWriter, MotRow, open_frames};
use sillage::toml_config::{read_toml_file, set_key};
use sillage::track::siftpf::{
    DetectedObject, FeatureSelection, SiftPfEstimate, SiftPfFrame, SiftPfParams, SiftPfTracker,
};

use crate::cli::TrackSiftpfArgs;
use crate::ground_plane::GroundPlaneFile;
use crate::progress::FrameProgress;

/// The `[tracker]` and `[motion_detector]` tables of a configuration file.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SiftPfConfig {
    /// The tracker.
    pub tracker: SiftPfParams,
    /// The motion detector giving the detected objects.
    pub motion_detector: MotionParams,
}

impl SiftPfConfig {
    /// Defaults, then `config`, then the `overrides`, then `selection`; validated.
    pub fn load(
        config: Option<&Path>,
        overrides: &[String],
        selection: Option<&str>,
    ) -> Result<Self> {
        let mut loaded: Self = match config {
            Some(path) => read_toml_file(path)?,
            None => Self::default(),
        };
        for assignment in overrides {
            set_key(&mut loaded, assignment)?;
        }
        if let Some(name) = selection {
            loaded.tracker.selection = FeatureSelection::parse(name)?;
        }
        loaded.validate()?;
        Ok(loaded)
    }

    /// Checks both tables; an error names the key as written (`tracker.filter.particles`).
    pub fn validate(&self) -> Result<()> {
        self.tracker
            .validate()
            .map_err(|e| e.in_section("tracker"))?;
        self.motion_detector
            .validate()
            .map_err(|e| e.in_section("motion_detector"))?;
        Ok(())
    }
}

/// What tracking one sequence gave.
pub struct SiftPfRun {
    /// Result rows, sorted by frame then identity (0-based frames).
    pub rows: Vec<MotRow>,
    /// Frames tracked.
    pub frames: u64,
    /// Time in the tracker (SIFT, features, association), excluding decoding and motion
    /// detection.
    pub tracking: Duration,
    /// Wall time of the whole run.
    pub total: Duration,
}

impl SiftPfRun {
    /// The number of distinct track identities in the rows.
    pub fn track_count(&self) -> usize {
        let mut ids: Vec<u64> = self.rows.iter().filter_map(|r| r.id).collect();
        ids.sort_unstable();
        ids.dedup();
        ids.len()
    }
}

/// Tracks the colour frames of `input` (the first `max_frames`).
pub fn track_sequence(
    input: &str,
    config: &SiftPfConfig,
    homography: Option<Homography>,
    seed: u64,
    max_frames: Option<usize>,
    show_progress: bool,
) -> Result<SiftPfRun> {
    let options = FrameOptions {
        colour: true,
        max_frames,
        ..FrameOptions::default()
    };
    let mut frames = open_frames(input, &options)?;
    let (width, height) = frames.dimensions();
    let mut motion = MotionDetector::new(&config.motion_detector, width, height)?;
    let mut tracker = SiftPfTracker::new(&config.tracker, homography, seed)?;
    let mut progress = show_progress.then(|| FrameProgress::new(frames.len(), "tracking"));
    let mut blobs = Vec::new();
    let mut estimates: Vec<SiftPfEstimate> = Vec::new();
    let (started, mut tracking, mut count) = (Instant::now(), Duration::ZERO, 0u64);
    for frame in &mut frames {
        let frame = frame?;
        let context = || format!("{}: frame {}", frame.path.display(), frame.index + 1);
        motion
            .detect(&frame.image, &mut blobs)
            .with_context(context)?;
        let detections: Vec<DetectedObject> = blobs
            .drain(..)
            .map(|b| DetectedObject {
                bbox: b.bbox,
                mask: b.mask,
                cut_from: b.cut_from,
            })
            .collect();
        let tick = Instant::now();
        let found = tracker
            .step(SiftPfFrame {
                frame: frame.index,
                grey: &frame.image,
                colour: frame.colour.as_ref(),
                foreground: motion.foreground(),
                detections: &detections,
            })
            .with_context(context)?;
        tracking += tick.elapsed();
        estimates.extend(found);
        count += 1;
        if let Some(p) = &mut progress {
            p.tick();
        }
    }
    if let Some(p) = progress {
        p.finish();
    }
    ensure!(count > 0, "{input}: the input holds no frame");
    estimates.sort_by_key(|e| (e.frame, e.id));
    Ok(SiftPfRun {
        rows: estimates.iter().map(mot_row).collect(),
        frames: count,
        tracking,
        total: started.elapsed(),
    })
}

/// An estimate as a MOTChallenge result row (confidence 1).
fn mot_row(e: &SiftPfEstimate) -> MotRow {
    MotRow {
        frame: e.frame,
        id: Some(e.id),
        left_px: e.bbox.left_px,
        top_px: e.bbox.top_px,
        width_px: e.bbox.width_px,
        height_px: e.bbox.height_px,
        confidence: Some(1.0),
        class: None,
        visibility: None,
        world: None,
    }
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
    let config = SiftPfConfig::load(
        args.config.as_deref(),
        &args.overrides,
        args.selection.as_deref(),
    )?;
    let homography = args
        .ground_plane
        .as_deref()
        .map(GroundPlaneFile::read_homography)
        .transpose()?;
    let run = track_sequence(
        &args.input,
        &config,
        homography,
        args.seed,
        args.max_frames,
        true,
    )?;
    let mut writer = MotResultsWriter::create(&args.out)?;
    writer.push(&run.rows)?;
    writer.finish()?;
    let per_frame = |d: Duration| 1e3 * d.as_secs_f64() / run.frames as f64;
    let summary = Summary {
        selection: config.tracker.selection.label().to_string(),
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

//! Any of the four trackers, and any of the three detectors, run on a frame source (a folder,
//! a glob pattern, a TIFF stack or a video): the one entry point the Python package and any
//! other runner call, whatever the tracker.
//!
//! PTV and the bedload trackers run through [`Pipeline`] (their detector chosen by
//! [`crate::DetectorConfig`]); the pedestrian trackers through their own runs, which pair the
//! motion detector's blobs, foreground and colour cues with the tracker
//! ([`crate::pedestrian`]). Every tracker's output reaches the [`TrackSink`] as
//! [`TrackPoint`]s; a pedestrian's point is its box's foot point, with the box in
//! [`TrackPoint::bbox`].

use std::path::PathBuf;

use sillage_core::{
    BoundingBox, Detection, Detector, FrameIndex, Homography, Result, TrackPoint, TrackSink, Vec2,
};
use sillage_detect::motion::{MotionDetector, MotionParams};
use sillage_io::{Frame, FrameOptions, open_frames};
use sillage_track::immpf::PedestrianEstimate;

use crate::pedestrian::immpf::{ImmpfRun, Scene};
use crate::pedestrian::siftpf::track_siftpf;
use crate::pedestrian::{ImmpfSettings, PedestrianInput, SiftPfSettings};
use crate::ptv_run::PtvRun;
use crate::{Pipeline, PipelineConfig};

/// One of the four trackers with everything it needs besides its frames.
#[derive(Debug, Clone)]
pub enum Tracking {
    /// PTV or a bedload tracker, with the detector of the configuration ([`Pipeline`]).
    Pipeline(Box<PipelineConfig>),
    /// Pedestrians, one IMM particle filter each (Madrigal & Hayet).
    Immpf(Box<ImmpfSetup>),
    /// Surveillance objects followed by their SIFT features' particle filters (Souded et al.).
    Siftpf(Box<SiftPfSetup>),
}

/// The IMM-PF tracker's settings, scene and seed.
#[derive(Debug, Clone)]
pub struct ImmpfSetup {
    /// The tracker's and the motion detector's parameters.
    pub settings: ImmpfSettings,
    /// Box sizing (ground plane) and the learned motion prior.
    pub scene: Scene,
    /// Seed of the particles.
    pub seed: u64,
    /// MOTChallenge detections to take as birth candidates instead of the motion blobs.
    pub detections: Option<PathBuf>,
}

/// The SIFT-PF tracker's settings, ground plane and seed.
#[derive(Debug, Clone)]
pub struct SiftPfSetup {
    /// The tracker's and the motion detector's parameters.
    pub settings: SiftPfSettings,
    /// Image → ground homography, for sizes and speeds in metres.
    pub homography: Option<Homography>,
    /// Seed of the particles.
    pub seed: u64,
}

/// The points of a person's box: its foot point (the point the pedestrian trackers follow),
/// its velocity and the box.
pub fn person_point(
    frame: FrameIndex,
    track_id: u64,
    bbox: BoundingBox,
    vel: Option<Vec2>,
) -> TrackPoint {
    TrackPoint {
        vel_px_per_frame: vel,
        bbox: Some(bbox),
        ..TrackPoint::at(frame, track_id, bbox.foot())
    }
}

fn immpf_point(e: &PedestrianEstimate) -> TrackPoint {
    person_point(e.frame, e.track_id, e.bbox, Some(e.vel_px_per_frame))
}

/// Tracks the frames of `source` that `frames` selects (all, the first `max_frames`, or a
/// time window `start_at..stop_at`) with `tracking`, handing the points to `sink` as they
/// become final; `on_frame` is called after each frame. Returns the number of frames tracked.
pub fn track_source(
    source: &str,
    tracking: &Tracking,
    frames: &FrameOptions,
    sink: &mut dyn TrackSink,
    on_frame: &mut dyn FnMut(),
) -> Result<u64> {
    match tracking {
        Tracking::Pipeline(config) => {
            let run = PtvRun::open_frames(config, source, frames.clone())?;
            let summary = run.run(sink, &mut |_| on_frame())?;
            Ok(summary.frames)
        }
        Tracking::Immpf(setup) => {
            let motion = setup.settings.motion_params(setup.scene.has_ground_plane());
            let input = PedestrianInput::open(
                Some(source),
                setup.detections.as_deref(),
                None,
                &motion,
                &setup.settings.tracker,
                frames,
                false,
            )?;
            let run = ImmpfRun::new(
                input,
                &setup.settings.tracker,
                setup.scene.clone(),
                setup.seed,
            )?;
            let mut points = Vec::new();
            let summary = run.run(&mut |_, estimates| -> Result<()> {
                points.clear();
                points.extend(estimates.iter().map(immpf_point));
                on_frame();
                sink.accept(&points)
            })?;
            Ok(summary.frames)
        }
        Tracking::Siftpf(setup) => {
            let run = track_siftpf(
                source,
                &setup.settings,
                setup.homography,
                setup.seed,
                frames,
                &mut |_| on_frame(),
            )?;
            let points: Vec<TrackPoint> = run
                .estimates
                .iter()
                .map(|e| person_point(e.frame, e.id, e.bbox, None))
                .collect();
            sink.accept(&points)?;
            Ok(run.frames)
        }
    }
}

/// One of the three detectors.
#[derive(Debug, Clone)]
pub enum Detecting {
    /// The blob or bead detector of the configuration, after its pre-processing.
    Pipeline(Box<PipelineConfig>),
    /// Moving blobs over a Gaussian-mixture background (the pedestrian trackers' births).
    Motion(MotionParams),
}

/// Receives each frame with its detections and their boxes (empty for point detectors).
pub type DetectionSink<'a> = dyn FnMut(&Frame, &[Detection], &[BoundingBox]) -> Result<()> + 'a;

/// Detects objects in every frame of `source` (the first `max_frames`), handing each frame
/// with its detections and, for detectors of extended objects, their boxes (else empty) to
/// `each`.
pub fn detect_source(
    source: &str,
    detecting: &Detecting,
    max_frames: Option<usize>,
    each: &mut DetectionSink<'_>,
) -> Result<()> {
    let options = FrameOptions {
        max_frames,
        ..FrameOptions::default()
    };
    let frames = open_frames(source, &options)?;
    match detecting {
        Detecting::Pipeline(config) => {
            let mut pipeline = Pipeline::from_config(config)?;
            if pipeline.background_init_frames() > 0 {
                pipeline.prime_background(open_frames(source, &options)?)?;
            }
            for frame in frames {
                let frame = frame?;
                let found = pipeline.locate(&frame)?;
                each(&frame, found, &[])?;
            }
        }
        Detecting::Motion(params) => {
            let (width, height) = frames.dimensions();
            let mut detector = MotionDetector::new(params, width, height)?;
            let mut found = Vec::new();
            for frame in frames {
                let frame = frame?;
                Detector::detect(&mut detector, &frame.image, &mut found)?;
                each(&frame, &found, detector.boxes())?;
            }
        }
    }
    Ok(())
}

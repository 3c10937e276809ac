//! `track siftpf`: surveillance objects found by motion detection and followed by their SIFT
//! features' particle filters (Souded et al. 2011), over a whole sequence.

use std::time::{Duration, Instant};

use sillage_core::{Error, Homography, Result};
use sillage_detect::motion::{MotionBlob, MotionDetector};
use sillage_io::{FrameOptions, MotRow};
use sillage_track::siftpf::{DetectedObject, SiftPfEstimate, SiftPfFrame, SiftPfTracker};

use super::input::open_sequence_frames;
use super::settings::SiftPfSettings;
use super::within;

/// The motion detector's blobs as the tracker's detected objects (box, mask, the group they
/// were cut from), emptying `blobs`.
pub fn detected_objects(blobs: &mut Vec<MotionBlob>) -> Vec<DetectedObject> {
    blobs
        .drain(..)
        .map(|b| DetectedObject {
            bbox: b.bbox,
            mask: b.mask,
            cut_from: b.cut_from,
        })
        .collect()
}

/// What tracking one sequence gave.
pub struct SiftPfRun {
    /// The reported boxes, sorted by frame then identity (0-based frames).
    pub estimates: Vec<SiftPfEstimate>,
    /// Frames tracked.
    pub frames: u64,
    /// Time in the tracker (SIFT, features, association), excluding decoding and motion
    /// detection.
    pub tracking: Duration,
    /// Wall time of the whole run.
    pub total: Duration,
}

impl SiftPfRun {
    /// The estimates as MOTChallenge result rows (confidence 1).
    pub fn rows(&self) -> Vec<MotRow> {
        self.estimates
            .iter()
            .map(|e| MotRow::result(e.frame, e.id, &e.bbox))
            .collect()
    }

    /// The number of distinct track identities in the estimates.
    pub fn track_count(&self) -> usize {
        let mut ids: Vec<u64> = self.estimates.iter().map(|e| e.id).collect();
        ids.sort_unstable();
        ids.dedup();
        ids.len()
    }
}

/// Tracks the colour frames of `input` that `frames` selects; `on_frame` is called after
/// each frame with the number of frames expected, when known (a progress bar's tick).
pub fn track_siftpf(
    input: &str,
    settings: &SiftPfSettings,
    homography: Option<Homography>,
    seed: u64,
    frames: &FrameOptions,
    on_frame: &mut dyn FnMut(Option<usize>),
) -> Result<SiftPfRun> {
    let options = FrameOptions {
        colour: true,
        ..frames.clone()
    };
    let mut frames = open_sequence_frames(input, &options)?;
    let (width, height) = frames.dimensions();
    let expected = frames.len();
    let mut motion = MotionDetector::new(&settings.motion_detector, width, height)?;
    let mut tracker = SiftPfTracker::new(&settings.tracker, homography, seed)?;
    let mut blobs = Vec::new();
    let mut estimates: Vec<SiftPfEstimate> = Vec::new();
    let (started, mut tracking, mut count) = (Instant::now(), Duration::ZERO, 0u64);
    for frame in &mut frames {
        let frame = frame?;
        let context = |e| {
            let what = format!("{}: frame {}", frame.path.display(), frame.index + 1);
            within(what, e)
        };
        motion.detect(&frame.image, &mut blobs).map_err(context)?;
        let detections = detected_objects(&mut blobs);
        let tick = Instant::now();
        let found = tracker
            .step(SiftPfFrame {
                frame: frame.index,
                grey: &frame.image,
                colour: frame.colour.as_ref(),
                foreground: motion.foreground(),
                detections: &detections,
            })
            .map_err(context)?;
        tracking += tick.elapsed();
        estimates.extend(found);
        count += 1;
        on_frame(expected);
    }
    if count == 0 {
        return Err(Error::input(format!("{input}: the input holds no frame")));
    }
    estimates.sort_by_key(|e| (e.frame, e.id));
    Ok(SiftPfRun {
        estimates,
        frames: count,
        tracking,
        total: started.elapsed(),
    })
}

//! `detect motion`: the motion detector the pedestrian and surveillance trackers use
//! (adaptive Gaussian-mixture background, morphology, blobs), its blobs as MOTChallenge
//! detections, streamed frame by frame.

use std::time::{Duration, Instant};

use sillage_core::{Error, Result};
use sillage_detect::motion::{MotionBlob, MotionDetector, MotionParams};
use sillage_io::{FrameOptions, FrameSource, MotRow};

use super::input::open_sequence_frames;
use super::within;

/// What a run found.
#[derive(Debug, Clone, Copy)]
pub struct MotionSummary {
    /// Frames read.
    pub frames: u64,
    /// Blobs found.
    pub blobs: usize,
    /// Wall time of the run.
    pub total: Duration,
}

/// The motion detector over a sequence of frames.
pub struct MotionDetection {
    input: String,
    frames: FrameSource,
    detector: MotionDetector,
}

impl MotionDetection {
    /// Opens the frames of `input` (the first `max_frames`) for a detector with `params`.
    pub fn open(input: &str, params: &MotionParams, max_frames: Option<usize>) -> Result<Self> {
        let options = FrameOptions {
            max_frames,
            ..FrameOptions::default()
        };
        let frames = open_sequence_frames(input, &options)?;
        let (width, height) = frames.dimensions();
        let detector = MotionDetector::new(params, width, height)?;
        Ok(Self {
            input: input.to_owned(),
            frames,
            detector,
        })
    }

    /// Frames to expect, when known.
    pub fn frames_expected(&self) -> Option<usize> {
        self.frames.len()
    }

    /// Detects every frame, handing its rows (one per blob: id `-1`, confidence the blob's
    /// share of motion pixels in its box) to `on_frame`; stops at the first error. An input
    /// without frames is an error.
    pub fn run<E: From<Error>>(
        mut self,
        on_frame: &mut dyn FnMut(&[MotRow]) -> Result<(), E>,
    ) -> Result<MotionSummary, E> {
        let (mut blobs, mut rows) = (Vec::new(), Vec::new());
        let (mut frames, mut found) = (0u64, 0usize);
        let start = Instant::now();
        for frame in &mut self.frames {
            let frame = frame?;
            self.detector
                .detect(&frame.image, &mut blobs)
                .map_err(|e| {
                    within(
                        format_args!("{}: frame {}", frame.path.display(), frame.index + 1),
                        e,
                    )
                })?;
            rows.clear();
            rows.extend(blobs.iter().map(|b| blob_row(frame.index, b)));
            on_frame(&rows)?;
            frames += 1;
            found += blobs.len();
        }
        if frames == 0 {
            let message = format!("{}: the input holds no frame", self.input);
            return Err(Error::input(message).into());
        }
        Ok(MotionSummary {
            frames,
            blobs: found,
            total: start.elapsed(),
        })
    }
}

/// A blob as a MOTChallenge detection row of `frame`.
fn blob_row(frame: u64, b: &MotionBlob) -> MotRow {
    let (w, h) = (b.bbox.width(), b.bbox.height());
    MotRow {
        frame,
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
}

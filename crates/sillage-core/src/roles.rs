//! The role traits the pipeline is built from.

use crate::{BoundingBox, Detection, FrameIndex, GrayImage, Result, TrackPoint};

/// Finds objects in one pre-processed frame.
pub trait Detector {
    /// Appends the detections of `image` to `out` (cleared first), reusing its allocation.
    fn detect(&mut self, image: &GrayImage, out: &mut Vec<Detection>) -> Result<()>;

    /// The box of each detection of the last [`Detector::detect`], in the same order, for
    /// detectors of extended objects (motion blobs); empty for detectors of points.
    fn boxes(&self) -> &[BoundingBox] {
        &[]
    }
}

/// Everything a tracker may look at for one frame.
#[derive(Debug, Clone, Copy)]
pub struct FrameObservations<'a> {
    /// Index of the frame in the sequence.
    pub frame: FrameIndex,
    /// The detections of this frame.
    pub detections: &'a [Detection],
    /// The pre-processed frame, for trackers that weigh particles against pixels.
    pub image: Option<&'a GrayImage>,
    /// The detector-confidence candidates of Eq. (1) of the MMPF+ paper: every response
    /// maximum above a low threshold, detections included, with its likelihood `L(d)` as
    /// `strength` and its class; empty when the detector makes none. A tracker evaluates the
    /// confidence density from them where it needs it (at particles), never as a full map.
    pub candidates: &'a [Detection],
}

impl<'a> FrameObservations<'a> {
    /// Observations made of detections only.
    pub fn from_detections(frame: FrameIndex, detections: &'a [Detection]) -> Self {
        Self {
            frame,
            detections,
            image: None,
            candidates: &[],
        }
    }
}

/// Follows objects one frame at a time and emits each point once it is final.
///
/// A tracker may hold points back (PTV's three-frame association emits frame `t-1` at step
/// `t`); [`Tracker::finish`] flushes what is left. Memory stays bounded whatever the length
/// of the sequence.
pub trait Tracker {
    /// Consumes one frame; frames must come in increasing order.
    fn step(
        &mut self,
        observations: &FrameObservations<'_>,
        sink: &mut dyn TrackSink,
    ) -> Result<()>;
    /// Emits whatever is still held back; the tracker is done afterwards.
    fn finish(&mut self, sink: &mut dyn TrackSink) -> Result<()>;
}

/// Receives final track points: a file writer, a collector, a metric.
pub trait TrackSink {
    /// Takes the points of one batch (typically one frame, in increasing track id order).
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()>;
}

impl TrackSink for Vec<TrackPoint> {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        self.extend_from_slice(points);
        Ok(())
    }
}

/// A sink that drops every point: training passes, and timing runs where only the cost of
/// tracking matters.
#[derive(Debug, Clone, Copy, Default)]
pub struct DiscardSink;

impl TrackSink for DiscardSink {
    fn accept(&mut self, _points: &[TrackPoint]) -> Result<()> {
        Ok(())
    }
}

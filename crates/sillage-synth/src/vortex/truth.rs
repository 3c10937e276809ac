//! Ground truth of the vortex flow, frame by frame, with the velocities a three-frame tracker
//! should report.

use sillage_core::{FrameIndex, Point2, Result, TrackId, TruthPoint, Vec2};

use super::{VortexFlow, VortexParams};

/// The true points of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct TruthFrame {
    /// Index of the frame.
    pub index: FrameIndex,
    /// One point per particle, in slot order.
    pub truth: Vec<TruthPoint>,
}

/// The slots of one frame (identities and positions), kept to compute velocities.
#[derive(Debug, Clone, Default)]
struct Snapshot {
    ids: Vec<TrackId>,
    positions: Vec<Point2>,
}

impl Snapshot {
    fn capture(&mut self, flow: &VortexFlow) {
        self.ids.clear();
        self.ids.extend_from_slice(flow.track_ids());
        self.positions.clear();
        self.positions.extend_from_slice(flow.positions());
    }

    fn clear(&mut self) {
        self.ids.clear();
        self.positions.clear();
    }
}

/// The truth of the vortex flow without images (for tracker tests on positions), streamed
/// frame by frame in bounded memory: frames `0..params.n_frames`.
///
/// Each point's `vel_px_per_frame` is the central difference `(x(t+1) − x(t−1)) / 2` that a
/// three-frame tracker reports (TracTrac Eq. 6), when the same identity exists at `t − 1`
/// and `t + 1` within the sequence; `None` otherwise: on the first and last frames (so that,
/// like TracTrac's output, only frames `1..n−2` carry velocities) and around a wrap or a
/// re-seeding.
#[derive(Debug, Clone)]
pub struct VortexTruth {
    flow: VortexFlow,
    n_frames: usize,
    first_frame: FrameIndex,
    /// Number of frames already yielded.
    yielded: usize,
    previous: Snapshot,
    current: Snapshot,
    next: Snapshot,
}

impl VortexTruth {
    /// The truth of the sequence `params` describe; fails on invalid parameters.
    pub fn new(params: &VortexParams) -> Result<Self> {
        Ok(Self::from_flow(VortexFlow::new(params)?, params.n_frames))
    }

    /// The truth of `n_frames` frames of `flow`, starting at its current frame.
    pub fn from_flow(flow: VortexFlow, n_frames: usize) -> Self {
        let mut truth = Self {
            first_frame: flow.frame(),
            flow,
            n_frames,
            yielded: 0,
            previous: Snapshot::default(),
            current: Snapshot::default(),
            next: Snapshot::default(),
        };
        truth.current.capture(&truth.flow);
        truth.capture_next();
        truth
    }

    /// The parameters of the flow.
    pub fn params(&self) -> &VortexParams {
        self.flow.params()
    }

    /// Advances the flow and captures the frame after the current one, if in the sequence.
    fn capture_next(&mut self) {
        if self.yielded + 1 < self.n_frames {
            self.flow.advance();
            self.next.capture(&self.flow);
        } else {
            self.next.clear();
        }
    }

    /// The central-difference velocity of slot `slot` of the current frame.
    fn velocity(&self, slot: usize) -> Option<Vec2> {
        let id = self.current.ids[slot];
        let same = |snapshot: &Snapshot| {
            (snapshot.ids.get(slot) == Some(&id)).then(|| snapshot.positions[slot])
        };
        let (before, after) = (same(&self.previous), same(&self.next));
        Some((after? - before?) / 2.0)
    }
}

impl Iterator for VortexTruth {
    type Item = TruthFrame;

    fn next(&mut self) -> Option<TruthFrame> {
        if self.yielded >= self.n_frames {
            return None;
        }
        let index = self.first_frame + self.yielded as u64;
        let truth = (0..self.current.ids.len())
            .map(|slot| TruthPoint {
                frame: index,
                track_id: self.current.ids[slot],
                pos_px: self.current.positions[slot],
                vel_px_per_frame: self.velocity(slot),
            })
            .collect();
        std::mem::swap(&mut self.previous, &mut self.current);
        std::mem::swap(&mut self.current, &mut self.next);
        self.yielded += 1;
        self.capture_next();
        Some(TruthFrame { index, truth })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.n_frames - self.yielded;
        (left, Some(left))
    }
}

impl ExactSizeIterator for VortexTruth {}

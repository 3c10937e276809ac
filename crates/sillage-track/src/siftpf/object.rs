//! One tracked object `to(t)` of Souded et al.: its box, its features, its life cycle
//! (intermediate until validated, §2.5; occluded and kept for resumption, §2.4) and what is
//! learned about it for resuming it (dominant colours, size and speed).

use sillage_core::{FrameIndex, Point2, TrackId, Vec2};
use sillage_image::{DominantColours, SiftDescriptor};

use super::coherence::Coherence;
use super::feature::TrackedFeature;
use sillage_core::BoundingBox;

/// Where an object is in its life.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObjectState {
    /// New, watched before it counts as an object of interest (§2.5).
    Intermediate,
    /// Validated and linked to a blob (alone or in a merge).
    Tracked,
    /// Validated, unseen, kept for resumption since this frame (§2.4).
    Occluded {
        /// The first frame it was missing.
        since: FrameIndex,
    },
}

/// One frame of an intermediate object's history, kept until it is validated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HistoryEntry {
    /// The frame.
    pub frame: FrameIndex,
    /// The object's box.
    pub bbox: BoundingBox,
    /// True when a blob supported the object.
    pub linked: bool,
}

/// A tracked object.
#[derive(Debug, Clone)]
pub struct TrackedObject {
    /// Its identity.
    pub id: TrackId,
    /// Its box in the current frame (predicted when unseen).
    pub bbox: BoundingBox,
    /// Its box in the previous frame (the velocity is learned from the step between them).
    pub previous: BoundingBox,
    /// Life-cycle state.
    pub state: ObjectState,
    /// Its tracked features.
    pub features: Vec<TrackedFeature>,
    /// Velocity of its box centre, px/frame (smoothed).
    pub vel_px_per_frame: Vec2,
    /// True once it shared a blob with another object or hid an occluded one: a later split
    /// resumes the others rather than giving every part a new identity (§2.3, third case).
    pub has_merged: bool,
    /// While it shares its detection with other objects (its box then comes from its
    /// features' pre-merge layout): where it would be had it kept its pre-merge velocity.
    pub merge_prediction: Option<BoundingBox>,
    /// Its dominant colours, from the last frame it had a blob of its own.
    pub colours: DominantColours,
    /// Its features' descriptors in the last frame it had a blob of its own: what a
    /// candidate must match to resume it after an occlusion (§2.4).
    pub signature: Vec<SiftDescriptor>,
    /// Its learned size and speed.
    pub coherence: Coherence,
    /// Boxes of the frames before validation (reported at once when it is validated).
    pub history: Vec<HistoryEntry>,
    /// Ground position and frame of its last one-to-one link, for the speed model.
    pub last_ground: Option<(Point2, FrameIndex)>,
    /// The frame it was born in.
    pub born: FrameIndex,
}

impl TrackedObject {
    /// A new intermediate object on `bbox` at `frame`.
    pub fn new(id: TrackId, bbox: BoundingBox, frame: FrameIndex) -> Self {
        Self {
            id,
            bbox,
            previous: bbox,
            state: ObjectState::Intermediate,
            features: Vec::new(),
            vel_px_per_frame: Vec2::new(0.0, 0.0),
            has_merged: false,
            merge_prediction: None,
            colours: DominantColours::default(),
            signature: Vec::new(),
            coherence: Coherence::default(),
            history: vec![HistoryEntry {
                frame,
                bbox,
                linked: true,
            }],
            last_ground: None,
            born: frame,
        }
    }

    /// True while its features are followed (not occluded).
    pub fn is_active(&self) -> bool {
        !matches!(self.state, ObjectState::Occluded { .. })
    }

    /// Sets the box of this frame to `bbox` (replacing the prediction) and updates the
    /// velocity: the reliability-weighted mean of its features' velocities (their particle
    /// filters'), steadier than the box, whose edges follow the blob's shape; with fewer than
    /// three features, the smoothed step of the box centre.
    pub fn move_to(&mut self, bbox: BoundingBox) {
        let (mut sum_w, mut u, mut v) = (0.0, 0.0, 0.0);
        for f in &self.features {
            let w = f.reliability().max(1e-6);
            u += w * f.vel_px_per_frame().x;
            v += w * f.vel_px_per_frame().y;
            sum_w += w;
        }
        self.vel_px_per_frame = if self.features.len() >= 3 {
            Vec2::new(u / sum_w, v / sum_w)
        } else {
            (self.vel_px_per_frame + (centre(&bbox) - centre(&self.previous))) * 0.5
        };
        self.bbox = bbox;
    }

    /// Starts a frame: the box predicted at constant velocity (kept when nothing corrects it).
    pub fn coast(&mut self) {
        self.previous = self.bbox;
        self.bbox.left_px += self.vel_px_per_frame.x;
        self.bbox.top_px += self.vel_px_per_frame.y;
    }

    /// The box estimated from its features' pre-merge layout (§2.3, second case): each
    /// feature at `(x, y)` with anchor `(a, b)` places the box's corner at
    /// `(x − a·w, y − b·h)`; the corners are averaged with the features' reliabilities as
    /// weights; the size is the pre-merge one. `None` without features.
    pub fn box_from_features(&self) -> Option<BoundingBox> {
        let (w, h) = (self.bbox.width_px, self.bbox.height_px);
        let (mut sum_w, mut left, mut top) = (0.0, 0.0, 0.0);
        for f in &self.features {
            let weight = f.reliability().max(1e-6);
            let (a, b) = f.anchor();
            left += weight * (f.pos_px().x - a * w);
            top += weight * (f.pos_px().y - b * h);
            sum_w += weight;
        }
        (sum_w > 0.0).then(|| BoundingBox {
            left_px: left / sum_w,
            top_px: top / sum_w,
            width_px: w,
            height_px: h,
        })
    }
}

/// The centre of a box.
fn centre(b: &BoundingBox) -> Point2 {
    Point2::new(b.left_px + b.width_px / 2.0, b.top_px + b.height_px / 2.0)
}

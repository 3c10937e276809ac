//! What flows through the pipeline: detections in, track points out, truth beside.

use serde::{Deserialize, Serialize};

use crate::{BoundingBox, Point2, Vec2};

/// 0-based index of a frame in its sequence.
pub type FrameIndex = u64;

/// Identity of a trajectory; unique within one run, never reused.
pub type TrackId = u64;

/// One object found in one frame by a detector.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Detection {
    /// Sub-pixel centre, px.
    pub pos_px: Point2,
    /// Detector response at the centre (filtered intensity, NCC score, ...): larger is surer.
    pub strength: f32,
    /// Object class (bead category: 0 black, 1 transparent; MOTChallenge class), 0 where a
    /// detector knows one kind only. Trackers associate only within a class.
    #[serde(default)]
    pub class: ObjectClass,
}

/// Class of an object, as a small integer (see [`Detection::class`]).
pub type ObjectClass = u32;

/// Class of the black (coarse, 6 mm) beads of the bedload experiments: BeadTracking's
/// category 0.
pub const BLACK_BEAD_CLASS: ObjectClass = 0;

/// Class of the transparent (fine, 4 mm) beads of the bedload experiments: BeadTracking's
/// category 1.
pub const TRANSPARENT_BEAD_CLASS: ObjectClass = 1;

impl Detection {
    /// A detection of class 0 at `pos_px` with response `strength`.
    pub const fn new(pos_px: Point2, strength: f32) -> Self {
        Self::of_class(pos_px, strength, 0)
    }

    /// A detection of class `class` at `pos_px` with response `strength`.
    pub const fn of_class(pos_px: Point2, strength: f32, class: ObjectClass) -> Self {
        Self {
            pos_px,
            strength,
            class,
        }
    }
}

/// Motion state of an object (the bedload states of the MMPF+ paper; `Unknown` elsewhere).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MotionState {
    /// Not estimated, or not yet known.
    #[default]
    Unknown,
    /// At rest on the bed.
    Resting,
    /// Rolling on the bed surface.
    Rolling,
    /// In a ballistic hop.
    Saltating,
}

impl MotionState {
    /// Every state, in the order of BeadTracking's codes (resting 0 … unknown 3).
    pub const ALL: [MotionState; 4] =
        [Self::Resting, Self::Rolling, Self::Saltating, Self::Unknown];

    /// The lowercase name written in CSV and Parquet track tables (`resting`, `rolling`,
    /// `saltating`, `unknown`), the same as the serde name.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Unknown => "unknown",
            Self::Resting => "resting",
            Self::Rolling => "rolling",
            Self::Saltating => "saltating",
        }
    }

    /// The state named `name` (any case), `None` for another name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|s| s.name().eq_ignore_ascii_case(name.trim()))
    }

    /// BeadTracking's code of the state, as in its ground truth (`trackData` row 9): 0
    /// resting, 1 rolling, 2 saltating, 3 unknown.
    pub const fn bead_tracking_code(self) -> u8 {
        match self {
            Self::Resting => 0,
            Self::Rolling => 1,
            Self::Saltating => 2,
            Self::Unknown => 3,
        }
    }

    /// The state of BeadTracking's code `code` (see [`MotionState::bead_tracking_code`]);
    /// `None` for any other value, fractional ones included.
    pub fn from_bead_tracking_code(code: f64) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|s| f64::from(s.bead_tracking_code()) == code)
    }
}

/// One final point of one trajectory, as a tracker emits it.
///
/// Kinematic fields are `None` where the tracker does not estimate them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrackPoint {
    /// Frame of this point.
    pub frame: FrameIndex,
    /// Trajectory identity.
    pub track_id: TrackId,
    /// Position, px.
    pub pos_px: Point2,
    /// Velocity, px/frame (PTV: the slope of a least-squares line through up to
    /// `tracker.velocity_window` positions of the trajectory, or the central difference of
    /// Eq. (6) of the TracTrac paper).
    pub vel_px_per_frame: Option<Vec2>,
    /// Acceleration, px/frame² (PTV: twice the leading coefficient of a least-squares
    /// parabola through those positions, or Eq. (7)).
    pub acc_px_per_frame2: Option<Vec2>,
    /// Velocity predicted by the motion model, px/frame (PTV: Eq. (8)).
    pub vel_pred_px_per_frame: Option<Vec2>,
    /// log10 of the prediction error in px (PTV: Eq. (10), Chebyshev norm as TracTrac's code).
    pub log10_pred_err: Option<f64>,
    /// Estimated motion state.
    pub motion_state: MotionState,
    /// Object class, as the detections it was built from (0 where there is one kind only).
    #[serde(default)]
    pub class: ObjectClass,
    /// Spread of the estimate, px: the root of the mean of the position covariance's two
    /// variances (particle filters: the weighted particle spread; Kalman: the posterior).
    #[serde(default)]
    pub spread_px: Option<f64>,
    /// Index of the detection this point is, in its frame's
    /// [`FrameObservations::detections`](crate::FrameObservations::detections) (`None` where the point is an estimate rather than
    /// a detection, or the tracker does not say; the PTV tracker always says). Joins a point
    /// back to its detection's other attributes without matching coordinates.
    #[serde(default)]
    pub detection: Option<u32>,
    /// The object's box, px, for trackers that follow boxes (pedestrians): `pos_px` is then
    /// the point the tracker follows in it (the IMM-PF's foot point, the SIFT-PF's centre).
    #[serde(default)]
    pub bbox: Option<BoundingBox>,
}

impl TrackPoint {
    /// A point with only a position (kinematics unknown).
    pub const fn at(frame: FrameIndex, track_id: TrackId, pos_px: Point2) -> Self {
        Self {
            frame,
            track_id,
            pos_px,
            vel_px_per_frame: None,
            acc_px_per_frame2: None,
            vel_pred_px_per_frame: None,
            log10_pred_err: None,
            motion_state: MotionState::Unknown,
            class: 0,
            spread_px: None,
            detection: None,
            bbox: None,
        }
    }
}

/// One point of a ground-truth trajectory.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TruthPoint {
    /// Frame of this point.
    pub frame: FrameIndex,
    /// Identity of the true object.
    pub track_id: TrackId,
    /// True position, px.
    pub pos_px: Point2,
    /// True displacement to the next frame, px/frame, when known.
    pub vel_px_per_frame: Option<Vec2>,
}

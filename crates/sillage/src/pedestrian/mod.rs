//! Pedestrians and surveillance objects: what `sillage track immpf` (one IMM particle filter
//! per person, Madrigal & Hayet), `sillage track siftpf` (SIFT features' particle filters,
//! Souded et al. 2011), `sillage detect motion` and the fits of `sillage fit homography` /
//! `sillage fit motion-prior` run, as library calls.
//!
//! A box's position is its foot point, the bottom centre `(bb_left + w/2, bb_top + h)`, in the
//! file's own pixel numbering (MOTChallenge boxes are kept as written, see `sillage_io::mot`),
//! so the prior, the homography and a tracker's MOTChallenge output agree.

pub mod boxes;
pub mod ground_plane;
pub mod homography;
pub mod immpf;
pub mod input;
pub mod motion;
pub mod motion_prior;
pub mod settings;
pub mod siftpf;
pub mod walkers;

pub use ground_plane::{FitTable, GroundPlaneFile};
pub use input::{PedestrianInput, PreparedFrame};
pub use settings::{ImmpfSettings, PedestrianMotionSettings, SiftPfSettings};

use std::fmt::Display;

use sillage_core::{Error, Point2};
use sillage_io::MotRow;

/// `error` behind `what`, as `what: error` (`frame 3: ...`): the message names where it
/// happened.
pub(crate) fn within(what: impl Display, error: Error) -> Error {
    Error::input(format!("{what}: {error}"))
}

/// The foot point of a box: its bottom centre.
pub fn foot_px(row: &MotRow) -> Point2 {
    Point2::new(row.left_px + 0.5 * row.width_px, row.top_px + row.height_px)
}

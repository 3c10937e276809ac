//! Motion models: how particles move from one frame to the next (the prediction of the SIR
//! filter, "update of particle positions and velocities according to motion models", §3.5
//! of the MMPF+ paper).
//!
//! - [`bedload`]: the four bead motions of Eq. (3) with jump-Markov switching (§3.5.1, §4.3);
//! - [`kinematic`]: constant position / velocity / acceleration, alone or switched;
//! - [`prior`]: the learned motion prior (MP) of the pedestrian IMM particle filter (§5.1 of
//!   Madrigal & Hayet): per-cell direction probabilities and mean velocities.
//!
//! Positions are in px and velocities in px/frame, so the Δt of Eq. (3) is one frame.

pub mod bedload;
pub mod kinematic;
pub mod prior;

use sillage_core::RngStream;

use crate::particles::Particles;

/// Moves every particle of one target one frame ahead, drawing from the target's own stream.
///
/// `track_len` is the number of frames of the track including the one predicted into (2 at
/// the first prediction after a birth); models that treat young tracks differently (§4.3,
/// variance inflation for the first 3 frames) read it.
pub trait MotionModel: Sync {
    /// Propagates `particles` in place.
    fn propagate(&self, particles: &mut Particles, track_len: u32, rng: &mut RngStream);
}

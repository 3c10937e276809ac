//! Seeded synthetic scenes with ground truth: the TracTrac vortex flow and its renderer, the
//! MMPF+ bedload sequence, and walkers with occlusions for the pedestrian trackers.
//!
//! - [`vortex`]: the unsteady, non-uniform vortex flow of the TracTrac paper (§4.1.1,
//!   Eqs. 13-16), as positions only ([`VortexFlow`], [`VortexTruth`]) or as rendered frames
//!   with truth ([`VortexSequence`]), plus its displacement statistics and `p⁻¹`.
//! - [`bedload`]: beads resting, rolling and saltating over a packed bed, with motion states
//!   (MMPF+ paper §3.5.1, §4.2), and detections made from them with misses, bursts of
//!   misses, false positives and the detector-confidence candidates of Eq. (1)
//!   ([`BedloadScene`], [`BeadDetectionModel`], [`BedloadSequence`]), and its frames rendered
//!   as backlit grey images like the paper's ([`BedloadRenderer`]).
//! - [`walkers`]: people walking over a static background, in depth order with full and
//!   partial occlusions, as colour and grey frames with MOTChallenge-style truth (box,
//!   visibility, depth): a crossing with a full occlusion, a group that splits, a random
//!   crowd ([`WalkersParams`], [`Scenario`], [`WalkersSequence`]); the acceptance sequences
//!   of the SIFT-PF tracker (Souded et al. 2011).
//! - [`render_spots`]: Gaussian spots plus uniform or Gaussian noise, for any test or bench
//!   that needs an image with known centres.
//!
//! Everything is seeded: the same parameters give the same frames, bit for bit, whatever
//! the number of threads.
//!
//! ```
//! use sillage_synth::{VortexParams, VortexSequence};
//! let params = VortexParams { width: 64, height: 64, n_particles: 10, n_frames: 3, ..Default::default() };
//! let frames: Vec<_> = VortexSequence::new(params).unwrap().collect();
//! assert_eq!(frames.len(), 3);
//! assert_eq!(frames[1].image.dimensions(), (64, 64));
//! assert_eq!(frames[1].truth.len(), 10);
//! // Velocities are central differences, so only the inner frames carry them.
//! assert!(frames[0].truth.iter().all(|p| p.vel_px_per_frame.is_none()));
//! assert!(frames[1].truth.iter().any(|p| p.vel_px_per_frame.is_some()));
//! ```

pub mod bedload;
mod noise;
mod render;
pub mod vortex;
pub mod walkers;

pub use bedload::{
    BeadDetectionModel, BedloadDetectionParams, BedloadFrame, BedloadObservation,
    BedloadRenderParams, BedloadRenderer, BedloadSample, BedloadScene, BedloadSceneParams,
    BedloadSequence, MissCause, MissedBead, TrueBead, generate_bedload, render_bedload_frame,
};

pub use noise::{Noise, NoiseKind};
pub use render::render_spots;
pub use vortex::{
    DisplacementStats, FlowField, FlowKind, SyntheticFrame, TruthFrame, VortexFlow, VortexParams,
    VortexSequence, VortexTruth, displacement_stats, p_inverse, vortex_map,
};
pub use walkers::{
    CrossingParams, GroupSplitParams, RandomParams, Scenario, WalkerTruth, WalkersFrame,
    WalkersParams, WalkersSequence,
};

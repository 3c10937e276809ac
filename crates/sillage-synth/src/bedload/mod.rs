//! A seeded synthetic bedload sequence for the MMPF+ tracker and its baselines (Lafaye de
//! Micheaux, Ducottet & Frey 2018, §3.3, §3.5.1, §4.2, §4.3): ground-truth bead trajectories
//! with motion states, and detections made from them with misses, bursts of misses, false
//! positives, position noise and the detector-confidence candidates of Eq. (1).
//!
//! - [`BedloadScene`] ([`BedloadSceneParams`]): a static bed of black beads in hexagonal layers
//!   in contact at the bottom of the frame (6 contacts inside the bed, as the motion-state
//!   rule `nbN ≥ 5` expects) with transparent beads lodged in its top layers, creeping layers
//!   of black beads slipping downstream over it in stop-and-go spells (the real sequence's
//!   rolling deposit), and mobile beads, black and transparent, resting on them or on each
//!   other (carried by the top layer), rolling downstream over them and over lower beads, or
//!   saltating above them in ballistic hops, their states switching per frame by the
//!   transition table (default Eq. (11)). The flume being about one bead wide (§4.1), no two
//!   beads come closer than their contact distance, measured on the real frames
//!   ([`BedloadSceneParams::contact_factors`]). Beads leaving downstream come back upstream
//!   as new identities. Yields [`BedloadFrame`]s of [`TrueBead`]s.
//! - [`BeadDetectionModel`] ([`BedloadDetectionParams`]): per frame, the detections of both
//!   classes and the candidates `D` of Eq. (1), with the true bead behind each
//!   ([`BedloadObservation`]).
//! - [`BedloadSequence`] streams both; [`generate_bedload`] collects a short sequence.
//! - [`BedloadRenderer`] ([`BedloadRenderParams`], [`render_bedload_frame`]): the frames
//!   themselves, backlit grey images that look like the paper's (black discs, faint dark
//!   rims of transparent beads, noise), for running the real bead detector on the scene.
//!
//! Coordinates are px, y down (the bed at large y, gravity towards +y), velocities
//! px/frame. The same parameters give the same frames; the truth draws from its own
//! streams, so changing the detector's parameters leaves it unchanged.
//!
//! ```
//! use sillage_core::MotionState;
//! use sillage_synth::{BedloadDetectionParams, BedloadSceneParams, generate_bedload};
//!
//! let params = BedloadSceneParams { n_frames: 3, ..Default::default() };
//! let frames = generate_bedload(params, BedloadDetectionParams::default())?;
//! assert_eq!(frames.len(), 3);
//! assert_eq!(frames[2].truth.beads.len(), 400);
//! // The static bed: 6 layers of 43 sites, 70 of which hold a transparent bead, always
//! // resting; over it, 2 creeping layers of 42 black beads.
//! let bed = frames[2].truth.beads.iter().filter(|b| b.in_bed).count();
//! assert_eq!(bed, 258);
//! assert!(frames[2].truth.beads.iter().filter(|b| b.in_bed).all(|b| b.motion_state == MotionState::Resting));
//! // Black beads are never missed by default, so there are at least 300 detections.
//! assert!(frames[2].observation.detections.len() >= 300);
//! # Ok::<(), sillage_core::Error>(())
//! ```

mod bed;
mod creep;
mod detection_params;
mod detections;
mod motion;
mod params;
mod pile;
mod render;
mod scene;
mod sequence;

pub use detection_params::BedloadDetectionParams;
pub use detections::{BeadDetectionModel, BedloadObservation, MissCause, MissedBead};
pub use params::BedloadSceneParams;
pub use render::{BedloadRenderParams, BedloadRenderer, render_bedload_frame};
pub use scene::{BedloadFrame, BedloadScene, TrueBead};
pub use sequence::{BedloadSample, BedloadSequence, generate_bedload};

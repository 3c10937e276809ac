//! The bedload trackers of the MMPF+ paper (Lafaye de Micheaux, Ducottet & Frey 2018) and the
//! baselines of its Table 1, on bead detections with classes (0 black, 1 transparent):
//!
//! - **MMPF+**: one particle filter per bead with switching motion states (resting, rolling,
//!   saltating-constant, saltating-rebound; Eq. (3)), the motion state measured from contacts
//!   and speed (Eq. (4)) rewarding the particles in that state (Eq. (9)), the Gaussian
//!   position likelihood of a detection (Eq. (8)) or the detector-confidence density of the
//!   candidates when none was associated (Eq. (1)), multinomial resampling, the estimate and
//!   its motion state re-assessed (§3.5.3), survival without detection of 100 / 10 / 5 frames
//!   by state (§4.3);
//! - **MMPF**: the same without the motion-state cue and with one saltating state;
//! - **PF**: one constant-velocity particle filter with the detector confidence;
//! - **IMM**: the Kalman IMM of the three linear motions; a track ends at its first miss;
//! - **DET**: the raw detections, linked; a track ends at its first miss.
//!
//! All share the greedy association of §3.4 with the cost of Eq. (2), births from the
//! detections no tracker took (a trajectory is confirmed by its second detection) and the
//! parameters ([`BedloadTrackerParams`], a TOML file). Where the paper and the authors' code
//! differ, the paper is the default and the code an option; `docs/bedload.md` lists both.
//!
//! ```
//! use sillage_core::{Detection, FrameObservations, Point2, TrackPoint, Tracker};
//! use sillage_track::bedload::{BedloadTracker, BedloadTrackerParams};
//!
//! let mut tracker = BedloadTracker::new(&BedloadTrackerParams::default())?;
//! let mut points: Vec<TrackPoint> = Vec::new();
//! for frame in 0..6u64 {
//!     // A transparent bead rolling 4 px/frame to the left; missed at frames 3 and 4.
//!     let x = 400.0 - 4.0 * frame as f64;
//!     let detections = if (3..5).contains(&frame) {
//!         vec![]
//!     } else {
//!         vec![Detection::of_class(Point2::new(x, 200.0), 0.5, 1)]
//!     };
//!     tracker.step(&FrameObservations::from_detections(frame, &detections), &mut points)?;
//! }
//! // The states are smoothed (`smoother.lag` + `smoother.half_window` frames of delay): the
//! // last points come at the end.
//! tracker.finish(&mut points)?;
//! // One trajectory through the two missed frames, its positions estimated there.
//! assert_eq!(points.len(), 6);
//! assert!(points.iter().all(|p| p.track_id == 1));
//! assert!((points[4].pos_px.x - 384.0).abs() < 4.0);
//! # Ok::<(), sillage_core::Error>(())
//! ```

mod association;
mod confidence;
mod contacts;
mod filters;
mod params;
mod particle;
mod smoother;
mod tracker;

pub use params::{
    AssociationParams, BedloadTrackerKind, BedloadTrackerParams, ConfidenceSet, LikelihoodParams,
    ObservedVelocity, Prediction, StateParams, SurvivalParams,
};
pub use smoother::{
    CONTACT_RATIO_CAP, EmissionParams, EmissionReport, LabelledPoint, LogGaussian, MAX_LAG,
    SALTATION_PLATEAU_F, STRETCH_POINTS, SaltationRule, SmootherParams, StateEmission,
    fit_emission,
};
pub use tracker::{BedloadStats, BedloadTracker};

//! State estimation for the trackers: the particle-filter engine, its motion models, and the
//! Kalman filter and Kalman IMM.
//!
//! Roles:
//! - [`ParticleFilter`]: one target's SIR (bootstrap) filter (§3.5 of the MMPF+ paper) —
//!   structure-of-arrays [`Particles`], log-domain weights that never underflow (an all-zero
//!   set recovers to uniform and is counted), the [`ResampleScheme`]s (multinomial, the
//!   paper's; systematic; stratified; residual) behind an optional ESS trigger, weighted mean
//!   and covariance, and its own random stream `rng_stream(seed, track_id)`. A tracker drives
//!   it phase by phase ([`ParticleFilter::predict`], [`ParticleFilter::weight`] with its own
//!   log-likelihood, [`ParticleFilter::resample`]) or with [`step_all`], in parallel over
//!   targets with results identical for any thread count.
//! - [`MotionModel`]s: the bedload motions of Eq. (3) with jump-Markov switching
//!   ([`BedloadModel`]), and constant position / velocity / acceleration
//!   ([`KinematicModel`], [`Switching`]).
//! - [`ImmParticleFilter`]: the IMM particle filter of the pedestrian paper (§4): a model
//!   label per particle, model weights π (Eqs. (6)-(9)), resampling over all particles every ρ
//!   frames and per model every φ frames with at least γ particles per model (§4.4).
//! - [`KalmanFilter`] and [`KalmanImm`] over small fixed-size matrices, for the IMM baseline.
//! - [`fit_bedload`]: the transition table of Eq. (11) and the process noises of Eq. (3)
//!   learned from ground-truth trajectories with motion states (§4.3), for `sillage fit bedload`.
//!
//! ```
//! use sillage_core::{Point2, Vec2};
//! use sillage_filter::{BedloadModel, BedloadParams, FilterParams, FilterSpec, step_all};
//!
//! let model = BedloadModel::new(BedloadParams::default()).unwrap();
//! let spec = FilterSpec::new(&FilterParams::default(), 42).unwrap();
//! // Two beads detected at frame 0, each with its own filter (track ids 1 and 2).
//! let mut detections = [Point2::new(100.0, 50.0), Point2::new(300.0, 80.0)];
//! let mut filters: Vec<_> = detections
//!     .iter()
//!     .zip(1..)
//!     .map(|(&d, id)| spec.spawn(id, &model.initial_spread(d)))
//!     .collect();
//! for _frame in 1..5 {
//!     // The beads roll 2 px/frame downstream; the likelihood is Gaussian, 3 px² (Eq. (8)).
//!     detections.iter_mut().for_each(|d| *d = *d + Vec2::new(-2.0, 0.0));
//!     let summary = step_all(&mut filters, &model, |k| {
//!         let z = detections[k];
//!         move |p: sillage_filter::Particle| -(p.pos_px - z).norm().powi(2) / (2.0 * 3.0)
//!     });
//!     assert_eq!(summary.recovered, 0);
//! }
//! let estimate = filters[0].estimate();
//! assert!((estimate.mean.at(0) - 92.0).abs() < 2.0 && (estimate.mean.at(1) - 50.0).abs() < 2.0);
//! ```

pub mod fit;
pub mod imm;
pub mod kalman;
pub mod linalg;
pub mod motion;
pub mod multiple_model;
pub mod noise;
pub mod normal;
pub mod params;
pub mod particles;
pub mod resample;
pub mod switching;
pub mod weights;

mod fast_math;
mod filter;
mod lanes;
mod sums;

pub use filter::{FilterSpec, ParticleFilter, StepReport, StepSummary, step_all};
pub use fit::{
    BedloadFit, FitOptions, FitReport, StatePoint, StateTrack, apply_min_probability, fit_bedload,
};
pub use imm::KalmanImm;
pub use kalman::{KalmanFilter, LinearGaussian, PositionMeasurement};
pub use linalg::{Gaussian, Matrix, Vector};
pub use motion::MotionModel;
pub use motion::bedload::{BedloadMode, BedloadModel};
pub use motion::kinematic::{KinematicModel, Switching};
pub use motion::prior::{MotionPrior, MotionPriorParams};
pub use multiple_model::{
    CompetingMotion, ImmParticleFilter, ImmPfParams, ImmPfSpec, ImmResampling, ImmWeighting,
    linear_model,
};
pub use noise::{Gauss2, Noise2};
pub use normal::Normals;
pub use params::{
    BedloadParams, FilterParams, KinematicParams, SwitchingParams, TRANSITION_EQ11, TRANSITION_EQ12,
};
pub use particles::{Columns, InitialSpread, Particle, Particles};
pub use resample::{ResampleScheme, Resampler, Resampling};
pub use switching::TransitionTable;

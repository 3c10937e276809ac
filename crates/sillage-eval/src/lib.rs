//! Metrics as pure functions of truth and estimate: multi-object tracking metrics (CLEAR
//! MOT, Identity, HOTA), PTV recovery indexes, detection recall/precision.
//!
//! - [`mot`]: CLEAR MOT, IDF1 and HOTA equal to TrackEval and py-motmetrics
//!   ([`mot::evaluate_mot`]; see `docs/evaluation.md`).
//! - [`ptv_accuracy`]: the four accuracy indexes of the TracTrac paper (§4.1.2, Fig. 4):
//!   true and false recovery rates, mean position and displacement errors.
//! - [`detection_scores`]: recall, precision and localisation error of a detector.
//! - [`eulerian`]: tracks binned on a grid in one streaming pass — mean velocity, Reynolds
//!   stresses, turbulent kinetic energy, concentration, profiles (TracTrac §5.1).
//! - [`papers`]: each paper's own scores — MMPF+ correct tracks and motion-state F-scores,
//!   IMM-PF's VACE (SFDA, ATA, N-MODP, MOTP), SIFT-PF's ETISEO M1–M3 — on the same matching.
//!
//! Metrics only read their inputs; inputs need not be sorted.
//!
//! ```
//! use sillage_core::{Point2, TrackPoint, TruthPoint, Vec2};
//! use sillage_eval::{PtvAccuracyParams, ptv_accuracy};
//! let v = Vec2::new(3.0, 4.0);
//! let truth = [TruthPoint { frame: 1, track_id: 0, pos_px: Point2::new(10.0, 10.0), vel_px_per_frame: Some(v) }];
//! let mut estimate = TrackPoint::at(1, 42, Point2::new(10.2, 10.0));
//! estimate.vel_px_per_frame = Some(Vec2::new(3.0, 4.5));
//! let accuracy = ptv_accuracy(&truth, &[estimate], &PtvAccuracyParams::default()).unwrap();
//! assert_eq!(accuracy.true_recovery_rate, Some(1.0));
//! assert_eq!(accuracy.false_recovery_rate, Some(0.0));
//! assert!((accuracy.mean_position_error_px.unwrap() - 0.2).abs() < 1e-12);
//! println!("{accuracy}");
//! ```

pub mod detection;
pub mod eulerian;
mod matching;
pub mod mot;
pub mod papers;
pub mod ptv;
mod summary;

pub use detection::{DetectionScores, detection_scores};
pub use mot::{MotData, MotMetrics, MotParams, MotReport, evaluate_mot};
pub use ptv::{PtvAccuracy, PtvAccuracyParams, ptv_accuracy};
pub use summary::Table;

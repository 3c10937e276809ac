//! Multi-object tracking metrics as the field computes them: CLEAR MOT, Identity (IDF1)
//! and HOTA, equal to TrackEval (default) and py-motmetrics (option) to the sixth decimal.
//!
//! The flow: build a [`MotData`] from true and estimated objects (boxes, discs or points,
//! with MOTChallenge's ignore flags and distractors) and a [`Similarity`] measure, then
//! score it with [`clear_mot`], [`identity`] and [`hota`] — or all three with
//! [`evaluate_mot`]. Sequences combine as TrackEval combines them
//! ([`MotMetrics::combine`]); [`clear_events`] gives the per-frame matching (who matched
//! whom, every switch) for debugging and for metrics built on it. Conventions and their
//! sources are in `docs/evaluation.md`.
//!
//! ```
//! use sillage_core::Point2;
//! use sillage_eval::mot::{MotData, MotEstimate, MotParams, MotTruth, Shape, Similarity, TruthRole, evaluate_mot};
//!
//! let truth: Vec<MotTruth> = (0..3)
//!     .map(|frame| MotTruth { frame, id: 7, shape: Shape::Point(Point2::new(frame as f64, 0.0)), role: TruthRole::Scored })
//!     .collect();
//! // A tracker that follows the object with a 0.5 px error under id 42.
//! let estimates: Vec<MotEstimate> = truth
//!     .iter()
//!     .map(|t| MotEstimate { frame: t.frame, id: 42, shape: Shape::Point(Point2::new(t.frame as f64, 0.5)) })
//!     .collect();
//! let data = MotData::new(&truth, &estimates, Similarity::Distance { zero_distance_px: 2.0 }, None)?;
//! let metrics = evaluate_mot(&data, &MotParams::default())?;
//! assert_eq!(metrics.clear.mota, 1.0);
//! assert_eq!(metrics.identity.idf1, 1.0);
//! assert!((metrics.clear.motp - 0.75).abs() < 1e-12); // similarity 1 − 0.5 / 2
//! println!("{metrics}");
//! # Ok::<(), sillage_core::Error>(())
//! ```

pub(crate) mod assignment;
mod clear;
mod combine;
mod data;
mod hota;
mod identity;
pub(crate) mod ids;
mod match_rule;
mod params;
mod similarity;

use serde::Serialize;
use sillage_core::Result;

pub use clear::{ClearMetrics, FrameEvents, MatchEvent, clear_events, clear_mot};
pub use combine::MotReport;
pub use data::{
    DISTRACTOR_MATCH_THRESHOLD, FrameSimilarities, FrameView, MotChallengeProtocol, MotData,
    MotEstimate, MotTruth, SimilarityPair, TruthRole,
};
pub use hota::{HOTA_ALPHA_COUNT, HotaCurves, HotaMetrics, PerAlpha, hota, hota_alphas};
pub use identity::{IdentityMetrics, identity};
pub use match_rule::MatchRule;
pub use params::{MotConvention, MotParams};
pub use similarity::{Shape, Similarity, box_iou, disc_iou, distance_similarity};

/// CLEAR MOT, Identity and HOTA of one sequence (or of several combined).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MotMetrics {
    /// CLEAR MOT.
    pub clear: ClearMetrics,
    /// Identity.
    pub identity: IdentityMetrics,
    /// HOTA.
    pub hota: HotaMetrics,
}

/// Scores `data` with CLEAR MOT and Identity under `params`, and with HOTA.
pub fn evaluate_mot(data: &MotData, params: &MotParams) -> Result<MotMetrics> {
    Ok(MotMetrics {
        clear: clear_mot(data, params)?,
        identity: identity(data, params)?,
        hota: hota(data),
    })
}

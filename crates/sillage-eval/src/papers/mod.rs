//! Each paper's own evaluation, as its authors report it, built on the matching of
//! [`mot`](crate::mot) ([`MotData`](crate::mot::MotData) and
//! [`clear_events`](crate::mot::clear_events)):
//!
//! - the MMPF+ paper (Lafaye de Micheaux et al. 2018, §5.3): percentage of correct tracks,
//!   FN and FP rates ([`bedload_scores`]), and per-state precision, recall and F-score of
//!   the motion states resting, rolling, saltating ([`motion_state_scores`]);
//! - the IMM-PF paper (Madrigal & Hayet, §5.2): VACE's SFDA, ATA, N-MODP, MOTP ([`vace()`]),
//!   and TrackEval's relaxed ATA beside Kasturi et al.'s;
//! - the SIFT-PF paper (Souded et al. 2011, §3): ETISEO's M1 tracking time, M2 object ID
//!   persistence, M3 object ID confusion and their mean ([`etiseo()`]).
//!
//! The TracTrac paper's true and false recovery rates (§4.1.2) are
//! [`ptv_accuracy`](crate::ptv_accuracy). [`PaperMetrics`] gathers them all for one
//! sequence; [`PapersReport`] prints several sequences and their combination. Definitions,
//! and where they depart from the authors' code: `docs/evaluation.md`.
//!
//! ```
//! use sillage_core::Point2;
//! use sillage_eval::mot::{
//!     MotData, MotEstimate, MotParams, MotTruth, Shape, Similarity, TruthRole, clear_events,
//! };
//! use sillage_eval::papers::{bedload_scores, etiseo, vace};
//!
//! // One bead followed for four frames; the tracker misses frame 2.
//! let truth: Vec<MotTruth> = (0..4)
//!     .map(|frame| {
//!         let shape = Shape::Point(Point2::new(frame as f64, 0.0));
//!         MotTruth { frame, id: 1, shape, role: TruthRole::Scored }
//!     })
//!     .collect();
//! let estimates: Vec<MotEstimate> = truth
//!     .iter()
//!     .filter(|t| t.frame != 2)
//!     .map(|t| MotEstimate { frame: t.frame, id: 9, shape: t.shape })
//!     .collect();
//! let within_1_px = Similarity::Distance { zero_distance_px: 2.0 };
//! let data = MotData::new(&truth, &estimates, within_1_px, None)?;
//! let events = clear_events(&data, &MotParams::default())?;
//! let scores = bedload_scores(&events);
//! assert_eq!(scores.correct_tracks, 0); // 3 of 4 frames right: 75 % ≤ 95 %
//! assert_eq!(scores.false_negative_rate, 0.25);
//! assert_eq!(etiseo(&events).tracking_time, 0.75);
//! assert_eq!(vace(&data).sfda, 0.75); // FDA 1, 1, 0, 1
//! # Ok::<(), sillage_core::Error>(())
//! ```

mod bead_tracks;
mod bedload;
mod etiseo;
mod report;
mod tally;
mod vace;

pub use bead_tracks::{BEAD_IOU_THRESHOLD, BeadTrackScores, score_bead_tracks};
pub use bedload::{
    BedloadScores, MotionStateScores, StateLabel, StateScores, bedload_scores, motion_state_scores,
};
pub use etiseo::{EtiseoMetrics, etiseo};
pub use report::{PaperMetrics, PapersReport};
pub use vace::{RELAXED_OVERLAP, VaceMetrics, vace};

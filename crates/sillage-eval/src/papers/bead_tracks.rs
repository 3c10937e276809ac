//! One call that scores bead tracks as the MMPF+ paper does (§5.3): beads are discs of their
//! class's radius matched at disc IoU ≥ 0.43, then CLEAR MOT / Identity / HOTA, Table 1's
//! correct tracks and error rates, and Fig. 7's motion-state scores.

use serde::Serialize;
use sillage_core::{Result, TrackPoint};

use super::bedload::{
    BedloadScores, MotionStateScores, StateLabel, bedload_scores, motion_state_scores,
};
use crate::mot::{
    MotData, MotEstimate, MotMetrics, MotParams, MotTruth, Shape, Similarity, TruthRole,
    clear_events, evaluate_mot,
};

/// The MMPF+ paper's matching threshold on disc IoU (§5.3).
pub const BEAD_IOU_THRESHOLD: f64 = 0.43;

/// Every score of one sequence of bead tracks.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BeadTrackScores {
    /// CLEAR MOT, Identity and HOTA at disc IoU ≥ 0.43.
    pub mot: MotMetrics,
    /// Table 1: correct tracks, FN and FP rates, identity switches.
    pub table1: BedloadScores,
    /// Fig. 7: precision, recall and F-score of each motion state.
    pub states: MotionStateScores,
}

impl std::fmt::Display for BeadTrackScores {
    /// One line: Table 1's scores, IDF1, HOTA and the motion-state F-scores.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (t, clear) = (&self.table1, &self.mot.clear);
        let state_f = |i: usize| {
            self.states.by_state()[i]
                .1
                .f_score
                .map_or("–".to_string(), |v| format!("{v:.2}"))
        };
        write!(
            f,
            "correct tracks {:.1} % ({}/{}), MOTA {:.2} %, MOTP {:.2} %, FN {:.2} %, FP {:.2} %, \
             IDSW {}, IDF1 {:.3}, HOTA {:.3}, state F rest/roll/salt {}/{}/{} over {}",
            100.0 * t.correct_track_rate,
            t.correct_tracks,
            t.truth_tracks,
            100.0 * clear.mota,
            100.0 * clear.motp,
            100.0 * t.false_negative_rate,
            100.0 * t.false_positive_rate,
            t.id_switches,
            self.mot.identity.idf1,
            self.mot.hota.hota,
            state_f(0),
            state_f(1),
            state_f(2),
            self.states.evaluated,
        )
    }
}

/// Scores `tracks` against `truth` (both as points with their class and motion state; the
/// truth's `track_id` is the bead id); a bead of class `c` is a disc of radius
/// `radius_px[c]` (the last radius for classes beyond the list).
pub fn score_bead_tracks(
    truth: &[TrackPoint],
    tracks: &[TrackPoint],
    radius_px: &[f64],
) -> Result<BeadTrackScores> {
    let disc = |p: &TrackPoint| Shape::Disc {
        centre_px: p.pos_px,
        radius_px: radius_px
            .get(p.class as usize)
            .or(radius_px.last())
            .copied()
            .unwrap_or(0.0),
    };
    let true_objects: Vec<_> = truth
        .iter()
        .map(|p| MotTruth {
            frame: p.frame,
            id: p.track_id,
            shape: disc(p),
            role: TruthRole::Scored,
        })
        .collect();
    let estimates: Vec<_> = tracks
        .iter()
        .map(|p| MotEstimate {
            frame: p.frame,
            id: p.track_id,
            shape: disc(p),
        })
        .collect();
    let data = MotData::new(&true_objects, &estimates, Similarity::DiscIou, None)?;
    let params = MotParams {
        threshold: BEAD_IOU_THRESHOLD,
        ..MotParams::default()
    };
    let events = clear_events(&data, &params)?;
    let label = |p: &TrackPoint| StateLabel {
        frame: p.frame,
        id: p.track_id,
        state: p.motion_state,
    };
    let truth_labels: Vec<_> = truth.iter().map(label).collect();
    let track_labels: Vec<_> = tracks.iter().map(label).collect();
    Ok(BeadTrackScores {
        mot: evaluate_mot(&data, &params)?,
        table1: bedload_scores(&events),
        states: motion_state_scores(&events, &truth_labels, &track_labels)?,
    })
}

#[cfg(test)]
mod tests {
    use sillage_core::{MotionState, Point2};

    use super::*;

    #[test]
    fn a_perfect_tracker_scores_perfectly_and_a_shift_breaks_matching() {
        let truth: Vec<_> = (0..10)
            .flat_map(|f| {
                (0..2).map(move |b| TrackPoint {
                    class: b as u32,
                    motion_state: MotionState::Rolling,
                    ..TrackPoint::at(f, b, Point2::new(4.0 * f as f64, 40.0 * b as f64))
                })
            })
            .collect();
        let tracks: Vec<_> = truth
            .iter()
            .map(|p| TrackPoint {
                track_id: p.track_id + 10,
                ..*p
            })
            .collect();
        let s = score_bead_tracks(&truth, &tracks, &[15.0, 10.0]).unwrap();
        assert_eq!(s.mot.clear.mota, 1.0);
        assert!(
            s.to_string()
                .starts_with("correct tracks 100.0 % (2/2), MOTA 100.00 %")
        );
        assert_eq!(s.table1.correct_tracks, 2);
        assert_eq!(s.states.evaluated, 20);
        // Two radius-10 discs 9 px apart have IoU < 0.43: the transparent bead is missed.
        let shifted: Vec<_> = tracks
            .iter()
            .map(|p| TrackPoint {
                pos_px: Point2::new(p.pos_px.x + 9.0 * p.class as f64, p.pos_px.y),
                ..*p
            })
            .collect();
        let s = score_bead_tracks(&truth, &shifted, &[15.0, 10.0]).unwrap();
        assert_eq!((s.table1.false_negatives, s.table1.correct_tracks), (10, 1));
    }
}

//! The MMPF+ paper's own scores (Lafaye de Micheaux, Ducottet & Frey 2018, "Multi-model
//! particle filter-based tracking with switching dynamical state to study bedload
//! transport", §5.3, Table 1 and Fig. 7): the percentage of correct tracks, the false
//! negative and false positive rates, and the precision, recall and F-score of each motion
//! state (resting, rolling, saltating).
//!
//! Both are read off the CLEAR MOT matching ([`clear_events`](crate::mot::clear_events)),
//! which the paper uses (§5.3, ref. 6); it matches beads by disc IoU ≥ 0.43
//! ([`Similarity::DiscIou`](crate::mot::Similarity::DiscIou) with `MotParams::threshold`
//! 0.43). Table 1's MOTP and MOTA are [`ClearMetrics`](crate::mot::ClearMetrics)' `motp` and
//! `mota` of that matching.

use serde::Serialize;
use sillage_core::{Error, FrameIndex, MotionState, Result};

use super::tally::TrajectoryTally;
use crate::mot::FrameEvents;
use crate::mot::ids::IdMap;
use crate::summary::{Table, count, optional_score, score};

/// Table 1 of the MMPF+ paper, but for MOTP and MOTA: correct tracks, FN and FP rates,
/// identity switches. Of one sequence, or of several ([`BedloadScores::combine`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BedloadScores {
    /// True tracks (distinct scored true ids).
    pub truth_tracks: u64,
    /// True tracks that are correct (see [`bedload_scores`]).
    pub correct_tracks: u64,
    /// `correct_tracks / truth_tracks` (0 without tracks).
    pub correct_track_rate: f64,
    /// True objects summed over frames (CLEAR MOT's `Σ g_t`).
    pub truth_objects: u64,
    /// Missed true objects.
    pub false_negatives: u64,
    /// Unmatched estimates.
    pub false_positives: u64,
    /// Mismatches: matches whose estimate differs from the one last matched to the object.
    pub id_switches: u64,
    /// `FN / Σ g_t` (CLEAR MOT's miss ratio; 0 without truth).
    pub false_negative_rate: f64,
    /// `FP / Σ g_t` (CLEAR MOT's false positive ratio; 0 without truth).
    pub false_positive_rate: f64,
}

/// Scores the CLEAR MOT `events` of one sequence as the MMPF+ paper (§5.3).
///
/// **Correct track**: a true track is correct "on its total length if more than 95 % of it
/// has no false negatives or mismatches". Its length is the number of frames in which the
/// true object is present in the ground truth (BeadTracking's `trackInfo` length; gaps, if
/// any, do not count); a frame is faulty when the object is missed (FN) or matched through
/// an identity switch (the frame of the mismatch). The track is correct when
/// `(length − FN − IDSW) / length > 0.95`, strictly. (The authors' `RunEvaluation` counts a
/// track as correct from 97.5 %, the top bin of its histogram, though labelled "> 95 %";
/// this follows the paper.)
///
/// **FN and FP rates**: the CLEAR MOT ratios the paper cites (ref. 6): misses and false
/// positives over the true objects summed over frames, so that
/// `MOTA = 1 − FN rate − FP rate − IDSW / Σ g_t` (Table 1 adds up this way). (The authors'
/// code divides by `Σ g_t + FP + FN` instead.)
pub fn bedload_scores(events: &[FrameEvents]) -> BedloadScores {
    let tally = TrajectoryTally::new(events);
    let mut counts = BedloadCounts {
        truth_tracks: tally.truths.len() as u64,
        false_positives: tally.false_positives,
        ..BedloadCounts::default()
    };
    for t in &tally.truths {
        let faulty = (t.present - t.matched) + t.switches;
        // (length − faulty) / length > 95 % (§5.3: "more than 95%"), in integers.
        if 100 * (t.present - faulty) > 95 * t.present {
            counts.correct_tracks += 1;
        }
        counts.truth_objects += t.present;
        counts.false_negatives += t.present - t.matched;
        counts.id_switches += t.switches;
    }
    BedloadScores::from_counts(counts)
}

/// The summable counts of [`BedloadScores`].
#[derive(Debug, Clone, Copy, Default)]
struct BedloadCounts {
    truth_tracks: u64,
    correct_tracks: u64,
    truth_objects: u64,
    false_negatives: u64,
    false_positives: u64,
    id_switches: u64,
}

impl BedloadScores {
    fn from_counts(c: BedloadCounts) -> Self {
        let truth = c.truth_objects.max(1) as f64;
        Self {
            truth_tracks: c.truth_tracks,
            correct_tracks: c.correct_tracks,
            correct_track_rate: c.correct_tracks as f64 / c.truth_tracks.max(1) as f64,
            truth_objects: c.truth_objects,
            false_negatives: c.false_negatives,
            false_positives: c.false_positives,
            id_switches: c.id_switches,
            false_negative_rate: c.false_negatives as f64 / truth,
            false_positive_rate: c.false_positives as f64 / truth,
        }
    }

    /// Combines sequences: sums the counts, then recomputes the rates.
    pub fn combine(sequences: &[BedloadScores]) -> BedloadScores {
        let sum = |f: fn(&BedloadScores) -> u64| sequences.iter().map(f).sum::<u64>();
        BedloadScores::from_counts(BedloadCounts {
            truth_tracks: sum(|s| s.truth_tracks),
            correct_tracks: sum(|s| s.correct_tracks),
            truth_objects: sum(|s| s.truth_objects),
            false_negatives: sum(|s| s.false_negatives),
            false_positives: sum(|s| s.false_positives),
            id_switches: sum(|s| s.id_switches),
        })
    }

    /// The heading of its tables.
    pub(crate) fn title(&self) -> String {
        "MMPF+ paper §5.3 (rates in %; MOTP and MOTA are CLEAR MOT's)".to_owned()
    }

    /// The table columns: name and formatted value.
    pub(crate) fn columns(&self) -> Vec<(&'static str, String)> {
        vec![
            ("Correct", score(self.correct_track_rate)),
            ("FN", score(self.false_negative_rate)),
            ("FP", score(self.false_positive_rate)),
            ("IDSW", count(self.id_switches)),
            ("Tracks", count(self.truth_tracks)),
            ("CorrectTracks", count(self.correct_tracks)),
        ]
    }
}

impl std::fmt::Display for BedloadScores {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{}", self.title())?;
        Table::single(&self.columns()).fmt(f)
    }
}

/// The motion state of one object in one frame, as [`motion_state_scores`] compares them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct StateLabel {
    /// 0-based frame.
    pub frame: FrameIndex,
    /// The object's id (a true id or an estimate id).
    pub id: u64,
    /// Its motion state.
    pub state: MotionState,
}

/// Precision, recall and F-score of one motion state, over matched points.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StateScores {
    /// Matched points of this true state estimated in it.
    pub true_positives: u64,
    /// Matched points estimated in this state whose (known) true state is another.
    pub false_positives: u64,
    /// Matched points of this true state estimated in another state (or unknown).
    pub false_negatives: u64,
    /// `TP / (TP + FP)`: "the fraction of retrieved instances that are relevant" (note 4);
    /// `None` when nothing was estimated in this state.
    pub precision: Option<f64>,
    /// `TP / (TP + FN)`: "the fraction of relevant instances that are retrieved" (note 5);
    /// `None` when no matched point has this true state.
    pub recall: Option<f64>,
    /// Their harmonic mean `2 P R / (P + R)` (0 when both are 0); `None` when either is.
    pub f_score: Option<f64>,
}

impl StateScores {
    /// The scores of the state in row and column `c` of a confusion matrix (see
    /// [`MotionStateScores::confusion`]): TP its diagonal cell, FP the rest of its column, FN
    /// the rest of its row (the unknown column included).
    fn from_confusion(confusion: &[[u64; 4]; 3], c: usize) -> Self {
        let tp = confusion[c][c];
        let fp = confusion.iter().map(|row| row[c]).sum::<u64>() - tp;
        let fn_ = confusion[c].iter().sum::<u64>() - tp;
        Self::from_counts([tp, fp, fn_])
    }

    fn from_counts([tp, fp, fn_]: [u64; 3]) -> Self {
        let ratio = |den: u64| (den > 0).then(|| tp as f64 / den as f64);
        let (precision, recall) = (ratio(tp + fp), ratio(tp + fn_));
        let f_score = match (precision, recall) {
            (Some(p), Some(r)) if p + r > 0.0 => Some(2.0 * p * r / (p + r)),
            (Some(_), Some(_)) => Some(0.0),
            _ => None,
        };
        Self {
            true_positives: tp,
            false_positives: fp,
            false_negatives: fn_,
            precision,
            recall,
            f_score,
        }
    }
}

/// How well the estimated motion states agree with the true ones (MMPF+ paper §5.3,
/// "Motion state estimation", Fig. 7), per state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MotionStateScores {
    /// Matched points whose true state is known: the sample scored.
    pub evaluated: u64,
    /// Matched points whose true state is unknown (the first point of each ground-truth
    /// track), left out.
    pub unknown_truth: u64,
    /// Resting.
    pub resting: StateScores,
    /// Rolling.
    pub rolling: StateScores,
    /// Saltating.
    pub saltating: StateScores,
    /// Confusion matrix of the matched points whose true state is known (`evaluated` in
    /// all): rows are the true state (resting, rolling, saltating), columns the estimated
    /// state (resting, rolling, saltating, unknown). The per-state scores are read off it.
    pub confusion: [[u64; 4]; 3],
}

/// The three states scored, in table order (rows of the confusion matrix; its columns add
/// unknown).
const STATES: [MotionState; 3] = [
    MotionState::Resting,
    MotionState::Rolling,
    MotionState::Saltating,
];

/// Scores the estimated motion states of the points matched by CLEAR MOT (`events`, from
/// the same sequence as the labels) against the true ones (MMPF+ paper §5.3, Fig. 7).
///
/// Each matched point is one classification sample, counted in the confusion matrix by its
/// true and estimated state; for each state `c`, a sample whose true state is `c` is a true
/// positive when estimated `c` and a false negative otherwise (an estimate in no state
/// included); a sample estimated `c` whose true state is another is a false positive.
/// Samples whose true state is unknown are left out (counted in `unknown_truth`); unmatched
/// points carry no state comparison. An object without a label has an unknown state. A
/// label given twice for the same object and frame is an error.
pub fn motion_state_scores(
    events: &[FrameEvents],
    truth: &[StateLabel],
    estimates: &[StateLabel],
) -> Result<MotionStateScores> {
    let truth_states = state_index("truth", truth)?;
    let estimate_states = state_index("estimate", estimates)?;
    let state = |index: &IdMap<(FrameIndex, u64), MotionState>, frame, id| {
        index
            .get(&(frame, id))
            .copied()
            .unwrap_or(MotionState::Unknown)
    };
    let slot = |s: MotionState| STATES.iter().position(|&c| c == s);
    let mut confusion = [[0u64; 4]; 3];
    let mut unknown_truth = 0;
    for frame in events {
        for m in &frame.matches {
            let Some(t) = slot(state(&truth_states, frame.frame, m.truth_id)) else {
                unknown_truth += 1;
                continue;
            };
            let e = slot(state(&estimate_states, frame.frame, m.estimate_id));
            confusion[t][e.unwrap_or(STATES.len())] += 1;
        }
    }
    Ok(MotionStateScores::from_confusion(unknown_truth, confusion))
}

/// The labels by (frame, id); a pair given twice is an error.
fn state_index(what: &str, labels: &[StateLabel]) -> Result<IdMap<(FrameIndex, u64), MotionState>> {
    let mut index = IdMap::default();
    for l in labels {
        if index.insert((l.frame, l.id), l.state).is_some() {
            return Err(Error::input(format!(
                "{what} id {} has two motion states in frame {} (0-based); give one state per \
                 object and frame",
                l.id, l.frame
            )));
        }
    }
    Ok(index)
}

impl MotionStateScores {
    /// The scores of a confusion matrix, all derived from it.
    fn from_confusion(unknown_truth: u64, confusion: [[u64; 4]; 3]) -> Self {
        Self {
            evaluated: confusion.iter().flatten().sum(),
            unknown_truth,
            resting: StateScores::from_confusion(&confusion, 0),
            rolling: StateScores::from_confusion(&confusion, 1),
            saltating: StateScores::from_confusion(&confusion, 2),
            confusion,
        }
    }

    /// The scores of each state, in the order resting, rolling, saltating.
    pub fn by_state(&self) -> [(MotionState, &StateScores); 3] {
        [
            (MotionState::Resting, &self.resting),
            (MotionState::Rolling, &self.rolling),
            (MotionState::Saltating, &self.saltating),
        ]
    }

    /// Combines sequences: sums the confusion matrices (and the unknown truths), then
    /// recomputes the scores.
    pub fn combine(sequences: &[MotionStateScores]) -> MotionStateScores {
        let mut confusion = [[0u64; 4]; 3];
        for s in sequences {
            for (total, row) in confusion.iter_mut().zip(&s.confusion) {
                for (t, c) in total.iter_mut().zip(row) {
                    *t += c;
                }
            }
        }
        MotionStateScores::from_confusion(
            sequences.iter().map(|s| s.unknown_truth).sum(),
            confusion,
        )
    }

    /// The heading of its tables.
    pub(crate) fn title(&self) -> String {
        "Motion states, MMPF+ paper §5.3 and Fig. 7 (precision, recall, F-score in %)".to_owned()
    }

    /// The table columns: name and formatted value.
    pub(crate) fn columns(&self) -> Vec<(&'static str, String)> {
        let [rest, roll, salt] = self.by_state().map(|(_, s)| *s);
        vec![
            ("Samples", count(self.evaluated)),
            ("P(rest)", optional_score(rest.precision)),
            ("R(rest)", optional_score(rest.recall)),
            ("F(rest)", optional_score(rest.f_score)),
            ("P(roll)", optional_score(roll.precision)),
            ("R(roll)", optional_score(roll.recall)),
            ("F(roll)", optional_score(roll.f_score)),
            ("P(salt)", optional_score(salt.precision)),
            ("R(salt)", optional_score(salt.recall)),
            ("F(salt)", optional_score(salt.f_score)),
        ]
    }

    /// The heading of its confusion tables.
    pub(crate) fn confusion_title(&self) -> String {
        "Motion-state confusion (rows: true state, columns: estimated state; matched points)"
            .to_owned()
    }

    /// The column names of a confusion table after the leading ones: the estimated states.
    pub(crate) const CONFUSION_COLUMNS: [&'static str; 4] = ["rest", "roll", "salt", "unknown"];

    /// The confusion matrix as table rows: the true state's short name, then the counts of
    /// each estimated state ([`Self::CONFUSION_COLUMNS`]).
    pub(crate) fn confusion_rows(&self) -> impl Iterator<Item = Vec<String>> + '_ {
        Self::CONFUSION_COLUMNS
            .iter()
            .zip(&self.confusion)
            .map(|(name, row)| {
                std::iter::once((*name).to_owned())
                    .chain(row.iter().map(|&n| count(n)))
                    .collect()
            })
    }
}

impl std::fmt::Display for MotionStateScores {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{}", self.title())?;
        Table::single(&self.columns()).fmt(f)?;
        writeln!(f, "\n{}", self.confusion_title())?;
        let header = std::iter::once("true").chain(Self::CONFUSION_COLUMNS);
        let mut table = Table::new(header.map(str::to_owned));
        for row in self.confusion_rows() {
            table.push(row);
        }
        table.fmt(f)
    }
}

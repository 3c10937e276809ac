//! CLEAR MOT (Bernardin & Stiefelhagen, "Evaluating multiple object tracking performance:
//! the CLEAR MOT metrics", EURASIP JIVP 2008): per-frame one-to-one matching that favours
//! continuing tracks, then TP / FN / FP / IDSW / Frag / MT / PT / ML, MOTA, MODA and MOTP.
//!
//! Follows TrackEval's `metrics/clear.py` by default and py-motmetrics 1.4.0
//! (`MOTAccumulator.update`, `metrics.py`) as an option; see [`MotConvention`].

use serde::Serialize;
use sillage_core::{FrameIndex, Result};

use super::assignment::{Edge, Matcher, Objective};
use super::data::{FrameView, MotData};
use super::params::{MotConvention, MotParams};

/// Marks "none" in per-id state.
const NONE: u32 = u32::MAX;

/// TrackEval's bonus for keeping the pair of the previous frame: larger than any sum of
/// similarities in a frame's matching, so continuations are maximised first.
const CONTINUATION_BONUS: f64 = 1000.0;

/// CLEAR MOT scores of one sequence, or of several combined ([`ClearMetrics::combine`]).
///
/// Rates follow TrackEval's formulas, denominators floored at 1 (an empty sequence scores
/// 0, not NaN).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ClearMetrics {
    /// The conventions followed.
    pub convention: MotConvention,
    /// The similarity threshold of a match.
    pub threshold: f64,
    /// Matched true objects (matches and switches), summed over frames.
    pub true_positives: u64,
    /// Unmatched true objects.
    pub false_negatives: u64,
    /// Unmatched estimates.
    pub false_positives: u64,
    /// Matches whose estimate differs from the last one matched to the same true object.
    pub id_switches: u64,
    /// Interruptions of tracking (see [`MotConvention`] for the two definitions).
    pub fragmentations: u64,
    /// True objects tracked for more than 80 % of their frames (py-motmetrics: at least).
    pub mostly_tracked: u64,
    /// True objects tracked for 20 % to 80 % of their frames.
    pub partially_tracked: u64,
    /// True objects tracked for less than 20 % of their frames.
    pub mostly_lost: u64,
    /// Sum of the similarities of the true positives (TrackEval's `MOTP_sum`).
    pub similarity_sum: f64,
    /// Sum of `1 − similarity` over the true positives (py-motmetrics' distances).
    pub distance_sum: f64,
    /// `(TP − FP − IDSW) / (TP + FN)`.
    pub mota: f64,
    /// `(TP − FP) / (TP + FN)`.
    pub moda: f64,
    /// MOTP as TrackEval and MOTChallenge report it: mean similarity (IoU) of the true
    /// positives, higher is better.
    pub motp: f64,
    /// MOTP as py-motmetrics reports it: mean `1 − similarity` (`1 − IoU`) of the true
    /// positives, lower is better.
    pub motp_distance: f64,
    /// `(Σ similarity − FP − IDSW) / (TP + FN)` (TrackEval's sMOTA).
    pub smota: f64,
    /// `TP / (TP + FN)`.
    pub recall: f64,
    /// `TP / (TP + FP)`.
    pub precision: f64,
}

/// One match of a frame under CLEAR MOT.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MatchEvent {
    /// The true object's id.
    pub truth_id: u64,
    /// The estimate's id.
    pub estimate_id: u64,
    /// Their similarity.
    pub similarity: f64,
    /// For an identity switch, the estimate last matched to this true object.
    pub switched_from: Option<u64>,
}

/// What CLEAR MOT decided in one frame: who matched whom, who was missed, which estimates
/// were false positives. For debugging a tracker and for metrics built on the matching.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameEvents {
    /// 0-based frame.
    pub frame: FrameIndex,
    /// Matches (true positives), in the order of the true objects in the frame.
    pub matches: Vec<MatchEvent>,
    /// Ids of the missed true objects (false negatives).
    pub misses: Vec<u64>,
    /// Ids of the unmatched estimates (false positives).
    pub false_positives: Vec<u64>,
}

/// Scores `data` with CLEAR MOT.
pub fn clear_mot(data: &MotData, params: &MotParams) -> Result<ClearMetrics> {
    params.validate()?;
    let mut state = ClearState::new(data, params);
    for frame in data.frames() {
        state.step(&frame);
    }
    Ok(state.finish())
}

/// The CLEAR MOT matching of every frame of `data`, with ids as given (the same matching
/// [`clear_mot`] counts).
pub fn clear_events(data: &MotData, params: &MotParams) -> Result<Vec<FrameEvents>> {
    params.validate()?;
    let mut state = ClearState::new(data, params);
    let mut events = Vec::with_capacity(data.frames().len());
    let mut matched_truth = Vec::new();
    let mut matched_estimate = Vec::new();
    for frame in data.frames() {
        state.step(&frame);
        matched_truth.clear();
        matched_truth.resize(frame.truth_ids.len(), false);
        matched_estimate.clear();
        matched_estimate.resize(frame.estimate_ids.len(), false);
        let mut matches = Vec::with_capacity(state.matches.len());
        for m in &state.matches {
            matched_truth[m.truth as usize] = true;
            matched_estimate[m.estimate as usize] = true;
            matches.push(MatchEvent {
                truth_id: data.truth_label(frame.truth_ids[m.truth as usize]),
                estimate_id: data.estimate_label(frame.estimate_ids[m.estimate as usize]),
                similarity: m.similarity,
                switched_from: (m.switched_from != NONE)
                    .then(|| data.estimate_label(m.switched_from)),
            });
        }
        let unmatched = |ids: &[u32], matched: &[bool], label: &dyn Fn(u32) -> u64| -> Vec<u64> {
            ids.iter()
                .zip(matched)
                .filter(|(_, m)| !**m)
                .map(|(&id, _)| label(id))
                .collect()
        };
        events.push(FrameEvents {
            frame: frame.frame,
            matches,
            misses: unmatched(frame.truth_ids, &matched_truth, &|id| data.truth_label(id)),
            false_positives: unmatched(frame.estimate_ids, &matched_estimate, &|id| {
                data.estimate_label(id)
            }),
        });
    }
    Ok(events)
}

/// One match of a frame, by positions in the frame; `switched_from` is a dense estimate id
/// or `NONE`.
#[derive(Debug, Clone, Copy)]
struct FrameMatch {
    truth: u32,
    estimate: u32,
    similarity: f64,
    switched_from: u32,
}

/// The summable counts of [`ClearMetrics`].
#[derive(Debug, Clone, Copy, Default)]
struct ClearCounts {
    true_positives: u64,
    false_negatives: u64,
    false_positives: u64,
    id_switches: u64,
    fragmentations: u64,
    mostly_tracked: u64,
    partially_tracked: u64,
    mostly_lost: u64,
    similarity_sum: f64,
    distance_sum: f64,
}

/// The frame-by-frame CLEAR MOT matcher and its counts. All per-id state is dense over the
/// sequence's ids and touched only for the ids of the current frame, so a sequence costs
/// time linear in its rows for bounded objects per frame.
struct ClearState {
    params: MotParams,
    counts: ClearCounts,
    /// Per true id: the estimate it was last matched to, at any earlier frame.
    last_match: Vec<u32>,
    /// TrackEval: per true id, its estimate in the previous frame that had both truth and
    /// estimates; the ids set there, to reset them.
    previous_step: Vec<u32>,
    previous_step_ids: Vec<u32>,
    /// TrackEval's Frag: number of times each true id starts being tracked.
    starts: Vec<u32>,
    /// py-motmetrics' Frag: tracked in its last frame; missed since it was last tracked.
    tracked_last: Vec<bool>,
    fragment_pending: Vec<bool>,
    /// Frames where each true id is present, and where it is matched.
    truth_frames: Vec<u32>,
    matched_frames: Vec<u32>,
    /// Position in the current frame of each dense estimate id, or `NONE`.
    position_of_estimate: Vec<u32>,
    matcher: Matcher,
    edges: Vec<Edge>,
    edge_similarity: Vec<f64>,
    matched: Vec<usize>,
    truth_taken: Vec<bool>,
    estimate_taken: Vec<bool>,
    /// The matches of the last frame stepped.
    matches: Vec<FrameMatch>,
}

impl ClearState {
    fn new(data: &MotData, params: &MotParams) -> Self {
        let (truth_ids, estimate_ids) = (data.truth_id_count(), data.estimate_id_count());
        Self {
            params: *params,
            counts: ClearCounts::default(),
            last_match: vec![NONE; truth_ids],
            previous_step: vec![NONE; truth_ids],
            previous_step_ids: Vec::new(),
            starts: vec![0; truth_ids],
            tracked_last: vec![false; truth_ids],
            fragment_pending: vec![false; truth_ids],
            truth_frames: vec![0; truth_ids],
            matched_frames: vec![0; truth_ids],
            position_of_estimate: vec![NONE; estimate_ids],
            matcher: Matcher::default(),
            edges: Vec::new(),
            edge_similarity: Vec::new(),
            matched: Vec::new(),
            truth_taken: Vec::new(),
            estimate_taken: Vec::new(),
            matches: Vec::new(),
        }
    }

    /// Matches one frame into `self.matches` and updates the counts and the state.
    fn step(&mut self, frame: &FrameView<'_>) {
        self.matches.clear();
        let (n, m) = (frame.truth_ids.len(), frame.estimate_ids.len());
        for &g in frame.truth_ids {
            self.truth_frames[g as usize] += 1;
        }
        if n == 0 {
            self.counts.false_positives += m as u64;
            return;
        }
        match self.params.convention {
            MotConvention::TrackEval => {
                if m == 0 {
                    // TrackEval skips the frame: no state changes, not even the restarts.
                    self.counts.false_negatives += n as u64;
                    return;
                }
                self.match_trackeval(frame);
            }
            MotConvention::PyMotMetrics => self.match_py_motmetrics(frame),
        }
        self.record(frame);
    }

    /// TrackEval: optimal matching of `1000 · [same pair as the previous frame] + similarity`
    /// over the pairs at or above the threshold.
    fn match_trackeval(&mut self, frame: &FrameView<'_>) {
        self.edges.clear();
        self.edge_similarity.clear();
        for p in frame.pairs {
            if !self
                .params
                .convention
                .clear_allows(p.similarity, self.params.threshold)
            {
                continue;
            }
            let g = frame.truth_ids[p.truth as usize] as usize;
            let continues = self.previous_step[g] == frame.estimate_ids[p.estimate as usize];
            let bonus = if continues { CONTINUATION_BONUS } else { 0.0 };
            self.edges.push(Edge {
                row: p.truth,
                col: p.estimate,
                value: bonus + p.similarity,
            });
            self.edge_similarity.push(p.similarity);
        }
        self.solve_edges(frame, Objective::MaxWeight);
    }

    /// py-motmetrics: keep each true object's last pair when its estimate is present and the
    /// pair allowed (in the frame's truth order), then match the rest with as many pairs as
    /// possible at least total `1 − similarity`.
    fn match_py_motmetrics(&mut self, frame: &FrameView<'_>) {
        let (n, m) = (frame.truth_ids.len(), frame.estimate_ids.len());
        let threshold = self.params.threshold;
        let convention = self.params.convention;
        for (j, &t) in frame.estimate_ids.iter().enumerate() {
            self.position_of_estimate[t as usize] = j as u32;
        }
        self.truth_taken.clear();
        self.truth_taken.resize(n, false);
        self.estimate_taken.clear();
        self.estimate_taken.resize(m, false);
        for (i, &g) in frame.truth_ids.iter().enumerate() {
            let last = self.last_match[g as usize];
            if last == NONE {
                continue;
            }
            let j = self.position_of_estimate[last as usize];
            if j == NONE || self.estimate_taken[j as usize] {
                continue;
            }
            let pair = frame
                .pairs
                .binary_search_by_key(&(i as u32, j), |p| (p.truth, p.estimate))
                .ok()
                .map(|k| frame.pairs[k]);
            if let Some(p) = pair.filter(|p| convention.clear_allows(p.similarity, threshold)) {
                self.truth_taken[i] = true;
                self.estimate_taken[j as usize] = true;
                self.matches.push(FrameMatch {
                    truth: p.truth,
                    estimate: p.estimate,
                    similarity: p.similarity,
                    switched_from: NONE,
                });
            }
        }
        self.edges.clear();
        self.edge_similarity.clear();
        for p in frame.pairs {
            if self.truth_taken[p.truth as usize]
                || self.estimate_taken[p.estimate as usize]
                || !convention.clear_allows(p.similarity, threshold)
            {
                continue;
            }
            self.edges.push(Edge {
                row: p.truth,
                col: p.estimate,
                value: 1.0 - p.similarity,
            });
            self.edge_similarity.push(p.similarity);
        }
        self.solve_edges(frame, Objective::MaxPairsMinCost);
        for &t in frame.estimate_ids {
            self.position_of_estimate[t as usize] = NONE;
        }
    }

    /// Matches the candidate `edges` (similarities in `edge_similarity`) optimally under
    /// `objective` and appends the matches.
    fn solve_edges(&mut self, frame: &FrameView<'_>, objective: Objective) {
        let (n, m) = (frame.truth_ids.len(), frame.estimate_ids.len());
        self.matcher
            .solve(n, m, &self.edges, objective, &mut self.matched);
        for &k in &self.matched {
            let e = self.edges[k];
            self.matches.push(FrameMatch {
                truth: e.row,
                estimate: e.col,
                similarity: self.edge_similarity[k],
                switched_from: NONE,
            });
        }
    }

    /// Marks switches, counts the frame and updates the per-id state.
    fn record(&mut self, frame: &FrameView<'_>) {
        let (n, m) = (frame.truth_ids.len(), frame.estimate_ids.len());
        self.matches.sort_unstable_by_key(|found| found.truth);
        self.truth_taken.clear();
        self.truth_taken.resize(n, false);
        for k in 0..self.matches.len() {
            let found = self.matches[k];
            let g = frame.truth_ids[found.truth as usize] as usize;
            let t = frame.estimate_ids[found.estimate as usize];
            let last = self.last_match[g];
            if last != NONE && last != t {
                self.matches[k].switched_from = last;
                self.counts.id_switches += 1;
            }
            self.last_match[g] = t;
            self.matched_frames[g] += 1;
            self.truth_taken[found.truth as usize] = true;
            self.counts.similarity_sum += found.similarity;
            self.counts.distance_sum += 1.0 - found.similarity;
        }
        match self.params.convention {
            MotConvention::TrackEval => {
                // A match with no pair in the previous frame (re)starts tracking.
                for found in &self.matches {
                    let g = frame.truth_ids[found.truth as usize] as usize;
                    if self.previous_step[g] == NONE {
                        self.starts[g] += 1;
                    }
                }
                for &g in &self.previous_step_ids {
                    self.previous_step[g as usize] = NONE;
                }
                self.previous_step_ids.clear();
                for found in &self.matches {
                    let g = frame.truth_ids[found.truth as usize];
                    self.previous_step[g as usize] = frame.estimate_ids[found.estimate as usize];
                    self.previous_step_ids.push(g);
                }
            }
            MotConvention::PyMotMetrics => {
                for (i, &g) in frame.truth_ids.iter().enumerate() {
                    let g = g as usize;
                    if self.truth_taken[i] {
                        if self.fragment_pending[g] {
                            self.counts.fragmentations += 1;
                            self.fragment_pending[g] = false;
                        }
                        self.tracked_last[g] = true;
                    } else {
                        self.fragment_pending[g] |= self.tracked_last[g];
                        self.tracked_last[g] = false;
                    }
                }
            }
        }
        let matched = self.matches.len() as u64;
        self.counts.true_positives += matched;
        self.counts.false_negatives += n as u64 - matched;
        self.counts.false_positives += m as u64 - matched;
    }

    fn finish(mut self) -> ClearMetrics {
        let convention = self.params.convention;
        for (&present, &matched) in self.truth_frames.iter().zip(&self.matched_frames) {
            let ratio = f64::from(matched) / f64::from(present.max(1));
            let mostly_tracked = match convention {
                MotConvention::TrackEval => ratio > 0.8,
                MotConvention::PyMotMetrics => ratio >= 0.8,
            };
            if mostly_tracked {
                self.counts.mostly_tracked += 1;
            } else if ratio >= 0.2 {
                self.counts.partially_tracked += 1;
            } else {
                self.counts.mostly_lost += 1;
            }
        }
        if convention == MotConvention::TrackEval {
            self.counts.fragmentations = self
                .starts
                .iter()
                .map(|&s| u64::from(s.saturating_sub(1)))
                .sum();
        }
        ClearMetrics::from_counts(self.counts, convention, self.params.threshold)
    }
}

impl ClearMetrics {
    /// The rates from the counts (TrackEval's `_compute_final_fields`).
    fn from_counts(c: ClearCounts, convention: MotConvention, threshold: f64) -> Self {
        let (tp, fn_, fp, idsw) = (
            c.true_positives as f64,
            c.false_negatives as f64,
            c.false_positives as f64,
            c.id_switches as f64,
        );
        let truth = (tp + fn_).max(1.0);
        Self {
            convention,
            threshold,
            true_positives: c.true_positives,
            false_negatives: c.false_negatives,
            false_positives: c.false_positives,
            id_switches: c.id_switches,
            fragmentations: c.fragmentations,
            mostly_tracked: c.mostly_tracked,
            partially_tracked: c.partially_tracked,
            mostly_lost: c.mostly_lost,
            similarity_sum: c.similarity_sum,
            distance_sum: c.distance_sum,
            mota: (tp - fp - idsw) / truth,
            moda: (tp - fp) / truth,
            motp: c.similarity_sum / tp.max(1.0),
            motp_distance: c.distance_sum / tp.max(1.0),
            smota: (c.similarity_sum - fp - idsw) / truth,
            recall: tp / truth,
            precision: tp / (tp + fp).max(1.0),
        }
    }

    /// The counts, to be summed over sequences.
    fn counts(&self) -> ClearCounts {
        ClearCounts {
            true_positives: self.true_positives,
            false_negatives: self.false_negatives,
            false_positives: self.false_positives,
            id_switches: self.id_switches,
            fragmentations: self.fragmentations,
            mostly_tracked: self.mostly_tracked,
            partially_tracked: self.partially_tracked,
            mostly_lost: self.mostly_lost,
            similarity_sum: self.similarity_sum,
            distance_sum: self.distance_sum,
        }
    }

    /// Combines sequences as TrackEval's `combine_sequences` (and py-motmetrics' OVERALL):
    /// sums the counts and the similarity sums, then recomputes the rates. The convention and
    /// threshold are the first sequence's (combine results of one setting).
    pub fn combine(sequences: &[ClearMetrics]) -> ClearMetrics {
        let mut total = ClearCounts::default();
        for s in sequences {
            let c = s.counts();
            total.true_positives += c.true_positives;
            total.false_negatives += c.false_negatives;
            total.false_positives += c.false_positives;
            total.id_switches += c.id_switches;
            total.fragmentations += c.fragmentations;
            total.mostly_tracked += c.mostly_tracked;
            total.partially_tracked += c.partially_tracked;
            total.mostly_lost += c.mostly_lost;
            total.similarity_sum += c.similarity_sum;
            total.distance_sum += c.distance_sum;
        }
        let (convention, threshold) = sequences.first().map_or(
            (MotConvention::default(), MotParams::default().threshold),
            |s| (s.convention, s.threshold),
        );
        ClearMetrics::from_counts(total, convention, threshold)
    }

    /// Number of true objects (`MT + PT + ML`, MOTChallenge's "GT").
    pub fn truth_objects(&self) -> u64 {
        self.mostly_tracked + self.partially_tracked + self.mostly_lost
    }

    /// The heading of its tables.
    pub(crate) fn title(&self) -> String {
        format!(
            "CLEAR MOT ({} convention, similarity ≥ {}; scores in %)",
            self.convention.label(),
            self.threshold
        )
    }

    /// The table columns: name and formatted value.
    pub(crate) fn columns(&self) -> Vec<(&'static str, String)> {
        use crate::summary::{count, score};
        vec![
            ("MOTA", score(self.mota)),
            ("MODA", score(self.moda)),
            ("MOTP", score(self.motp)),
            ("MOTP(1-sim)", score(self.motp_distance)),
            ("sMOTA", score(self.smota)),
            ("Rcll", score(self.recall)),
            ("Prcn", score(self.precision)),
            ("TP", count(self.true_positives)),
            ("FN", count(self.false_negatives)),
            ("FP", count(self.false_positives)),
            ("IDSW", count(self.id_switches)),
            ("Frag", count(self.fragmentations)),
            ("GT", count(self.truth_objects())),
            ("MT", count(self.mostly_tracked)),
            ("PT", count(self.partially_tracked)),
            ("ML", count(self.mostly_lost)),
        ]
    }
}

impl std::fmt::Display for ClearMetrics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{}", self.title())?;
        crate::summary::Table::single(&self.columns()).fmt(f)
    }
}

//! The evaluation data of one sequence: per frame, the ids of the true and estimated
//! objects that are scored and the similarity of every overlapping pair — TrackEval's
//! "preprocessed sequence data", on which every metric is a pure function.
//!
//! Building it applies the MOTChallenge protocol: truth that is not scored (zero-marked
//! rows, non-pedestrian classes) is dropped, and estimates that match a distractor
//! (TrackEval `MotChallenge2DBox.get_preprocessed_seq_data`) are removed first.

use std::ops::Range;

use serde::{Deserialize, Serialize};
use sillage_core::{Error, FrameIndex, Result};

use super::assignment::{Edge, Matcher, Objective};
use super::ids::IdMap;
use super::similarity::{Shape, Similarity};

/// The similarity above which an estimate is taken by the distractor it overlaps: TrackEval
/// matches estimates to all truth at IoU ≥ 0.5 before scoring, whatever the metrics'
/// thresholds.
pub const DISTRACTOR_MATCH_THRESHOLD: f64 = 0.5;

/// What a true object is for the evaluation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TruthRole {
    /// Scored: a miss is a false negative.
    #[default]
    Scored,
    /// Not scored and not matched against: dropped before evaluation (MOTChallenge's
    /// zero-marked rows and classes that are neither pedestrians nor distractors). An
    /// estimate on it is a false positive, as in TrackEval.
    Skipped,
    /// Not scored, and an estimate matched to it is removed before evaluation
    /// (MOTChallenge's distractor classes: person on vehicle, static person, distractor,
    /// reflection; and non-motorised vehicle on MOT20).
    Distractor,
}

/// The MOTChallenge benchmarks' rules for turning a ground-truth row into a [`TruthRole`]
/// (TrackEval `MotChallenge2DBox`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotChallengeProtocol {
    /// 2D MOT 2015: no classes; only the consider flag counts. No distractor removal.
    #[default]
    Mot15,
    /// MOT16 and MOT17: pedestrians (class 1) with a non-zero consider flag are scored;
    /// classes 2, 7, 8, 12 are distractors; everything else is skipped.
    Mot17,
    /// MOT20: as MOT17, with non-motorised vehicles (class 6) among the distractors.
    Mot20,
}

impl MotChallengeProtocol {
    /// The role of a ground-truth row with consider flag `consider` (MOTChallenge column 7,
    /// truncated to an integer as TrackEval does: 0 means "ignore") and `class` (column 8,
    /// `None` when the file has no class column, read as pedestrian).
    pub fn truth_role(self, consider: f64, class: Option<i64>) -> TruthRole {
        let considered = consider.trunc() != 0.0;
        if self == MotChallengeProtocol::Mot15 {
            return if considered {
                TruthRole::Scored
            } else {
                TruthRole::Skipped
            };
        }
        let class = class.unwrap_or(1);
        let distractor =
            matches!(class, 2 | 7 | 8 | 12) || (self == MotChallengeProtocol::Mot20 && class == 6);
        if distractor {
            TruthRole::Distractor
        } else if class == 1 && considered {
            TruthRole::Scored
        } else {
            TruthRole::Skipped
        }
    }
}

/// One true object in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MotTruth {
    /// 0-based frame.
    pub frame: FrameIndex,
    /// Identity of the true object.
    pub id: u64,
    /// Its geometry.
    pub shape: Shape,
    /// Whether it is scored.
    pub role: TruthRole,
}

/// One estimated object (a tracker's output) in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MotEstimate {
    /// 0-based frame.
    pub frame: FrameIndex,
    /// Track identity.
    pub id: u64,
    /// Its geometry.
    pub shape: Shape,
}

/// The similarity of one true and one estimated object of a frame, by their positions in
/// the frame's [`FrameView::truth_ids`] and [`FrameView::estimate_ids`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SimilarityPair {
    /// Position of the true object in its frame.
    pub truth: u32,
    /// Position of the estimate in its frame.
    pub estimate: u32,
    /// Similarity in `(0, 1]`.
    pub similarity: f64,
}

/// One frame of [`MotData`]: dense ids (`0..truth_id_count()`, `0..estimate_id_count()`)
/// and the non-zero similarities, sorted by truth then estimate.
#[derive(Debug, Clone, Copy)]
pub struct FrameView<'a> {
    /// 0-based frame.
    pub frame: FrameIndex,
    /// Dense ids of the scored true objects.
    pub truth_ids: &'a [u32],
    /// Dense ids of the estimates.
    pub estimate_ids: &'a [u32],
    /// Every pair with similarity > 0.
    pub pairs: &'a [SimilarityPair],
}

/// A frame given by its similarity matrix, for [`MotData::from_similarities`] (the way
/// TrackEval's tests feed its metrics).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrameSimilarities {
    /// 0-based frame.
    pub frame: FrameIndex,
    /// Ids of the true objects (all scored).
    pub truth_ids: Vec<u64>,
    /// Ids of the estimates.
    pub estimate_ids: Vec<u64>,
    /// Row-major `truth × estimate` similarities in `[0, 1]`.
    pub similarity: Vec<f64>,
}

/// Where one frame's items lie in the flat arrays of [`MotData`].
#[derive(Debug, Clone)]
struct FrameSpan {
    frame: FrameIndex,
    truth: Range<usize>,
    estimates: Range<usize>,
    pairs: Range<usize>,
}

/// The evaluation data of one sequence (see the module docs); build it with
/// [`MotData::new`] or [`MotData::from_similarities`], then score it with the metrics.
///
/// Only frames with at least one scored true object or estimate are kept, in increasing
/// order: empty frames change no metric.
#[derive(Debug, Clone, Default)]
pub struct MotData {
    similarity: Option<Similarity>,
    frame_count: Option<u64>,
    frames: Vec<FrameSpan>,
    truth_ids: Vec<u32>,
    estimate_ids: Vec<u32>,
    pairs: Vec<SimilarityPair>,
    truth_labels: Vec<u64>,
    estimate_labels: Vec<u64>,
    truth_index: IdMap<u64, u32>,
    estimate_index: IdMap<u64, u32>,
    unscored_truth: usize,
    removed_estimates: usize,
}

impl MotData {
    /// Prepares `truth` and `estimates` (any order) for evaluation with the `similarity`
    /// measure: groups them by frame, drops the truth that is not scored, removes the
    /// estimates matched to distractors, and keeps every pair with similarity > 0.
    ///
    /// Errors, each naming the frame and the id: a shape the measure cannot compare or
    /// with a non-finite coordinate or negative size; an id twice in one frame; and, when
    /// `frame_count` is given (e.g. `seqLength` of `seqinfo.ini`), an object at or beyond
    /// that frame, so that a prediction longer than its sequence is reported, not dropped.
    pub fn new(
        truth: &[MotTruth],
        estimates: &[MotEstimate],
        similarity: Similarity,
        frame_count: Option<u64>,
    ) -> Result<Self> {
        similarity.validate()?;
        let truth_items = truth.iter().map(|t| (t.frame, t.id, &t.shape));
        check_objects("truth", truth_items, similarity, frame_count)?;
        let estimate_items = estimates.iter().map(|e| (e.frame, e.id, &e.shape));
        check_objects("estimate", estimate_items, similarity, frame_count)?;
        let truth_order = order_by_frame(truth.iter().map(|t| t.frame));
        let estimate_order = order_by_frame(estimates.iter().map(|e| e.frame));
        let mut data = MotData {
            similarity: Some(similarity),
            frame_count,
            ..Default::default()
        };
        let mut scratch = Scratch::default();
        let (mut t, mut e) = (0, 0);
        while t < truth_order.len() || e < estimate_order.len() {
            let frame_of_truth = truth_order.get(t).map(|&i| truth[i].frame);
            let frame_of_estimate = estimate_order.get(e).map(|&i| estimates[i].frame);
            let frame = match (frame_of_truth, frame_of_estimate) {
                (Some(a), Some(b)) => a.min(b),
                (a, b) => a.or(b).unwrap_or_default(),
            };
            let t_end = t + truth_order[t..]
                .iter()
                .take_while(|&&i| truth[i].frame == frame)
                .count();
            let e_end = e + estimate_order[e..]
                .iter()
                .take_while(|&&i| estimates[i].frame == frame)
                .count();
            let objects = FrameObjects {
                frame,
                truth,
                truth_order: &truth_order[t..t_end],
                estimates,
                estimate_order: &estimate_order[e..e_end],
            };
            data.push_objects(&objects, similarity, &mut scratch)?;
            (t, e) = (t_end, e_end);
        }
        Ok(data)
    }

    /// Builds the data from per-frame similarity matrices (every true object scored), as
    /// TrackEval's metric tests do: for hand-made cases and other matching rules. Frames may
    /// come in any order; a frame given twice, a matrix of the wrong size, a similarity
    /// outside `[0, 1]` or an id twice in a frame is an error.
    pub fn from_similarities(frames: &[FrameSimilarities]) -> Result<Self> {
        let mut order: Vec<usize> = (0..frames.len()).collect();
        order.sort_by_key(|&i| frames[i].frame);
        let mut data = MotData::default();
        let mut scratch = Scratch::default();
        for (k, &i) in order.iter().enumerate() {
            let f = &frames[i];
            if k > 0 && frames[order[k - 1]].frame == f.frame {
                return Err(Error::input(format!(
                    "frame {} is given twice; give each frame once",
                    f.frame
                )));
            }
            let (n, m) = (f.truth_ids.len(), f.estimate_ids.len());
            if f.similarity.len() != n * m {
                return Err(Error::input(format!(
                    "frame {}: {} similarities for {n} true objects × {m} estimates; give \
                     {} (row-major)",
                    f.frame,
                    f.similarity.len(),
                    n * m
                )));
            }
            if let Some(s) = f.similarity.iter().find(|s| !(0.0..=1.0).contains(*s)) {
                return Err(Error::input(format!(
                    "frame {}: similarity {s} is outside [0, 1]",
                    f.frame
                )));
            }
            check_unique(
                f.frame,
                "truth",
                f.truth_ids.iter().copied(),
                &mut scratch.ids,
            )?;
            check_unique(
                f.frame,
                "estimate",
                f.estimate_ids.iter().copied(),
                &mut scratch.ids,
            )?;
            scratch.pairs.clear();
            for (index, &s) in f.similarity.iter().enumerate() {
                if s > 0.0 {
                    scratch.pairs.push(SimilarityPair {
                        truth: (index / m) as u32,
                        estimate: (index % m) as u32,
                        similarity: s,
                    });
                }
            }
            data.push_frame(f.frame, &f.truth_ids, &f.estimate_ids, &scratch.pairs);
        }
        Ok(data)
    }

    /// Scores one frame's objects: similarity, distractor removal, then the kept frame.
    fn push_objects(
        &mut self,
        objects: &FrameObjects<'_>,
        similarity: Similarity,
        scratch: &mut Scratch,
    ) -> Result<()> {
        let frame = objects.frame;
        let truth = || objects.truth_order.iter().map(|&i| &objects.truth[i]);
        let estimates = || {
            objects
                .estimate_order
                .iter()
                .map(|&i| &objects.estimates[i])
        };
        check_unique(frame, "truth", truth().map(|t| t.id), &mut scratch.ids)?;
        check_unique(
            frame,
            "estimate",
            estimates().map(|e| e.id),
            &mut scratch.ids,
        )?;
        let (n, m) = (objects.truth_order.len(), objects.estimate_order.len());
        scratch.similarity.clear();
        for t in truth() {
            for e in estimates() {
                scratch
                    .similarity
                    .push(similarity.between(&t.shape, &e.shape));
            }
        }
        // Estimates matched to a distractor leave (TrackEval: Hungarian on IoU ≥ 0.5 − ε
        // against all truth, whatever its role).
        scratch.removed.clear();
        scratch.removed.resize(m, false);
        let role = |row: usize| objects.truth[objects.truth_order[row]].role;
        if m > 0 && (0..n).any(|i| role(i) == TruthRole::Distractor) {
            scratch.edges.clear();
            for (index, &s) in scratch.similarity.iter().enumerate() {
                if s >= DISTRACTOR_MATCH_THRESHOLD - f64::EPSILON {
                    scratch.edges.push(Edge {
                        row: (index / m) as u32,
                        col: (index % m) as u32,
                        value: s,
                    });
                }
            }
            scratch.matcher.solve(
                n,
                m,
                &scratch.edges,
                Objective::MaxWeight,
                &mut scratch.matched,
            );
            for &k in &scratch.matched {
                let edge = scratch.edges[k];
                if role(edge.row as usize) == TruthRole::Distractor {
                    scratch.removed[edge.col as usize] = true;
                }
            }
        }
        scratch.truth_labels.clear();
        scratch.estimate_labels.clear();
        scratch.pairs.clear();
        scratch.kept_estimate.clear();
        for (j, e) in estimates().enumerate() {
            scratch
                .kept_estimate
                .push(scratch.estimate_labels.len() as u32);
            if !scratch.removed[j] {
                scratch.estimate_labels.push(e.id);
            }
        }
        for (i, t) in truth().enumerate() {
            if t.role != TruthRole::Scored {
                continue;
            }
            let row = scratch.truth_labels.len() as u32;
            scratch.truth_labels.push(t.id);
            for j in 0..m {
                let s = scratch.similarity[i * m + j];
                if s > 0.0 && !scratch.removed[j] {
                    scratch.pairs.push(SimilarityPair {
                        truth: row,
                        estimate: scratch.kept_estimate[j],
                        similarity: s,
                    });
                }
            }
        }
        self.unscored_truth += n - scratch.truth_labels.len();
        self.removed_estimates += m - scratch.estimate_labels.len();
        self.push_frame(
            frame,
            &scratch.truth_labels,
            &scratch.estimate_labels,
            &scratch.pairs,
        );
        Ok(())
    }

    /// Appends a frame (ids given by label, pairs sorted by truth then estimate); empty
    /// frames are not kept.
    fn push_frame(
        &mut self,
        frame: FrameIndex,
        truth_labels: &[u64],
        estimate_labels: &[u64],
        pairs: &[SimilarityPair],
    ) {
        if truth_labels.is_empty() && estimate_labels.is_empty() {
            return;
        }
        let truth_start = self.truth_ids.len();
        for &label in truth_labels {
            let dense = dense_id(&mut self.truth_index, &mut self.truth_labels, label);
            self.truth_ids.push(dense);
        }
        let estimate_start = self.estimate_ids.len();
        for &label in estimate_labels {
            let dense = dense_id(&mut self.estimate_index, &mut self.estimate_labels, label);
            self.estimate_ids.push(dense);
        }
        let pair_start = self.pairs.len();
        self.pairs.extend_from_slice(pairs);
        self.frames.push(FrameSpan {
            frame,
            truth: truth_start..self.truth_ids.len(),
            estimates: estimate_start..self.estimate_ids.len(),
            pairs: pair_start..self.pairs.len(),
        });
    }

    /// The frames, in increasing order.
    pub fn frames(&self) -> impl ExactSizeIterator<Item = FrameView<'_>> + '_ {
        self.frames.iter().map(|span| FrameView {
            frame: span.frame,
            truth_ids: &self.truth_ids[span.truth.clone()],
            estimate_ids: &self.estimate_ids[span.estimates.clone()],
            pairs: &self.pairs[span.pairs.clone()],
        })
    }

    /// The measure the similarities come from (`None` for [`MotData::from_similarities`]).
    pub fn similarity(&self) -> Option<Similarity> {
        self.similarity
    }

    /// The sequence length given to [`MotData::new`].
    pub fn frame_count(&self) -> Option<u64> {
        self.frame_count
    }

    /// Number of distinct scored true ids (dense ids run over `0..truth_id_count()`).
    pub fn truth_id_count(&self) -> usize {
        self.truth_labels.len()
    }

    /// Number of distinct estimate ids.
    pub fn estimate_id_count(&self) -> usize {
        self.estimate_labels.len()
    }

    /// Number of scored true objects over all frames (MOTChallenge's "GT" detections).
    pub fn truth_count(&self) -> usize {
        self.truth_ids.len()
    }

    /// Number of evaluated estimates over all frames.
    pub fn estimate_count(&self) -> usize {
        self.estimate_ids.len()
    }

    /// The original id of dense truth id `dense`.
    ///
    /// # Panics
    /// When `dense >= truth_id_count()`.
    pub fn truth_label(&self, dense: u32) -> u64 {
        self.truth_labels[dense as usize]
    }

    /// The original id of dense estimate id `dense`.
    ///
    /// # Panics
    /// When `dense >= estimate_id_count()`.
    pub fn estimate_label(&self, dense: u32) -> u64 {
        self.estimate_labels[dense as usize]
    }

    /// True objects dropped because they are not scored (skipped or distractors).
    pub fn unscored_truth(&self) -> usize {
        self.unscored_truth
    }

    /// Estimates removed because they matched a distractor.
    pub fn removed_estimates(&self) -> usize {
        self.removed_estimates
    }
}

/// The objects of one frame: positions into the caller's slices.
struct FrameObjects<'a> {
    frame: FrameIndex,
    truth: &'a [MotTruth],
    truth_order: &'a [usize],
    estimates: &'a [MotEstimate],
    estimate_order: &'a [usize],
}

/// Reusable per-frame buffers of the constructors.
#[derive(Default)]
struct Scratch {
    ids: Vec<u64>,
    similarity: Vec<f64>,
    removed: Vec<bool>,
    kept_estimate: Vec<u32>,
    edges: Vec<Edge>,
    matched: Vec<usize>,
    matcher: Matcher,
    truth_labels: Vec<u64>,
    estimate_labels: Vec<u64>,
    pairs: Vec<SimilarityPair>,
}

/// The dense id of `label`, given on first sight in order of appearance (so that results do
/// not depend on how ids are numbered).
fn dense_id(index: &mut IdMap<u64, u32>, labels: &mut Vec<u64>, label: u64) -> u32 {
    *index.entry(label).or_insert_with(|| {
        labels.push(label);
        (labels.len() - 1) as u32
    })
}

/// Positions of the items sorted by frame, input order kept within a frame.
fn order_by_frame(frames: impl ExactSizeIterator<Item = FrameIndex>) -> Vec<usize> {
    let frames: Vec<FrameIndex> = frames.collect();
    let mut order: Vec<usize> = (0..frames.len()).collect();
    order.sort_by_key(|&i| frames[i]);
    order
}

/// Rejects shapes the measure cannot compare or with bad coordinates, and frames at or
/// beyond `frame_count`.
fn check_objects<'a>(
    what: &str,
    items: impl Iterator<Item = (FrameIndex, u64, &'a Shape)>,
    similarity: Similarity,
    frame_count: Option<u64>,
) -> Result<()> {
    for (frame, id, shape) in items {
        if let Some(count) = frame_count.filter(|&count| frame >= count) {
            return Err(Error::input(format!(
                "{what} id {id} is in frame {frame} (0-based; {} in 1-based files such as \
                 MOTChallenge's), beyond the sequence's {count} frames; cut the file to the \
                 sequence length or check that it belongs to this sequence",
                frame.saturating_add(1)
            )));
        }
        if let Some(defect) = shape.defect() {
            return Err(Error::input(format!(
                "{what} id {id} in frame {frame} (0-based): {defect}; fix or remove it"
            )));
        }
        if !similarity.accepts(shape) {
            return Err(Error::input(format!(
                "{what} id {id} in frame {frame} (0-based) is not a shape that {} can \
                 compare; use boxes with IoU, discs with disc IoU, or the distance",
                similarity.label()
            )));
        }
    }
    Ok(())
}

/// Rejects an id given twice in one frame (TrackEval's `_check_unique_ids`).
fn check_unique(
    frame: FrameIndex,
    what: &str,
    ids: impl Iterator<Item = u64>,
    buffer: &mut Vec<u64>,
) -> Result<()> {
    buffer.clear();
    buffer.extend(ids);
    buffer.sort_unstable();
    match buffer.windows(2).find(|w| w[0] == w[1]) {
        Some(w) => Err(Error::input(format!(
            "{what} id {} appears twice in frame {frame} (0-based); ids must be unique \
             within a frame, fix the file",
            w[0]
        ))),
        None => Ok(()),
    }
}

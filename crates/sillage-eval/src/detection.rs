//! Detection scores: recall, precision and localisation error of a detector against truth.

use std::fmt;

use serde::Serialize;
use sillage_core::{Detection, FrameIndex, Result, TruthPoint};

use crate::matching::{by_frame, check_finite, check_radius, greedy_match};
use crate::summary::{Mean, percent, px};

/// How well detections find the true points (see [`detection_scores`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DetectionScores {
    /// The matching radius used, px.
    pub max_distance_px: f64,
    /// Detections matched to a true point.
    pub true_positives: usize,
    /// Detections matched to nothing.
    pub false_positives: usize,
    /// True points matched by no detection.
    pub false_negatives: usize,
    /// `tp / (tp + fn)`; `None` without truth.
    pub recall: Option<f64>,
    /// `tp / (tp + fp)`; `None` without detections.
    pub precision: Option<f64>,
    /// Mean Euclidean localisation error of the true positives, px.
    pub mean_error_px: Option<f64>,
    /// Root-mean-square Euclidean localisation error of the true positives, px.
    pub rms_error_px: Option<f64>,
}

/// Scores `detections` (one entry per frame: its index and its detections; frames in any
/// order, a repeated frame adds to it) against the `truth` points of the same frames: per
/// frame, one-to-one greedy matching by ascending distance, pairs strictly closer than
/// `max_distance_px`. A frame with truth and no detections counts its truth as missed;
/// detections in a frame without truth are all false positives. Non-finite positions and a
/// radius that is not a finite number > 0 are rejected.
pub fn detection_scores(
    truth: &[TruthPoint],
    detections: &[(FrameIndex, Vec<Detection>)],
    max_distance_px: f64,
) -> Result<DetectionScores> {
    check_radius("max_distance_px", max_distance_px)?;
    for p in truth {
        check_finite("truth point", p.frame, p.track_id, p.pos_px)?;
    }
    for (frame, list) in detections {
        for (index, d) in list.iter().enumerate() {
            check_finite("detection", *frame, index as u64, d.pos_px)?;
        }
    }
    let estimates = detections
        .iter()
        .flat_map(|(frame, list)| list.iter().map(move |d| (*frame, d)));
    let frames = by_frame(truth.iter().map(|p| (p.frame, p)), estimates);
    let (mut error, mut squared_error) = (Mean::default(), Mean::default());
    let (mut n_truth, mut n_detections) = (0, 0);
    for pair in frames.values() {
        n_truth += pair.truth.len();
        n_detections += pair.estimates.len();
        let truth_pos: Vec<_> = pair.truth.iter().map(|p| p.pos_px).collect();
        let detection_pos: Vec<_> = pair.estimates.iter().map(|d| d.pos_px).collect();
        for m in greedy_match(&truth_pos, &detection_pos, max_distance_px) {
            error.add(m.distance);
            squared_error.add(m.distance * m.distance);
        }
    }
    let tp = error.count();
    let rate = |total: usize| (total > 0).then(|| tp as f64 / total as f64);
    Ok(DetectionScores {
        max_distance_px,
        true_positives: tp,
        false_positives: n_detections - tp,
        false_negatives: n_truth - tp,
        recall: rate(n_truth),
        precision: rate(n_detections),
        mean_error_px: error.value(),
        rms_error_px: squared_error.value().map(f64::sqrt),
    })
}

impl fmt::Display for DetectionScores {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "detections (radius {} px): recall {}, precision {} \
             (tp {}, fp {}, fn {}); localisation error mean {}, RMS {}",
            self.max_distance_px,
            percent(self.recall),
            percent(self.precision),
            self.true_positives,
            self.false_positives,
            self.false_negatives,
            px(self.mean_error_px),
            px(self.rms_error_px)
        )
    }
}

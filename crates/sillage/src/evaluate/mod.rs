//! Evaluation of trackers against ground truth, as `sillage eval mot` runs it: sequences
//! paired by name ([`pair_sequences`]), files of every supported format read into the
//! shapes a [`MatchRule`] compares ([`load_sequence`]), and CLEAR MOT, IDF1 and HOTA — with
//! the papers' own scores and the per-frame events on request — per sequence and combined
//! ([`evaluate_files`]). [`evaluate_rows`] scores data already in memory the same way.
//!
//! ```
//! use sillage::core::Point2;
//! use sillage::eval::mot::Shape;
//! use sillage::evaluate::{EvalOptions, ObjectRow, evaluate_rows};
//!
//! let truth: Vec<ObjectRow> = (0..3)
//!     .map(|frame| ObjectRow { frame, id: 7, shape: Shape::Point(Point2::new(frame as f64, 0.0)) })
//!     .collect();
//! let tracks: Vec<ObjectRow> = truth.iter().map(|t| ObjectRow { id: 42, ..*t }).collect();
//! let options = EvalOptions { rule: "dist:1".parse()?, ..EvalOptions::default() };
//! let evaluation = evaluate_rows("walk", &truth, &tracks, &options)?;
//! assert_eq!(evaluation.combined.metrics.identity.idf1, 1.0);
//! println!("{evaluation}");
//! # Ok::<(), sillage::core::Error>(())
//! ```

mod objects;
mod pairing;
mod ptv;
mod scores;
mod shapes;

use std::path::Path;

use sillage_core::{Error, FrameIndex, Result};
use sillage_eval::mot::{
    MatchRule, MotChallengeProtocol, MotConvention, MotData, MotEstimate, MotParams, MotTruth,
    Shape, TruthRole, clear_events, evaluate_mot,
};
use sillage_eval::papers::PaperMetrics;

pub use pairing::{SequencePaths, pair_sequences};
pub use ptv::ptv_accuracy_of_files;
pub use scores::{Evaluation, Scores, SequenceScores};
pub use shapes::{LoadedSequence, load_sequence, load_truth};

/// How to score: the matching rule, the ground-truth rules, whose conventions, and what to
/// add to the MOT metrics.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EvalOptions {
    /// When a prediction matches a true object (default `iou:0.5`).
    pub rule: MatchRule,
    /// MOTChallenge ground-truth rules: which rows are scored, which are distractors.
    pub protocol: MotChallengeProtocol,
    /// Whose conventions to follow where TrackEval and py-motmetrics differ.
    pub convention: MotConvention,
    /// Also score the papers' own measures (MMPF+, VACE, ETISEO).
    pub papers: bool,
    /// Keep every frame's events (for [`Evaluation::write_events`]).
    pub events: bool,
}

impl EvalOptions {
    /// The parameters of CLEAR MOT and Identity.
    pub fn params(&self) -> MotParams {
        MotParams {
            threshold: self.rule.threshold(),
            convention: self.convention,
        }
    }
}

/// Scores the predictions `pred` against the ground truth `gt` (a file, a MOTChallenge
/// sequence folder or a folder of them; predictions paired by sequence name).
pub fn evaluate_files(gt: &Path, pred: &Path, options: &EvalOptions) -> Result<Evaluation> {
    let mut sequences = Vec::new();
    for paths in pair_sequences(gt, pred)? {
        let loaded = load_sequence(&paths, options.rule, options.protocol)?;
        let (gt, pred) = (paths.gt.display(), paths.pred.display());
        let scored = score(paths.name.clone(), &loaded, options, |e| {
            Error::input(format!("cannot score {pred} against {gt}: {e}"))
        })?;
        sequences.push(SequenceScores {
            gt: Some(gt.to_string()),
            pred: Some(pred.to_string()),
            ..scored
        });
    }
    Ok(evaluation(options, sequences))
}

/// One object of a sequence held in memory: a true object or a prediction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectRow {
    /// 0-based frame.
    pub frame: FrameIndex,
    /// Object or track id.
    pub id: u64,
    /// Its point, disc or box, as the matching rule compares it.
    pub shape: Shape,
}

/// Scores the `predicted` rows against the `truth` rows of one sequence named `name` as
/// [`evaluate_files`] scores files (every true row scored, no motion states); the shapes
/// must be those the rule compares (points or boxes for `dist`, boxes for `iou`, discs for
/// `disc`).
pub fn evaluate_rows(
    name: &str,
    truth: &[ObjectRow],
    predicted: &[ObjectRow],
    options: &EvalOptions,
) -> Result<Evaluation> {
    let loaded = LoadedSequence {
        truth: truth
            .iter()
            .map(|r| MotTruth {
                frame: r.frame,
                id: r.id,
                shape: r.shape,
                role: TruthRole::Scored,
            })
            .collect(),
        estimates: predicted
            .iter()
            .map(|r| MotEstimate {
                frame: r.frame,
                id: r.id,
                shape: r.shape,
            })
            .collect(),
        frame_count: None,
        states: None,
    };
    let scored = score(name.to_owned(), &loaded, options, |e| e)?;
    Ok(evaluation(options, vec![scored]))
}

/// The evaluation of scored `sequences` under `options`.
fn evaluation(options: &EvalOptions, sequences: Vec<SequenceScores>) -> Evaluation {
    Evaluation::new(
        options.rule.to_string(),
        options.rule.similarity(),
        options.params(),
        sequences,
    )
}

/// Scores one loaded sequence named `name`; `data_error` words an error of its data.
fn score(
    name: String,
    loaded: &LoadedSequence,
    options: &EvalOptions,
    data_error: impl FnOnce(Error) -> Error,
) -> Result<SequenceScores> {
    let data = MotData::new(
        &loaded.truth,
        &loaded.estimates,
        options.rule.similarity(),
        loaded.frame_count,
    )
    .map_err(data_error)?;
    let params = options.params();
    let metrics = evaluate_mot(&data, &params)?;
    let events = if options.papers || options.events {
        clear_events(&data, &params)?
    } else {
        Vec::new()
    };
    let papers = if options.papers {
        let states = loaded
            .states
            .as_ref()
            .map(|(truth, estimates)| (truth.as_slice(), estimates.as_slice()));
        Some(PaperMetrics::new(&data, &events, states)?)
    } else {
        None
    };
    Ok(SequenceScores {
        name,
        gt: None,
        pred: None,
        scores: Scores { metrics, papers },
        events: if options.events { events } else { Vec::new() },
    })
}

#[cfg(test)]
mod tests {
    use sillage_core::BoundingBox;

    use super::*;

    /// A box row; `frame` 0-based.
    fn row(frame: u64, id: u64, left_px: f64) -> ObjectRow {
        let bounding = BoundingBox {
            left_px,
            top_px: 10.0,
            width_px: 20.0,
            height_px: 40.0,
        };
        ObjectRow {
            frame,
            id,
            shape: Shape::Box(bounding),
        }
    }

    /// `rows` as MOTChallenge lines (1-based frames).
    fn mot_text(rows: &[ObjectRow]) -> String {
        rows.iter()
            .map(|r| match r.shape {
                Shape::Box(b) => format!(
                    "{},{},{},{},{},{},1,-1,-1,-1\n",
                    r.frame + 1,
                    r.id,
                    b.left_px,
                    b.top_px,
                    b.width_px,
                    b.height_px
                ),
                _ => unreachable!("box rows only"),
            })
            .collect()
    }

    #[test]
    fn rows_in_memory_score_as_the_same_rows_in_files() {
        let truth: Vec<ObjectRow> = (0..4)
            .flat_map(|f| [row(f, 1, 5.0 * f as f64), row(f, 2, 100.0)])
            .collect();
        let predicted: Vec<ObjectRow> = (0..4)
            .flat_map(|f| [row(f, 8, 5.0 * f as f64 + 3.0), row(f, 9 + f / 2, 101.0)])
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let (gt, pred) = (dir.path().join("walk.txt"), dir.path().join("pred.txt"));
        std::fs::write(&gt, mot_text(&truth)).unwrap();
        std::fs::write(&pred, mot_text(&predicted)).unwrap();
        let options = EvalOptions {
            papers: true,
            events: true,
            ..EvalOptions::default()
        };
        let files = evaluate_files(&gt, &pred, &options).unwrap();
        let rows = evaluate_rows("walk", &truth, &predicted, &options).unwrap();
        assert_eq!(files.to_string(), rows.to_string());
        assert_eq!(files.combined.metrics, rows.combined.metrics);
        assert_eq!(files.sequences[0].events, rows.sequences[0].events);
        assert_eq!(rows.combined.metrics.clear.id_switches, 1);
        assert_eq!(
            files.sequences[0].gt.as_deref(),
            Some(&*gt.display().to_string())
        );
        assert_eq!(rows.sequences[0].gt, None);
    }

    #[test]
    fn shapes_the_rule_cannot_compare_are_refused() {
        let point = ObjectRow {
            frame: 0,
            id: 1,
            shape: Shape::Point(sillage_core::Point2::new(1.0, 2.0)),
        };
        let error = evaluate_rows("p", &[point], &[point], &EvalOptions::default()).unwrap_err();
        assert!(error.to_string().contains("frame 0"), "{error}");
    }
}

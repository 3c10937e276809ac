//! The scores of an evaluation: per sequence and combined, CLEAR MOT, Identity and HOTA and,
//! on request, the papers' own scores and the per-frame events. Serialised, they are what
//! `sillage eval mot --json` prints; displayed, its tables.

use std::fmt;
use std::path::Path;

use serde::Serialize;
use sillage_core::Result;
use sillage_eval::mot::{FrameEvents, MotMetrics, MotParams, MotReport, Similarity};
use sillage_eval::papers::{PaperMetrics, PapersReport};
use sillage_io::{MotEventKind, MotEventRow, MotEventsCsvWriter, WrittenSummary};

/// Every sequence scored and their combination.
#[derive(Debug, Clone, Serialize)]
pub struct Evaluation {
    /// The matching rule, in words (`iou:0.5 (box IoU ≥ 0.5)`).
    pub matching: String,
    /// The similarity measure.
    pub similarity: Similarity,
    /// Threshold and convention.
    pub params: MotParams,
    /// Each sequence, in pairing order.
    pub sequences: Vec<SequenceScores>,
    /// All sequences combined, as TrackEval combines them.
    pub combined: Scores,
}

/// One sequence scored.
#[derive(Debug, Clone, Serialize)]
pub struct SequenceScores {
    /// The name shown in the tables.
    pub name: String,
    /// The ground-truth file, when read from files.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gt: Option<String>,
    /// The prediction file, when read from files.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pred: Option<String>,
    /// Its scores.
    #[serde(flatten)]
    pub scores: Scores,
    /// The CLEAR MOT matching frame by frame, when asked for (`EvalOptions::events`).
    #[serde(skip)]
    pub events: Vec<FrameEvents>,
}

/// The scores of a sequence or of the combination.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Scores {
    /// CLEAR MOT, Identity and HOTA.
    pub metrics: MotMetrics,
    /// The papers' own scores, when asked for (`EvalOptions::papers`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub papers: Option<PaperMetrics>,
}

impl Evaluation {
    /// The evaluation of `sequences`, combined.
    pub(super) fn new(
        matching: String,
        similarity: Similarity,
        params: MotParams,
        sequences: Vec<SequenceScores>,
    ) -> Self {
        let report = MotReport::new(named(&sequences, |s| Some(s.metrics)));
        let papers = sequences
            .iter()
            .any(|s| s.scores.papers.is_some())
            .then(|| PapersReport::new(named(&sequences, |s| s.papers)));
        Evaluation {
            matching,
            similarity,
            params,
            sequences,
            combined: Scores {
                metrics: report.combined,
                papers: papers.map(|p| p.combined),
            },
        }
    }

    /// Writes the events of every sequence (match, switch, miss, false positive) to the CSV
    /// `path`, through a temporary file renamed at the end.
    pub fn write_events(&self, path: &Path) -> Result<WrittenSummary> {
        let mut writer = MotEventsCsvWriter::create(path)?;
        let mut rows: Vec<MotEventRow<'_>> = Vec::new();
        for s in &self.sequences {
            for frame in &s.events {
                rows.clear();
                let row = |kind, truth_id, estimate_id| MotEventRow {
                    sequence: &s.name,
                    frame: frame.frame,
                    truth_id,
                    estimate_id,
                    similarity: None,
                    kind,
                    previous_estimate_id: None,
                };
                for m in &frame.matches {
                    let kind = if m.switched_from.is_some() {
                        MotEventKind::Switch
                    } else {
                        MotEventKind::Match
                    };
                    rows.push(MotEventRow {
                        similarity: Some(m.similarity),
                        previous_estimate_id: m.switched_from,
                        ..row(kind, Some(m.truth_id), Some(m.estimate_id))
                    });
                }
                for &id in &frame.misses {
                    rows.push(row(MotEventKind::Miss, Some(id), None));
                }
                for &id in &frame.false_positives {
                    rows.push(row(MotEventKind::FalsePositive, None, Some(id)));
                }
                writer.push(&rows)?;
            }
        }
        writer.finish()
    }
}

impl fmt::Display for Evaluation {
    /// The tables of `sillage eval mot`: a row per sequence and a `COMBINED` row, for the
    /// MOT metrics and, when scored, each paper's scores.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let report = MotReport {
            sequences: named(&self.sequences, |s| Some(s.metrics)),
            combined: self.combined.metrics,
        };
        write!(
            f,
            "{} sequence(s); matching {}\n\n{report}",
            self.sequences.len(),
            self.matching
        )?;
        if let Some(combined) = self.combined.papers {
            let papers = PapersReport {
                sequences: named(&self.sequences, |s| s.papers),
                combined,
            };
            write!(f, "\n{papers}")?;
        }
        Ok(())
    }
}

/// One score of each sequence that has it, by name.
fn named<T>(
    sequences: &[SequenceScores],
    score: impl Fn(&Scores) -> Option<T>,
) -> Vec<(String, T)> {
    sequences
        .iter()
        .filter_map(|s| Some((s.name.clone(), score(&s.scores)?)))
        .collect()
}

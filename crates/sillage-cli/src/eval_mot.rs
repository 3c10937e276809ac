//! `sillage eval mot`: HOTA, CLEAR MOT and IDF1 — and with `--papers` each paper's own
//! scores — of predictions against ground truth, per sequence and combined, as tables or
//! JSON, with the per-frame events as CSV on request.

use std::io::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;
use sillage::eval::mot::{
    FrameEvents, MotData, MotMetrics, MotParams, MotReport, Similarity, clear_events, evaluate_mot,
};
use sillage::eval::papers::{PaperMetrics, PapersReport};
use sillage::io::{MotEventKind, MotEventRow, MotEventsCsvWriter};

use crate::cli::EvalMotArgs;
use crate::eval_inputs::{SequencePaths, load_sequence, pair_sequences};

/// One sequence scored.
struct Scored {
    paths: SequencePaths,
    metrics: MotMetrics,
    papers: Option<PaperMetrics>,
    /// The CLEAR MOT matching, kept for `--per-frame`.
    events: Vec<FrameEvents>,
}

/// `sillage eval mot --gt FILE_OR_DIR --pred FILE_OR_DIR`.
pub fn run(args: &EvalMotArgs) -> Result<()> {
    let params = MotParams {
        threshold: args.rule.threshold(),
        convention: args.convention.into(),
    };
    let mut scored = Vec::new();
    for paths in pair_sequences(&args.gt, &args.pred)? {
        scored.push(score(paths, args, &params)?);
    }
    let report = MotReport::new(
        scored
            .iter()
            .map(|s| (s.paths.name.clone(), s.metrics))
            .collect(),
    );
    let papers = args.papers.then(|| {
        PapersReport::new(
            scored
                .iter()
                .filter_map(|s| Some((s.paths.name.clone(), s.papers?)))
                .collect(),
        )
    });
    if let Some(path) = &args.per_frame {
        write_events(path, &scored)?;
    }
    let text = if args.json {
        let json = JsonReport {
            matching: args.rule.to_string(),
            similarity: args.rule.similarity(),
            params,
            sequences: scored
                .iter()
                .map(|s| JsonSequence {
                    name: &s.paths.name,
                    gt: s.paths.gt.display().to_string(),
                    pred: s.paths.pred.display().to_string(),
                    scores: JsonScores {
                        metrics: s.metrics,
                        papers: s.papers,
                    },
                })
                .collect(),
            combined: JsonScores {
                metrics: report.combined,
                papers: papers.as_ref().map(|p| p.combined),
            },
        };
        format!("{}\n", serde_json::to_string_pretty(&json)?)
    } else {
        let mut text = format!(
            "{} sequence(s); matching {}\n\n{report}",
            scored.len(),
            args.rule
        );
        if let Some(papers) = &papers {
            text.push_str(&format!("\n{papers}"));
        }
        text
    };
    print_stdout(&text)
}

/// Writes `text` to stdout; a reader that stops early (`| head`) is not an error.
fn print_stdout(text: &str) -> Result<()> {
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(anyhow::Error::new(e).context("cannot write to stdout"))
        }
        _ => Ok(()),
    }
}

/// Reads and scores one sequence.
fn score(paths: SequencePaths, args: &EvalMotArgs, params: &MotParams) -> Result<Scored> {
    let loaded = load_sequence(&paths, args.rule, args.protocol.into())?;
    let data = MotData::new(
        &loaded.truth,
        &loaded.estimates,
        args.rule.similarity(),
        loaded.frame_count,
    )
    .with_context(|| {
        format!(
            "cannot score {} against {}",
            paths.pred.display(),
            paths.gt.display()
        )
    })?;
    let metrics = evaluate_mot(&data, params)?;
    let events = if args.papers || args.per_frame.is_some() {
        clear_events(&data, params)?
    } else {
        Vec::new()
    };
    let papers = if args.papers {
        let states = loaded
            .states
            .as_ref()
            .map(|(truth, estimates)| (truth.as_slice(), estimates.as_slice()));
        Some(PaperMetrics::new(&data, &events, states)?)
    } else {
        None
    };
    Ok(Scored {
        paths,
        metrics,
        papers,
        events: if args.per_frame.is_some() {
            events
        } else {
            Vec::new()
        },
    })
}

/// Writes the events of every sequence to `path` (through a temporary file renamed at the
/// end).
fn write_events(path: &Path, scored: &[Scored]) -> Result<()> {
    let mut writer = MotEventsCsvWriter::create(path)?;
    let mut rows: Vec<MotEventRow<'_>> = Vec::new();
    for s in scored {
        for frame in &s.events {
            rows.clear();
            let row = |kind, truth_id, estimate_id| MotEventRow {
                sequence: &s.paths.name,
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
    let written = writer.finish()?;
    eprintln!(
        "wrote {} events to {}",
        written.rows,
        written.path.display()
    );
    Ok(())
}

/// What `--json` prints.
#[derive(Serialize)]
struct JsonReport<'a> {
    /// The `--match` rule, in words.
    matching: String,
    /// The similarity measure.
    similarity: Similarity,
    /// Threshold and convention.
    params: MotParams,
    /// Each sequence.
    sequences: Vec<JsonSequence<'a>>,
    /// All sequences combined.
    combined: JsonScores,
}

/// One sequence in `--json`.
#[derive(Serialize)]
struct JsonSequence<'a> {
    name: &'a str,
    gt: String,
    pred: String,
    #[serde(flatten)]
    scores: JsonScores,
}

/// The scores of a sequence or of the combination in `--json`.
#[derive(Serialize)]
struct JsonScores {
    metrics: MotMetrics,
    #[serde(skip_serializing_if = "Option::is_none")]
    papers: Option<PaperMetrics>,
}

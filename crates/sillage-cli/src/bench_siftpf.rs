//! `sillage bench siftpf`: the SIFT-PF paper's evaluation (§3, Tables 1 and 3) — each feature
//! selection of §3.1.1 on MOTChallenge sequences, scored by ETISEO's M1–M3 and their mean,
//! by CLEAR MOT, IDF1 and HOTA, with the tracking speed; per sequence and combined. The
//! tracker is deterministic for a seed; with `--runs N`, each score is the median over N
//! seeds, and each row says in how many of them its selection was best on M̄ (the paper's
//! ranking is only worth stating when it holds beyond the spread between seeds).

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Context, Result};
use serde::Serialize;
use sillage::core::BoundingBox;
use sillage::eval::mot::{MotMetrics, MotParams, clear_events, evaluate_mot};
use sillage::eval::papers::{EtiseoMetrics, etiseo};
use sillage::track::siftpf::FeatureSelection;

use crate::bench_sequence::{SequenceTruth, sequence_frames, sequence_name};
use crate::cli::BenchSiftpfArgs;
use crate::fit_pedestrian::median;
use crate::ground_plane::GroundPlaneFile;
use crate::track_siftpf::{SiftPfConfig, track_sequence};

/// A sequence folder, checked before any run.
struct Sequence {
    folder: PathBuf,
    name: String,
    frames: String,
    truth: SequenceTruth,
}

/// What one run (or several, combined) counts: the scores' sums and the times.
#[derive(Debug, Clone, Copy)]
struct Tally {
    frames: u64,
    tracks: usize,
    mot: MotMetrics,
    etiseo: EtiseoMetrics,
    tracking: Duration,
    total: Duration,
}

impl Tally {
    /// Several runs as one longer sequence.
    fn combine(runs: &[Tally]) -> Tally {
        let mot: Vec<MotMetrics> = runs.iter().map(|r| r.mot).collect();
        let etiseo: Vec<EtiseoMetrics> = runs.iter().map(|r| r.etiseo).collect();
        Tally {
            frames: runs.iter().map(|r| r.frames).sum(),
            tracks: runs.iter().map(|r| r.tracks).sum(),
            mot: MotMetrics::combine(&mot),
            etiseo: EtiseoMetrics::combine(&etiseo),
            tracking: runs.iter().map(|r| r.tracking).sum(),
            total: runs.iter().map(|r| r.total).sum(),
        }
    }
}

/// One row of the table: a selection on a sequence, or on all of them (`COMBINED`); one
/// run, or the medians over several.
#[derive(Debug, Clone, Serialize)]
struct Row {
    sequence: String,
    selection: &'static str,
    frames: u64,
    /// Runs (seeds) the scores are the medians of.
    runs: usize,
    /// Runs in which this selection had the highest M̄ of the selections (ties count for
    /// each).
    best_mean_in: usize,
    /// ETISEO M1, tracking time, in [0, 1].
    tracking_time: f64,
    /// ETISEO M2, object ID persistence, in [0, 1].
    id_persistence: f64,
    /// ETISEO M3, object ID confusion, in [0, 1].
    id_confusion: f64,
    /// `M̄`, the mean of M1, M2, M3.
    mean: f64,
    /// CLEAR MOT accuracy, %.
    mota: f64,
    /// Identity switches.
    id_switches: u64,
    /// Identity F1, %.
    idf1: f64,
    /// HOTA, %.
    hota: f64,
    /// Trajectories reported.
    tracks: usize,
    /// Time in the tracker per frame, ms (no decoding, no motion detection).
    tracking_ms_per_frame: f64,
    /// Frames per second, end to end (decoding, motion detection, tracking).
    fps: f64,
}

impl Row {
    fn new(sequence: &str, selection: FeatureSelection, t: &Tally) -> Self {
        let frames = t.frames.max(1) as f64;
        Row {
            sequence: sequence.to_owned(),
            selection: selection.label(),
            frames: t.frames,
            runs: 1,
            best_mean_in: 0,
            tracking_time: t.etiseo.tracking_time,
            id_persistence: t.etiseo.id_persistence,
            id_confusion: t.etiseo.id_confusion,
            mean: t.etiseo.mean,
            mota: 100.0 * t.mot.clear.mota,
            id_switches: t.mot.clear.id_switches,
            idf1: 100.0 * t.mot.identity.idf1,
            hota: 100.0 * t.mot.hota.hota,
            tracks: t.tracks,
            tracking_ms_per_frame: 1e3 * t.tracking.as_secs_f64() / frames,
            fps: frames / t.total.as_secs_f64().max(f64::MIN_POSITIVE),
        }
    }
}

/// The median of each score over `rows` (one selection on one sequence, one row a run;
/// not empty), with how often the selection was best on M̄ (`best_mean_in`, summed).
fn median_row(rows: &[Row]) -> Row {
    let med = |f: fn(&Row) -> f64| {
        let mut values: Vec<f64> = rows.iter().map(f).collect();
        median(&mut values).unwrap_or(f64::NAN)
    };
    Row {
        runs: rows.len(),
        best_mean_in: rows.iter().map(|r| r.best_mean_in).sum(),
        tracking_time: med(|r| r.tracking_time),
        id_persistence: med(|r| r.id_persistence),
        id_confusion: med(|r| r.id_confusion),
        mean: med(|r| r.mean),
        mota: med(|r| r.mota),
        id_switches: med(|r| r.id_switches as f64).round() as u64,
        idf1: med(|r| r.idf1),
        hota: med(|r| r.hota),
        tracks: med(|r| r.tracks as f64).round() as usize,
        tracking_ms_per_frame: med(|r| r.tracking_ms_per_frame),
        fps: med(|r| r.fps),
        ..rows[0].clone()
    }
}

/// Marks, in the rows of one run on one sequence (one row a selection), those with the
/// highest M̄.
fn mark_best_mean(rows: &mut [Row]) {
    let best = rows
        .iter()
        .map(|r| r.mean)
        .fold(f64::NEG_INFINITY, f64::max);
    for row in rows {
        row.best_mean_in = usize::from(row.mean == best);
    }
}

/// What `--json` prints.
#[derive(Serialize)]
struct Report {
    sequences: Vec<Row>,
    combined: Vec<Row>,
}

/// `sillage bench siftpf SEQ... [--selections ...]`.
pub fn run(args: &BenchSiftpfArgs) -> Result<()> {
    let last_seed = args.seed.checked_add(args.runs - 1).with_context(|| {
        format!(
            "--seed {} with --runs {} passes the largest seed, {}: give a smaller --seed",
            args.seed,
            args.runs,
            u64::MAX
        )
    })?;
    let config = SiftPfConfig::load(args.config.as_deref(), &args.overrides, None)?;
    let selections = args
        .selections
        .iter()
        .map(|s| FeatureSelection::parse(s))
        .collect::<sillage::core::Result<Vec<_>>>()?;
    let homography = args
        .ground_plane
        .as_deref()
        .map(GroundPlaneFile::read_homography)
        .transpose()?;
    let sequences = args
        .sequences
        .iter()
        .map(|folder| open(folder.clone()))
        .collect::<Result<Vec<_>>>()?;
    // tallies[sequence][run][selection]
    let mut tallies: Vec<Vec<Vec<Tally>>> = Vec::new();
    let mut rows = Vec::new();
    for sequence in &sequences {
        let mut of_sequence = Vec::new();
        for seed in args.seed..=last_seed {
            let mut of_run = Vec::new();
            for &selection in &selections {
                let mut config = config.clone();
                config.tracker.selection = selection;
                config.validate()?;
                let tally =
                    run_once(sequence, &config, homography, seed, args).with_context(|| {
                        format!(
                            "{} ({}, seed {seed})",
                            sequence.folder.display(),
                            selection.label()
                        )
                    })?;
                let row = Row::new(&sequence.name, selection, &tally);
                eprintln!(
                    "{} {} seed {seed}: M̄ {:.2}, MOTA {:.1} %, IDF1 {:.1} %, HOTA {:.1} %",
                    row.sequence, row.selection, row.mean, row.mota, row.idf1, row.hota
                );
                of_run.push(tally);
            }
            of_sequence.push(of_run);
        }
        rows.extend(summary_rows(&sequence.name, &selections, &of_sequence));
        tallies.push(of_sequence);
    }
    // The sequences of each run as one longer sequence.
    let combined_runs: Vec<Vec<Tally>> = (0..args.runs as usize)
        .map(|run| {
            (0..selections.len())
                .map(|k| {
                    let parts: Vec<Tally> = tallies.iter().map(|t| t[run][k]).collect();
                    Tally::combine(&parts)
                })
                .collect()
        })
        .collect();
    let combined = summary_rows("COMBINED", &selections, &combined_runs);
    let report = Report {
        sequences: rows,
        combined,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!("{}", markdown(&report));
    }
    Ok(())
}

/// One row per selection for one sequence: the medians over the runs (`runs[run][k]` is the
/// tally of `selections[k]`).
fn summary_rows(sequence: &str, selections: &[FeatureSelection], runs: &[Vec<Tally>]) -> Vec<Row> {
    let per_run: Vec<Vec<Row>> = runs
        .iter()
        .map(|of_run| {
            let mut rows: Vec<Row> = selections
                .iter()
                .zip(of_run)
                .map(|(&selection, tally)| Row::new(sequence, selection, tally))
                .collect();
            mark_best_mean(&mut rows);
            rows
        })
        .collect();
    (0..selections.len())
        .map(|k| {
            let of_selection: Vec<Row> = per_run.iter().map(|rows| rows[k].clone()).collect();
            median_row(&of_selection)
        })
        .collect()
}

/// Checks a sequence folder (frames, ground truth) and reads its truth.
fn open(folder: PathBuf) -> Result<Sequence> {
    Ok(Sequence {
        name: sequence_name(&folder),
        frames: sequence_frames(&folder)?,
        truth: SequenceTruth::load(&folder)?,
        folder,
    })
}

/// Tracks one sequence with one configuration and scores it.
fn run_once(
    sequence: &Sequence,
    config: &SiftPfConfig,
    homography: Option<sillage::core::Homography>,
    seed: u64,
    args: &BenchSiftpfArgs,
) -> Result<Tally> {
    let run = track_sequence(
        &sequence.frames,
        config,
        homography,
        seed,
        args.max_frames,
        true,
    )?;
    let boxes = run.rows.iter().filter_map(|r| {
        let bbox = BoundingBox {
            left_px: r.left_px,
            top_px: r.top_px,
            width_px: r.width_px,
            height_px: r.height_px,
        };
        Some((r.frame, r.id?, bbox))
    });
    let data = sequence.truth.data(boxes, run.frames)?;
    let params = MotParams::default();
    Ok(Tally {
        frames: run.frames,
        tracks: run.track_count(),
        mot: evaluate_mot(&data, &params)?,
        etiseo: etiseo(&clear_events(&data, &params)?),
        tracking: run.tracking,
        total: run.total,
    })
}

const HEADER: &str = "| sequence | selection | frames | M1 | M2 | M3 | M̄ | best M̄ in | MOTA % | IDF1 % | HOTA % | IDSW | tracks | tracking ms/frame | fps |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|";

fn format_row(row: &Row) -> String {
    format!(
        "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {}/{} | {:.1} | {:.1} | {:.1} | {} | {} | {:.1} | {:.1} |",
        row.sequence,
        row.selection,
        row.frames,
        row.tracking_time,
        row.id_persistence,
        row.id_confusion,
        row.mean,
        row.best_mean_in,
        row.runs,
        row.mota,
        row.idf1,
        row.hota,
        row.id_switches,
        row.tracks,
        row.tracking_ms_per_frame,
        row.fps
    )
}

fn markdown(report: &Report) -> String {
    let mut text = String::from(HEADER);
    for row in report.sequences.iter().chain(&report.combined) {
        text.push('\n');
        text.push_str(&format_row(row));
    }
    text
}

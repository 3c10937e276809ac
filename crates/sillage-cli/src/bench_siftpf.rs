//! `sillage bench siftpf`: the SIFT-PF paper's evaluation (§3, Tables 1 and 3) — each feature
//! selection of §3.1.1 on MOTChallenge sequences, scored by ETISEO's M1–M3 and their mean,
//! by CLEAR MOT, IDF1 and HOTA, with the tracking speed; per sequence and combined. One run
//! per selection: the tracker is deterministic for a seed.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Context, Result};
use serde::Serialize;
use sillage::eval::mot::{BoundingBox, MotMetrics, MotParams, clear_events, evaluate_mot};
use sillage::eval::papers::{EtiseoMetrics, etiseo};
use sillage::track::siftpf::FeatureSelection;

use crate::bench_sequence::{SequenceTruth, sequence_frames, sequence_name};
use crate::cli::BenchSiftpfArgs;
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

/// One row of the table: a selection on a sequence, or on all of them (`COMBINED`).
#[derive(Debug, Clone, Serialize)]
struct Row {
    sequence: String,
    selection: &'static str,
    frames: u64,
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

/// What `--json` prints.
#[derive(Serialize)]
struct Report {
    sequences: Vec<Row>,
    combined: Vec<Row>,
}

/// `sillage bench siftpf SEQ... [--selections ...]`.
pub fn run(args: &BenchSiftpfArgs) -> Result<()> {
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
    let mut runs: Vec<(FeatureSelection, Tally)> = Vec::new();
    let mut rows = Vec::new();
    for sequence in &sequences {
        for &selection in &selections {
            let mut config = config.clone();
            config.tracker.selection = selection;
            config.validate()?;
            let tally = run_once(sequence, &config, homography, args).with_context(|| {
                format!("{} ({})", sequence.folder.display(), selection.label())
            })?;
            let row = Row::new(&sequence.name, selection, &tally);
            eprintln!("{}", format_row(&row));
            rows.push(row);
            runs.push((selection, tally));
        }
    }
    let combined = selections
        .iter()
        .map(|&selection| {
            let of_selection: Vec<Tally> = runs
                .iter()
                .filter(|(s, _)| *s == selection)
                .map(|(_, t)| *t)
                .collect();
            Row::new("COMBINED", selection, &Tally::combine(&of_selection))
        })
        .collect();
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
    args: &BenchSiftpfArgs,
) -> Result<Tally> {
    let run = track_sequence(
        &sequence.frames,
        config,
        homography,
        args.seed,
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

const HEADER: &str = "| sequence | selection | frames | M1 | M2 | M3 | M̄ | MOTA % | IDF1 % | HOTA % | IDSW | tracks | tracking ms/frame | fps |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|";

fn format_row(row: &Row) -> String {
    format!(
        "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1} | {:.1} | {:.1} | {} | {} | {:.1} | {:.1} |",
        row.sequence,
        row.selection,
        row.frames,
        row.tracking_time,
        row.id_persistence,
        row.id_confusion,
        row.mean,
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

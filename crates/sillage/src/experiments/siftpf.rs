//! `bench siftpf`: the SIFT-PF paper's evaluation (§3, Tables 1 and 3) — each feature
//! selection of §3.1.1 on MOTChallenge sequences, scored by ETISEO's M1–M3 and their mean,
//! by CLEAR MOT, IDF1 and HOTA, with the tracking speed; per sequence and combined. The
//! tracker is deterministic for a seed; over several seeds, each score is the median, and
//! each row says in how many of them its selection was best on M̄ (the paper's ranking is
//! only worth stating when it holds beyond the spread between seeds).

use std::path::PathBuf;
use std::time::Duration;

use serde::Serialize;
use sillage_core::{Error, Homography, Result};
use sillage_eval::mot::{MotMetrics, MotParams, clear_events, evaluate_mot};
use sillage_eval::papers::{EtiseoMetrics, etiseo};
use sillage_io::FrameOptions;
use sillage_track::siftpf::FeatureSelection;

use super::median_over;
use super::sequences::{SequenceTruth, sequence_frames, sequence_name};
use crate::pedestrian::siftpf::track_siftpf;
use crate::pedestrian::{SiftPfSettings, within};
use crate::toml_config::Settings;

/// A sequence folder, checked before any run.
struct Sequence {
    folder: PathBuf,
    name: String,
    frames: String,
    truth: SequenceTruth,
}

impl Sequence {
    /// Checks a sequence folder (frames, ground truth) and reads its truth.
    fn open(folder: PathBuf) -> Result<Self> {
        Ok(Self {
            name: sequence_name(&folder),
            frames: sequence_frames(&folder)?,
            truth: SequenceTruth::load(&folder)?,
            folder,
        })
    }
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
pub struct Row {
    /// The sequence folder's name, or `COMBINED`.
    pub sequence: String,
    /// The selection's label.
    pub selection: &'static str,
    /// Frames tracked.
    pub frames: u64,
    /// Runs (seeds) the scores are the medians of.
    pub runs: usize,
    /// Runs in which this selection had the highest M̄ of the selections (ties count for
    /// each).
    pub best_mean_in: usize,
    /// ETISEO M1, tracking time, in [0, 1].
    pub tracking_time: f64,
    /// ETISEO M2, object ID persistence, in [0, 1].
    pub id_persistence: f64,
    /// ETISEO M3, object ID confusion, in [0, 1].
    pub id_confusion: f64,
    /// `M̄`, the mean of M1, M2, M3.
    pub mean: f64,
    /// CLEAR MOT accuracy, %.
    pub mota: f64,
    /// Identity switches.
    pub id_switches: u64,
    /// Identity F1, %.
    pub idf1: f64,
    /// HOTA, %.
    pub hota: f64,
    /// Trajectories reported.
    pub tracks: usize,
    /// Time in the tracker per frame, ms (no decoding, no motion detection).
    pub tracking_ms_per_frame: f64,
    /// Frames per second, end to end (decoding, motion detection, tracking).
    pub fps: f64,
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

    /// The median of each score over `rows` (one selection on one sequence, one row a run;
    /// not empty), with how often the selection was best on M̄ (`best_mean_in`, summed).
    fn median(rows: &[Row]) -> Row {
        let med = |f: fn(&Row) -> f64| median_over(rows, f);
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

/// The table: a row per selection and sequence, and per selection over all sequences.
#[derive(Debug, Serialize)]
pub struct Report {
    /// One row per sequence and selection.
    pub sequences: Vec<Row>,
    /// The sequences of each run as one longer sequence, one row per selection.
    pub combined: Vec<Row>,
}

/// What [`bench`](fn@bench) reports as it goes.
pub enum BenchProgress<'a> {
    /// A frame of a run is tracked; the number of frames the run expects, when known.
    Frame(Option<usize>),
    /// A run is done: its row and its seed.
    Run(&'a Row, u64),
}

/// The seeds `first_seed..first_seed + runs`, checked: the last must not pass `u64::MAX`.
pub fn seeds(first_seed: u64, runs: u64) -> Result<std::ops::RangeInclusive<u64>> {
    let last = first_seed.checked_add(runs - 1).ok_or_else(|| {
        Error::input(format!(
            "--seed {first_seed} with --runs {runs} passes the largest seed, {}: give a smaller \
             --seed",
            u64::MAX
        ))
    })?;
    Ok(first_seed..=last)
}

/// Every selection of `selections` on every sequence folder for every seed of `seeds`
/// (the first `max_frames` frames), scored and summarised.
pub fn bench(
    folders: &[PathBuf],
    settings: &SiftPfSettings,
    selections: &[FeatureSelection],
    homography: Option<Homography>,
    seeds: std::ops::RangeInclusive<u64>,
    max_frames: Option<usize>,
    on_progress: &mut dyn FnMut(BenchProgress),
) -> Result<Report> {
    let sequences = folders
        .iter()
        .map(|folder| Sequence::open(folder.clone()))
        .collect::<Result<Vec<_>>>()?;
    // tallies[sequence][run][selection]
    let mut tallies: Vec<Vec<Vec<Tally>>> = Vec::new();
    let mut rows = Vec::new();
    for sequence in &sequences {
        let mut of_sequence = Vec::new();
        for seed in seeds.clone() {
            let mut of_run = Vec::new();
            for &selection in selections {
                let mut settings = settings.clone();
                settings.tracker.selection = selection;
                settings.validate()?;
                let mut on_frame = |expected| on_progress(BenchProgress::Frame(expected));
                let run = RunOf {
                    sequence,
                    settings: &settings,
                    homography,
                    seed,
                    max_frames,
                };
                let tally = run.tally(&mut on_frame).map_err(|e| {
                    let what = format!(
                        "{} ({}, seed {seed})",
                        sequence.folder.display(),
                        selection.label()
                    );
                    within(what, e)
                })?;
                on_progress(BenchProgress::Run(
                    &Row::new(&sequence.name, selection, &tally),
                    seed,
                ));
                of_run.push(tally);
            }
            of_sequence.push(of_run);
        }
        rows.extend(summary_rows(&sequence.name, selections, &of_sequence));
        tallies.push(of_sequence);
    }
    // The sequences of each run as one longer sequence.
    let runs = seeds.count();
    let combined_runs: Vec<Vec<Tally>> = (0..runs)
        .map(|run| {
            (0..selections.len())
                .map(|k| {
                    let parts: Vec<Tally> = tallies.iter().map(|t| t[run][k]).collect();
                    Tally::combine(&parts)
                })
                .collect()
        })
        .collect();
    Ok(Report {
        sequences: rows,
        combined: summary_rows("COMBINED", selections, &combined_runs),
    })
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
            Row::median(&of_selection)
        })
        .collect()
}

/// One run: a sequence, a configuration, a seed.
struct RunOf<'a> {
    sequence: &'a Sequence,
    settings: &'a SiftPfSettings,
    homography: Option<Homography>,
    seed: u64,
    max_frames: Option<usize>,
}

impl RunOf<'_> {
    /// Tracks the sequence and scores it.
    fn tally(&self, on_frame: &mut dyn FnMut(Option<usize>)) -> Result<Tally> {
        let run = track_siftpf(
            &self.sequence.frames,
            self.settings,
            self.homography,
            self.seed,
            &FrameOptions {
                max_frames: self.max_frames,
                ..FrameOptions::default()
            },
            on_frame,
        )?;
        let boxes = run.estimates.iter().map(|e| (e.frame, e.id, e.bbox));
        let data = self.sequence.truth.data(boxes, run.frames)?;
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
}

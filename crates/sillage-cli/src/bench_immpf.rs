//! `sillage bench immpf`: the IMM-PF paper's evaluation (Tables 1-2) — every model
//! combination on MOTChallenge sequences, scored by VACE (SFDA, ATA, N-MODP, MOTP) and by
//! CLEAR MOT, IDF1 and HOTA, as the median over `--runs` seeds (§5: "the median over 30
//! experiments"), with the tracking time per frame.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, ensure};
use rayon::prelude::*;
use serde::Serialize;
use sillage::core::BoundingBox;
use sillage::core::{FrameIndex, Point2};
use sillage::eval::papers::vace;
use sillage::eval::{MotParams, evaluate_mot};
use sillage::filter::{MotionPrior, MotionPriorParams};
use sillage::track::immpf::{ModelName, PedestrianEstimate, PedestrianParams, PedestrianTracker};

use crate::bench_sequence::{SequenceTruth, sequence_name};
use crate::cli::{BenchImmpfArgs, TrackImmpfArgs};
use crate::fit_pedestrian::median;
use crate::pedestrian_input::{PedestrianInput, PreparedFrame, seqinfo_beside};
use crate::track_immpf::{load_params, load_scene, step};

/// The scores of one run, or their medians.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct RunScores {
    /// VACE Sequence Frame Detection Accuracy.
    pub sfda: f64,
    /// VACE Average Tracking Accuracy (Kasturi et al.: overlaps summed).
    pub ata: f64,
    /// TrackEval's relaxed ATA (frames with overlap ≥ 0.5 counted).
    pub ata_relaxed: f64,
    /// VACE normalised Multiple Object Detection Precision.
    pub n_modp: f64,
    /// VACE Multiple Object Tracking Precision.
    pub motp: f64,
    /// CLEAR MOT accuracy (IoU ≥ 0.5), %.
    pub mota: f64,
    /// Identity F1, %.
    pub idf1: f64,
    /// HOTA, %.
    pub hota: f64,
    /// Identity switches.
    pub id_switches: f64,
    /// Trajectories reported.
    pub tracks: f64,
    /// Tracking time per frame, ms (frames prepared beforehand).
    pub tracking_ms_per_frame: f64,
}

/// One row of the table: a combination on a sequence.
#[derive(Debug, Clone, Serialize)]
struct Row {
    sequence: String,
    models: String,
    runs: usize,
    median: RunScores,
}

/// One sequence, prepared once for every run.
struct Sequence {
    name: String,
    frames: Vec<PreparedFrame>,
    frame_size_px: (usize, usize),
    truth: SequenceTruth,
}

/// `sillage bench immpf SEQ... [--runs 30]`.
pub fn run(args: &BenchImmpfArgs) -> Result<()> {
    let track_args = TrackImmpfArgs {
        input: None,
        detections: None,
        size: None,
        ground_plane: args.ground_plane.clone(),
        motion_prior: args.motion_prior.clone(),
        models: None,
        out: PathBuf::new(),
        model_weights: None,
        overlay: None,
        config: args.config.clone(),
        overrides: args.overrides.clone(),
        seed: 1,
        max_frames: None,
        json: false,
    };
    let (params, motion) = load_params(&track_args)?;
    let (sizing, given_prior) =
        load_scene(args.ground_plane.as_deref(), args.motion_prior.as_deref())?;
    let combinations = args
        .models
        .iter()
        .map(|m| ModelName::parse_combination(m))
        .collect::<sillage::core::Result<Vec<_>>>()?;
    let mut rows = Vec::new();
    for folder in &args.sequences {
        let sequence = prepare(folder, args, &motion, &params)
            .with_context(|| format!("cannot prepare the sequence {}", folder.display()))?;
        eprintln!(
            "{}: {} frames prepared",
            sequence.name,
            sequence.frames.len()
        );
        let needs_prior = combinations.iter().any(|c| c.contains(&ModelName::Mp));
        let prior = match (&given_prior, needs_prior) {
            (Some(prior), _) => Some(prior.clone()),
            (None, true) => Some(self_prior(&sequence, &params, &sizing)?),
            (None, false) => None,
        };
        for models in &combinations {
            let mut params = params.clone();
            params.models = models.clone();
            let scores: Vec<RunScores> = (1..=args.runs as u64)
                .into_par_iter()
                .map(|seed| run_once(&sequence, &params, &sizing, prior.as_ref(), seed))
                .collect::<Result<_>>()?;
            let row = Row {
                sequence: sequence.name.clone(),
                models: ModelName::combination_label(models),
                runs: scores.len(),
                median: medians(&scores),
            };
            eprintln!("{}", format_row(&row));
            rows.push(row);
        }
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        println!("{}", markdown(&rows));
    }
    Ok(())
}

/// Reads and prepares one MOTChallenge sequence folder (`img1/`, `det/det.txt`,
/// `gt/gt.txt`, `seqinfo.ini`).
fn prepare(
    folder: &Path,
    args: &BenchImmpfArgs,
    motion: &sillage::detect::motion::MotionParams,
    params: &PedestrianParams,
) -> Result<Sequence> {
    let detections = folder.join("det").join("det.txt");
    let images = folder.join("img1");
    let use_images = !args.detections_only;
    ensure!(
        !use_images || images.is_dir(),
        "{} has no img1/ folder of frames; add --detections-only to track its det/det.txt",
        folder.display()
    );
    let size = seqinfo_beside(&detections)
        .and_then(|(_, info)| Some((info.image_width? as usize, info.image_height? as usize)));
    let images = images.to_string_lossy().into_owned();
    let mut input = PedestrianInput::open(
        use_images.then_some(images.as_str()),
        (args.births_from_detections || !use_images).then_some(detections.as_path()),
        size,
        motion,
        &params.appearance,
        args.max_frames,
        false,
    )?;
    let mut frames = Vec::new();
    while let Some(frame) = input.next_frame()? {
        frames.push(frame);
    }
    Ok(Sequence {
        name: sequence_name(folder),
        frames,
        frame_size_px: input.frame_size_px,
        truth: SequenceTruth::load(folder)?,
    })
}

/// The tracker's estimates of one run.
fn track(
    sequence: &Sequence,
    params: &PedestrianParams,
    sizing: &sillage::track::immpf::BoxSizing,
    prior: Option<&MotionPrior>,
    seed: u64,
) -> Result<(Vec<PedestrianEstimate>, f64)> {
    let mut tracker =
        PedestrianTracker::new(params, sizing.clone(), prior, sequence.frame_size_px, seed)?;
    let mut estimates = Vec::new();
    let started = Instant::now();
    for frame in &sequence.frames {
        step(&mut tracker, frame, &mut estimates)?;
    }
    let ms = 1e3 * started.elapsed().as_secs_f64() / sequence.frames.len().max(1) as f64;
    Ok((estimates, ms))
}

/// The motion prior learned from the sequence's own tracks by CV_CA (seed 1): no ground
/// truth involved (the paper learns it on other sequences of the same view, which we do not
/// have).
fn self_prior(
    sequence: &Sequence,
    params: &PedestrianParams,
    sizing: &sillage::track::immpf::BoxSizing,
) -> Result<MotionPrior> {
    let mut linear = params.clone();
    linear.models = vec![ModelName::Cv, ModelName::Ca];
    let (estimates, _) = track(sequence, &linear, sizing, None, 1)?;
    let mut tracks: std::collections::BTreeMap<u64, Vec<(FrameIndex, Point2)>> = Default::default();
    for e in &estimates {
        tracks
            .entry(e.track_id)
            .or_default()
            .push((e.frame, e.bbox.foot()));
    }
    let mut tracks: Vec<Vec<(FrameIndex, Point2)>> = tracks.into_values().collect();
    tracks.iter_mut().for_each(|t| t.sort_by_key(|p| p.0));
    let (w, h) = sequence.frame_size_px;
    Ok(MotionPrior::fit(
        &tracks,
        w as u32,
        h as u32,
        &MotionPriorParams::default(),
    )?)
}

/// One seeded run, scored.
fn run_once(
    sequence: &Sequence,
    params: &PedestrianParams,
    sizing: &sillage::track::immpf::BoxSizing,
    prior: Option<&MotionPrior>,
    seed: u64,
) -> Result<RunScores> {
    let (estimates, ms) = track(sequence, params, sizing, prior, seed)?;
    let boxes = estimates.iter().map(|e| {
        let bbox = BoundingBox {
            left_px: e.bbox.left_px,
            top_px: e.bbox.top_px,
            width_px: e.bbox.width_px,
            height_px: e.bbox.height_px,
        };
        (e.frame, e.track_id, bbox)
    });
    let data = sequence.truth.data(boxes, sequence.frames.len() as u64)?;
    let metrics = evaluate_mot(&data, &MotParams::default())?;
    let v = vace(&data);
    Ok(RunScores {
        sfda: v.sfda,
        ata: v.ata,
        ata_relaxed: v.ata_relaxed,
        n_modp: v.n_modp,
        motp: v.motp,
        mota: 100.0 * metrics.clear.mota,
        idf1: 100.0 * metrics.identity.idf1,
        hota: 100.0 * metrics.hota.hota,
        id_switches: metrics.clear.id_switches as f64,
        tracks: v.estimate_tracks as f64,
        tracking_ms_per_frame: ms,
    })
}

/// The median of each score over the runs.
fn medians(runs: &[RunScores]) -> RunScores {
    let of = |f: fn(&RunScores) -> f64| {
        let mut values: Vec<f64> = runs.iter().map(f).collect();
        median(&mut values).unwrap_or(f64::NAN)
    };
    RunScores {
        sfda: of(|r| r.sfda),
        ata: of(|r| r.ata),
        ata_relaxed: of(|r| r.ata_relaxed),
        n_modp: of(|r| r.n_modp),
        motp: of(|r| r.motp),
        mota: of(|r| r.mota),
        idf1: of(|r| r.idf1),
        hota: of(|r| r.hota),
        id_switches: of(|r| r.id_switches),
        tracks: of(|r| r.tracks),
        tracking_ms_per_frame: of(|r| r.tracking_ms_per_frame),
    }
}

const HEADER: &str = "| sequence | models | runs | SFDA | ATA | ATA(0.5) | N-MODP | MOTP | MOTA % | IDF1 % | HOTA % | IDSW | tracks | ms/frame |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|";

fn format_row(row: &Row) -> String {
    let m = &row.median;
    format!(
        "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1} | {:.1} | {:.1} | {:.0} | {:.0} | {:.2} |",
        row.sequence,
        row.models,
        row.runs,
        m.sfda,
        m.ata,
        m.ata_relaxed,
        m.n_modp,
        m.motp,
        m.mota,
        m.idf1,
        m.hota,
        m.id_switches,
        m.tracks,
        m.tracking_ms_per_frame
    )
}

fn markdown(rows: &[Row]) -> String {
    let mut text = String::from(HEADER);
    for row in rows {
        text.push('\n');
        text.push_str(&format_row(row));
    }
    text
}

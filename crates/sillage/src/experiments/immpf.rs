//! `bench immpf`: the IMM-PF paper's evaluation (Tables 1-2) — every model combination on
//! MOTChallenge sequences, scored by VACE (SFDA, ATA, N-MODP, MOTP) and by CLEAR MOT, IDF1
//! and HOTA, as the median over seeds (§5: "the median over 30 experiments"), with the
//! tracking time per frame.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;
use sillage_core::BoundingBox;
use sillage_core::{Error, FrameIndex, Point2, Result};
use sillage_detect::motion::MotionParams;
use sillage_eval::papers::vace;
use sillage_eval::{MotParams, evaluate_mot};
use sillage_filter::{MotionPrior, MotionPriorParams};
use sillage_io::FrameOptions;
use sillage_track::bytetrack::ByteTrackParams;
use sillage_track::immpf::{
    BoxSizing, ModelName, PedestrianEstimate, PedestrianParams, PedestrianTracker,
};
use sillage_track::sort::SortParams;

use super::median_over;
use super::sequences::{SequenceTruth, sequence_frames, sequence_name};
use crate::pedestrian::boxes::{BoxTracker, track_boxes};
use crate::pedestrian::immpf::{Scene, step};
use crate::pedestrian::input::{PedestrianInput, PreparedFrame, frame_size_beside};
use crate::pedestrian::{ImmpfSettings, within};

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

impl RunScores {
    /// The median of each score over the runs.
    pub fn medians(runs: &[RunScores]) -> RunScores {
        let of = |f: fn(&RunScores) -> f64| median_over(runs, f);
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
}

/// One row of the table: a combination on a sequence.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// The sequence folder's name.
    pub sequence: String,
    /// The combination (`CV_CA_MP`).
    pub models: String,
    /// Seeded runs.
    pub runs: usize,
    /// The median of each score over the runs.
    pub median: RunScores,
}

/// How the frames of a sequence are read.
#[derive(Debug, Clone, Copy, Default)]
pub struct BenchInput {
    /// Track `det/det.txt` alone (no frames).
    pub detections_only: bool,
    /// With frames, also read `det/det.txt` (as measurements or births, by
    /// `tracker.detection.with_frames`).
    pub with_detections: bool,
    /// Use the first N frames of each sequence.
    pub max_frames: Option<usize>,
    /// Leave out the SORT and ByteTrack rows (already benched on the same sequences).
    pub skip_baselines: bool,
}

/// What [`bench`](fn@bench) reports as it goes.
pub enum BenchProgress<'a> {
    /// A sequence is read and prepared.
    Prepared {
        /// Its name.
        sequence: &'a str,
        /// Its frames.
        frames: usize,
    },
    /// A row of the table is done.
    Row(&'a Row),
}

/// Every combination of `combinations` on every sequence folder, each row the medians over
/// the seeds `1..=runs` (run in parallel), then SORT and ByteTrack on the sequence's
/// `det/det.txt`, when it has one, over the same frames (rows `SORT`, `ByteTrack`). Without
/// a motion prior in `scene`, MP uses one learned from the sequence's own CV_CA tracks
/// (`self_prior`).
pub fn bench(
    folders: &[impl AsRef<Path>],
    input: BenchInput,
    settings: &ImmpfSettings,
    scene: &Scene,
    combinations: &[Vec<ModelName>],
    runs: usize,
    on_progress: &mut dyn FnMut(BenchProgress),
) -> Result<Vec<Row>> {
    let params = &settings.tracker;
    let motion = settings.motion_params(scene.has_ground_plane());
    let mut rows = Vec::new();
    for folder in folders {
        let folder = folder.as_ref();
        let sequence = Sequence::prepare(folder, input, &motion, params).map_err(|e| {
            within(
                format_args!("cannot prepare the sequence {}", folder.display()),
                e,
            )
        })?;
        on_progress(BenchProgress::Prepared {
            sequence: &sequence.name,
            frames: sequence.frames.len(),
        });
        let needs_prior = combinations.iter().any(|c| c.contains(&ModelName::Mp));
        let prior = match (&scene.prior, needs_prior) {
            (Some(prior), _) => Some(prior.clone()),
            (None, true) => Some(self_prior(&sequence, params, &scene.sizing)?),
            (None, false) => None,
        };
        for models in combinations {
            let mut params = params.clone();
            params.models = models.clone();
            let scores: Vec<RunScores> = (1..=runs as u64)
                .into_par_iter()
                .map(|seed| sequence.run_once(&params, &scene.sizing, prior.as_ref(), seed))
                .collect::<Result<_>>()?;
            let row = Row {
                sequence: sequence.name.clone(),
                models: ModelName::combination_label(models),
                runs: scores.len(),
                median: RunScores::medians(&scores),
            };
            on_progress(BenchProgress::Row(&row));
            rows.push(row);
        }
        let baselines = if !input.skip_baselines && folder.join("det").join("det.txt").is_file() {
            vec![
                BoxTracker::Sort(SortParams::default()),
                BoxTracker::ByteTrack(ByteTrackParams::default()),
            ]
        } else {
            Vec::new()
        };
        for baseline in baselines {
            let row = sequence.baseline(folder, baseline)?;
            on_progress(BenchProgress::Row(&row));
            rows.push(row);
        }
    }
    Ok(rows)
}

/// One sequence, prepared once for every run.
struct Sequence {
    name: String,
    frames: Vec<PreparedFrame>,
    frame_size_px: (usize, usize),
    truth: SequenceTruth,
}

impl Sequence {
    /// Reads and prepares one MOTChallenge sequence folder (`img1/` or one `video/*.mp4`,
    /// `det/det.txt`, `gt/gt.txt`, `seqinfo.ini`).
    fn prepare(
        folder: &Path,
        input: BenchInput,
        motion: &MotionParams,
        params: &PedestrianParams,
    ) -> Result<Self> {
        let detections = folder.join("det").join("det.txt");
        let use_images = !input.detections_only;
        let images = if use_images {
            Some(sequence_frames(folder).map_err(|e| {
                Error::input(format!(
                    "{e}; or add --detections-only to track its det/det.txt"
                ))
            })?)
        } else {
            None
        };
        let mut source = PedestrianInput::open(
            images.as_deref(),
            (input.with_detections || !use_images).then_some(detections.as_path()),
            frame_size_beside(&detections),
            motion,
            params,
            &FrameOptions {
                max_frames: input.max_frames,
                ..FrameOptions::default()
            },
            false,
        )?;
        let mut frames = Vec::new();
        while let Some(frame) = source.next_frame()? {
            frames.push(frame);
        }
        Ok(Self {
            name: sequence_name(folder),
            frames,
            frame_size_px: source.frame_size_px,
            truth: SequenceTruth::load(folder)?,
        })
    }

    /// The tracker's estimates of one run, and its time per frame, ms.
    fn track(
        &self,
        params: &PedestrianParams,
        sizing: &BoxSizing,
        prior: Option<&MotionPrior>,
        seed: u64,
    ) -> Result<(Vec<PedestrianEstimate>, f64)> {
        let mut tracker =
            PedestrianTracker::new(params, sizing.clone(), prior, self.frame_size_px, seed)?;
        let mut estimates = Vec::new();
        let started = Instant::now();
        for frame in &self.frames {
            step(&mut tracker, frame, &mut estimates)?;
        }
        tracker.finish(&mut estimates);
        let ms = 1e3 * started.elapsed().as_secs_f64() / self.frames.len().max(1) as f64;
        Ok((estimates, ms))
    }

    /// A box-tracking baseline on the sequence's `det/det.txt` over the same frames, scored
    /// as the runs (one row; the baselines are deterministic).
    fn baseline(&self, folder: &Path, tracker: BoxTracker) -> Result<Row> {
        let started = Instant::now();
        let rows = track_boxes(&folder.join("det").join("det.txt"), tracker, None)?;
        let ms = 1e3 * started.elapsed().as_secs_f64() / self.frames.len().max(1) as f64;
        let frames = self.frames.len() as u64;
        let boxes = rows
            .iter()
            .filter(|r| r.frame < frames)
            .filter_map(|r| r.id.map(|id| (r.frame, id, r.bbox())));
        Ok(Row {
            sequence: self.name.clone(),
            models: tracker.label().to_owned(),
            runs: 1,
            median: self.score(boxes, ms)?,
        })
    }

    /// One seeded run, scored.
    fn run_once(
        &self,
        params: &PedestrianParams,
        sizing: &BoxSizing,
        prior: Option<&MotionPrior>,
        seed: u64,
    ) -> Result<RunScores> {
        let (estimates, ms) = self.track(params, sizing, prior, seed)?;
        let boxes = estimates.iter().map(|e| {
            let bbox = BoundingBox {
                left_px: e.bbox.left_px,
                top_px: e.bbox.top_px,
                width_px: e.bbox.width_px,
                height_px: e.bbox.height_px,
            };
            (e.frame, e.track_id, bbox)
        });
        self.score(boxes, ms)
    }

    /// The scores of the boxes `(frame, track id, box)` of a run that took `ms` per frame.
    fn score(
        &self,
        boxes: impl Iterator<Item = (FrameIndex, u64, BoundingBox)>,
        ms: f64,
    ) -> Result<RunScores> {
        let data = self.truth.data(boxes, self.frames.len() as u64)?;
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
}

/// The motion prior learned from the sequence's own tracks by CV_CA (seed 1): no ground
/// truth involved (the paper learns it on other sequences of the same view, which we do not
/// have).
fn self_prior(
    sequence: &Sequence,
    params: &PedestrianParams,
    sizing: &BoxSizing,
) -> Result<MotionPrior> {
    let mut linear = params.clone();
    linear.models = vec![ModelName::Cv, ModelName::Ca];
    let (estimates, _) = sequence.track(&linear, sizing, None, 1)?;
    let mut tracks: BTreeMap<u64, Vec<(FrameIndex, Point2)>> = BTreeMap::new();
    for e in &estimates {
        tracks
            .entry(e.track_id)
            .or_default()
            .push((e.frame, e.bbox.foot()));
    }
    let mut tracks: Vec<Vec<(FrameIndex, Point2)>> = tracks.into_values().collect();
    tracks.iter_mut().for_each(|t| t.sort_by_key(|p| p.0));
    let (w, h) = sequence.frame_size_px;
    MotionPrior::fit(&tracks, w as u32, h as u32, &MotionPriorParams::default())
}

//! `track immpf`: pedestrians with one IMM particle filter each (Madrigal & Hayet), on colour
//! frames (motion blobs as births, or detections driving the trackers) or on detections
//! alone, streamed frame by frame to a callback; the rows of its MOTChallenge results and of
//! its model-weights file.

use std::io::Write as _;
use std::path::Path;
use std::time::{Duration, Instant};

use sillage_core::{Error, Result};
use sillage_filter::MotionPrior;
use sillage_io::{MotRow, PartialFile};
use sillage_track::immpf::{
    BoxSizing, ModelName, PedestrianEstimate, PedestrianFrame, PedestrianParams, PedestrianTracker,
};

use super::ground_plane::GroundPlaneFile;
use super::input::{PedestrianInput, PreparedFrame};
use super::motion_prior::read_motion_prior;
use super::within;

/// What the tracker knows of the scene before tracking: how boxes are sized and, for the MP
/// model, the learned motion prior.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Box sizes: from a ground plane, or each tracker's birth box.
    pub sizing: BoxSizing,
    /// The learned motion prior (§5.1), when given.
    pub prior: Option<MotionPrior>,
}

impl Scene {
    /// Reads the ground-plane file (box sizing) and the motion prior, when given.
    pub fn load(ground_plane: Option<&Path>, motion_prior: Option<&Path>) -> Result<Self> {
        let sizing = match ground_plane {
            Some(path) => GroundPlaneFile::read_sizing(path)?,
            None => BoxSizing::FromCandidate,
        };
        let prior = motion_prior.map(read_motion_prior).transpose()?;
        Ok(Self { sizing, prior })
    }

    /// Whether boxes are sized by a ground plane.
    pub fn has_ground_plane(&self) -> bool {
        matches!(self.sizing, BoxSizing::Ground { .. })
    }
}

/// What a run did.
#[derive(Debug, Clone, Copy)]
pub struct ImmpfSummary {
    /// Frames tracked.
    pub frames: u64,
    /// Estimates reported.
    pub rows: u64,
    /// The largest track id reported (ids count from 1).
    pub tracks: u64,
    /// Rows of `rows` interpolated over gaps (`tracker.detection.fill_gaps`), not measured.
    pub gap_rows: u64,
    /// Wall time of the whole run.
    pub total: Duration,
    /// Time in the tracker's steps.
    pub tracking: Duration,
}

/// Receives each tracked frame with the estimates its step reported.
pub type EstimateSink<'a, E> =
    dyn FnMut(&PreparedFrame, &[PedestrianEstimate]) -> Result<(), E> + 'a;

/// One run of the tracker over a [`PedestrianInput`].
pub struct ImmpfRun {
    input: PedestrianInput,
    tracker: PedestrianTracker,
}

impl ImmpfRun {
    /// A tracker with `params`, `scene` and `seed` over the frames of `input`.
    pub fn new(
        input: PedestrianInput,
        params: &PedestrianParams,
        scene: Scene,
        seed: u64,
    ) -> Result<Self> {
        let tracker = PedestrianTracker::new(
            params,
            scene.sizing,
            scene.prior.as_ref(),
            input.frame_size_px,
            seed,
        )?;
        Ok(Self { input, tracker })
    }

    /// Frames to expect, when known.
    pub fn frames_expected(&self) -> Option<usize> {
        self.input.len
    }

    /// Tracks every frame, handing each with the estimates its step reported to `on_frame`
    /// (once per frame, one frame late; the last frame with the estimates the tracker still
    /// held back too, `detection.smooth_frames`); an input without frames is an error.
    pub fn run<E: From<Error>>(
        mut self,
        on_frame: &mut EstimateSink<'_, E>,
    ) -> Result<ImmpfSummary, E> {
        let (mut frames, mut rows, mut last_id) = (0u64, 0u64, 0u64);
        let started = Instant::now();
        let mut tracking = Duration::ZERO;
        let mut hand_over = |prepared: &PreparedFrame, estimates: &[PedestrianEstimate]| {
            rows += estimates.len() as u64;
            last_id = estimates.iter().map(|e| e.track_id).fold(last_id, u64::max);
            on_frame(prepared, estimates)
        };
        let mut pending: Option<(PreparedFrame, Vec<PedestrianEstimate>)> = None;
        let mut spare = Vec::new();
        while let Some(prepared) = self.input.next_frame()? {
            let mut estimates: Vec<PedestrianEstimate> = std::mem::take(&mut spare);
            estimates.clear();
            let tick = Instant::now();
            step(&mut self.tracker, &prepared, &mut estimates)?;
            tracking += tick.elapsed();
            frames += 1;
            if let Some((done, done_estimates)) = pending.replace((prepared, estimates)) {
                hand_over(&done, &done_estimates)?;
                self.input.recycle(done);
                spare = done_estimates;
            }
        }
        let Some((last, mut estimates)) = pending else {
            return Err(Error::input("the input holds no frame").into());
        };
        self.tracker.finish(&mut estimates);
        hand_over(&last, &estimates)?;
        Ok(ImmpfSummary {
            frames,
            rows,
            tracks: last_id,
            gap_rows: self.tracker.gap_rows(),
            total: started.elapsed(),
            tracking,
        })
    }
}

/// One tracker step on a prepared frame; errors name the frame (1-based).
pub fn step(
    tracker: &mut PedestrianTracker,
    prepared: &PreparedFrame,
    out: &mut Vec<PedestrianEstimate>,
) -> Result<()> {
    let frame = PedestrianFrame {
        frame: prepared.frame,
        cues: prepared.cues.as_ref(),
        candidates: &prepared.candidates,
        candidates_are_detections: prepared.candidates_are_detections,
    };
    tracker
        .step(&frame, out)
        .map_err(|e| within(format_args!("frame {}", prepared.frame + 1), e))
}

/// Estimates as MOTChallenge result rows (confidence 1).
pub fn mot_rows(estimates: &[PedestrianEstimate]) -> Vec<MotRow> {
    estimates
        .iter()
        .map(|e| MotRow::result(e.frame, e.track_id, &e.bbox))
        .collect()
}

/// `--model-weights FILE`: `frame,id,<model>...` with πₘ per row (1-based frames), written to
/// a partial file renamed at the end.
pub struct ModelWeightsWriter {
    path: std::path::PathBuf,
    out: PartialFile,
}

impl ModelWeightsWriter {
    /// Creates the file with the header of `models`.
    pub fn create(path: &Path, models: &[ModelName]) -> Result<Self> {
        let mut writer = Self {
            path: path.to_path_buf(),
            out: PartialFile::create(path)?,
        };
        let header: Vec<&str> = models.iter().map(|m| m.label()).collect();
        writeln!(writer.out, "frame,id,{}", header.join(",")).map_err(|e| writer.error(e))?;
        Ok(writer)
    }

    /// Appends one row per estimate.
    pub fn push(&mut self, estimates: &[PedestrianEstimate]) -> Result<()> {
        let mut write = || -> std::io::Result<()> {
            for e in estimates {
                write!(self.out, "{},{}", e.frame + 1, e.track_id)?;
                for w in &e.model_weights {
                    write!(self.out, ",{w:.4}")?;
                }
                writeln!(self.out)?;
            }
            Ok(())
        };
        write().map_err(|e| self.error(e))
    }

    /// Completes the file.
    pub fn finish(self) -> Result<()> {
        self.out.commit()?;
        Ok(())
    }

    fn error(&self, cause: std::io::Error) -> Error {
        Error::io(&self.path, cause)
    }
}

//! Bedload beads (the MMPF+ paper): the bead detector built from its settings and files
//! ([`detector`]), the trajectory writers ([`output`]), the fit of the motion parameters to a
//! ground truth ([`fit`]), synthetic sequences ([`synth`]), and the five trackers of
//! `sillage_track::bedload` run over detection tables through [`crate::Pipeline`], each scored
//! against the truth as the paper scores (§5, Table 1: `sillage_eval::papers::score_bead_tracks`).

pub mod detector;
pub mod fit;
pub mod output;
pub mod run;
pub mod synth;

use std::collections::BTreeMap;
use std::path::Path;

use sillage_core::{Detection, Error, FrameIndex, Result, TrackPoint};
use sillage_eval::papers::{BeadTrackScores, score_bead_tracks};
use sillage_io::read_detections_csv;
use sillage_track::bedload::{BedloadTrackerKind, BedloadTrackerParams};

use crate::config::{PipelineConfig, TrackerConfig};
use crate::pipeline::{FrameInput, Pipeline};

/// The input of one frame: its index, its detections (with classes) and its
/// detector-confidence candidates.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BeadFrame {
    /// 0-based frame index.
    pub frame: FrameIndex,
    /// Detections of every class.
    pub detections: Vec<Detection>,
    /// Candidates of Eq. (1).
    pub candidates: Vec<Detection>,
}

impl From<BeadFrame> for FrameInput {
    fn from(bead: BeadFrame) -> Self {
        FrameInput::Detections {
            frame: bead.frame,
            detections: bead.detections,
            candidates: bead.candidates,
        }
    }
}

/// The frames of a detections table (`frame,x,y,class,score`) and, when given, of a
/// candidates table of the same layout, merged by frame in increasing order: a frame present
/// in either table is present. Errors when the detections table has no row.
pub fn read_bead_frames(detections: &Path, candidates: Option<&Path>) -> Result<Vec<BeadFrame>> {
    let mut frames: BTreeMap<FrameIndex, BeadFrame> = BTreeMap::new();
    for (frame, found) in read_detections_csv(detections)? {
        bead_frame(&mut frames, frame).detections = found;
    }
    if let Some(path) = candidates {
        for (frame, found) in read_detections_csv(path)? {
            bead_frame(&mut frames, frame).candidates = found;
        }
    }
    if frames.is_empty() {
        return Err(Error::input(format!(
            "{} holds no detection; give a file with rows `frame,x,y,class,score`",
            detections.display()
        )));
    }
    Ok(frames.into_values().collect())
}

/// The entry of `frame` in `frames`, created empty when missing.
fn bead_frame(frames: &mut BTreeMap<FrameIndex, BeadFrame>, frame: FrameIndex) -> &mut BeadFrame {
    frames.entry(frame).or_insert_with(|| BeadFrame {
        frame,
        ..BeadFrame::default()
    })
}

/// The pipeline of one bedload tracker over detections made elsewhere.
fn bedload_pipeline(params: &BedloadTrackerParams) -> Result<Pipeline> {
    Pipeline::from_config(&PipelineConfig {
        tracker: TrackerConfig::Bedload(Box::new(params.clone())),
        ..PipelineConfig::default()
    })
}

/// Runs one bedload tracker over `frames` and collects its points.
pub fn track_beads(params: &BedloadTrackerParams, frames: &[BeadFrame]) -> Result<Vec<TrackPoint>> {
    let mut points = Vec::new();
    let inputs = frames.iter().map(|frame| Ok(frame.clone().into()));
    bedload_pipeline(params)?.run_inputs(inputs, &mut points, &mut |_, _| {})?;
    Ok(points)
}

/// Table 1: every tracker of `kinds` with `params` (its `tracker` replaced), scored against
/// `truth` with discs of `params.radius_px`.
pub fn bedload_table(
    params: &BedloadTrackerParams,
    kinds: &[BedloadTrackerKind],
    frames: &[BeadFrame],
    truth: &[TrackPoint],
) -> Result<Vec<(BedloadTrackerKind, BeadTrackScores)>> {
    kinds
        .iter()
        .map(|&kind| {
            let params = BedloadTrackerParams {
                tracker: kind,
                ..params.clone()
            };
            let points = track_beads(&params, frames)?;
            Ok((kind, score_bead_tracks(truth, &points, &params.radius_px)?))
        })
        .collect()
}

/// Creates `dir` and its parents; the error names the folder.
pub(crate) fn create_folder(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::input(format!("cannot create the folder {}: {e}", dir.display())))
}

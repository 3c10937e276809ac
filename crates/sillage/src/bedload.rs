//! The bedload benchmark of the MMPF+ paper (§5, Table 1): the five trackers of
//! `sillage_track::bedload` on the same detections, each scored against the truth as the
//! paper scores (`sillage_eval::papers::score_bead_tracks`).

use sillage_core::{Detection, FrameIndex, FrameObservations, Result, TrackPoint, Tracker};
use sillage_eval::papers::{BeadTrackScores, score_bead_tracks};
use sillage_track::bedload::{BedloadTracker, BedloadTrackerKind, BedloadTrackerParams};

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

/// Runs one bedload tracker over `frames` and collects its points.
pub fn track_beads(params: &BedloadTrackerParams, frames: &[BeadFrame]) -> Result<Vec<TrackPoint>> {
    let mut tracker = BedloadTracker::new(params)?;
    let mut points = Vec::new();
    for input in frames {
        let observations = FrameObservations {
            candidates: &input.candidates,
            ..FrameObservations::from_detections(input.frame, &input.detections)
        };
        tracker.step(&observations, &mut points)?;
    }
    tracker.finish(&mut points)?;
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

//! The MMPF+ paper's evaluation (§5): Table 1 (the five bedload trackers on the same
//! detections, scored against the truth) and the τ_t sweep of Fig. 6 (correct tracks and MOTA
//! of transparent beads against the detector threshold), on the [`sequences`]; the
//! [`figures`] 6 and 7 drawn from the rows; and the [`demo`] (a rendered sequence detected,
//! tracked with MMPF+ and scored).

pub mod demo;
pub mod figures;
pub mod sequences;

use std::time::Instant;

use serde::Serialize;
use sillage_core::{Result, TRANSPARENT_BEAD_CLASS, TrackPoint};
use sillage_eval::papers::{BeadTrackScores, score_bead_tracks};
use sillage_track::bedload::{BedloadTrackerKind, BedloadTrackerParams};

use crate::bedload::track_beads;
use sequences::Sequence;

/// τ_t of Table 1 (BeadTracking's sequence default is 0.23; 0.25 is the paper's figure's
/// middle and where both trackers reach 99 % on the real frames).
pub const TABLE_THRESHOLD: f64 = 0.25;

/// Which beads a row scores.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Scope {
    /// Every bead (Table 1).
    AllBeads,
    /// Transparent beads only (Fig. 6).
    Transparent,
}

/// One scored run: a tracker on a sequence at one τ_t.
#[derive(Debug, Serialize)]
pub struct Row {
    /// The sequence's name.
    pub sequence: &'static str,
    /// The tracker.
    pub tracker: BedloadTrackerKind,
    /// The transparent-bead detection threshold.
    pub transparent_threshold: f64,
    /// Which beads are scored.
    pub scope: Scope,
    /// Every score.
    pub scores: BeadTrackScores,
    /// Tracking time (scoring excluded), ms per frame.
    pub track_ms_per_frame: f64,
}

/// The threshold every frame is detected at: the lowest of the sweep's `thresholds` and of
/// Table 1.
pub fn lowest_threshold(thresholds: &[f64]) -> f64 {
    thresholds.iter().copied().fold(TABLE_THRESHOLD, f64::min)
}

/// The rows of every sequence: Table 1 (every bead at [`TABLE_THRESHOLD`]), then the sweep
/// over `thresholds` (transparent beads), every tracker at each.
pub fn evaluate(sequences: &[Sequence], thresholds: &[f64]) -> Result<Vec<Row>> {
    let mut rows = Vec::new();
    for sequence in sequences {
        run_trackers(&mut rows, sequence, TABLE_THRESHOLD, Scope::AllBeads)?;
        for &tau in thresholds {
            run_trackers(&mut rows, sequence, tau, Scope::Transparent)?;
        }
    }
    Ok(rows)
}

/// Runs every tracker on `sequence` at τ_t = `tau` and appends a row each, scored on `scope`.
fn run_trackers(rows: &mut Vec<Row>, sequence: &Sequence, tau: f64, scope: Scope) -> Result<()> {
    let frames = sequence.at_threshold(tau);
    let truth: Vec<TrackPoint> = match scope {
        Scope::AllBeads => sequence.truth.clone(),
        Scope::Transparent => transparent_only(&sequence.truth),
    };
    let params = BedloadTrackerParams {
        radius_px: sequence.radii.clone(),
        ..BedloadTrackerParams::default()
    };
    for kind in BedloadTrackerKind::ALL {
        let params = BedloadTrackerParams {
            tracker: kind,
            ..params.clone()
        };
        let start = Instant::now();
        let points = track_beads(&params, &frames)?;
        let track_s = start.elapsed().as_secs_f64();
        let points = match scope {
            Scope::AllBeads => points,
            Scope::Transparent => transparent_only(&points),
        };
        rows.push(Row {
            sequence: sequence.name,
            tracker: kind,
            transparent_threshold: tau,
            scope,
            scores: score_bead_tracks(&truth, &points, &sequence.radii)?,
            track_ms_per_frame: 1e3 * track_s / frames.len().max(1) as f64,
        });
    }
    Ok(())
}

fn transparent_only(points: &[TrackPoint]) -> Vec<TrackPoint> {
    points
        .iter()
        .filter(|p| p.class == TRANSPARENT_BEAD_CLASS)
        .copied()
        .collect()
}

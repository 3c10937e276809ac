//! How far a stitched run agrees with the single run of the same sequence: the points it keeps
//! and the identities that survive its seams.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use serde::Serialize;
use sillage_core::{FrameIndex, TrackId, TrackPoint};

/// A stitched run against the single run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WindowAgreement {
    /// Points of the single run.
    pub single_points: usize,
    /// Of them, present in the stitched run at the same frame and position (within 10⁻⁶ px).
    pub points_present: usize,
    /// Points of the stitched run that the single run does not have.
    pub extra_points: usize,
    /// Trajectories of the single run with points on both sides of a cut.
    pub crossing_tracks: usize,
    /// Of them, those whose points found in the stitched run carry one identity.
    pub crossing_kept: usize,
}

impl WindowAgreement {
    /// Share of the single run's points present, 0–1.
    pub fn points_share(&self) -> f64 {
        self.points_present as f64 / self.single_points.max(1) as f64
    }

    /// Share of the trajectories crossing a seam that keep one identity, 0–1.
    pub fn identity_share(&self) -> f64 {
        self.crossing_kept as f64 / self.crossing_tracks.max(1) as f64
    }
}

/// Compares `stitched` with `single` (both of one sequence) at the seams' `cuts`.
pub fn agreement(
    single: &[TrackPoint],
    stitched: &[TrackPoint],
    cuts: &[FrameIndex],
) -> WindowAgreement {
    let key = |p: &TrackPoint| (p.frame, p.pos_px.x.to_bits(), p.pos_px.y.to_bits());
    let stitched_id: HashMap<(FrameIndex, u64, u64), TrackId> =
        stitched.iter().map(|p| (key(p), p.track_id)).collect();
    let single_keys: BTreeSet<(FrameIndex, u64, u64)> = single.iter().map(key).collect();
    let mut tracks: BTreeMap<TrackId, Vec<&TrackPoint>> = BTreeMap::new();
    for p in single {
        tracks.entry(p.track_id).or_default().push(p);
    }
    let points_present = single
        .iter()
        .filter(|p| stitched_id.contains_key(&key(p)))
        .count();
    let (mut crossing_tracks, mut crossing_kept) = (0, 0);
    for points in tracks.values() {
        let (first, last) = points.iter().fold((FrameIndex::MAX, 0), |(lo, hi), p| {
            (lo.min(p.frame), hi.max(p.frame))
        });
        if !cuts.iter().any(|&cut| first < cut && cut <= last) {
            continue;
        }
        crossing_tracks += 1;
        let ids: BTreeSet<TrackId> = points
            .iter()
            .filter_map(|p| stitched_id.get(&key(p)).copied())
            .collect();
        if ids.len() == 1 {
            crossing_kept += 1;
        }
    }
    WindowAgreement {
        single_points: single.len(),
        points_present,
        extra_points: stitched
            .iter()
            .filter(|p| !single_keys.contains(&key(p)))
            .count(),
        crossing_tracks,
        crossing_kept,
    }
}

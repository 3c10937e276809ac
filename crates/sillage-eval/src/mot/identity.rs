//! Identity metrics (Ristani et al., "Performance measures and a data set for multi-target,
//! multi-camera tracking", ECCV Workshops 2016): one global one-to-one assignment of true
//! to estimated trajectories maximising the frames where the pair matches, then IDTP /
//! IDFP / IDFN, IDF1, IDP and IDR. As TrackEval's `metrics/identity.py` (py-motmetrics gives
//! the same counts).

use serde::Serialize;
use sillage_core::Result;

use super::assignment::{Edge, Matcher, Objective};
use super::data::MotData;
use super::ids::{IdMap, pair_key, split_pair_key};
use super::params::{MotConvention, MotParams};

/// Identity scores of one sequence, or of several combined ([`IdentityMetrics::combine`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IdentityMetrics {
    /// The conventions followed (only the threshold test differs).
    pub convention: MotConvention,
    /// The similarity threshold of a match.
    pub threshold: f64,
    /// True objects matched by the estimate trajectory assigned to their trajectory.
    pub idtp: u64,
    /// Estimates not matched by the true trajectory assigned to theirs.
    pub idfp: u64,
    /// True objects not matched by the estimate trajectory assigned to theirs.
    pub idfn: u64,
    /// `IDTP / (IDTP + ½ IDFP + ½ IDFN)`.
    pub idf1: f64,
    /// `IDTP / (IDTP + IDFP)`.
    pub idp: f64,
    /// `IDTP / (IDTP + IDFN)`.
    pub idr: f64,
}

/// Scores `data` with the Identity metrics.
///
/// TrackEval solves a dense `(true ids + estimate ids)²` assignment; maximising the matched
/// co-occurrences over the pairs that do co-occur is the same optimum (IDFN + IDFP =
/// Σ truth + Σ estimates − 2 IDTP), found here component by component in time linear in
/// the rows for trajectories that meet few others.
pub fn identity(data: &MotData, params: &MotParams) -> Result<IdentityMetrics> {
    params.validate()?;
    let mut co_occurrences: IdMap<u64, u32> = IdMap::default();
    for frame in data.frames() {
        for p in frame.pairs {
            if params
                .convention
                .identity_allows(p.similarity, params.threshold)
            {
                let key = pair_key(
                    frame.truth_ids[p.truth as usize],
                    frame.estimate_ids[p.estimate as usize],
                );
                *co_occurrences.entry(key).or_insert(0) += 1;
            }
        }
    }
    // Sorted pairs: the matching (and its tie-breaking) does not depend on hash order.
    let mut pairs: Vec<(u64, u32)> = co_occurrences.into_iter().collect();
    pairs.sort_unstable_by_key(|&(key, _)| key);
    let edges: Vec<Edge> = pairs
        .iter()
        .map(|&(key, count)| {
            let (row, col) = split_pair_key(key);
            Edge {
                row,
                col,
                value: f64::from(count),
            }
        })
        .collect();
    let mut matched = Vec::new();
    Matcher::default().solve(
        data.truth_id_count(),
        data.estimate_id_count(),
        &edges,
        Objective::MaxWeight,
        &mut matched,
    );
    let idtp: u64 = matched.iter().map(|&k| u64::from(pairs[k].1)).sum();
    Ok(IdentityMetrics::from_counts(
        idtp,
        data.estimate_count() as u64 - idtp,
        data.truth_count() as u64 - idtp,
        params,
    ))
}

impl IdentityMetrics {
    /// The rates from the counts (TrackEval's `_compute_final_fields`, denominators floored
    /// at 1).
    fn from_counts(idtp: u64, idfp: u64, idfn: u64, params: &MotParams) -> Self {
        let (tp, fp, fn_) = (idtp as f64, idfp as f64, idfn as f64);
        Self {
            convention: params.convention,
            threshold: params.threshold,
            idtp,
            idfp,
            idfn,
            idf1: tp / (tp + 0.5 * fp + 0.5 * fn_).max(1.0),
            idp: tp / (tp + fp).max(1.0),
            idr: tp / (tp + fn_).max(1.0),
        }
    }

    /// Combines sequences as TrackEval (sums IDTP, IDFP, IDFN, then the rates).
    pub fn combine(sequences: &[IdentityMetrics]) -> IdentityMetrics {
        let params = sequences
            .first()
            .map_or_else(MotParams::default, |s| MotParams {
                threshold: s.threshold,
                convention: s.convention,
            });
        let sum = |f: fn(&IdentityMetrics) -> u64| sequences.iter().map(f).sum::<u64>();
        IdentityMetrics::from_counts(sum(|s| s.idtp), sum(|s| s.idfp), sum(|s| s.idfn), &params)
    }

    /// The heading of its tables.
    pub(crate) fn title(&self) -> String {
        format!(
            "Identity ({} convention, similarity ≥ {}; scores in %)",
            self.convention.label(),
            self.threshold
        )
    }

    /// The table columns: name and formatted value.
    pub(crate) fn columns(&self) -> Vec<(&'static str, String)> {
        use crate::summary::{count, score};
        vec![
            ("IDF1", score(self.idf1)),
            ("IDP", score(self.idp)),
            ("IDR", score(self.idr)),
            ("IDTP", count(self.idtp)),
            ("IDFP", count(self.idfp)),
            ("IDFN", count(self.idfn)),
        ]
    }
}

impl std::fmt::Display for IdentityMetrics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{}", self.title())?;
        crate::summary::Table::single(&self.columns()).fmt(f)
    }
}

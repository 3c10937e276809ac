//! Combining sequences the way TrackEval does (`combine_sequences` of each metric: counts
//! summed, HOTA's association and localisation scores weighted by true positives), and the
//! table of a multi-sequence evaluation.

use std::fmt;

use serde::Serialize;

use super::MotMetrics;
use super::clear::ClearMetrics;
use super::hota::HotaMetrics;
use super::identity::IdentityMetrics;
use crate::summary::{FamilyColumns, family_tables};

impl MotMetrics {
    /// Combines sequences: each family as TrackEval's `combine_sequences` (see
    /// [`ClearMetrics::combine`], [`IdentityMetrics::combine`], [`HotaMetrics::combine`]).
    pub fn combine(sequences: &[MotMetrics]) -> MotMetrics {
        let clear: Vec<ClearMetrics> = sequences.iter().map(|s| s.clear).collect();
        let identity: Vec<IdentityMetrics> = sequences.iter().map(|s| s.identity).collect();
        let hota: Vec<HotaMetrics> = sequences.iter().map(|s| s.hota).collect();
        MotMetrics {
            clear: ClearMetrics::combine(&clear),
            identity: IdentityMetrics::combine(&identity),
            hota: HotaMetrics::combine(&hota),
        }
    }
}

impl fmt::Display for MotMetrics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{}", self.hota)?;
        writeln!(f, "{}", self.clear)?;
        write!(f, "{}", self.identity)
    }
}

/// The scores of several named sequences and their combination: what an evaluation run
/// reports. Displays one table per metric family, a row per sequence and a `COMBINED` row.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MotReport {
    /// Each sequence by name, in the order given.
    pub sequences: Vec<(String, MotMetrics)>,
    /// All sequences combined ([`MotMetrics::combine`]).
    pub combined: MotMetrics,
}

impl MotReport {
    /// The report of `sequences`, with their combination.
    pub fn new(sequences: Vec<(String, MotMetrics)>) -> Self {
        let metrics: Vec<MotMetrics> = sequences.iter().map(|(_, m)| *m).collect();
        let combined = MotMetrics::combine(&metrics);
        Self {
            sequences,
            combined,
        }
    }
}

impl fmt::Display for MotReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let rows: Vec<(&str, &MotMetrics)> = self
            .sequences
            .iter()
            .map(|(name, m)| (name.as_str(), m))
            .chain([("COMBINED", &self.combined)])
            .collect();
        let c = &self.combined;
        let families: [(String, FamilyColumns<MotMetrics>); 3] = [
            (c.hota.title(), |m| Some(m.hota.columns())),
            (c.clear.title(), |m| Some(m.clear.columns())),
            (c.identity.title(), |m| Some(m.identity.columns())),
        ];
        family_tables(f, &rows, &families)
    }
}

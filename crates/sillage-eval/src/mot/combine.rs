//! Combining sequences the way TrackEval does (`combine_sequences` of each metric: counts
//! summed, HOTA's association and localisation scores weighted by true positives), and the
//! table of a multi-sequence evaluation.

use std::fmt;

use serde::Serialize;

use super::MotMetrics;
use super::clear::ClearMetrics;
use super::hota::HotaMetrics;
use super::identity::IdentityMetrics;
use crate::summary::Table;

/// The columns of one metric family of a sequence.
type Columns = fn(&MotMetrics) -> Vec<(&'static str, String)>;

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
        let families: [(String, Columns); 3] = [
            (c.hota.title(), |m| m.hota.columns()),
            (c.clear.title(), |m| m.clear.columns()),
            (c.identity.title(), |m| m.identity.columns()),
        ];
        for (k, (title, columns)) in families.iter().enumerate() {
            if k > 0 {
                writeln!(f)?;
            }
            writeln!(f, "{title}")?;
            let header = columns(c).into_iter().map(|(name, _)| name.to_owned());
            let mut table = Table::new(std::iter::once("sequence".to_owned()).chain(header));
            for (name, metrics) in &rows {
                let values = columns(metrics).into_iter().map(|(_, value)| value);
                table.push(std::iter::once((*name).to_owned()).chain(values));
            }
            table.fmt(f)?;
        }
        Ok(())
    }
}

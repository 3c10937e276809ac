//! Profiles: the bins of each grid row (or column) pooled into one, e.g. the mean
//! streamwise velocity and the Reynolds stress as functions of the height above a wall (the
//! TracTrac paper's Fig. 6d and Fig. 7).

use std::collections::BTreeMap;

use sillage_core::Vec2;

use super::grid::{BinAccumulator, BinStats, EulerianGrid};

/// The axis a profile runs along.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProfileAxis {
    /// Statistics as a function of `x`: each column of bins pooled over `y`.
    X,
    /// Statistics as a function of `y`: each row of bins pooled over `x`.
    Y,
}

impl EulerianGrid {
    /// The profile along `axis`: one entry per occupied column (`X`) or row (`Y`), its
    /// samples pooled exactly (Chan et al.'s merge), so the profile equals the statistics of
    /// all the rows that fell in that band. The concentration is per unit area of the bins
    /// that were occupied; the other coordinate of `centre`, `row` or `column` is 0.
    pub fn profile(&self, axis: ProfileAxis) -> Vec<BinStats> {
        let mut bands: BTreeMap<i64, (BinAccumulator, u64)> = BTreeMap::new();
        for (&(column, row), accumulator) in self.accumulators() {
            let key = match axis {
                ProfileAxis::X => column,
                ProfileAxis::Y => row,
            };
            let (pooled, bins) = bands.entry(key).or_default();
            pooled.merge(accumulator);
            *bins += 1;
        }
        let size = self.params().bin_size;
        bands
            .into_iter()
            .map(|(index, (pooled, bins))| {
                let at = (index as f64 + 0.5) * size;
                let (column, row, centre) = match axis {
                    ProfileAxis::X => (index, 0, Vec2::new(at, 0.0)),
                    ProfileAxis::Y => (0, index, Vec2::new(0.0, at)),
                };
                self.stats(column, row, centre, size * size * bins as f64, &pooled)
            })
            .collect()
    }
}

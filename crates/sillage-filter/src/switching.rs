//! Jump-Markov switching: a row-stochastic transition table `π = p(sₜ | sₜ₋₁)` (Eqs. (11) and
//! (12) of the MMPF+ paper) that each particle draws its next motion state from, and that the
//! Kalman IMM mixes with.

use sillage_core::{Error, Result};

/// How far a row's sum may be from 1.
pub const ROW_SUM_TOLERANCE: f64 = 1e-9;

/// A validated transition table: `rows` from-states × `columns` to-states, non-negative, each
/// row summing to 1. Rows may outnumber columns (an initial "unknown" state that is only left).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TransitionTable {
    columns: usize,
    probabilities: Vec<f64>,
    /// Per row, the running sums used for sampling; the last positive entry is exactly 1.
    cumulative: Vec<f64>,
}

impl TransitionTable {
    /// Validates `rows` (all of the same non-zero length, entries finite and ≥ 0, sums 1 within
    /// [`ROW_SUM_TOLERANCE`]); errors name `key` and the offending row.
    pub fn new<R: AsRef<[f64]>>(key: &str, rows: &[R]) -> Result<Self> {
        let columns = rows.first().map_or(0, |r| r.as_ref().len());
        if rows.is_empty() || columns == 0 {
            return Err(Error::parameter(
                key,
                "[]",
                "must hold at least one row of at least one probability",
            ));
        }
        let mut probabilities = Vec::with_capacity(rows.len() * columns);
        let mut cumulative = Vec::with_capacity(rows.len() * columns);
        for (r, row) in rows.iter().enumerate() {
            let row = row.as_ref();
            let shown = format!("{row:?}");
            if row.len() != columns {
                return Err(Error::parameter(
                    key,
                    shown,
                    format!("row {r} has {} entries, row 0 has {columns}", row.len()),
                ));
            }
            if let Some(bad) = row.iter().find(|p| !(p.is_finite() && **p >= 0.0)) {
                return Err(Error::parameter(
                    key,
                    shown,
                    format!("row {r} holds {bad}: probabilities must be finite and ≥ 0"),
                ));
            }
            let sum: f64 = row.iter().sum();
            if (sum - 1.0).abs() > ROW_SUM_TOLERANCE {
                return Err(Error::parameter(
                    key,
                    shown,
                    format!(
                        "row {r} sums to {sum}: each row of a transition table must sum to 1 \
                         (within {ROW_SUM_TOLERANCE:e})"
                    ),
                ));
            }
            probabilities.extend_from_slice(row);
            let last_positive = row.iter().rposition(|&p| p > 0.0).unwrap_or(columns - 1);
            let mut running = 0.0;
            for (c, &p) in row.iter().enumerate() {
                running += p;
                cumulative.push(if c >= last_positive { 1.0 } else { running });
            }
        }
        Ok(Self {
            columns,
            probabilities,
            cumulative,
        })
    }

    /// Number of from-states.
    pub fn rows(&self) -> usize {
        self.probabilities.len() / self.columns
    }

    /// Number of to-states.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// `p(to | from)`.
    pub fn probability(&self, from: usize, to: usize) -> f64 {
        self.probabilities[from * self.columns + to]
    }

    /// The next state from `from`, given a uniform draw `u` in `[0, 1)`: the first column whose
    /// running sum exceeds `u` (the last positive column for `u ≥ 1`). Zero-probability
    /// columns are never returned.
    #[inline]
    pub fn next_state(&self, from: usize, u: f64) -> usize {
        let row = &self.cumulative[from * self.columns..(from + 1) * self.columns];
        row.iter()
            .position(|&c| u < c || c == 1.0)
            .unwrap_or(self.columns - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_key_and_row() {
        let eq12 = [[0.80, 0.15, 0.05], [0.10, 0.80, 0.10], [0.05, 0.15, 0.80]];
        let t = TransitionTable::new("transition", &eq12).unwrap();
        assert_eq!((t.rows(), t.columns()), (3, 3));
        assert_eq!(t.probability(1, 2), 0.10);
        let short = [[0.8, 0.15, 0.05], [0.1, 0.8, 0.05]];
        let e = TransitionTable::new("transition", &short)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`transition`") && e.contains("row 1 sums to 0.95"),
            "{e}"
        );
        let negative = [[1.1, -0.1]];
        let e = TransitionTable::new("transition", &negative)
            .unwrap_err()
            .to_string();
        assert!(e.contains("row 0 holds -0.1"), "{e}");
        let ragged: [&[f64]; 2] = [&[1.0], &[0.5, 0.5]];
        assert!(TransitionTable::new("t", &ragged).is_err());
        let empty: [[f64; 0]; 0] = [];
        assert!(TransitionTable::new("t", &empty).is_err());
    }

    #[test]
    fn sampling_follows_the_running_sums() {
        // Eq. (11): a zero entry in the last column must never be drawn, even at u → 1.
        let eq11 = [[0.95, 0.05, 0.00], [0.07, 0.92, 0.01], [0.00, 0.09, 0.91]];
        let t = TransitionTable::new("transition", &eq11).unwrap();
        assert_eq!(t.next_state(0, 0.0), 0);
        assert_eq!(t.next_state(0, 0.9499), 0);
        assert_eq!(t.next_state(0, 0.95), 1);
        assert_eq!(t.next_state(0, 1.0 - f64::EPSILON / 2.0), 1);
        assert_eq!(t.next_state(0, 1.0), 1);
        assert_eq!(t.next_state(2, 0.0), 1);
        assert_eq!(t.next_state(2, 0.5), 2);
    }
}

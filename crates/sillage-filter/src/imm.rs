//! The Kalman interacting multiple model (IMM) filter: one Kalman filter per motion model,
//! mixed through a transition table at every step (Blom & Bar-Shalom 1988; the IMM baseline of
//! Table 1 of the MMPF+ paper, survey in its ref. 33, Mazor et al. 1998).
//!
//! One cycle, with models j = 1..M, probabilities μ and table π:
//! 1. mixing: `c_j = Σᵢ πᵢⱼ μᵢ`, `μ_{i|j} = πᵢⱼ μᵢ / c_j`, `x⁰_j = Σᵢ μ_{i|j} xᵢ`,
//!    `P⁰_j = Σᵢ μ_{i|j} (Pᵢ + (xᵢ − x⁰_j)(xᵢ − x⁰_j)ᵀ)`;
//! 2. mode-matched filters: each `(x⁰_j, P⁰_j)` predicted by model j, then updated by z with
//!    likelihood `Λ_j`;
//! 3. model probabilities: `μ_j ∝ Λ_j c_j`;
//! 4. combination: `x = Σ_j μ_j x_j`, `P = Σ_j μ_j (P_j + (x_j − x)(x_j − x)ᵀ)`.
//!
//! [`KalmanImm::predict`] runs 1 and the predictions of 2 (and sets μ to c);
//! [`KalmanImm::update`] runs the updates of 2 and 3; [`KalmanImm::estimate`] is 4.

use sillage_core::{Error, Point2, Result};

use crate::kalman::{KalmanFilter, LinearGaussian, PositionMeasurement};
use crate::linalg::{Gaussian, Matrix, Vector};
use crate::switching::TransitionTable;
use crate::weights::log_sum_exp;

/// A Kalman IMM over an `N`-dimensional state whose first two components are the position.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct KalmanImm<const N: usize> {
    models: Vec<LinearGaussian<N>>,
    table: TransitionTable,
    filters: Vec<KalmanFilter<N>>,
    probabilities: Vec<f64>,
    /// Reused buffers: mixed beliefs, mixing weights μ_{i|j}, and one term per mode (c_j in
    /// `predict`, ln Λ_j + ln μ_j in `update`).
    mixed: Vec<Gaussian<N>>,
    mixing: Vec<f64>,
    terms: Vec<f64>,
}

impl<const N: usize> KalmanImm<N> {
    /// An IMM whose every mode starts at `initial`, with mode probabilities `probabilities`
    /// (non-negative, summing to 1 within 1e-9). `table` must be M×M for M = `models.len()` ≥ 1.
    pub fn new(
        models: Vec<LinearGaussian<N>>,
        table: TransitionTable,
        initial: Gaussian<N>,
        probabilities: &[f64],
    ) -> Result<Self> {
        let m = models.len();
        if m == 0 || table.rows() != m || table.columns() != m {
            return Err(Error::input(format!(
                "a Kalman IMM of {m} models needs a {m}×{m} transition table, got {}×{}",
                table.rows(),
                table.columns()
            )));
        }
        if probabilities.len() != m {
            return Err(Error::input(format!(
                "a Kalman IMM of {m} models needs {m} initial probabilities, got {}",
                probabilities.len()
            )));
        }
        // Same rule as a table row: finite, ≥ 0, summing to 1.
        TransitionTable::new("initial mode probabilities", &[probabilities])?;
        Ok(Self {
            filters: vec![KalmanFilter::new(initial); m],
            mixed: vec![initial; m],
            mixing: vec![0.0; m * m],
            terms: vec![0.0; m],
            probabilities: probabilities.to_vec(),
            models,
            table,
        })
    }

    /// Mixing, then each mode-matched prediction; the mode probabilities become the predicted
    /// ones `c_j`.
    pub fn predict(&mut self) {
        let m = self.models.len();
        // c_j and μ_{i|j}, stored as mixing[i·m + j].
        for j in 0..m {
            let c_j: f64 = (0..m)
                .map(|i| self.table.probability(i, j) * self.probabilities[i])
                .sum();
            for i in 0..m {
                let joint = self.table.probability(i, j) * self.probabilities[i];
                self.mixing[i * m + j] = if c_j > 0.0 { joint / c_j } else { 0.0 };
            }
            self.terms[j] = c_j;
        }
        for j in 0..m {
            let weights = (0..m).map(|i| self.mixing[i * m + j]);
            self.mixed[j] = combine(self.filters.iter().map(|f| &f.state), weights);
        }
        for j in 0..m {
            self.filters[j].state = self.mixed[j];
            self.filters[j].predict(&self.models[j]);
        }
        self.probabilities.copy_from_slice(&self.terms);
    }

    /// Updates every mode-matched filter with the measured position `z` and the mode
    /// probabilities with their likelihoods (in the log domain). Returns the log-likelihood of
    /// `z` under the mixture; if every mode finds `z` impossible, the probabilities are kept.
    pub fn update(&mut self, z: Point2, measurement: &PositionMeasurement) -> f64 {
        for ((filter, term), &p) in self
            .filters
            .iter_mut()
            .zip(self.terms.iter_mut())
            .zip(&self.probabilities)
        {
            *term = filter.update(z, measurement) + p.ln();
        }
        let total = log_sum_exp(&self.terms);
        if total.is_finite() {
            for (p, &term) in self.probabilities.iter_mut().zip(&self.terms) {
                *p = (term - total).exp();
            }
        }
        total
    }

    /// The combined estimate: the moment-matched Gaussian of the mode mixture.
    pub fn estimate(&self) -> Gaussian<N> {
        combine(
            self.filters.iter().map(|f| &f.state),
            self.probabilities.iter().copied(),
        )
    }

    /// The mode probabilities μ, in model order.
    pub fn mode_probabilities(&self) -> &[f64] {
        &self.probabilities
    }

    /// The mode-matched filters, in model order.
    pub fn mode_filters(&self) -> &[KalmanFilter<N>] {
        &self.filters
    }
}

/// The moment-matched Gaussian of a mixture: `x = Σ wᵢ xᵢ`, `P = Σ wᵢ (Pᵢ + (xᵢ − x)(xᵢ − x)ᵀ)`.
fn combine<'a, const N: usize>(
    components: impl Iterator<Item = &'a Gaussian<N>> + Clone,
    weights: impl Iterator<Item = f64> + Clone,
) -> Gaussian<N> {
    let mut mean = Vector::<N>::ZERO;
    for (g, w) in components.clone().zip(weights.clone()) {
        mean = mean + g.mean.scaled(w);
    }
    let mut cov = Matrix::<N, N>::ZERO;
    for (g, w) in components.zip(weights) {
        cov = cov + (g.cov + (g.mean - mean).outer()).scaled(w);
    }
    Gaussian {
        mean,
        cov: cov.symmetrised(),
    }
}

//! Log-domain importance weights: normalisation by log-sum-exp (Eq. (6) of the MMPF+ paper,
//! "normalizing", §3.5.2), effective sample size and the recovery of an all-zero weight set.

use crate::fast_math::exp_nonpositive;
use crate::sums::lane_max;

/// What one normalisation found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Normalisation {
    /// `ln Σᵢ wᵢ` before normalising: with weights that summed to 1 before the likelihood was
    /// applied, the log-likelihood of the observation given the past (−∞ when recovered).
    pub log_evidence: f64,
    /// Effective sample size `1 / Σᵢ wᵢ²` of the normalised weights, in `[1, N]`.
    pub ess: f64,
    /// Every weight was zero (−∞, or NaN): the weights were reset to uniform.
    pub recovered: bool,
}

/// `ln Σᵢ exp(xᵢ)` without overflow or underflow; −∞ for an empty slice or all −∞.
pub fn log_sum_exp(values: &[f64]) -> f64 {
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if max == f64::NEG_INFINITY {
        return f64::NEG_INFINITY;
    }
    max + values.iter().map(|&v| (v - max).exp()).sum::<f64>().ln()
}

/// A log-likelihood as the weights accept it: NaN (a likelihood that could not be evaluated)
/// counts as a zero weight, +∞ as the largest finite value so that sums stay defined.
#[inline]
pub fn sanitise_log_likelihood(value: f64) -> f64 {
    if value.is_nan() {
        f64::NEG_INFINITY
    } else {
        value.min(f64::MAX)
    }
}

/// `linear[i] = exp(log_weights[i] − max)`, and `(Σ linear, Σ linear²)`: the exponentials in
/// one vectorisable pass, then the sums over four fixed lanes (the same order, so the same
/// bits, on every machine).
#[inline(always)]
fn exponentials(log_weights: &[f64], linear: &mut [f64], max: f64) -> (f64, f64) {
    for (lw, w) in log_weights.iter().zip(linear.iter_mut()) {
        *w = exp_nonpositive(lw - max);
    }
    let (mut sums, mut squares) = ([0.0; 4], [0.0; 4]);
    let mut quads = linear.chunks_exact(4);
    for quad in &mut quads {
        for lane in 0..4 {
            sums[lane] += quad[lane];
            squares[lane] += quad[lane] * quad[lane];
        }
    }
    for (lane, &e) in quads.remainder().iter().enumerate() {
        sums[lane] += e;
        squares[lane] += e * e;
    }
    (
        (sums[0] + sums[1]) + (sums[2] + sums[3]),
        (squares[0] + squares[1]) + (squares[2] + squares[3]),
    )
}

sillage_core::multiversion! {
    /// [`exponentials`] on the widest SIMD the CPU offers.
    fn exponentials_widest(log_weights: &[f64], linear: &mut [f64], max: f64) -> (f64, f64) => exponentials
}

/// `log_weights[i] −= log_norm` and `linear[i] ·= inv`: the normalisation's last pass.
#[inline(always)]
fn rescale(log_weights: &mut [f64], linear: &mut [f64], log_norm: f64, inv: f64) {
    for (lw, w) in log_weights.iter_mut().zip(linear.iter_mut()) {
        *lw -= log_norm;
        *w *= inv;
    }
}

sillage_core::multiversion! {
    /// [`rescale`] on the widest SIMD the CPU offers.
    fn rescale_widest(log_weights: &mut [f64], linear: &mut [f64], log_norm: f64, inv: f64) => rescale
}

/// Normalises `log_weights` in place so that `Σᵢ exp(log_weightsᵢ) = 1`, and writes the linear
/// normalised weights to `linear` (same length). When every weight is zero the set is reset to
/// uniform and `recovered` says so: the caller counts that event.
pub fn normalise(log_weights: &mut [f64], linear: &mut [f64]) -> Normalisation {
    debug_assert_eq!(log_weights.len(), linear.len());
    let n = log_weights.len();
    let max = lane_max(log_weights);
    // The maximum skips NaN, so an all-NaN set also ends at −∞ here.
    if n == 0 || max == f64::NEG_INFINITY {
        let uniform = -(n.max(1) as f64).ln();
        log_weights.fill(uniform);
        linear.fill(1.0 / n.max(1) as f64);
        return Normalisation {
            log_evidence: f64::NEG_INFINITY,
            ess: n as f64,
            recovered: true,
        };
    }
    // e = exp(x − max) ∈ [0, 1]: no overflow, and the largest term is exactly 1, so the sum
    // cannot underflow either.
    let (sum, sum_sq) = exponentials_widest(log_weights, linear, max);
    let log_norm = max + sum.ln();
    rescale_widest(log_weights, linear, log_norm, 1.0 / sum);
    Normalisation {
        log_evidence: log_norm,
        ess: sum * sum / sum_sq,
        recovered: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_sum_exp_is_stable() {
        assert_eq!(log_sum_exp(&[]), f64::NEG_INFINITY);
        assert_eq!(log_sum_exp(&[f64::NEG_INFINITY; 3]), f64::NEG_INFINITY);
        let v = log_sum_exp(&[-1e6, -1e6]);
        assert!((v - (-1e6 + 2f64.ln())).abs() < 1e-9);
        let v = log_sum_exp(&[800.0, 800.0]);
        assert!((v - (800.0 + 2f64.ln())).abs() < 1e-12);
    }

    #[test]
    fn normalise_far_below_underflow_keeps_ratios() {
        // exp(-1e5) underflows to 0 in the linear domain; the log domain keeps 2:1.
        let mut lw = [-1e5, -1e5 - 2f64.ln()];
        let mut w = [0.0; 2];
        let out = normalise(&mut lw, &mut w);
        assert!(!out.recovered);
        assert!((w[0] - 2.0 / 3.0).abs() < 1e-12 && (w[1] - 1.0 / 3.0).abs() < 1e-12);
        assert!((out.ess - 1.0 / (4.0 / 9.0 + 1.0 / 9.0)).abs() < 1e-12);
        assert!((out.log_evidence - (-1e5 + 1.5f64.ln())).abs() < 1e-9);
    }

    #[test]
    fn all_zero_weights_recover_to_uniform() {
        let mut lw = [f64::NEG_INFINITY; 4];
        let mut w = [0.0; 4];
        let out = normalise(&mut lw, &mut w);
        assert!(out.recovered);
        assert_eq!(out.log_evidence, f64::NEG_INFINITY);
        assert_eq!(out.ess, 4.0);
        assert!(lw.iter().all(|&v| (v + 4f64.ln()).abs() < 1e-15));
        assert_eq!(w, [0.25; 4]);
        assert_eq!(sanitise_log_likelihood(f64::NAN), f64::NEG_INFINITY);
        assert_eq!(sanitise_log_likelihood(f64::INFINITY), f64::MAX);
    }
}

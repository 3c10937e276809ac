//! Prediction error and the adaptive outlier threshold (§3.1.3, Eqs. 10 and 12).

use sillage_core::Vec2;

/// Threshold on the log10 error at the start, and after a frame without any triplet
/// (TracTrac's value: errors up to 10² px pass).
pub(crate) const INITIAL_THRESHOLD: f64 = 2.0;

/// Floor of the log10 error (TracTrac's), so an exact prediction gives −10, not −∞.
const LOG_ERR_FLOOR: f64 = -10.0;

/// Eq. (10) as TracTrac's code computes it: log10 of the Chebyshev norm of the prediction
/// error in px, `max(|U_motion − u_m|·|dt|)`, floored at −10 (the paper writes the
/// Euclidean norm of the velocity difference).
pub(crate) fn log10_error(predicted: Vec2, measured: Vec2, dt: f64) -> f64 {
    ((predicted - measured).max_abs() * dt.abs())
        .log10()
        .max(LOG_ERR_FLOOR)
}

/// The threshold after a frame whose candidate tracklets (outliers included) have log
/// errors `errors`: `(filter_time·th + filter_std·std(errors)) / (filter_time + 1)`, back to
/// [`INITIAL_THRESHOLD`] when there is no candidate or the result is NaN.
///
/// This is TracTrac's code version of Eq. (12): with α = 1/(1 + filter_time) it is
/// th(t) = α·n_σ·σ(t) + (1−α)·th(t−1), i.e. the paper's n_σ·σ̄_ε(t) where σ̄_ε is the
/// exponentially smoothed std of Eq. (12) — except that it starts at 2 rather than at
/// n_σ·σ, and a frame is tested against the threshold of the previous update.
pub(crate) fn updated_threshold(
    threshold: f64,
    errors: &[f64],
    filter_std: f64,
    filter_time: f64,
) -> f64 {
    if errors.is_empty() {
        return INITIAL_THRESHOLD;
    }
    let next =
        (filter_time * threshold + filter_std * population_std(errors)) / (filter_time + 1.0);
    if next.is_nan() {
        INITIAL_THRESHOLD
    } else {
        next
    }
}

/// Population standard deviation (NumPy's `std`), two passes, sequential: the same bits
/// whatever the number of threads.
fn population_std(values: &[f64]) -> f64 {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    (values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_error_uses_chebyshev_norm_and_floor() {
        let e = log10_error(Vec2::new(1.0, 0.0), Vec2::new(1.5, 3.0), -2.0);
        assert!((e - 6f64.log10()).abs() < 1e-15);
        assert_eq!(
            log10_error(Vec2::new(1.0, 1.0), Vec2::new(1.0, 1.0), 1.0),
            -10.0
        );
    }

    #[test]
    fn threshold_relaxes_towards_n_sigma_std() {
        // std of [0, 2] is 1: (1·2 + 1.5·1) / 2 = 1.75.
        assert_eq!(updated_threshold(2.0, &[0.0, 2.0], 1.5, 1.0), 1.75);
        assert_eq!(updated_threshold(0.3, &[], 1.5, 1.0), INITIAL_THRESHOLD);
        assert_eq!(
            updated_threshold(f64::NAN, &[1.0], 1.5, 1.0),
            INITIAL_THRESHOLD
        );
    }
}

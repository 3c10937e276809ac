//! The linear Kalman filter over a state whose first two components are the position, observed
//! directly (`z = H·x + r`, `H = [I₂ 0]`): the mode-matched filter of the IMM baseline and the
//! closed form the particle filter is tested against.

use std::f64::consts::TAU;

use sillage_core::{Point2, Result};

use crate::linalg::{Gaussian, Matrix, Vector};
use crate::noise::Noise2;

/// A linear-Gaussian motion `x ← F·x + w`, `w ~ N(0, Q)`, one frame per step.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LinearGaussian<const N: usize> {
    /// F, the state transition.
    pub transition: Matrix<N, N>,
    /// Q, the process-noise covariance.
    pub noise: Matrix<N, N>,
}

/// A validated position measurement noise R (positive definite), px².
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PositionMeasurement {
    noise: Matrix<2, 2>,
}

impl PositionMeasurement {
    /// Validates `noise` (positive definite); errors name `key`.
    pub fn new(key: &str, noise: &Noise2) -> Result<Self> {
        noise.factor_positive_definite(key)?;
        Ok(Self {
            noise: noise.matrix(),
        })
    }

    /// R.
    pub fn noise(&self) -> Matrix<2, 2> {
        self.noise
    }
}

/// The Kalman filter: a Gaussian belief, predicted by a [`LinearGaussian`] motion and updated
/// by a position measurement (Joseph form, so the covariance stays symmetric and positive).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct KalmanFilter<const N: usize> {
    /// The current belief.
    pub state: Gaussian<N>,
}

impl<const N: usize> KalmanFilter<N> {
    /// H = [I₂ 0]: the position is the first two state components.
    fn observation() -> Matrix<2, N> {
        const { assert!(N >= 2, "the state must start with the 2-D position") };
        let mut h = Matrix::<2, N>::ZERO;
        h.0[0][0] = 1.0;
        h.0[1][1] = 1.0;
        h
    }

    /// A filter starting from `state`.
    pub fn new(state: Gaussian<N>) -> Self {
        Self { state }
    }

    /// `x ← F·x`, `P ← F·P·Fᵀ + Q`.
    pub fn predict(&mut self, model: &LinearGaussian<N>) {
        let f = model.transition;
        self.state = Gaussian {
            mean: f * self.state.mean,
            cov: (f * self.state.cov * f.transpose() + model.noise).symmetrised(),
        };
    }

    /// Corrects the belief with the measured position `z`; returns `ln N(z; H·x, S)`, the
    /// log-likelihood of `z` before the update (the IMM's mode likelihood).
    pub fn update(&mut self, z: Point2, measurement: &PositionMeasurement) -> f64 {
        let h = Self::observation();
        let r = measurement.noise;
        let p = self.state.cov;
        let innovation = Vector::from_array([z.x, z.y]) - h * self.state.mean;
        let s = (h * p * h.transpose() + r).symmetrised();
        // S = H·P·Hᵀ + R is positive definite whenever P is positive semi-definite (R is, by
        // validation); a non-finite z or P is the only way here, and leaves the belief as is.
        let Some(s_inv) = s.inverse_positive_definite() else {
            return f64::NEG_INFINITY;
        };
        let gain = p * h.transpose() * s_inv;
        let i_kh = Matrix::<N, N>::identity() - gain * h;
        self.state = Gaussian {
            mean: self.state.mean + gain * innovation,
            cov: (i_kh * p * i_kh.transpose() + gain * r * gain.transpose()).symmetrised(),
        };
        let mahalanobis = (innovation.transpose() * s_inv * innovation).0[0][0];
        -0.5 * (mahalanobis + s.determinant().ln() + 2.0 * TAU.ln())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_update_matches_closed_form() {
        // Position-only state, P = 2·I, R = 2·I: gain 1/2, posterior variance 1, and the
        // innovation (2, 0) has S = 4·I, so ln L = −(4/4)/2 − ln(16)/2 − ln(2π).
        let mut kf = KalmanFilter::new(Gaussian {
            mean: Vector::from_array([0.0, 0.0]),
            cov: Matrix::diagonal([2.0, 2.0]),
        });
        let r = PositionMeasurement::new("r", &Noise2::diagonal(2.0, 2.0)).unwrap();
        let ll = kf.update(Point2::new(2.0, 0.0), &r);
        assert!((kf.state.mean.at(0) - 1.0).abs() < 1e-15);
        assert!(kf.state.cov.max_abs_diff(&Matrix::identity()) < 1e-15);
        let expected = -0.5 - 0.5 * 16f64.ln() - TAU.ln();
        assert!((ll - expected).abs() < 1e-12, "{ll} vs {expected}");
    }
}

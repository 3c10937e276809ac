//! Zero-mean 2-D Gaussian noises: the process noises ε of Eq. (3) of the MMPF+ paper and the
//! measurement noise of the Kalman filters.

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result};

use crate::linalg::Matrix;
use crate::normal::Normals;

/// A 2-D covariance as the user writes it (px² for positions, px²/frame² for velocities):
/// both variances and the covariance, so the correlated noises of the authors' code fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Noise2 {
    /// Variance along x (columns).
    pub var_x: f64,
    /// Variance along y (rows).
    pub var_y: f64,
    /// Covariance of x and y (0 for independent axes).
    #[serde(default)]
    pub cov_xy: f64,
}

impl Noise2 {
    /// Independent axes with variances `var_x` and `var_y`.
    pub const fn diagonal(var_x: f64, var_y: f64) -> Self {
        Self {
            var_x,
            var_y,
            cov_xy: 0.0,
        }
    }

    /// Every entry multiplied by `factor` (variance inflation).
    pub fn scaled(self, factor: f64) -> Self {
        Self {
            var_x: self.var_x * factor,
            var_y: self.var_y * factor,
            cov_xy: self.cov_xy * factor,
        }
    }

    /// The covariance as a matrix.
    pub fn matrix(&self) -> Matrix<2, 2> {
        Matrix([[self.var_x, self.cov_xy], [self.cov_xy, self.var_y]])
    }

    /// Checks that this is a covariance (finite, variances ≥ 0, |cov_xy| ≤ √(var_x·var_y))
    /// and factors it for sampling; errors name `key`.
    pub fn factor(&self, key: &str) -> Result<Gauss2> {
        for (name, value) in [("var_x", self.var_x), ("var_y", self.var_y)] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::parameter(
                    format!("{key}.{name}"),
                    value,
                    "must be a finite variance ≥ 0",
                ));
            }
        }
        let bound = (self.var_x * self.var_y).sqrt();
        if !(self.cov_xy.is_finite() && self.cov_xy.abs() <= bound * (1.0 + 1e-12)) {
            return Err(Error::parameter(
                format!("{key}.cov_xy"),
                self.cov_xy,
                format!(
                    "must satisfy |cov_xy| ≤ √(var_x·var_y) = {bound} (a covariance is positive \
                     semi-definite)"
                ),
            ));
        }
        // Cholesky factor L with L·Lᵀ = Σ; a zero variance gives a zero column.
        let l11 = self.var_x.sqrt();
        let l21 = if l11 > 0.0 { self.cov_xy / l11 } else { 0.0 };
        let l22 = (self.var_y - l21 * l21).max(0.0).sqrt();
        Ok(Gauss2 { l11, l21, l22 })
    }

    /// As [`Noise2::factor`], and also requires a positive determinant (a measurement noise
    /// must be invertible).
    pub fn factor_positive_definite(&self, key: &str) -> Result<Gauss2> {
        let factor = self.factor(key)?;
        let determinant = self.matrix().determinant();
        if determinant.is_nan() || determinant <= 0.0 {
            return Err(Error::parameter(
                key,
                format!("{self:?}"),
                "must be positive definite: var_x > 0, var_y > 0 and cov_xy² < var_x·var_y",
            ));
        }
        Ok(factor)
    }
}

/// A validated 2-D Gaussian noise, stored as its lower Cholesky factor for sampling.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Gauss2 {
    l11: f64,
    l21: f64,
    l22: f64,
}

impl Gauss2 {
    /// No noise at all.
    pub const ZERO: Gauss2 = Gauss2 {
        l11: 0.0,
        l21: 0.0,
        l22: 0.0,
    };

    /// One draw, with standard deviations multiplied by `scale` (√ of a variance factor).
    #[inline]
    pub fn sample(&self, scale: f64, normals: &mut Normals<'_>) -> (f64, f64) {
        self.correlate(scale, normals.pair())
    }

    /// The draw made of the standard normal pair `(z1, z2)`: `scale·L·z`.
    #[inline(always)]
    pub(crate) fn correlate(&self, scale: f64, (z1, z2): (f64, f64)) -> (f64, f64) {
        (
            scale * self.l11 * z1,
            scale * (self.l21 * z1 + self.l22 * z2),
        )
    }

    /// The covariance this factor stands for.
    pub fn covariance(&self) -> Matrix<2, 2> {
        let cov_xy = self.l11 * self.l21;
        Matrix([
            [self.l11 * self.l11, cov_xy],
            [cov_xy, self.l21 * self.l21 + self.l22 * self.l22],
        ])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factor_reproduces_the_covariance_and_names_bad_keys() {
        // The saltating position noise of the authors' code (beadtracking.md §2.3).
        let salt = Noise2 {
            var_x: 20.16,
            var_y: 20.52,
            cov_xy: -13.0,
        };
        let g = salt.factor("salt_pos_noise").unwrap();
        assert!(g.covariance().max_abs_diff(&salt.matrix()) < 1e-12);
        let singular = Noise2::diagonal(0.0, 2.0).factor("k").unwrap();
        assert!(
            singular
                .covariance()
                .max_abs_diff(&Matrix([[0.0, 0.0], [0.0, 2.0]]))
                < 1e-15
        );
        let err = Noise2::diagonal(-1.0, 1.0)
            .factor("rest_pos_noise")
            .unwrap_err();
        assert!(err.to_string().contains("`rest_pos_noise.var_x`"), "{err}");
        let err = Noise2 {
            var_x: 1.0,
            var_y: 1.0,
            cov_xy: 2.0,
        }
        .factor("k")
        .unwrap_err();
        assert!(err.to_string().contains("`k.cov_xy`"), "{err}");
        let err = Noise2::diagonal(0.0, 1.0)
            .factor_positive_definite("measurement_noise")
            .unwrap_err();
        assert!(err.to_string().contains("`measurement_noise`"), "{err}");
    }
}

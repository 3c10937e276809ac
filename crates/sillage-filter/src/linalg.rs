//! Small fixed-size matrices for the Kalman filters (4×4 states, 2×2 innovations) and the
//! Gaussian refill of the IMM particle filter (6×6).
//!
//! Hand-written rather than a dependency: the filters need products, transposes, sums and one
//! 2×2 inverse and a Cholesky factor, all on the stack.

use std::ops::{Add, Mul, Sub};

/// A dense `R × C` matrix of `f64`, row-major, on the stack.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Matrix<const R: usize, const C: usize>(pub [[f64; C]; R]);

/// A column vector of `N` entries.
pub type Vector<const N: usize> = Matrix<N, 1>;

/// Serialised as its `R·C` entries in row-major order (serde derives arrays of fixed sizes
/// only, not of const-generic ones); checkpoints of the filters carry their matrices.
impl<const R: usize, const C: usize> serde::Serialize for Matrix<R, C> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.0.iter().flatten())
    }
}

impl<'de, const R: usize, const C: usize> serde::Deserialize<'de> for Matrix<R, C> {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let entries = Vec::<f64>::deserialize(deserializer)?;
        if entries.len() != R * C {
            return Err(serde::de::Error::invalid_length(
                entries.len(),
                &format!("{} entries of a {R}×{C} matrix", R * C).as_str(),
            ));
        }
        let mut out = Self::ZERO;
        for (slot, value) in out.0.iter_mut().flatten().zip(entries) {
            *slot = value;
        }
        Ok(out)
    }
}

impl<const R: usize, const C: usize> Matrix<R, C> {
    /// The zero matrix.
    pub const ZERO: Self = Matrix([[0.0; C]; R]);

    /// The transpose.
    pub fn transpose(&self) -> Matrix<C, R> {
        let mut out = Matrix::<C, R>::ZERO;
        for (r, row) in self.0.iter().enumerate() {
            for (c, &value) in row.iter().enumerate() {
                out.0[c][r] = value;
            }
        }
        out
    }

    /// Every entry multiplied by `factor`.
    pub fn scaled(&self, factor: f64) -> Self {
        let mut out = *self;
        out.0.iter_mut().flatten().for_each(|v| *v *= factor);
        out
    }

    /// The largest absolute entry-wise difference to `other` (for tests and tolerances).
    pub fn max_abs_diff(&self, other: &Self) -> f64 {
        self.0
            .iter()
            .flatten()
            .zip(other.0.iter().flatten())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    }
}

impl<const N: usize> Matrix<N, N> {
    /// The identity matrix.
    pub fn identity() -> Self {
        let mut out = Self::ZERO;
        for i in 0..N {
            out.0[i][i] = 1.0;
        }
        out
    }

    /// A diagonal matrix with `diagonal` on its diagonal.
    pub fn diagonal(diagonal: [f64; N]) -> Self {
        let mut out = Self::ZERO;
        for (i, d) in diagonal.into_iter().enumerate() {
            out.0[i][i] = d;
        }
        out
    }

    /// The lower-triangular `L` with `L·Lᵀ = self` for a symmetric positive semi-definite
    /// matrix (a covariance to sample from): a pivot that rounding leaves at or below zero
    /// gives a zero column, so a degenerate covariance (a coordinate with no spread) still
    /// samples. Only the lower triangle is read.
    pub fn cholesky_semidefinite(&self) -> Self {
        let mut l = Self::ZERO;
        for c in 0..N {
            let pivot = self.0[c][c] - (0..c).map(|k| l.0[c][k] * l.0[c][k]).sum::<f64>();
            if pivot.is_nan() || pivot <= 1e-12 * self.0[c][c].abs() || pivot.is_infinite() {
                continue;
            }
            let root = pivot.sqrt();
            l.0[c][c] = root;
            for r in c + 1..N {
                let dot: f64 = (0..c).map(|k| l.0[r][k] * l.0[c][k]).sum();
                l.0[r][c] = (self.0[r][c] - dot) / root;
            }
        }
        l
    }

    /// `(self + selfᵀ) / 2`: removes the rounding asymmetry a covariance update leaves.
    pub fn symmetrised(&self) -> Self {
        let mut out = *self;
        for r in 0..N {
            for c in r + 1..N {
                let mean = 0.5 * (self.0[r][c] + self.0[c][r]);
                out.0[r][c] = mean;
                out.0[c][r] = mean;
            }
        }
        out
    }
}

impl<const N: usize> Vector<N> {
    /// A column vector from its entries.
    pub fn from_array(values: [f64; N]) -> Self {
        Matrix(values.map(|v| [v]))
    }

    /// Entry `i`.
    pub fn at(&self, i: usize) -> f64 {
        self.0[i][0]
    }

    /// The outer product `self · selfᵀ` (a spread term of the IMM mixing and combination).
    pub fn outer(&self) -> Matrix<N, N> {
        let mut out = Matrix::<N, N>::ZERO;
        for r in 0..N {
            for c in 0..N {
                out.0[r][c] = self.0[r][0] * self.0[c][0];
            }
        }
        out
    }
}

impl Matrix<2, 2> {
    /// The determinant.
    pub fn determinant(&self) -> f64 {
        let [[a, b], [c, d]] = self.0;
        a * d - b * c
    }

    /// The inverse, or `None` when the determinant is not a positive finite number (the only
    /// case a covariance needs).
    pub fn inverse_positive_definite(&self) -> Option<Self> {
        let det = self.determinant();
        if !(det.is_finite() && det > 0.0) {
            return None;
        }
        let [[a, b], [c, d]] = self.0;
        Some(Matrix([[d / det, -b / det], [-c / det, a / det]]))
    }
}

impl<const R: usize, const C: usize, const K: usize> Mul<Matrix<C, K>> for Matrix<R, C> {
    type Output = Matrix<R, K>;

    fn mul(self, rhs: Matrix<C, K>) -> Matrix<R, K> {
        let mut out = Matrix::<R, K>::ZERO;
        for r in 0..R {
            for c in 0..C {
                let a = self.0[r][c];
                for k in 0..K {
                    out.0[r][k] += a * rhs.0[c][k];
                }
            }
        }
        out
    }
}

impl<const R: usize, const C: usize> Add for Matrix<R, C> {
    type Output = Self;

    fn add(mut self, rhs: Self) -> Self {
        self.0
            .iter_mut()
            .flatten()
            .zip(rhs.0.iter().flatten())
            .for_each(|(a, b)| *a += b);
        self
    }
}

impl<const R: usize, const C: usize> Sub for Matrix<R, C> {
    type Output = Self;

    fn sub(mut self, rhs: Self) -> Self {
        self.0
            .iter_mut()
            .flatten()
            .zip(rhs.0.iter().flatten())
            .for_each(|(a, b)| *a -= b);
        self
    }
}

/// A Gaussian density over an `N`-dimensional state: the Kalman filter's belief and the
/// particle filter's weighted moments, so the two compare directly.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Gaussian<const N: usize> {
    /// Mean.
    pub mean: Vector<N>,
    /// Covariance (symmetric, positive semi-definite).
    pub cov: Matrix<N, N>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_transposes_and_inverse() {
        let a = Matrix([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        let b = Matrix([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]);
        assert_eq!((a * b).0, [[4.0, 5.0], [10.0, 11.0]]);
        assert_eq!(a.transpose().0, [[1.0, 4.0], [2.0, 5.0], [3.0, 6.0]]);
        let s = Matrix([[4.0, 1.0], [1.0, 3.0]]);
        let inv = s.inverse_positive_definite().unwrap();
        assert!((s * inv).max_abs_diff(&Matrix::identity()) < 1e-15);
        assert!(
            Matrix([[1.0, 2.0], [2.0, 1.0]])
                .inverse_positive_definite()
                .is_none()
        );
        let v = Vector::from_array([1.0, -2.0]);
        assert_eq!(v.outer().0, [[1.0, -2.0], [-2.0, 4.0]]);
        let cov = Matrix([[4.0, 2.0, 0.0], [2.0, 5.0, 0.0], [0.0, 0.0, 0.0]]);
        let l = cov.cholesky_semidefinite();
        assert!((l * l.transpose()).max_abs_diff(&cov) < 1e-12);
        assert_eq!(l.0[2], [0.0; 3]);
        assert_eq!(
            Matrix([[1.0, 2.0], [4.0, 1.0]]).symmetrised().0,
            [[1.0, 3.0], [3.0, 1.0]]
        );
    }
}

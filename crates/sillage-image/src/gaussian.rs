//! Gaussian blur of a [`GrayImage`]: separable, SIMD-friendly, parallel over row bands.
//!
//! The kernel is the sampled Gaussian `exp(-j²/2σ²)` truncated at `±ceil(3σ)` (99.7 % of the
//! mass) and normalised to sum 1; the border is reflect-101 (`… 2 1 | 0 1 2 …`, OpenCV's
//! default, which is also what TracTrac really gets, see its quirk 2).

use sillage_core::{Error, GrayImage, Result};

use crate::separable::{Combine, filter};

/// Largest σ accepted (px): beyond it the kernel would be wider than any sensible frame.
pub const MAX_SIGMA_PX: f64 = 100.0;

/// A normalised, truncated, sampled 1-D Gaussian, stored as a half-kernel.
#[derive(Debug, Clone, PartialEq)]
pub struct GaussianKernel {
    sigma: f64,
    half: Vec<f32>,
}

impl GaussianKernel {
    /// The kernel of standard deviation `sigma` px, truncated at `±ceil(3σ)`; `sigma` must be
    /// finite and in `(0, MAX_SIGMA_PX]`.
    pub fn new(sigma: f64) -> Result<Self> {
        if !(sigma.is_finite() && sigma > 0.0 && sigma <= MAX_SIGMA_PX) {
            return Err(Error::parameter(
                "sigma",
                sigma,
                format!("must be a finite number in (0, {MAX_SIGMA_PX}] px"),
            ));
        }
        let radius = (3.0 * sigma).ceil() as usize;
        let full: Vec<f64> = (0..=radius)
            .map(|j| (-((j * j) as f64) / (2.0 * sigma * sigma)).exp())
            .collect();
        let total = full[0] + 2.0 * full[1..].iter().sum::<f64>();
        let half = full.iter().map(|&w| (w / total) as f32).collect();
        Ok(Self { sigma, half })
    }

    /// Standard deviation, px.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// Truncation radius `ceil(3σ)`: the kernel has `2·radius + 1` taps.
    pub fn radius(&self) -> usize {
        self.half.len() - 1
    }

    /// Weights at offsets `0, 1, …, radius` (the kernel is symmetric).
    pub fn half_weights(&self) -> &[f32] {
        &self.half
    }

    /// Weight at signed offset `j` (0 outside the support).
    pub fn weight(&self, j: isize) -> f32 {
        self.half.get(j.unsigned_abs()).copied().unwrap_or(0.0)
    }
}

/// A reusable Gaussian blur: owns its kernel and scratch, so blurring frame after frame
/// allocates nothing once the first frame has grown the scratch.
#[derive(Debug, Clone)]
pub struct GaussianFilter {
    kernel: GaussianKernel,
    scratch: Vec<f32>,
}

impl GaussianFilter {
    /// A blur of standard deviation `sigma` px (see [`GaussianKernel::new`] for the range).
    pub fn new(sigma: f64) -> Result<Self> {
        Ok(Self {
            kernel: GaussianKernel::new(sigma)?,
            scratch: Vec::new(),
        })
    }

    /// The kernel in use.
    pub fn kernel(&self) -> &GaussianKernel {
        &self.kernel
    }

    /// Blurs `src` into `dst` (reshaped to the size of `src`). Bit-identical whatever the
    /// number of rayon threads.
    pub fn apply(&mut self, src: &GrayImage, dst: &mut GrayImage) {
        filter(
            src,
            dst,
            Combine::Single(&self.kernel.half),
            &mut self.scratch,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernel_is_normalised_and_truncated_at_three_sigma() {
        let k = GaussianKernel::new(2.0).unwrap();
        assert_eq!(k.radius(), 6);
        let sum: f32 = (-6..=6).map(|j| k.weight(j)).sum();
        assert!((sum - 1.0).abs() < 1e-6);
        assert_eq!(k.weight(7), 0.0);
        assert_eq!(GaussianKernel::new(0.1).unwrap().radius(), 1);
        for bad in [0.0, -1.0, f64::NAN, 1e9] {
            let e = GaussianKernel::new(bad).unwrap_err().to_string();
            assert!(e.contains("sigma"), "{e}");
        }
    }
}

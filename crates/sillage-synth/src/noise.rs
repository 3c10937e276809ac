//! Pixel noise models of the synthetic images (TracTrac paper §4.1.1, Fig. 2).

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result};

/// Distribution of the uncorrelated noise added to every pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NoiseKind {
    /// Uniform on `[0, magnitude)`: the paper's "underlying uniform noise" (§4.1.2), so that
    /// SNR = blob peak / noise magnitude. It adds a mean background of `magnitude / 2`.
    #[default]
    Uniform,
    /// Zero-mean white Gaussian noise of standard deviation `magnitude`: the model of
    /// Cramér–Rao bounds on sub-pixel localisation. Pixels can go negative.
    Gaussian,
}

/// A noise model: its kind and its magnitude in grey levels (full scale 1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Noise {
    /// Distribution of the noise.
    pub kind: NoiseKind,
    /// Width of the uniform range, or standard deviation of the Gaussian; 0 draws nothing.
    pub magnitude: f64,
}

impl Noise {
    /// No noise at all (noise-free images, exact tests).
    pub const fn none() -> Self {
        Self {
            kind: NoiseKind::Uniform,
            magnitude: 0.0,
        }
    }

    /// Noise of `kind` and `magnitude`.
    pub const fn new(kind: NoiseKind, magnitude: f64) -> Self {
        Self { kind, magnitude }
    }

    pub(crate) fn validate(&self) -> Result<()> {
        if !(self.magnitude.is_finite() && self.magnitude >= 0.0) {
            return Err(Error::parameter(
                "noise.magnitude",
                self.magnitude,
                "must be a finite number ≥ 0",
            ));
        }
        Ok(())
    }
}

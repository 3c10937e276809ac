//! Parameters of the SIFT detector (Lowe 2004, with OpenCV's defaults and conventions).

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result};

/// Largest number of layers per octave accepted (Lowe 2004 found 3 best; more only costs).
pub const MAX_OCTAVE_LAYERS: usize = 10;

/// Largest base blur σ₀ accepted, px of the first octave.
pub const MAX_SIFT_SIGMA: f64 = 10.0;

/// SIFT parameters, with the names and meanings of OpenCV's `SIFT_create` (Lowe 2004's values).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SiftParams {
    /// `s`, DoG layers searched per octave (the Gaussian octave holds `s + 3` levels and the
    /// DoG `s + 2`); default 3 (Lowe 2004 §3.2, OpenCV's `nOctaveLayers`).
    pub octave_layers: usize,
    /// σ₀, the blur of the first level of each octave, in that octave's px; default 1.6 (Lowe
    /// 2004 §3.3).
    pub sigma: f64,
    /// Contrast threshold, OpenCV's convention: a refined extremum is kept when
    /// `|D(x̂)| ≥ contrast_threshold / octave_layers` on `[0, 1]` grey, and candidates are
    /// pre-filtered at half that (floored to whole 8-bit grey levels, as OpenCV does); default
    /// 0.04 (OpenCV; Lowe 2004 §4 used 0.03 with 3 layers).
    pub contrast_threshold: f32,
    /// Edge threshold `r`: a keypoint is kept when `tr(H)²/det(H) < (r+1)²/r` for the 2×2
    /// Hessian of the DoG (Lowe 2004 §4.1, Eq. (4)); default 10.
    pub edge_threshold: f32,
    /// Doubles the input first (assumed blur 0.5 px, so 1.0 px after doubling), the first
    /// octave being that doubled image (Lowe 2004 §3.3, OpenCV's default); default true.
    pub upsample: bool,
    /// At most this many octaves (`None`: OpenCV's count, `round(log2(min side)) − 2`, plus one
    /// for the doubled octave).
    pub max_octaves: Option<usize>,
}

impl Default for SiftParams {
    fn default() -> Self {
        Self {
            octave_layers: 3,
            sigma: 1.6,
            contrast_threshold: 0.04,
            edge_threshold: 10.0,
            upsample: true,
            max_octaves: None,
        }
    }
}

impl SiftParams {
    /// The permissive thresholds of the SIFT-PF tracker (Souded et al. 2011, §3.1.1: contrast
    /// 0.005, curvature 7.5), which give more keypoints to select from by robustness; other
    /// fields default.
    pub fn permissive() -> Self {
        Self {
            contrast_threshold: 0.005,
            edge_threshold: 7.5,
            ..Self::default()
        }
    }

    /// Checks every field; the error names the key and the allowed range.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_OCTAVE_LAYERS).contains(&self.octave_layers) {
            return Err(Error::parameter(
                "octave_layers",
                self.octave_layers,
                format!("must be an integer in [1, {MAX_OCTAVE_LAYERS}]"),
            ));
        }
        if !(self.sigma.is_finite() && self.sigma > 0.0 && self.sigma <= MAX_SIFT_SIGMA) {
            return Err(Error::parameter(
                "sigma",
                self.sigma,
                format!("must be a finite number in (0, {MAX_SIFT_SIGMA}] px"),
            ));
        }
        if !(self.contrast_threshold.is_finite() && (0.0..=1.0).contains(&self.contrast_threshold))
        {
            return Err(Error::parameter(
                "contrast_threshold",
                self.contrast_threshold,
                "must be a finite number in [0, 1] (grey levels in [0, 1])",
            ));
        }
        if !(self.edge_threshold.is_finite() && self.edge_threshold >= 1.0) {
            return Err(Error::parameter(
                "edge_threshold",
                self.edge_threshold,
                "must be a finite number ≥ 1 (the ratio of principal curvatures)",
            ));
        }
        if self.max_octaves == Some(0) {
            return Err(Error::parameter(
                "max_octaves",
                0,
                "must be at least 1, or left out for OpenCV's count",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_validate_and_bad_values_name_their_key() {
        SiftParams::default().validate().unwrap();
        SiftParams::permissive().validate().unwrap();
        let cases = [
            (
                SiftParams {
                    octave_layers: 0,
                    ..Default::default()
                },
                "octave_layers",
            ),
            (
                SiftParams {
                    sigma: f64::NAN,
                    ..Default::default()
                },
                "sigma",
            ),
            (
                SiftParams {
                    sigma: 0.0,
                    ..Default::default()
                },
                "sigma",
            ),
            (
                SiftParams {
                    contrast_threshold: -0.1,
                    ..Default::default()
                },
                "contrast_threshold",
            ),
            (
                SiftParams {
                    edge_threshold: 0.5,
                    ..Default::default()
                },
                "edge_threshold",
            ),
            (
                SiftParams {
                    max_octaves: Some(0),
                    ..Default::default()
                },
                "max_octaves",
            ),
        ];
        for (params, key) in cases {
            let message = params.validate().unwrap_err().to_string();
            assert!(message.contains(key), "{message}");
        }
    }
}

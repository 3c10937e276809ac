//! Parameters of the synthetic vortex flow (TracTrac paper §4.1.1) and their checks.

use rand::RngExt;
use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result, rng_stream};

use super::FlowKind;
use crate::noise::{Noise, NoiseKind};

/// Parameters of the vortex sequence. Defaults are the paper's Fig. 4 defaults where it gives
/// them (N = 1000, SNR = 4, intermittency = 0, Brownian = 0, δ = 0.01) and documented choices
/// elsewhere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VortexParams {
    /// Image width, px (default 1024).
    pub width: usize,
    /// Image height, px (default 1024).
    pub height: usize,
    /// Number of particles N alive in each frame (default 1000, Fig. 4).
    pub n_particles: usize,
    /// Number of frames the sequence yields (default 100: one period of Eq. 14's first term).
    pub n_frames: usize,
    /// The flow the particles follow (default the paper's vortex, Eqs. 13-16).
    pub flow: FlowKind,
    /// Time step δ of Eqs. 14-16 (default 0.01, §4.1.1); only for the paper's vortex.
    pub delta: f64,
    /// Largest displacement of the other flows, px per frame (default 5); the paper's vortex
    /// takes its speed from `delta`.
    pub max_displacement_px: f64,
    /// Standard deviation of each particle's Gaussian blob, px (default 2.0). TracTrac's DoG
    /// (Gaussians of 0.8δ_det and 1.2δ_det, §2.2) answers most to a blob of std
    /// √(0.8 · 1.2) δ_det ≈ 0.98 δ_det, so 2 px suits its δ_det = 2 px.
    pub blob_sigma_px: f64,
    /// When set, each particle's blob std is drawn uniformly in `[blob_sigma_px, this]` once
    /// for its identity (real particle images differ in size); default unset: all the same.
    pub blob_sigma_max_px: Option<f64>,
    /// Blob peak amplitude A in grey levels, full scale 1 (default 0.5, which leaves room for
    /// the noise and for overlaps below full scale).
    pub peak: f64,
    /// Signal-to-noise ratio: A over the noise magnitude (default 4, Fig. 4). Infinity gives
    /// noise-free images.
    pub snr: f64,
    /// Noise distribution (default uniform on `[0, A/SNR)`, as the paper).
    pub noise: NoiseKind,
    /// Probability, per particle and frame, of being re-seeded at a uniformly random position
    /// as a new identity (the paper's "intermittency", 0 to 0.5; default 0).
    pub intermittency: f64,
    /// Standard deviation of the white noise ξ of Eqs. 15-16, per axis, as a share of the
    /// particle's local deterministic displacement magnitude (§4.1.2: "in proportion of the
    /// deterministic flow velocity magnitude"; default 0).
    pub brownian: f64,
    /// Seed of every random draw (positions, re-seeding, ξ, pixel noise; default 0).
    pub seed: u64,
}

impl Default for VortexParams {
    fn default() -> Self {
        Self {
            width: 1024,
            height: 1024,
            n_particles: 1000,
            n_frames: 100,
            flow: FlowKind::PaperVortex,
            delta: 0.01,
            max_displacement_px: 5.0,
            blob_sigma_px: 2.0,
            blob_sigma_max_px: None,
            peak: 0.5,
            snr: 4.0,
            noise: NoiseKind::Uniform,
            intermittency: 0.0,
            brownian: 0.0,
            seed: 0,
        }
    }
}

/// Seed tag of the blob-size draws, apart from the particles' own streams.
const SIGMA_STREAM_TAG: u64 = 0x5167_6d61;

/// Largest image side accepted, px.
const MAX_SIDE: usize = 32_768;
/// Largest number of particles accepted.
const MAX_PARTICLES: usize = 10_000_000;

impl VortexParams {
    /// Checks every value; the error names the key and its allowed range.
    pub fn validate(&self) -> Result<()> {
        for (key, side) in [("width", self.width), ("height", self.height)] {
            if !(1..=MAX_SIDE).contains(&side) {
                return Err(Error::parameter(
                    key,
                    side,
                    format!("must be in 1..={MAX_SIDE}"),
                ));
            }
        }
        if self.n_particles > MAX_PARTICLES {
            return Err(Error::parameter(
                "n_particles",
                self.n_particles,
                format!("must be in 0..={MAX_PARTICLES}"),
            ));
        }
        check("delta", self.delta, 0.0..=1.0)?;
        check(
            "max_displacement_px",
            self.max_displacement_px,
            0.0..=1000.0,
        )?;
        check(
            "blob_sigma_px",
            self.blob_sigma_px,
            f64::MIN_POSITIVE..=100.0,
        )?;
        if let Some(max) = self.blob_sigma_max_px {
            check("blob_sigma_max_px", max, self.blob_sigma_px..=100.0)?;
        }
        check("peak", self.peak, f64::MIN_POSITIVE..=f64::MAX)?;
        if self.snr.is_nan() || self.snr <= 0.0 {
            return Err(Error::parameter(
                "snr",
                self.snr,
                "must be > 0 (inf: no noise)",
            ));
        }
        check("intermittency", self.intermittency, 0.0..=0.5)?;
        check("brownian", self.brownian, 0.0..=f64::MAX)
    }

    /// The blob std of the particle `track_id`: `blob_sigma_px`, or a draw in
    /// `[blob_sigma_px, blob_sigma_max_px]` from the identity's own stream.
    pub fn blob_sigma_of(&self, track_id: u64) -> f64 {
        match self.blob_sigma_max_px {
            Some(max) if max > self.blob_sigma_px => {
                let mut rng = rng_stream(self.seed ^ SIGMA_STREAM_TAG, track_id);
                rng.random_range(self.blob_sigma_px..=max)
            }
            _ => self.blob_sigma_px,
        }
    }

    /// The pixel noise these parameters ask for: magnitude A / SNR.
    pub fn pixel_noise(&self) -> Noise {
        Noise::new(self.noise, self.peak / self.snr)
    }
}

/// `value` must be finite and in `range`.
fn check(key: &str, value: f64, range: std::ops::RangeInclusive<f64>) -> Result<()> {
    if value.is_finite() && range.contains(&value) {
        Ok(())
    } else {
        let (low, high) = (range.start(), range.end());
        let message = if *high == f64::MAX {
            format!("must be a finite number ≥ {low}")
        } else {
            format!("must be a finite number in [{low}, {high}]")
        };
        Err(Error::parameter(key, value, message))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_name_their_key() {
        VortexParams::default().validate().unwrap();
        let cases: [(&str, VortexParams); 6] = [
            (
                "width",
                VortexParams {
                    width: 0,
                    ..Default::default()
                },
            ),
            (
                "delta",
                VortexParams {
                    delta: f64::NAN,
                    ..Default::default()
                },
            ),
            (
                "blob_sigma_px",
                VortexParams {
                    blob_sigma_px: 0.0,
                    ..Default::default()
                },
            ),
            (
                "snr",
                VortexParams {
                    snr: 0.0,
                    ..Default::default()
                },
            ),
            (
                "intermittency",
                VortexParams {
                    intermittency: 0.6,
                    ..Default::default()
                },
            ),
            (
                "brownian",
                VortexParams {
                    brownian: -1.0,
                    ..Default::default()
                },
            ),
        ];
        for (key, params) in cases {
            let err = params.validate().unwrap_err().to_string();
            assert!(err.contains(&format!("`{key}`")), "{err}");
        }
    }

    #[test]
    fn infinite_snr_means_no_noise() {
        let params = VortexParams {
            snr: f64::INFINITY,
            ..Default::default()
        };
        params.validate().unwrap();
        assert_eq!(params.pixel_noise().magnitude, 0.0);
    }
}

//! Parameters of the synthetic bead detector (MMPF+ paper §3.3) and their checks.

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result};

use super::params::{check, check_range};

/// Parameters of the detector model that turns true beads into detections and the
/// detector-confidence candidates of Eq. (1). Scores are the ring-correlation values of the
/// transparent-bead detector; black detections always have strength 1 (Eq. (1): `L(d) = 1`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BedloadDetectionParams {
    /// Standard deviation of the Gaussian noise added to each coordinate of a true bead's
    /// detection or weak candidate, px (default 0.5; §4.2 adds white noise to ExpSeq's
    /// truth to simulate measurements). Noisy positions are clamped into the frame.
    pub position_sigma_px: f64,
    /// Probability that a black bead is missed in a frame (default 0: §3.3.1, "black beads
    /// are never missed").
    pub black_miss_probability: f64,
    /// Probability that a transparent bead outside a burst is missed in a frame, on its own
    /// (default 0.03).
    pub transparent_miss_probability: f64,
    /// Probability, per transparent bead and frame outside a burst, that a burst of misses
    /// starts (default 0.01): an occluded or faint bead.
    pub burst_probability: f64,
    /// Consecutive frames a burst of misses lasts, its first included (default 5).
    pub burst_length: u32,
    /// Mean of the Poisson number of false positives per frame: transparent-class
    /// detections at uniform positions in the frame (default 1.0).
    pub false_positive_mean: f64,
    /// Range `[min, max)` of the uniform score of transparent detections, true or false
    /// (default [0.25, 0.6]: from the paper's threshold τ_t = 0.25 up).
    pub detection_score_range: [f64; 2],
    /// Probability that a missed transparent bead still leaves a weak candidate, a
    /// correlation maximum below τ_t, at its noisy position (default 0.8).
    pub weak_candidate_probability: f64,
    /// Range `[min, max)` of the weak candidates' scores (default [0.20, 0.25): from the
    /// code's candidate threshold 0.20 up to τ_t); at most the detection scores' minimum.
    pub weak_score_range: [f64; 2],
}

impl Default for BedloadDetectionParams {
    fn default() -> Self {
        Self {
            position_sigma_px: 0.5,
            black_miss_probability: 0.0,
            transparent_miss_probability: 0.03,
            burst_probability: 0.01,
            burst_length: 5,
            false_positive_mean: 1.0,
            detection_score_range: [0.25, 0.6],
            weak_candidate_probability: 0.8,
            weak_score_range: [0.20, 0.25],
        }
    }
}

/// Longest burst accepted, frames.
const MAX_BURST: u32 = 1_000_000;

impl BedloadDetectionParams {
    /// Checks every value; the error names the key and its allowed range.
    pub fn validate(&self) -> Result<()> {
        check("position_sigma_px", self.position_sigma_px, 0.0, 100.0)?;
        for (key, p) in [
            ("black_miss_probability", self.black_miss_probability),
            (
                "transparent_miss_probability",
                self.transparent_miss_probability,
            ),
            ("burst_probability", self.burst_probability),
            (
                "weak_candidate_probability",
                self.weak_candidate_probability,
            ),
        ] {
            check(key, p, 0.0, 1.0)?;
        }
        if !(1..=MAX_BURST).contains(&self.burst_length) {
            let message = format!("must be in 1..={MAX_BURST}");
            return Err(Error::parameter("burst_length", self.burst_length, message));
        }
        check("false_positive_mean", self.false_positive_mean, 0.0, 1e6)?;
        check_range(
            "detection_score_range",
            self.detection_score_range,
            0.0,
            1.0,
        )?;
        check_range("weak_score_range", self.weak_score_range, 0.0, 1.0)?;
        if self.weak_score_range[1] > self.detection_score_range[0] {
            return Err(Error::parameter(
                "weak_score_range",
                format!("{:?}", self.weak_score_range),
                format!(
                    "its max must be ≤ the min of `detection_score_range` ({}): weak \
                     candidates are the maxima below the detection threshold",
                    self.detection_score_range[0]
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_name_their_key() {
        BedloadDetectionParams::default().validate().unwrap();
        type Case = (&'static str, fn(&mut BedloadDetectionParams));
        let cases: [Case; 10] = [
            ("position_sigma_px", |p| p.position_sigma_px = -1.0),
            ("black_miss_probability", |p| {
                p.black_miss_probability = f64::NAN
            }),
            ("transparent_miss_probability", |p| {
                p.transparent_miss_probability = 1.5
            }),
            ("burst_probability", |p| p.burst_probability = -0.1),
            ("weak_candidate_probability", |p| {
                p.weak_candidate_probability = 2.0
            }),
            ("burst_length", |p| p.burst_length = 0),
            ("false_positive_mean", |p| p.false_positive_mean = -0.5),
            ("detection_score_range", |p| {
                p.detection_score_range = [0.25, 1.5]
            }),
            ("weak_score_range", |p| p.weak_score_range = [0.25, 0.2]),
            ("weak_score_range", |p| p.weak_score_range = [0.2, 0.3]),
        ];
        for (key, spoil) in cases {
            let mut params = BedloadDetectionParams::default();
            spoil(&mut params);
            let err = params.validate().unwrap_err().to_string();
            assert!(err.contains(&format!("`{key}`")), "{key}: {err}");
        }
    }
}

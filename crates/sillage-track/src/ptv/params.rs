//! Parameters of the PTV tracker, with TracTrac's defaults.

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result};

/// Parameters of [`crate::ptv::PtvTracker`]. Keys and defaults are those of TracTrac's
/// parameter file as its command line fills them in (`set_default_parameter`), so a
/// TracTrac `*_par.txt` maps one to one; `vote_search_px`, `ambiguity_ratio`, `max_displacement_px`
/// and `dt`
/// are additions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PtvParams {
    /// Use the motion model to predict positions before associating (default `true`).
    pub motion: bool,
    /// k, the number of nearest model samples averaged (Eq. 8); default 10.
    pub motion_av: usize,
    /// Extra predict–associate iterations per frame, the model rebuilt from the frame's own
    /// tracklets (§3.1.2 "iterative sequence"); default 0.
    pub motion_it: usize,
    /// Reject tracklets whose prediction error is an outlier (§3.1.3); default `true`.
    pub filter: bool,
    /// n_σ of the outlier test on the log10 error (§3.1.3); default 1.5. May be negative.
    pub filter_std: f64,
    /// Memory weight of the motion model and of the threshold (TracTrac's relaxation weight;
    /// the paper's α ≈ 1 / (1 + filter_time)); default 1.0.
    pub filter_time: f64,
    /// Displacement voting for fast flows (p⁻¹ ≳ 0.5, see `voting`): at every frame, the
    /// motion model's prediction is corrected by the local displacement that the pairs
    /// within this many px of it vote for, and before the model has samples (the start of
    /// the first pass) the prediction is voted from zero motion. Set it to the largest
    /// expected error of a zero-motion guess, i.e. the largest displacement; default `None`
    /// (TracTrac's behaviour: the prediction is the model alone, zero at the start).
    pub vote_search_px: Option<f64>,
    /// Ambiguity (ratio) test, for flows where objects appear and vanish (intermittency):
    /// a link is dropped when the nearest point of frame t to the prediction is not
    /// clearly nearer than the second, `d₁ > ambiguity_ratio · d₂` (Lowe's ratio test).
    /// A correct link sits at the prediction's error from it, far closer than the spacing;
    /// a point that appeared at random does not. 0.3 is a good value; default `None`
    /// (TracTrac's behaviour). In fast flows, use it with `vote_search_px`.
    pub ambiguity_ratio: Option<f64>,
    /// Reject pairs whose displacement exceeds this many px (TracTrac has no such gate);
    /// default `None`.
    pub max_displacement_px: Option<f64>,
    /// Time between frames in the unit velocities are reported in; 1.0 gives px/frame.
    pub dt: f64,
}

impl Default for PtvParams {
    fn default() -> Self {
        Self {
            motion: true,
            motion_av: 10,
            motion_it: 0,
            filter: true,
            filter_std: 1.5,
            filter_time: 1.0,
            vote_search_px: None,
            ambiguity_ratio: None,
            max_displacement_px: None,
            dt: 1.0,
        }
    }
}

/// Largest accepted `motion_it` (each iteration costs a full association).
const MAX_MOTION_IT: usize = 100;

impl PtvParams {
    /// Checks every value; the error names the key and its allowed range.
    pub fn validate(&self) -> Result<()> {
        if self.motion_av == 0 {
            return Err(Error::parameter(
                "motion_av",
                self.motion_av,
                "must be an integer ≥ 1 (number of neighbours averaged; TracTrac uses 10)",
            ));
        }
        if self.motion_it > MAX_MOTION_IT {
            return Err(Error::parameter(
                "motion_it",
                self.motion_it,
                format!("must be an integer in 0..={MAX_MOTION_IT}"),
            ));
        }
        if !self.filter_std.is_finite() {
            return Err(Error::parameter(
                "filter_std",
                self.filter_std,
                "must be a finite number (n_σ, typically 1.5)",
            ));
        }
        if !(self.filter_time.is_finite() && self.filter_time >= 0.0) {
            return Err(Error::parameter(
                "filter_time",
                self.filter_time,
                "must be a finite number ≥ 0 (typically 1)",
            ));
        }
        if let Some(radius) = self.vote_search_px
            && !(radius.is_finite() && radius > 0.0)
        {
            return Err(Error::parameter(
                "vote_search_px",
                radius,
                "must be a finite number > 0 (the largest expected displacement, px), or \
                 absent for no displacement voting",
            ));
        }
        if let Some(ratio) = self.ambiguity_ratio
            && !(ratio > 0.0 && ratio <= 1.0)
        {
            return Err(Error::parameter(
                "ambiguity_ratio",
                ratio,
                "must be a number in (0, 1] (typically 0.3), or absent for no ambiguity test",
            ));
        }
        if let Some(gate) = self.max_displacement_px
            && !(gate.is_finite() && gate > 0.0)
        {
            return Err(Error::parameter(
                "max_displacement_px",
                gate,
                "must be a finite number > 0, or absent for no gate",
            ));
        }
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(Error::parameter(
                "dt",
                self.dt,
                "must be a finite number > 0 (backward passes negate it themselves)",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_errors_name_the_key() {
        PtvParams::default().validate().unwrap();
        let cases = [
            (
                "motion_av",
                PtvParams {
                    motion_av: 0,
                    ..Default::default()
                },
            ),
            (
                "motion_it",
                PtvParams {
                    motion_it: 1000,
                    ..Default::default()
                },
            ),
            (
                "filter_std",
                PtvParams {
                    filter_std: f64::NAN,
                    ..Default::default()
                },
            ),
            (
                "filter_time",
                PtvParams {
                    filter_time: -1.0,
                    ..Default::default()
                },
            ),
            (
                "vote_search_px",
                PtvParams {
                    vote_search_px: Some(f64::INFINITY),
                    ..Default::default()
                },
            ),
            (
                "ambiguity_ratio",
                PtvParams {
                    ambiguity_ratio: Some(1.5),
                    ..Default::default()
                },
            ),
            (
                "max_displacement_px",
                PtvParams {
                    max_displacement_px: Some(0.0),
                    ..Default::default()
                },
            ),
            (
                "dt",
                PtvParams {
                    dt: 0.0,
                    ..Default::default()
                },
            ),
        ];
        for (key, params) in cases {
            let message = params.validate().unwrap_err().to_string();
            assert!(message.contains(&format!("`{key}`")), "{message}");
        }
    }
}

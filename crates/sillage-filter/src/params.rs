//! Parameters as the user writes them (serde), with the MMPF+ paper's defaults and, where the
//! paper gives none, the authors' code's (`../shared/reference/beadtracking.md`, §2.3).
//! Each is validated once, before any work runs; errors name the key.

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result, Vec2};

use crate::noise::Noise2;
use crate::resample::Resampling;

/// The transition table of Eq. (11), as estimated on the training halves (§4.3); rows are
/// from-states, columns to-states, both in the order resting, rolling, saltating.
pub const TRANSITION_EQ11: [[f64; 3]; 3] =
    [[0.95, 0.05, 0.00], [0.07, 0.92, 0.01], [0.00, 0.09, 0.91]];

/// The transition table of Eq. (12): Eq. (11) with a minimal probability of 0.05, so that each
/// state keeps particles at N = 100 (§4.3; the default).
pub const TRANSITION_EQ12: [[f64; 3]; 3] =
    [[0.80, 0.15, 0.05], [0.10, 0.80, 0.10], [0.05, 0.15, 0.80]];

/// Largest particle count (ancestor indices are 32-bit).
pub const MAX_PARTICLES: usize = u32::MAX as usize;

/// Parameters of one particle filter per target.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FilterParams {
    /// N, the particles per target; default 100 (§4.3, "a good compromise between
    /// computational cost and tracking reliability").
    pub particles: usize,
    /// When and how to resample; default multinomial at every step (§3.5.2).
    pub resampling: Resampling,
}

impl Default for FilterParams {
    fn default() -> Self {
        Self {
            particles: 100,
            resampling: Resampling::default(),
        }
    }
}

impl FilterParams {
    /// Checks every value; the error names the key and its allowed range.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_PARTICLES).contains(&self.particles) {
            return Err(Error::parameter(
                "particles",
                self.particles,
                format!("must be an integer in 1..={MAX_PARTICLES} (the paper uses N = 100)"),
            ));
        }
        self.resampling.validate()
    }
}

/// Parameters of the bedload motion models of Eq. (3) and their jump-Markov switching
/// (§3.5.1, §4.3). Positions in px, velocities in px/frame, so Δt = 1 frame; noises are
/// covariances (px², px²/frame²).
///
/// The paper estimates the noises on training sequences without printing them; the position
/// noises default to the authors' code's. Neither gives velocity noises: they default to the
/// position noise of the same state, until `sillage fit bedload` estimates them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BedloadParams {
    /// π = p(sₜ | sₜ₋₁) over (resting, rolling, saltating), rows summing to 1; default Eq. (12),
    /// [`TRANSITION_EQ11`] is the unmodified estimate.
    pub transition: [[f64; 3]; 3],
    /// The row of the initial "unknown" state (§4.3: "the particles had an equivalent chance to
    /// go in any of the motion states"); default ⅓ each (the code's is [0.33, 0.33, 0.34]).
    pub unknown_transition: [f64; 3],
    /// Probability of the saltating-rebound sub-state when saltating is drawn; default 0.5
    /// (§4.3).
    pub rebound_probability: f64,
    /// ε_rest^(x,y), px²; default the code's `pfXYCovRest` = diag(0.25, 0.25).
    pub rest_pos_noise: Noise2,
    /// ε_roll^(x,y), px²; default the code's `pfXYCovRoll` = [3.04 0.04; 0.04 2.20].
    pub roll_pos_noise: Noise2,
    /// ε_roll^(u,v), px²/frame²; default as `roll_pos_noise` (not given by the paper or code).
    pub roll_vel_noise: Noise2,
    /// ε_salt^(x,y), px²; default the code's `pfXYCovSalt` = [20.16 −13.0; −13.0 20.52].
    pub salt_pos_noise: Noise2,
    /// ε_salt^(u,v), px²/frame²; default as `salt_pos_noise` (not given by the paper or code).
    pub salt_vel_noise: Noise2,
    /// A track is young while its length, counting the frame predicted into, is at most this;
    /// default 3 (§4.3, "during the first 3 frames"; the code's `newTrackLength`).
    pub young_frames: u32,
    /// Factor on every process-noise variance of a young track; default 1.5 (the code's
    /// `newTrackCovCoef`; the paper says only "increased the variances").
    pub young_variance_factor: f64,
    /// Spread of the initial positions around the detection, px²; default 1.5·`pfXYCovRoll`
    /// (the code's initialisation).
    pub init_pos_noise: Noise2,
    /// Spread of the initial velocities around zero, px²/frame² (§4.3, "velocities centered
    /// to null velocity"); default as `init_pos_noise`.
    pub init_vel_noise: Noise2,
    /// Velocity of the water flow, px/frame; default the code's example sequence, vMax =
    /// 0.83 m/s at 2.056e-4 m/px and 130 fps flowing right to left: (−31.05, 0). Set it for
    /// your sequence.
    pub flow_vel_px_per_frame: Vec2,
    /// A particle leaving the unknown state for saltating starts at this fraction of the flow
    /// velocity (§3.5.1); default 0.5 (the code's `veloSaltInit` = vMax/2).
    pub salt_init_fraction: f64,
}

impl Default for BedloadParams {
    fn default() -> Self {
        let roll = Noise2 {
            var_x: 3.04,
            var_y: 2.20,
            cov_xy: 0.04,
        };
        let salt = Noise2 {
            var_x: 20.16,
            var_y: 20.52,
            cov_xy: -13.0,
        };
        let init = roll.scaled(1.5);
        Self {
            transition: TRANSITION_EQ12,
            unknown_transition: [1.0 / 3.0; 3],
            rebound_probability: 0.5,
            rest_pos_noise: Noise2::diagonal(0.25, 0.25),
            roll_pos_noise: roll,
            roll_vel_noise: roll,
            salt_pos_noise: salt,
            salt_vel_noise: salt,
            young_frames: 3,
            young_variance_factor: 1.5,
            init_pos_noise: init,
            init_vel_noise: init,
            flow_vel_px_per_frame: Vec2::new(-0.83 / 2.056e-4 / 130.0, 0.0),
            salt_init_fraction: 0.5,
        }
    }
}

impl BedloadParams {
    /// The four transition rows (resting, rolling, saltating, unknown) after validation.
    pub(crate) fn transition_rows(&self) -> Result<[[f64; 3]; 4]> {
        crate::switching::TransitionTable::new("transition", &self.transition)?;
        crate::switching::TransitionTable::new("unknown_transition", &[self.unknown_transition])?;
        let [rest, roll, salt] = self.transition;
        Ok([rest, roll, salt, self.unknown_transition])
    }

    /// Checks every value; the error names the key and its allowed range.
    pub fn validate(&self) -> Result<()> {
        self.transition_rows()?;
        for (key, noise) in self.noises() {
            noise.factor(key)?;
        }
        let checks = [
            (
                "rebound_probability",
                self.rebound_probability,
                (0.0..=1.0).contains(&self.rebound_probability),
                "must be a probability in [0, 1] (the paper uses 0.5)",
            ),
            (
                "young_variance_factor",
                self.young_variance_factor,
                self.young_variance_factor.is_finite() && self.young_variance_factor > 0.0,
                "must be a finite factor > 0 (the authors' code uses 1.5)",
            ),
            (
                "salt_init_fraction",
                self.salt_init_fraction,
                self.salt_init_fraction.is_finite(),
                "must be a finite number (the authors' code uses 0.5)",
            ),
            (
                "flow_vel_px_per_frame.x",
                self.flow_vel_px_per_frame.x,
                self.flow_vel_px_per_frame.x.is_finite(),
                "must be a finite velocity, px/frame",
            ),
            (
                "flow_vel_px_per_frame.y",
                self.flow_vel_px_per_frame.y,
                self.flow_vel_px_per_frame.y.is_finite(),
                "must be a finite velocity, px/frame",
            ),
        ];
        for (key, value, ok, message) in checks {
            if !ok {
                return Err(Error::parameter(key, value, message));
            }
        }
        Ok(())
    }

    /// Every noise with its key.
    pub(crate) fn noises(&self) -> [(&'static str, &Noise2); 7] {
        [
            ("rest_pos_noise", &self.rest_pos_noise),
            ("roll_pos_noise", &self.roll_pos_noise),
            ("roll_vel_noise", &self.roll_vel_noise),
            ("salt_pos_noise", &self.salt_pos_noise),
            ("salt_vel_noise", &self.salt_vel_noise),
            ("init_pos_noise", &self.init_pos_noise),
            ("init_vel_noise", &self.init_vel_noise),
        ]
    }
}

/// One kinematic model as the user writes it (`model = "constant_velocity"`, ...); noises are
/// covariances per frame (px², px²/frame², px²/frame⁴).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum KinematicParams {
    /// Position random walk, velocity and acceleration zero (Eq. (10) of the IMM-PF paper).
    ConstantPosition {
        /// Position noise.
        pos_noise: Noise2,
    },
    /// Constant velocity with velocity noise, acceleration zero (Eq. (11)).
    ConstantVelocity {
        /// Position noise.
        pos_noise: Noise2,
        /// Velocity noise.
        vel_noise: Noise2,
    },
    /// Constant acceleration with acceleration noise (Eq. (12)).
    ConstantAcceleration {
        /// Position noise.
        pos_noise: Noise2,
        /// Velocity noise.
        vel_noise: Noise2,
        /// Acceleration noise.
        acc_noise: Noise2,
    },
}

/// Kinematic models switched by a transition table (see `motion::kinematic::Switching`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SwitchingParams {
    /// The models; a particle's mode is an index into this list.
    pub models: Vec<KinematicParams>,
    /// Square row-stochastic table, `transition[from][to]`.
    pub transition: Vec<Vec<f64>>,
}

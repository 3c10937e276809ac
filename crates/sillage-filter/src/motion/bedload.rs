//! The bead motions of the MMPF+ paper, Eq. (3), switched per particle by the transition table
//! π (§3.5.1, Eqs. (11)-(12)):
//!
//! - resting: `x ← x + ε_rest`;
//! - rolling: `x ← x + (u, 0) + ε_roll`, `u ← (u, 0) + ε_roll^(u,v)`;
//! - saltating-constant: `x ← x + (u, v) + ε_salt`, `u ← (u, v) + ε_salt^(u,v)`;
//! - saltating-rebound: `x ← x + (u, −v) + ε_salt`, `u ← (u, −v) + ε_salt^(u,v)`.
//!
//! Particles start "unknown" (§4.3); when saltating is drawn, each sub-state has probability
//! 0.5; a particle leaving "unknown" for saltating takes a fraction of the flow velocity
//! (§3.5.1); the noises of a young track are inflated (§4.3). Resting has no velocity equation
//! in Eq. (3): its velocity is carried unchanged.

use sillage_core::{MotionState, Point2, Result, RngStream, Vec2};

use crate::imm::KalmanImm;
use crate::kalman::LinearGaussian;
use crate::linalg::{Gaussian, Matrix};
use crate::motion::MotionModel;
use crate::motion::kinematic::{constant_position, constant_velocity};
use crate::noise::Gauss2;
use crate::normal::Normals;
use crate::params::BedloadParams;
use crate::particles::{InitialSpread, Particles};
use crate::switching::TransitionTable;

/// A particle's bedload motion state, stored as its `u8` index in the mode column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum BedloadMode {
    /// Not yet drawn: every particle of a new tracker (§4.3).
    Unknown = 0,
    /// At rest on the bed.
    Resting = 1,
    /// Rolling or sliding on the bed: no vertical velocity.
    Rolling = 2,
    /// Saltating, flight continues.
    SaltatingConstant = 3,
    /// Saltating, vertical velocity reversed by a rebound.
    SaltatingRebound = 4,
}

impl BedloadMode {
    /// The mode stored as `index`, or `None` for an index no mode has.
    pub const fn from_index(index: u8) -> Option<Self> {
        match index {
            0 => Some(Self::Unknown),
            1 => Some(Self::Resting),
            2 => Some(Self::Rolling),
            3 => Some(Self::SaltatingConstant),
            4 => Some(Self::SaltatingRebound),
            _ => None,
        }
    }

    /// The index stored in the mode column.
    pub const fn index(self) -> u8 {
        self as u8
    }

    /// The motion state this mode belongs to (both saltating sub-states are `Saltating`): what
    /// the motion-state likelihood of Eq. (9) compares with the measured state.
    pub const fn motion_state(self) -> MotionState {
        match self {
            Self::Unknown => MotionState::Unknown,
            Self::Resting => MotionState::Resting,
            Self::Rolling => MotionState::Rolling,
            Self::SaltatingConstant | Self::SaltatingRebound => MotionState::Saltating,
        }
    }

    /// Row of the transition table: resting 0, rolling 1, saltating 2, unknown 3.
    const fn row(self) -> usize {
        match self {
            Self::Resting => 0,
            Self::Rolling => 1,
            Self::SaltatingConstant | Self::SaltatingRebound => 2,
            Self::Unknown => 3,
        }
    }
}

/// Table column of the saltating state.
const SALTATING: usize = 2;

/// The validated bedload motion model: Eq. (3) with jump-Markov switching.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BedloadModel {
    params: BedloadParams,
    /// Rows resting, rolling, saltating, unknown; columns resting, rolling, saltating.
    table: TransitionTable,
    rest_pos: Gauss2,
    roll_pos: Gauss2,
    roll_vel: Gauss2,
    salt_pos: Gauss2,
    salt_vel: Gauss2,
    init_pos: Gauss2,
    init_vel: Gauss2,
    /// √ of the young-track variance factor.
    young_scale: f64,
    salt_init_vel: Vec2,
}

impl BedloadModel {
    /// Validates `params` (errors name the key) and prepares the sampling factors.
    pub fn new(params: BedloadParams) -> Result<Self> {
        params.validate()?;
        let table = TransitionTable::new("transition", &params.transition_rows()?)?;
        Ok(Self {
            table,
            rest_pos: params.rest_pos_noise.factor("rest_pos_noise")?,
            roll_pos: params.roll_pos_noise.factor("roll_pos_noise")?,
            roll_vel: params.roll_vel_noise.factor("roll_vel_noise")?,
            salt_pos: params.salt_pos_noise.factor("salt_pos_noise")?,
            salt_vel: params.salt_vel_noise.factor("salt_vel_noise")?,
            init_pos: params.init_pos_noise.factor("init_pos_noise")?,
            init_vel: params.init_vel_noise.factor("init_vel_noise")?,
            young_scale: params.young_variance_factor.sqrt(),
            salt_init_vel: params.flow_vel_px_per_frame * params.salt_init_fraction,
            params,
        })
    }

    /// The parameters this model was built from.
    pub fn params(&self) -> &BedloadParams {
        &self.params
    }

    /// How a new tracker's particles start at detection `pos_px`: Gaussian positions around it,
    /// velocities around zero, every particle "unknown" (§4.3).
    pub fn initial_spread(&self, pos_px: Point2) -> InitialSpread {
        InitialSpread {
            pos_px,
            pos_noise: self.init_pos,
            vel_px_per_frame: Vec2::ZERO,
            vel_noise: self.init_vel,
            mode: BedloadMode::Unknown.index(),
        }
    }

    /// The linear-Gaussian form `(F, Q)` of one motion of Eq. (3) over `(x, y, u, v)`, for
    /// Kalman filtering; `None` for `Unknown`, which has no motion of its own.
    pub fn linear_model(&self, mode: BedloadMode) -> Option<LinearGaussian<4>> {
        let p = &self.params;
        // F of constant velocity, then the velocity transform of each motion before it.
        let cv = Matrix([
            [1.0, 0.0, 1.0, 0.0],
            [0.0, 1.0, 0.0, 1.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        let (transition, pos, vel) = match mode {
            BedloadMode::Unknown => return None,
            BedloadMode::Resting => (Matrix::identity(), p.rest_pos_noise, None),
            BedloadMode::Rolling => (
                cv * Matrix::diagonal([1.0, 1.0, 1.0, 0.0]),
                p.roll_pos_noise,
                Some(p.roll_vel_noise),
            ),
            BedloadMode::SaltatingConstant => (cv, p.salt_pos_noise, Some(p.salt_vel_noise)),
            BedloadMode::SaltatingRebound => (
                cv * Matrix::diagonal([1.0, 1.0, 1.0, -1.0]),
                p.salt_pos_noise,
                Some(p.salt_vel_noise),
            ),
        };
        let mut noise = Matrix::<4, 4>::ZERO;
        let blocks = [(0, Some(pos)), (2, vel)];
        for (offset, block) in blocks {
            if let Some(block) = block {
                let m = block.matrix();
                for r in 0..2 {
                    for c in 0..2 {
                        noise.0[offset + r][offset + c] = m.0[r][c];
                    }
                }
            }
        }
        Some(LinearGaussian { transition, noise })
    }

    /// The Kalman IMM of the three linear motions (resting, rolling, saltating-constant) with
    /// the transition table `transition` and initial mode probabilities the unknown row:
    /// the IMM baseline of Table 1 of the MMPF+ paper.
    pub fn kalman_imm(&self, initial: Gaussian<4>) -> KalmanImm<4> {
        let modes = [
            BedloadMode::Resting,
            BedloadMode::Rolling,
            BedloadMode::SaltatingConstant,
        ];
        let models = modes.map(|m| self.linear_model(m).expect("a motion of Eq. (3)"));
        let table = TransitionTable::new("transition", &self.params.transition)
            .expect("validated by BedloadModel::new");
        KalmanImm::new(
            models.to_vec(),
            table,
            initial,
            &self.params.unknown_transition,
        )
        .expect("three models, a 3×3 table and three probabilities")
    }
}

impl MotionModel for BedloadModel {
    fn propagate(&self, particles: &mut Particles, track_len: u32, rng: &mut RngStream) {
        let scale = if track_len <= self.params.young_frames {
            self.young_scale
        } else {
            1.0
        };
        let mut c = particles.columns_mut();
        let mut normals = Normals::new(rng);
        for i in 0..c.mode.len() {
            let from = BedloadMode::from_index(c.mode[i]).unwrap_or(BedloadMode::Unknown);
            let to = self.table.next_state(from.row(), normals.uniform());
            let mode = match to {
                0 => {
                    constant_position(&mut c, i, &self.rest_pos, scale, &mut normals);
                    BedloadMode::Resting
                }
                1 => {
                    c.vel_y[i] = 0.0;
                    constant_velocity(
                        &mut c,
                        i,
                        &self.roll_pos,
                        &self.roll_vel,
                        scale,
                        &mut normals,
                    );
                    BedloadMode::Rolling
                }
                _ => {
                    debug_assert_eq!(to, SALTATING);
                    if from == BedloadMode::Unknown {
                        c.vel_x[i] = self.salt_init_vel.x;
                        c.vel_y[i] = self.salt_init_vel.y;
                    }
                    let rebound = normals.uniform() < self.params.rebound_probability;
                    if rebound {
                        c.vel_y[i] = -c.vel_y[i];
                    }
                    constant_velocity(
                        &mut c,
                        i,
                        &self.salt_pos,
                        &self.salt_vel,
                        scale,
                        &mut normals,
                    );
                    if rebound {
                        BedloadMode::SaltatingRebound
                    } else {
                        BedloadMode::SaltatingConstant
                    }
                }
            };
            c.mode[i] = mode.index();
        }
    }
}

//! Constant position, constant velocity and constant acceleration models (Eqs. (10)-(12) of
//! the IMM-PF paper), alone, switched by a transition table, or competing inside the IMM
//! particle filter. The per-particle steps here are also the building blocks of the bedload
//! motions of Eq. (3) of the MMPF+ paper.

use sillage_core::{Error, Result, RngStream};

use crate::motion::MotionModel;
use crate::noise::{Gauss2, Noise2};
use crate::normal::Normals;
use crate::params::{KinematicParams, SwitchingParams};
use crate::particles::{Columns, Particles};
use crate::switching::TransitionTable;

/// `x ← x + ε_x`: particle `i` stays where it is up to noise; its velocity is kept.
#[inline]
pub(crate) fn constant_position(
    c: &mut Columns<'_>,
    i: usize,
    pos: &Gauss2,
    scale: f64,
    normals: &mut Normals<'_>,
) {
    let (dx, dy) = pos.sample(scale, normals);
    c.pos_x[i] += dx;
    c.pos_y[i] += dy;
}

/// `x ← x + u + ε_x, u ← u + ε_u` (one frame): the saltating-constant motion of Eq. (3).
#[inline]
pub(crate) fn constant_velocity(
    c: &mut Columns<'_>,
    i: usize,
    pos: &Gauss2,
    vel: &Gauss2,
    scale: f64,
    normals: &mut Normals<'_>,
) {
    let (dx, dy) = pos.sample(scale, normals);
    let (du, dv) = vel.sample(scale, normals);
    c.pos_x[i] += c.vel_x[i] + dx;
    c.pos_y[i] += c.vel_y[i] + dy;
    c.vel_x[i] += du;
    c.vel_y[i] += dv;
}

/// A validated kinematic model over `(x, y, u, v[, aₓ, a_y])`, one frame per step (T = 1):
/// `X ← A_k·X + ν` with the matrices of Eqs. (10)-(12) of the IMM-PF paper.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum KinematicModel {
    /// Eq. (10): `x ← x + ε_x`; velocity and acceleration reduced to zero.
    ConstantPosition {
        /// Position noise.
        pos: Gauss2,
    },
    /// Eq. (11): `x ← x + u + ε_x`, `u ← u + ε_u`; acceleration reduced to zero.
    ConstantVelocity {
        /// Position noise.
        pos: Gauss2,
        /// Velocity noise.
        vel: Gauss2,
    },
    /// Eq. (12): `x ← x + u + a/2 + ε_x`, `u ← u + a + ε_u`, `a ← a + ε_a`.
    ConstantAcceleration {
        /// Position noise.
        pos: Gauss2,
        /// Velocity noise.
        vel: Gauss2,
        /// Acceleration noise.
        acc: Gauss2,
    },
}

impl KinematicModel {
    /// Validates `params`; errors name the key under `key` (e.g. `models[1].vel_noise.var_x`).
    pub fn new(key: &str, params: &KinematicParams) -> Result<Self> {
        let factor = |name: &str, noise: &Noise2| noise.factor(&format!("{key}.{name}"));
        Ok(match params {
            KinematicParams::ConstantPosition { pos_noise } => Self::ConstantPosition {
                pos: factor("pos_noise", pos_noise)?,
            },
            KinematicParams::ConstantVelocity {
                pos_noise,
                vel_noise,
            } => Self::ConstantVelocity {
                pos: factor("pos_noise", pos_noise)?,
                vel: factor("vel_noise", vel_noise)?,
            },
            KinematicParams::ConstantAcceleration {
                pos_noise,
                vel_noise,
                acc_noise,
            } => Self::ConstantAcceleration {
                pos: factor("pos_noise", pos_noise)?,
                vel: factor("vel_noise", vel_noise)?,
                acc: factor("acc_noise", acc_noise)?,
            },
        })
    }

    /// Whether the model reads the acceleration columns (the constant-acceleration model).
    pub(crate) fn uses_acceleration(&self) -> bool {
        matches!(self, Self::ConstantAcceleration { .. })
    }

    /// Moves particle `i` one frame.
    #[inline]
    pub(crate) fn advance(&self, c: &mut Columns<'_>, i: usize, normals: &mut Normals<'_>) {
        match self {
            Self::ConstantPosition { pos } => {
                constant_position(c, i, pos, 1.0, normals);
                c.vel_x[i] = 0.0;
                c.vel_y[i] = 0.0;
                zero_acceleration(c, i);
            }
            Self::ConstantVelocity { pos, vel } => {
                constant_velocity(c, i, pos, vel, 1.0, normals);
                zero_acceleration(c, i);
            }
            Self::ConstantAcceleration { pos, vel, acc } => {
                let (dx, dy) = pos.sample(1.0, normals);
                let (du, dv) = vel.sample(1.0, normals);
                let (dax, day) = acc.sample(1.0, normals);
                let (ax, ay) = (c.acc_x[i], c.acc_y[i]);
                c.pos_x[i] += c.vel_x[i] + 0.5 * ax + dx;
                c.pos_y[i] += c.vel_y[i] + 0.5 * ay + dy;
                c.vel_x[i] += ax + du;
                c.vel_y[i] += ay + dv;
                c.acc_x[i] += dax;
                c.acc_y[i] += day;
            }
        }
    }
}

/// Sets particle `i`'s acceleration to zero where the set has acceleration columns (the zero
/// blocks of `A₁` and `A₂`, Eqs. (10)-(11) of the IMM-PF paper).
#[inline]
fn zero_acceleration(c: &mut Columns<'_>, i: usize) {
    if let (Some(ax), Some(ay)) = (c.acc_x.get_mut(i), c.acc_y.get_mut(i)) {
        *ax = 0.0;
        *ay = 0.0;
    }
}

impl MotionModel for KinematicModel {
    fn propagate(&self, particles: &mut Particles, _track_len: u32, rng: &mut RngStream) {
        if self.uses_acceleration() {
            particles.enable_acceleration();
        }
        let mut c = particles.columns_mut();
        let mut normals = Normals::new(rng);
        for i in 0..c.mode.len() {
            self.advance(&mut c, i, &mut normals);
        }
    }
}

/// Kinematic models switched per particle by a transition table (a jump-Markov system, as the
/// IMM particle filter uses): each particle draws its next mode from the row of its current
/// one, then moves by that mode's model. The mode index is the model's position in the list;
/// a particle whose mode is not one (set by its creator) is a bug and panics.
#[derive(Debug, Clone, PartialEq)]
pub struct Switching {
    table: TransitionTable,
    models: Vec<KinematicModel>,
}

impl Switching {
    /// Validates `params`: 1 to 255 models, a square table of that size; errors name the key.
    pub fn new(params: &SwitchingParams) -> Result<Self> {
        let count = params.models.len();
        if count == 0 || count > usize::from(u8::MAX) {
            return Err(Error::parameter(
                "models",
                count,
                "must list between 1 and 255 kinematic models",
            ));
        }
        let table = TransitionTable::new("transition", &params.transition)?;
        if table.rows() != count || table.columns() != count {
            return Err(Error::parameter(
                "transition",
                format!("{}×{}", table.rows(), table.columns()),
                format!("must be a square table of {count}×{count}, one row per model"),
            ));
        }
        let models = params
            .models
            .iter()
            .enumerate()
            .map(|(k, m)| KinematicModel::new(&format!("models[{k}]"), m))
            .collect::<Result<_>>()?;
        Ok(Self { table, models })
    }

    /// The transition table (for mixing or inspection).
    pub fn table(&self) -> &TransitionTable {
        &self.table
    }
}

impl MotionModel for Switching {
    fn propagate(&self, particles: &mut Particles, _track_len: u32, rng: &mut RngStream) {
        if self.models.iter().any(KinematicModel::uses_acceleration) {
            particles.enable_acceleration();
        }
        let mut c = particles.columns_mut();
        let mut normals = Normals::new(rng);
        for i in 0..c.mode.len() {
            let next = self
                .table
                .next_state(usize::from(c.mode[i]), normals.uniform());
            c.mode[i] = next as u8;
            self.models[next].advance(&mut c, i, &mut normals);
        }
    }
}

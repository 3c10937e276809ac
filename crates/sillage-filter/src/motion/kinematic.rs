//! Constant position, constant velocity and constant acceleration models (Eqs. (10)-(12) of
//! the IMM-PF paper), alone, switched by a transition table, or competing inside the IMM
//! particle filter. The per-particle steps here are also the building blocks of the bedload
//! motions of Eq. (3) of the MMPF+ paper.

use sillage_core::{Error, Result, RngStream};

use crate::motion::MotionModel;
use crate::noise::{Gauss2, Noise2};
use crate::normal::{BLOCK, Block, Normals};
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

    /// Standard normal pairs one step of this model draws: position, velocity, acceleration.
    fn draws(&self) -> usize {
        match self {
            Self::ConstantPosition { .. } => 1,
            Self::ConstantVelocity { .. } => 2,
            Self::ConstantAcceleration { .. } => 3,
        }
    }

    /// The state after one frame (Eqs. (10)-(12)), given standard normal pairs `z` for the
    /// position, velocity and acceleration noises.
    #[inline(always)]
    fn moved(&self, s: Kinematics, z: &Draws) -> Kinematics {
        match self {
            Self::ConstantPosition { pos } => position_step(pos, s, z),
            Self::ConstantVelocity { pos, vel } => velocity_step(pos, vel, s, z),
            Self::ConstantAcceleration { pos, vel, acc } => acceleration_step(pos, vel, acc, s, z),
        }
    }

    /// Moves particle `i` one frame.
    #[inline]
    pub(crate) fn advance(&self, c: &mut Columns<'_>, i: usize, normals: &mut Normals<'_>) {
        let mut z = [(0.0, 0.0); 3];
        for pair in &mut z[..self.draws()] {
            *pair = normals.pair();
        }
        let acc = |column: &[f64]| column.get(i).copied().unwrap_or(0.0);
        let state = Kinematics {
            x: c.pos_x[i],
            y: c.pos_y[i],
            u: c.vel_x[i],
            v: c.vel_y[i],
            ax: acc(c.acc_x),
            ay: acc(c.acc_y),
        };
        let moved = self.moved(state, &z);
        c.pos_x[i] = moved.x;
        c.pos_y[i] = moved.y;
        c.vel_x[i] = moved.u;
        c.vel_y[i] = moved.v;
        if let (Some(ax), Some(ay)) = (c.acc_x.get_mut(i), c.acc_y.get_mut(i)) {
            *ax = moved.ax;
            *ay = moved.ay;
        }
    }
}

/// One particle's state as the kinematic models move it (acceleration 0 where the set has no
/// acceleration columns).
#[derive(Debug, Clone, Copy, Default)]
struct Kinematics {
    x: f64,
    y: f64,
    u: f64,
    v: f64,
    ax: f64,
    ay: f64,
}

/// Standard normal pairs for the position, velocity and acceleration noises of one particle.
type Draws = [(f64, f64); 3];

/// Eq. (10), constant position: `x ← x + ε_x`, velocity and acceleration set to zero.
#[inline(always)]
fn position_step(pos: &Gauss2, s: Kinematics, z: &Draws) -> Kinematics {
    let (dx, dy) = pos.correlate(1.0, z[0]);
    Kinematics {
        x: s.x + dx,
        y: s.y + dy,
        ..Kinematics::default()
    }
}

/// Eq. (11), constant velocity: `x ← x + u + ε_x`, `u ← u + ε_u`, acceleration set to zero.
#[inline(always)]
fn velocity_step(pos: &Gauss2, vel: &Gauss2, s: Kinematics, z: &Draws) -> Kinematics {
    let (dx, dy) = pos.correlate(1.0, z[0]);
    let (du, dv) = vel.correlate(1.0, z[1]);
    Kinematics {
        x: s.x + (s.u + dx),
        y: s.y + (s.v + dy),
        u: s.u + du,
        v: s.v + dv,
        ..Kinematics::default()
    }
}

/// Eq. (12), constant acceleration: `x ← x + u + a/2 + ε_x`, `u ← u + a + ε_u`,
/// `a ← a + ε_a`.
#[inline(always)]
fn acceleration_step(
    pos: &Gauss2,
    vel: &Gauss2,
    acc: &Gauss2,
    s: Kinematics,
    z: &Draws,
) -> Kinematics {
    let (dx, dy) = pos.correlate(1.0, z[0]);
    let (du, dv) = vel.correlate(1.0, z[1]);
    let (dax, day) = acc.correlate(1.0, z[2]);
    Kinematics {
        x: s.x + ((s.u + 0.5 * s.ax) + dx),
        y: s.y + ((s.v + 0.5 * s.ay) + dy),
        u: s.u + (s.ax + du),
        v: s.v + (s.ay + dv),
        ax: s.ax + dax,
        ay: s.ay + day,
    }
}

/// Moves every particle one frame by `models[mode]` (the only model when there is one), a
/// chunk of [`BLOCK`] particles at a time: the noise pairs of a chunk are drawn as blocks, then
/// each model updates the chunk's columns in a loop the compiler vectorises, keeping the
/// particles of other modes as they were. The same [`KinematicModel::moved`] equations as
/// [`KinematicModel::advance`], one chunk instead of one particle at a time.
fn advance_in_chunks(models: &[KinematicModel], c: &mut Columns<'_>, normals: &mut Normals<'_>) {
    let draws = models.iter().map(KinematicModel::draws).max().unwrap_or(0);
    let mut blocks = [Block::ZERO, Block::ZERO, Block::ZERO];
    let n = c.mode.len();
    for start in (0..n).step_by(BLOCK) {
        let range = start..(start + BLOCK).min(n);
        for block in &mut blocks[..draws] {
            normals.fill_block(block);
        }
        // Empty when the set has no acceleration columns.
        let acc = if c.acc_x.is_empty() {
            0..0
        } else {
            range.clone()
        };
        let mut chunk = Chunk {
            x: &mut c.pos_x[range.clone()],
            y: &mut c.pos_y[range.clone()],
            u: &mut c.vel_x[range.clone()],
            v: &mut c.vel_y[range.clone()],
            ax: &mut c.acc_x[acc.clone()],
            ay: &mut c.acc_y[acc],
            mode: &c.mode[range],
        };
        for (mode, model) in models.iter().enumerate() {
            let only = (models.len() > 1).then_some(mode as u8);
            advance_chunk_widest(&mut chunk, model, only, &blocks);
        }
    }
}

sillage_core::multiversion! {
    /// [`Chunk::advance`] on the widest SIMD the CPU offers.
    fn advance_chunk_widest(chunk: &mut Chunk<'_>, model: &KinematicModel, only: Option<u8>, blocks: &[Block; 3]) => Chunk::advance
}

/// The columns of one chunk of particles (the acceleration ones empty when the set has none).
struct Chunk<'a> {
    x: &'a mut [f64],
    y: &'a mut [f64],
    u: &'a mut [f64],
    v: &'a mut [f64],
    ax: &'a mut [f64],
    ay: &'a mut [f64],
    mode: &'a [u8],
}

impl Chunk<'_> {
    /// Moves the chunk's particles by `model`, only those in mode `only` when given.
    #[inline(always)]
    fn advance(&mut self, model: &KinematicModel, only: Option<u8>, blocks: &[Block; 3]) {
        // One loop per model, so that the compiler sees straight-line arithmetic.
        match *model {
            KinematicModel::ConstantPosition { pos } => {
                self.apply(only, blocks, |s, z| position_step(&pos, s, z));
            }
            KinematicModel::ConstantVelocity { pos, vel } => {
                self.apply(only, blocks, |s, z| velocity_step(&pos, &vel, s, z));
            }
            KinematicModel::ConstantAcceleration { pos, vel, acc } => {
                self.apply(only, blocks, |s, z| {
                    acceleration_step(&pos, &vel, &acc, s, z)
                });
            }
        }
    }

    /// `step` applied to the particles in mode `only` (all when `None`), branch-free.
    #[inline(always)]
    fn apply(
        &mut self,
        only: Option<u8>,
        blocks: &[Block; 3],
        step: impl Fn(Kinematics, &Draws) -> Kinematics,
    ) {
        if self.ax.is_empty() {
            self.apply_with::<false>(only, blocks, step);
        } else {
            self.apply_with::<true>(only, blocks, step);
        }
    }

    /// [`Chunk::apply`] with (`ACC`) or without acceleration columns.
    #[inline(always)]
    fn apply_with<const ACC: bool>(
        &mut self,
        only: Option<u8>,
        blocks: &[Block; 3],
        step: impl Fn(Kinematics, &Draws) -> Kinematics,
    ) {
        let every = only.is_none();
        let wanted = only.unwrap_or(0);
        let len = self.x.len();
        for j in 0..len {
            let state = Kinematics {
                x: self.x[j],
                y: self.y[j],
                u: self.u[j],
                v: self.v[j],
                ax: if ACC { self.ax[j] } else { 0.0 },
                ay: if ACC { self.ay[j] } else { 0.0 },
            };
            let z = blocks.each_ref().map(|b| b.pair(j));
            let moved = step(state, &z);
            let take = every | (self.mode[j] == wanted);
            let pick = |new: f64, old: f64| if take { new } else { old };
            self.x[j] = pick(moved.x, state.x);
            self.y[j] = pick(moved.y, state.y);
            self.u[j] = pick(moved.u, state.u);
            self.v[j] = pick(moved.v, state.v);
            if ACC {
                self.ax[j] = pick(moved.ax, state.ax);
                self.ay[j] = pick(moved.ay, state.ay);
            }
        }
    }
}

impl MotionModel for KinematicModel {
    fn propagate(&self, particles: &mut Particles, _track_len: u32, rng: &mut RngStream) {
        if self.uses_acceleration() {
            particles.enable_acceleration();
        }
        let mut c = particles.columns_mut();
        advance_in_chunks(std::slice::from_ref(self), &mut c, &mut Normals::new(rng));
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
        for mode in c.mode.iter_mut() {
            *mode = self.table.next_state(usize::from(*mode), normals.uniform()) as u8;
        }
        advance_in_chunks(&self.models, &mut c, &mut normals);
    }
}

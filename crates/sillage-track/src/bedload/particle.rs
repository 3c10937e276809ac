//! The particle-filter step of MMPF+, MMPF and PF (§3.5 of the MMPF+ paper): prediction by
//! the motion models, the observed velocity set on every particle (§3.5.2), the weights of
//! Eq. (10), multinomial resampling, and the estimate of §3.5.3.

use sillage_core::{MotionState, ObjectClass, Point2, RngStream, Vec2};
use sillage_filter::{
    BedloadMode, BedloadModel, KinematicModel, KinematicParams, MotionModel, ParticleFilter,
    Particles,
};

use crate::bedload::confidence::ConfidenceDensity;
use crate::bedload::filters::{Estimate, Observation};

/// The motion model of a particle tracker.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(crate) enum ParticleMotion {
    /// MMPF+ and MMPF: the bedload motions of Eq. (3) with jump-Markov switching.
    Switching(Box<BedloadModel>),
    /// PF: one constant-velocity model (Breitenstein et al.).
    ConstantVelocity(KinematicModel),
}

impl ParticleMotion {
    /// PF's model: constant velocity with the rolling noises of `model` (the one motion of
    /// Eq. (3) with both a position and a velocity noise and no state-specific behaviour).
    pub fn constant_velocity(model: &BedloadModel) -> Self {
        let p = model.params();
        let params = KinematicParams::ConstantVelocity {
            pos_noise: p.roll_pos_noise,
            vel_noise: p.roll_vel_noise,
        };
        Self::ConstantVelocity(
            KinematicModel::new("motion", &params).expect("noises validated with the model"),
        )
    }
}

impl MotionModel for ParticleMotion {
    fn propagate(&self, particles: &mut Particles, track_len: u32, rng: &mut RngStream) {
        match self {
            Self::Switching(model) => model.as_ref().propagate(particles, track_len, rng),
            Self::ConstantVelocity(model) => model.propagate(particles, track_len, rng),
        }
    }
}

/// What the weighting of one step needs besides the observation.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Weighting<'a> {
    /// `1 / (2σ²)` of the Gaussian position likelihood, Eq. (8).
    pub inv_two_variance: f64,
    /// `(ln γ, ln(1 − γ))` of Eq. (9), or `None` without the motion-state cue (MMPF, PF).
    pub state_cue: Option<(f64, f64)>,
    /// The detector-confidence density of Eq. (1), for missed trackers.
    pub density: &'a ConfidenceDensity,
    /// Squared recapture distance, px², and the model whose initial spread recaptures.
    pub recapture: Option<(f64, &'a BedloadModel)>,
}

/// One SIR step of a tracker of class `class`; returns its estimate.
pub(crate) fn step(
    filter: &mut ParticleFilter,
    motion: &ParticleMotion,
    observation: &Observation,
    class: ObjectClass,
    weighting: &Weighting<'_>,
) -> Estimate {
    filter.predict(motion);
    let observed_velocity = match *observation {
        Observation::Detected {
            pos_px,
            vel_px_per_frame,
            state,
        } => {
            // Recapture (ours): when no particle came within the recapture distance of the
            // associated detection, the likelihood cannot pull the estimate onto it; the
            // particles restart around it, the tracker keeping its identity (the authors'
            // code instead drops the association and starts a new track, §3.4 of
            // `reference/beadtracking.md`).
            if let Some((distance2, model)) = weighting.recapture
                && nearest_squared(filter.particles(), pos_px) > distance2
            {
                filter.reinitialise(&model.initial_spread(pos_px));
            }
            // §3.5.2: every particle takes the observed velocity, so the velocity likelihood
            // of Eq. (7) drops out.
            filter.particles_mut().set_velocity(vel_px_per_frame);
            let inv = weighting.inv_two_variance;
            match weighting.state_cue {
                // Eq. (10), first case: p_γ(s) · p_N(x − x_obs).
                Some((same, other)) => filter.weight(|p| {
                    let cue = if particle_state(p.mode) == state {
                        same
                    } else {
                        other
                    };
                    cue - (p.pos_px - pos_px).norm_squared() * inv
                }),
                None => filter.weight(|p| -(p.pos_px - pos_px).norm_squared() * inv),
            }
            Some(vel_px_per_frame)
        }
        Observation::Missed => {
            // Eq. (10), second case, without p_γ: no detection, so no motion state is
            // measured (as the authors' code).
            let density = weighting.density;
            filter.weight(|p| density.log_value(class, p.pos_px));
            None
        }
    };
    filter.resample();
    let estimate = filter.estimate();
    let mean = |k| estimate.mean.at(k);
    Estimate {
        pos_px: Point2::new(mean(0), mean(1)),
        // §3.5.3: the velocity estimate is the observed one; without it, the particles'.
        vel_px_per_frame: observed_velocity.unwrap_or(Vec2::new(mean(2), mean(3))),
        spread_px: Some(((estimate.cov.0[0][0] + estimate.cov.0[1][1]) / 2.0).sqrt()),
    }
}

/// Squared distance from `z` to the nearest particle.
fn nearest_squared(particles: &Particles, z: Point2) -> f64 {
    particles
        .pos_x()
        .iter()
        .zip(particles.pos_y())
        .map(|(&x, &y)| (x - z.x) * (x - z.x) + (y - z.y) * (y - z.y))
        .fold(f64::INFINITY, f64::min)
}

/// The motion state of a particle's mode (a single-model filter's mode 0 is `Unknown`).
fn particle_state(mode: u8) -> MotionState {
    BedloadMode::from_index(mode).map_or(MotionState::Unknown, BedloadMode::motion_state)
}

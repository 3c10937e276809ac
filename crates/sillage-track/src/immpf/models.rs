//! The motion models that compete inside each person's filter (§5.1): the linear CP, CV and
//! CA of Eqs. (10)-(12), and the learned motion prior.

use std::sync::Arc;

use sillage_core::{Error, Point2, Result};
use sillage_filter::{Columns, Gauss2, KinematicModel, MotionPrior, Noise2, Normals};

use super::params::{ModelName, PedestrianParams};
use super::tracker::kinematic;

/// One competing model, ready to move particles.
#[derive(Debug, Clone)]
pub enum PedestrianMotion {
    /// CP, CV or CA.
    Linear(KinematicModel),
    /// MP: "for a given particle, we determine its corresponding cell and then sample a
    /// velocity from the prior" (§5.1); the particle moves by that velocity plus the position
    /// noise, its acceleration is zero.
    Prior {
        /// The learned prior.
        prior: Arc<MotionPrior>,
        /// Position noise.
        pos: Gauss2,
        /// Noise added to the prior's velocity.
        vel: Gauss2,
    },
}

impl PedestrianMotion {
    /// The model `name` with the noises of `params`; MP needs `prior`.
    pub fn new(
        name: ModelName,
        params: &PedestrianParams,
        prior: Option<&MotionPrior>,
    ) -> Result<Self> {
        if name != ModelName::Mp {
            return kinematic(name, params).map(Self::Linear);
        }
        let prior = prior.ok_or_else(|| {
            Error::parameter(
                "models",
                "MP",
                "needs a learned motion prior: give one with --motion-prior (make it with \
                 `sillage fit motion-prior`)",
            )
        })?;
        let noise = |sd: f64, key: &str| Noise2::diagonal(sd * sd, sd * sd).factor(key);
        Ok(Self::Prior {
            prior: Arc::new(prior.clone()),
            pos: noise(params.pos_noise_px, "pos_noise_px")?,
            vel: noise(params.vel_noise_px_per_frame, "vel_noise_px_per_frame")?,
        })
    }

    /// Moves particle `i` one frame.
    #[inline]
    pub(super) fn advance_particle(
        &self,
        c: &mut Columns<'_>,
        i: usize,
        normals: &mut Normals<'_>,
    ) {
        match self {
            Self::Linear(model) => sillage_filter::CompetingMotion::advance(model, c, i, normals),
            Self::Prior { prior, pos, vel } => {
                let at = Point2::new(c.pos_x[i], c.pos_y[i]);
                let velocity = prior.sample_velocity(at, normals.uniform(), vel, normals);
                let (dx, dy) = pos.sample(1.0, normals);
                c.pos_x[i] += velocity.x + dx;
                c.pos_y[i] += velocity.y + dy;
                c.vel_x[i] = velocity.x;
                c.vel_y[i] = velocity.y;
                c.acc_x[i] = 0.0;
                c.acc_y[i] = 0.0;
            }
        }
    }
}

//! The state estimator of one bedload tracker, one kind per tracker of Table 1: particles
//! (MMPF+, MMPF, PF), a Kalman IMM (IMM) or none (DET, the raw detections).

use sillage_core::{MotionState, ObjectClass, Point2, Vec2};
use sillage_filter::{Gaussian, KalmanImm, Matrix, ParticleFilter, Vector};

use crate::bedload::params::{BedloadTrackerKind, Settings};
use crate::bedload::particle::{self, ParticleMotion, Weighting};

/// What a tracker observes in the current frame.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) enum Observation {
    /// A detection was associated: its position `x_obs`, the observed velocity `u_obs` and
    /// the motion state `s_obs` measured by Eq. (4).
    Detected {
        /// x_obs, px.
        pos_px: Point2,
        /// u_obs, px/frame.
        vel_px_per_frame: Vec2,
        /// s_obs.
        state: MotionState,
    },
    /// No detection was associated.
    Missed,
}

/// A tracker's estimate after one frame.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct Estimate {
    /// Position, px.
    pub pos_px: Point2,
    /// Velocity, px/frame.
    pub vel_px_per_frame: Vec2,
    /// Spread of the position, px (none for DET).
    pub spread_px: Option<f64>,
}

/// One tracker's estimator.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(crate) enum TrackFilter {
    /// MMPF+, MMPF, PF.
    Particles(Box<ParticleFilter>),
    /// IMM.
    Imm(Box<KalmanImm<4>>),
    /// DET.
    Raw,
}

/// What every tracker's update reads, shared by all trackers of a frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Shared<'a> {
    pub settings: &'a Settings,
    pub motion: &'a ParticleMotion,
    pub weighting: Weighting<'a>,
}

impl TrackFilter {
    /// The estimator of a tracker born at detection `pos_px`, drawing from the random stream
    /// `serial` of the run.
    pub fn spawn(settings: &Settings, serial: u64, pos_px: Point2) -> Self {
        match settings.kind {
            BedloadTrackerKind::MmpfPlus | BedloadTrackerKind::Mmpf | BedloadTrackerKind::Pf => {
                let spread = settings.model.initial_spread(pos_px);
                Self::Particles(Box::new(settings.spec.spawn(serial, &spread)))
            }
            BedloadTrackerKind::Imm => {
                let p = settings.model.params();
                let (pos, vel) = (p.init_pos_noise.matrix().0, p.init_vel_noise.matrix().0);
                let mut cov = Matrix::<4, 4>::ZERO;
                for r in 0..2 {
                    for c in 0..2 {
                        cov.0[r][c] = pos[r][c];
                        cov.0[r + 2][c + 2] = vel[r][c];
                    }
                }
                let initial = Gaussian {
                    mean: Vector::from_array([pos_px.x, pos_px.y, 0.0, 0.0]),
                    cov,
                };
                Self::Imm(Box::new(settings.model.kalman_imm(initial)))
            }
            BedloadTrackerKind::Det => Self::Raw,
        }
    }

    /// One frame of the tracker of class `class`; `None` when the estimator cannot go on
    /// without a detection (IMM, DET: the track ends).
    pub fn update(
        &mut self,
        observation: &Observation,
        class: ObjectClass,
        shared: &Shared<'_>,
    ) -> Option<Estimate> {
        match (self, *observation) {
            (Self::Particles(filter), _) => Some(particle::step(
                filter,
                shared.motion,
                observation,
                class,
                &shared.weighting,
            )),
            (
                Self::Imm(imm),
                Observation::Detected {
                    pos_px,
                    vel_px_per_frame: _,
                    state: _,
                },
            ) => {
                imm.predict();
                imm.update(pos_px, &shared.settings.measurement);
                Some(gaussian_estimate(&imm.estimate()))
            }
            (
                Self::Raw,
                Observation::Detected {
                    pos_px,
                    vel_px_per_frame,
                    state: _,
                },
            ) => Some(Estimate {
                pos_px,
                vel_px_per_frame,
                spread_px: None,
            }),
            (Self::Imm(_) | Self::Raw, Observation::Missed) => None,
        }
    }
}

/// Position, velocity and spread of a Gaussian over `(x, y, u, v)`.
fn gaussian_estimate(g: &Gaussian<4>) -> Estimate {
    Estimate {
        pos_px: Point2::new(g.mean.at(0), g.mean.at(1)),
        vel_px_per_frame: Vec2::new(g.mean.at(2), g.mean.at(3)),
        spread_px: Some(((g.cov.0[0][0] + g.cov.0[1][1]) / 2.0).sqrt()),
    }
}

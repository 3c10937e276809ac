//! The sequential importance resampling (SIR, bootstrap) filter of one target (§3.5 of the
//! MMPF+ paper): predict by a motion model, weight by the caller's log-likelihood
//! (Eq. (6): `wᵢ ∝ p(zₜ | cᵢ)`), normalise, resample; and the run over many targets.

use rayon::prelude::*;
use sillage_core::{Result, RngStream, TrackId, rng_stream};

use crate::linalg::Gaussian;
use crate::motion::MotionModel;
use crate::params::FilterParams;
use crate::particles::{InitialSpread, Particle, Particles};
use crate::resample::{Resampler, Resampling};
use crate::weights::normalise;

/// Validated [`FilterParams`] and the run seed: spawns the filter of each new target, each with
/// its own random stream `rng_stream(seed, track_id)`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FilterSpec {
    particles: usize,
    resampling: Resampling,
    seed: u64,
}

impl FilterSpec {
    /// Validates `params` (errors name the key) for a run seeded with `seed`.
    pub fn new(params: &FilterParams, seed: u64) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            particles: params.particles,
            resampling: params.resampling,
            seed,
        })
    }

    /// N, the particles per target.
    pub fn particles(&self) -> usize {
        self.particles
    }

    /// A filter for `track_id`, its particles drawn from `spread`.
    pub fn spawn(&self, track_id: TrackId, spread: &InitialSpread) -> ParticleFilter {
        let mut filter = ParticleFilter {
            track_id,
            rng: rng_stream(self.seed, track_id),
            particles: Particles::new(self.particles),
            resampling: self.resampling,
            resampler: Resampler::default(),
            linear_weights: vec![0.0; self.particles],
            track_len: 1,
            weight_recoveries: 0,
            last: StepReport::default(),
            weighted: false,
        };
        filter.particles.initialise(spread, &mut filter.rng);
        filter
    }
}

/// What the weighting and resampling of one step found.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepReport {
    /// `ln p(zₜ | z₁..ₜ₋₁)` as the particles estimate it (−∞ when every weight was zero).
    pub log_evidence: f64,
    /// Effective sample size of the weights before resampling.
    pub ess: f64,
    /// The particles were resampled.
    pub resampled: bool,
    /// Every weight was zero and the set was reset to uniform weights (counted in
    /// [`ParticleFilter::weight_recoveries`]).
    pub recovered: bool,
}

/// The particle filter of one target: its particles, its random stream and its counters.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct ParticleFilter {
    track_id: TrackId,
    rng: RngStream,
    particles: Particles,
    resampling: Resampling,
    resampler: Resampler,
    linear_weights: Vec<f64>,
    track_len: u32,
    weight_recoveries: u64,
    last: StepReport,
    /// `linear_weights` hold the weights of the last `weight` call, not yet resampled.
    weighted: bool,
}

impl ParticleFilter {
    /// The target's identity (and the id of its random stream).
    pub fn track_id(&self) -> TrackId {
        self.track_id
    }

    /// Frames of the track so far, counting the birth frame (1 before the first prediction).
    pub fn track_len(&self) -> u32 {
        self.track_len
    }

    /// The particles.
    pub fn particles(&self) -> &Particles {
        &self.particles
    }

    /// The particles, to edit between the phases of a step (e.g. set the observed velocity,
    /// §3.5.2).
    pub fn particles_mut(&mut self) -> &mut Particles {
        &mut self.particles
    }

    /// How many times every weight came out zero and the set was reset to uniform: the
    /// likelihood ruled out every particle (an observation far from all of them).
    pub fn weight_recoveries(&self) -> u64 {
        self.weight_recoveries
    }

    /// What the last weighting and resampling found.
    pub fn last_report(&self) -> StepReport {
        self.last
    }

    /// Restarts the filter from `spread` (a target re-initialised on a detection): particles
    /// redrawn, track length 1; the counters and the random stream go on.
    pub fn reinitialise(&mut self, spread: &InitialSpread) {
        self.weighted = false;
        self.particles.initialise(spread, &mut self.rng);
        self.track_len = 1;
    }

    /// Prediction: moves the particles one frame by `model` (the track grows by one frame).
    pub fn predict(&mut self, model: &impl MotionModel) {
        self.weighted = false;
        self.track_len = self.track_len.saturating_add(1);
        model.propagate(&mut self.particles, self.track_len, &mut self.rng);
    }

    /// Weighting: multiplies each weight by `exp(log_likelihood(particle))` and normalises in
    /// the log domain. NaN counts as a zero likelihood; if all are zero the weights become
    /// uniform and the event is counted.
    pub fn weight(&mut self, log_likelihood: impl FnMut(Particle) -> f64) {
        self.particles.add_log_likelihood(log_likelihood);
        let normalisation = normalise(self.particles.log_weights_mut(), &mut self.linear_weights);
        if normalisation.recovered {
            self.weight_recoveries += 1;
            self.particles.set_uniform_weights();
        }
        self.last = StepReport {
            log_evidence: normalisation.log_evidence,
            ess: normalisation.ess,
            resampled: false,
            recovered: normalisation.recovered,
        };
        self.weighted = true;
    }

    /// Resampling of the weights of the last [`ParticleFilter::weight`] call, when the policy
    /// asks for it; returns whether it resampled (never twice for one weighting).
    pub fn resample(&mut self) -> bool {
        let n = self.particles.len();
        if !(self.weighted && self.resampling.triggers(self.last.ess, n)) {
            return false;
        }
        self.weighted = false;
        let ancestors = self.resampler.draw(
            self.resampling.scheme,
            &mut self.linear_weights,
            &mut self.rng,
        );
        self.particles.select(ancestors);
        self.last.resampled = true;
        true
    }

    /// One SIR step: predict, weight, resample.
    pub fn step(
        &mut self,
        model: &impl MotionModel,
        log_likelihood: impl FnMut(Particle) -> f64,
    ) -> StepReport {
        self.predict(model);
        self.weight(log_likelihood);
        self.resample();
        self.last
    }

    /// The weighted mean and covariance of `(x, y, u, v)`.
    pub fn estimate(&self) -> Gaussian<4> {
        self.particles.estimate()
    }
}

/// Totals of one [`step_all`] over many targets.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StepSummary {
    /// Targets whose particles were resampled.
    pub resampled: usize,
    /// Targets whose weights were all zero and were reset to uniform.
    pub recovered: usize,
}

/// One SIR step of every filter, in parallel over targets. `likelihood_of(k)` gives the
/// log-likelihood of target `k` (its index in `filters`), evaluated per particle. Each target
/// draws from its own stream, so the result is identical for any number of threads.
pub fn step_all<M, F, L>(filters: &mut [ParticleFilter], model: &M, likelihood_of: F) -> StepSummary
where
    M: MotionModel,
    F: Fn(usize) -> L + Sync,
    L: FnMut(Particle) -> f64,
{
    filters
        .par_iter_mut()
        .enumerate()
        .map(|(k, filter)| {
            let report = filter.step(model, likelihood_of(k));
            StepSummary {
                resampled: usize::from(report.resampled),
                recovered: usize::from(report.recovered),
            }
        })
        .reduce(StepSummary::default, |a, b| StepSummary {
            resampled: a.resampled + b.resampled,
            recovered: a.recovered + b.recovered,
        })
}

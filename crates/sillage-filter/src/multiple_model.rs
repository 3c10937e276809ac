//! The interacting-multiple-model particle filter of one target (IMM-PF, §4 of Madrigal &
//! Hayet, "Evaluation of multiple motion models for multiple pedestrian visual tracking").
//!
//! Each particle carries a model label `l⁽ⁿ⁾` (its mode). The posterior of Eq. (6),
//! `Σₘ πₘ Σ_{n∈ψₘ} ω⁽ⁿ⁾ δ_{X⁽ⁿ⁾}`, is stored as one log weight per particle,
//! `ln(π_{l⁽ⁿ⁾} ω⁽ⁿ⁾)`, which sums to 1 over all particles: the model weights are
//! `πₘ = Σ_{n∈ψₘ} πₘω⁽ⁿ⁾`, the within-model weights `ω⁽ⁿ⁾ = πₘω⁽ⁿ⁾ / πₘ`. In this form the
//! updates of Eqs. (8)-(9) are a plain Bayes update of the products,
//! `πₘ'ω⁽ⁿ⁾' ∝ πₘω⁽ⁿ⁾ p(Zₜ | X⁽ⁿ⁾)`, so the weighting is the SIR filter's. What the IMM-PF adds
//! is the prediction by each particle's own model (Eq. (7)) and the two resamplings of §4.4:
//! over all particles every ρ frames (particles move to the models that explain the target),
//! and per model every φ frames, with at least γ particles per model, the missing ones drawn
//! from a Gaussian of the whole previous distribution.

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Point2, Result, RngStream, TrackId, Vec2, rng_stream};

use crate::linalg::{Gaussian, Matrix};
use crate::motion::kinematic::KinematicModel;
use crate::normal::Normals;
use crate::params::KinematicParams;
use crate::particles::{Columns, InitialSpread, Particle, Particles};
use crate::resample::{ResampleScheme, Resampler};
use crate::weights::normalise;

/// Parameters of the IMM particle filter, with the paper's values as defaults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ImmPfParams {
    /// N, particles per target, split N/M per model at birth; default 200 (§5.3).
    pub particles: usize,
    /// ρ: resample over all particles every ρ frames; default 4 (§4.4).
    pub resample_all_every: u32,
    /// φ: resample per model every φ frames; default 5 (§4.4).
    pub resample_models_every: u32,
    /// γ/N: the least share of particles each model keeps at the per-model resampling;
    /// default 0.1 (§4.4, "γ = 0.1 * N").
    pub min_model_fraction: f64,
    /// How ancestors are drawn in both resamplings (the paper does not say); default
    /// systematic, the lowest-variance scheme.
    pub scheme: ResampleScheme,
}

impl Default for ImmPfParams {
    fn default() -> Self {
        Self {
            particles: 200,
            resample_all_every: 4,
            resample_models_every: 5,
            min_model_fraction: 0.1,
            scheme: ResampleScheme::Systematic,
        }
    }
}

/// A motion model that competes inside the IMM particle filter: it moves one labelled
/// particle one frame (Eq. (7), `X⁽ⁿ⁾ ← tr_l(X⁽ⁿ⁾) + ν_l`).
pub trait CompetingMotion: Sync {
    /// Moves particle `i` of `columns` one frame (acceleration columns are always present).
    fn advance(&self, columns: &mut Columns<'_>, i: usize, normals: &mut Normals<'_>);
}

impl CompetingMotion for KinematicModel {
    fn advance(&self, columns: &mut Columns<'_>, i: usize, normals: &mut Normals<'_>) {
        KinematicModel::advance(self, columns, i, normals);
    }
}

/// Validated [`ImmPfParams`] for `models` competing models, and the run seed: spawns the
/// filter of each new target with its own random stream `rng_stream(seed, track_id)`.
#[derive(Debug, Clone, PartialEq)]
pub struct ImmPfSpec {
    params: ImmPfParams,
    models: usize,
    min_per_model: usize,
    seed: u64,
}

impl ImmPfSpec {
    /// Validates `params` for `models` competing models (1 to 255); errors name the key.
    pub fn new(params: &ImmPfParams, models: usize, seed: u64) -> Result<Self> {
        if !(1..=usize::from(u8::MAX)).contains(&models) {
            return Err(Error::parameter(
                "models",
                models,
                "must list between 1 and 255 motion models",
            ));
        }
        if params.particles < models || params.particles > crate::params::MAX_PARTICLES {
            return Err(Error::parameter(
                "particles",
                params.particles,
                format!(
                    "must be at least one per model ({models}) and at most {} (the paper uses 200)",
                    crate::params::MAX_PARTICLES
                ),
            ));
        }
        for (key, every) in [
            ("resample_all_every", params.resample_all_every),
            ("resample_models_every", params.resample_models_every),
        ] {
            if every == 0 {
                return Err(Error::parameter(
                    key,
                    every,
                    "must be a number of frames ≥ 1 (the paper uses ρ = 4 and φ = 5)",
                ));
            }
        }
        let fraction = params.min_model_fraction;
        if !(fraction >= 0.0 && fraction * models as f64 <= 1.0) {
            return Err(Error::parameter(
                "min_model_fraction",
                fraction,
                format!(
                    "must be in [0, 1/{models}] so that every model can keep that share (the \
                     paper uses 0.1)"
                ),
            ));
        }
        let min_per_model = (fraction * params.particles as f64).round() as usize;
        Ok(Self {
            params: params.clone(),
            models,
            min_per_model: min_per_model.min(params.particles / models),
            seed,
        })
    }

    /// N, the particles per target.
    pub fn particles(&self) -> usize {
        self.params.particles
    }

    /// M, the number of competing models.
    pub fn models(&self) -> usize {
        self.models
    }

    /// A filter for `track_id`: particles drawn from `spread` (its mode is ignored), the
    /// first N/M labelled with model 0, the next with model 1, …, all weights equal
    /// (`πₘ = 1/M`, §5.3).
    pub fn spawn(&self, track_id: TrackId, spread: &InitialSpread) -> ImmParticleFilter {
        let n = self.params.particles;
        let mut filter = ImmParticleFilter {
            track_id,
            rng: rng_stream(self.seed, track_id),
            particles: Particles::new(n),
            spec: self.clone(),
            resampler: Resampler::default(),
            linear_weights: vec![0.0; n],
            steps: 0,
            scratch: ResampleScratch::default(),
        };
        filter.particles.enable_acceleration();
        filter.particles.initialise(spread, &mut filter.rng);
        let columns = filter.particles.columns_mut();
        for (i, mode) in columns.mode.iter_mut().enumerate() {
            *mode = (i * self.models / n) as u8;
        }
        filter
    }
}

/// What one weighting found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImmWeighting {
    /// Mean of `p(Zₜ | X⁽ⁿ⁾)` over the particles, unweighted: the paper's death criterion
    /// (§5.3, "the mean likelihood within the particles").
    pub mean_likelihood: f64,
    /// Every weight came out zero and the set was reset to uniform weights.
    pub recovered: bool,
}

/// Which resampling a step ran (§4.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImmResampling {
    /// None this frame.
    None,
    /// Over all particles, by `πₘω⁽ⁿ⁾` (every ρ frames).
    AllParticles,
    /// Per model, at least γ particles each (every φ frames).
    PerModel,
    /// Both, over all particles first (a frame that is a multiple of ρ and φ).
    Both,
}

/// Buffers the per-model resampling reuses from step to step.
#[derive(Debug, Clone, Default)]
struct ResampleScratch {
    indices: Vec<u32>,
    weights: Vec<f64>,
    ancestors: Vec<u32>,
    /// Slots of the new set to draw from the Gaussian, with their model.
    refills: Vec<(usize, u8)>,
    /// Log weight of each new particle.
    log_weights: Vec<f64>,
}

/// The IMM particle filter of one target: labelled particles, its random stream, its step
/// count.
#[derive(Debug, Clone)]
pub struct ImmParticleFilter {
    track_id: TrackId,
    rng: RngStream,
    particles: Particles,
    spec: ImmPfSpec,
    resampler: Resampler,
    linear_weights: Vec<f64>,
    steps: u32,
    scratch: ResampleScratch,
}

impl ImmParticleFilter {
    /// The target's identity (and the id of its random stream).
    pub fn track_id(&self) -> TrackId {
        self.track_id
    }

    /// The particles; `modes()` are the model labels.
    pub fn particles(&self) -> &Particles {
        &self.particles
    }

    /// Frames predicted since birth.
    pub fn steps(&self) -> u32 {
        self.steps
    }

    /// Prediction (Eq. (7)): each particle moves by the model of its label, `models[label]`.
    /// Panics if a label has no model (the models must be the ones the spec was made for).
    pub fn predict<M: CompetingMotion>(&mut self, models: &[M]) {
        assert_eq!(models.len(), self.spec.models, "one model per label");
        self.steps = self.steps.saturating_add(1);
        let mut columns = self.particles.columns_mut();
        let mut normals = Normals::new(&mut self.rng);
        for i in 0..columns.mode.len() {
            let model = &models[usize::from(columns.mode[i])];
            model.advance(&mut columns, i, &mut normals);
        }
    }

    /// Moves about `share` of the particles, evenly spread over the set, to positions drawn
    /// from `N(centre, sd_px² I)`, keeping their velocity, acceleration, label and weight:
    /// the observation-driven half of a mixture proposal (Okuma et al., "A boosted particle
    /// filter", ECCV 2004), so that a filter whose prediction lags or drifts keeps
    /// hypotheses on the person an observation shows. Call between [`Self::predict`] and
    /// [`Self::weight`]; the likelihood then judges the moved particles like the others
    /// (the proposal's importance ratio is not applied, as in Okuma et al.). A share ≤ 0
    /// moves nothing.
    pub fn propose_near(&mut self, share: f64, centre: Point2, sd_px: f64) {
        self.propose(share, centre, sd_px, None);
    }

    /// [`Self::propose_near`] that also draws the moved particles' velocities from
    /// `N(velocity, vel_sd² I)` (px/frame) and sets their accelerations to zero: where an
    /// observation gives the motion too (two detections of one person), a filter whose
    /// particles have not learnt the person's speed yet gets hypotheses that move with it,
    /// without the accelerations of the few ancestors a sharp likelihood leaves, which would
    /// bend every hypothesis alike while the target goes unobserved.
    pub fn propose_moving_near(
        &mut self,
        share: f64,
        centre: Point2,
        sd_px: f64,
        velocity: Vec2,
        vel_sd: f64,
    ) {
        self.propose(share, centre, sd_px, Some((velocity, vel_sd)));
    }

    /// The proposal of [`Self::propose_near`], velocities drawn too with `velocity`.
    fn propose(&mut self, share: f64, centre: Point2, sd_px: f64, velocity: Option<(Vec2, f64)>) {
        if share.is_nan() || share <= 0.0 {
            return;
        }
        let share = share.min(1.0);
        let columns = self.particles.columns_mut();
        let mut normals = Normals::new(&mut self.rng);
        for i in 0..columns.pos_x.len() {
            // Particle i is moved when the running count ⌊(i + 1)·share⌋ steps up.
            if ((i + 1) as f64 * share).floor() > (i as f64 * share).floor() {
                let (dx, dy) = normals.pair();
                columns.pos_x[i] = centre.x + sd_px * dx;
                columns.pos_y[i] = centre.y + sd_px * dy;
                if let Some((v, sd)) = velocity {
                    let (dx, dy) = normals.pair();
                    columns.vel_x[i] = v.x + sd * dx;
                    columns.vel_y[i] = v.y + sd * dy;
                    if let (Some(ax), Some(ay)) =
                        (columns.acc_x.get_mut(i), columns.acc_y.get_mut(i))
                    {
                        *ax = 0.0;
                        *ay = 0.0;
                    }
                }
            }
        }
    }

    /// Correction (Eqs. (8)-(9)): multiplies each particle's weight by
    /// `exp(log_likelihood(particle))`, updating the model weights with it. NaN counts as a
    /// zero likelihood; if every weight comes out zero the weights are reset to uniform.
    pub fn weight(&mut self, mut log_likelihood: impl FnMut(Particle) -> f64) -> ImmWeighting {
        let mut likelihood_sum = 0.0;
        self.particles.add_log_likelihood(|p| {
            let value = log_likelihood(p);
            likelihood_sum += value.exp();
            value
        });
        let n = self.particles.len();
        let normalisation = normalise(self.particles.log_weights_mut(), &mut self.linear_weights);
        if normalisation.recovered {
            self.particles.set_uniform_weights();
        }
        ImmWeighting {
            mean_likelihood: if likelihood_sum.is_finite() {
                likelihood_sum / n.max(1) as f64
            } else {
                0.0
            },
            recovered: normalisation.recovered,
        }
    }

    /// The resampling of §4.4 due at this step: over all particles when the step count is a
    /// multiple of ρ, per model when it is a multiple of φ.
    pub fn resample(&mut self) -> ImmResampling {
        let all = self
            .steps
            .is_multiple_of(self.spec.params.resample_all_every);
        let per_model = self
            .steps
            .is_multiple_of(self.spec.params.resample_models_every);
        if all {
            self.resample_all();
        }
        if per_model {
            self.resample_per_model();
        }
        match (all, per_model) {
            (false, false) => ImmResampling::None,
            (true, false) => ImmResampling::AllParticles,
            (false, true) => ImmResampling::PerModel,
            (true, true) => ImmResampling::Both,
        }
    }

    /// Sampling over particles: N draws by `πₘω⁽ⁿ⁾` from one cumulative distribution; the
    /// best particles of the best model multiply, and the model counts change with them.
    pub fn resample_all(&mut self) {
        for (w, lw) in self
            .linear_weights
            .iter_mut()
            .zip(self.particles.log_weights())
        {
            *w = lw.exp();
        }
        let ancestors = self.resampler.draw(
            self.spec.params.scheme,
            &mut self.linear_weights,
            &mut self.rng,
        );
        self.particles.select(ancestors);
    }

    /// Sampling per model: each model resampled within itself by `ω⁽ⁿ⁾`, keeping its count,
    /// except that a model with fewer than γ particles is brought up to γ with draws from
    /// `N(X̄, S)`, the Gaussian of the whole previous distribution, and the models with the
    /// most particles give up as many. The model weights are kept; a refilled model's weight
    /// is raised to at least γ/N (the share its new hypotheses hold — without it a model
    /// whose weight fell to zero could never win particles back; the paper is silent here).
    pub fn resample_per_model(&mut self) {
        let n = self.particles.len();
        let models = self.spec.models;
        let min = self.spec.min_per_model;
        let mut counts = vec![0usize; models];
        self.particles
            .modes()
            .iter()
            .for_each(|&m| counts[usize::from(m)] += 1);
        let mut targets: Vec<usize> = counts.iter().map(|&c| c.max(min)).collect();
        let mut excess = targets.iter().sum::<usize>() - n;
        while excess > 0 {
            let largest = (0..models)
                .max_by_key(|&m| (targets[m], std::cmp::Reverse(m)))
                .expect("at least one model");
            targets[largest] -= 1;
            excess -= 1;
        }
        let mut shares = vec![0.0; models];
        self.particles.mode_probabilities(&mut shares);
        let previous = self.state_distribution();
        let refilled = |m: usize| counts[m] < targets[m];
        let mut floored = 0.0;
        for m in (0..models).filter(|&m| refilled(m)) {
            shares[m] = shares[m].max(targets[m] as f64 / n as f64);
            floored += shares[m];
        }
        // The other models share the rest in their old proportions.
        let others: f64 = (0..models)
            .filter(|&m| !refilled(m))
            .map(|m| shares[m])
            .sum();
        if others > 0.0 {
            for m in (0..models).filter(|&m| !refilled(m)) {
                shares[m] *= (1.0 - floored).max(0.0) / others;
            }
        }

        let scratch = &mut self.scratch;
        scratch.ancestors.clear();
        scratch.refills.clear();
        scratch.log_weights.clear();
        for m in 0..models {
            scratch.indices.clear();
            scratch.weights.clear();
            for (i, (&mode, &lw)) in self
                .particles
                .modes()
                .iter()
                .zip(self.particles.log_weights())
                .enumerate()
            {
                if usize::from(mode) == m {
                    scratch.indices.push(i as u32);
                    scratch.weights.push(lw.exp());
                }
            }
            let kept = counts[m].min(targets[m]);
            let drawn = self.resampler.draw_count(
                self.spec.params.scheme,
                &mut scratch.weights,
                kept,
                &mut self.rng,
            );
            scratch
                .ancestors
                .extend(drawn.iter().map(|&k| scratch.indices[k as usize]));
            for _ in kept..targets[m] {
                scratch.refills.push((scratch.ancestors.len(), m as u8));
                scratch.ancestors.push(0);
            }
            let log_weight = (shares[m] / targets[m].max(1) as f64).ln();
            scratch
                .log_weights
                .extend(std::iter::repeat_n(log_weight, targets[m]));
        }
        self.particles.select(&scratch.ancestors);
        let factor = previous.cov.cholesky_semidefinite();
        let columns = self.particles.columns_mut();
        let mut normals = Normals::new(&mut self.rng);
        for &(slot, model) in &scratch.refills {
            let (a, b) = normals.pair();
            let (c, d) = normals.pair();
            let (e, f) = normals.pair();
            let z = [a, b, c, d, e, f];
            let mut x = [0.0; 6];
            for (r, value) in x.iter_mut().enumerate() {
                *value = previous.mean.at(r) + (0..=r).map(|k| factor.0[r][k] * z[k]).sum::<f64>();
            }
            columns.pos_x[slot] = x[0];
            columns.pos_y[slot] = x[1];
            columns.vel_x[slot] = x[2];
            columns.vel_y[slot] = x[3];
            columns.acc_x[slot] = x[4];
            columns.acc_y[slot] = x[5];
            columns.mode[slot] = model;
        }
        self.particles
            .log_weights_mut()
            .copy_from_slice(&scratch.log_weights);
    }

    /// The weighted mean and covariance of the whole state `(x, y, u, v, aₓ, a_y)`.
    fn state_distribution(&self) -> Gaussian<6> {
        let p = &self.particles;
        let columns = [
            p.pos_x(),
            p.pos_y(),
            p.vel_x(),
            p.vel_y(),
            p.acc_x(),
            p.acc_y(),
        ];
        let mut mean = [0.0; 6];
        let mut total = 0.0;
        for (i, lw) in p.log_weights().iter().enumerate() {
            let w = lw.exp();
            total += w;
            for (m, column) in mean.iter_mut().zip(&columns) {
                *m += w * column[i];
            }
        }
        mean.iter_mut().for_each(|m| *m /= total);
        let mut cov = Matrix::<6, 6>::ZERO;
        for (i, lw) in p.log_weights().iter().enumerate() {
            let w = lw.exp() / total;
            let d: [f64; 6] = std::array::from_fn(|k| columns[k][i] - mean[k]);
            for r in 0..6 {
                for c in 0..=r {
                    cov.0[r][c] += w * d[r] * d[c];
                }
            }
        }
        for r in 0..6 {
            for c in 0..r {
                cov.0[c][r] = cov.0[r][c];
            }
        }
        Gaussian {
            mean: crate::linalg::Vector::from_array(mean),
            cov,
        }
    }

    /// The model weights `πₘ` (Eq. (9)), written into `out` (one entry per model).
    pub fn model_weights(&self, out: &mut [f64]) {
        self.particles.mode_probabilities(out);
    }

    /// The model with the largest weight (the colour of Fig. 2).
    pub fn dominant_model(&self) -> u8 {
        let mut weights = vec![0.0; self.spec.models];
        self.model_weights(&mut weights);
        (0..weights.len())
            .max_by(|&a, &b| weights[a].total_cmp(&weights[b]).then(b.cmp(&a)))
            .unwrap_or(0) as u8
    }

    /// The posterior mean and covariance of `(x, y, u, v)` (Eq. (6)).
    pub fn estimate(&self) -> Gaussian<4> {
        self.particles.estimate()
    }
}

/// The kinematic model named `name` (`cp`, `cv`, `ca`, any case) with the given per-frame
/// noise standard deviations of position, velocity and acceleration: the linear models of
/// Eqs. (10)-(12) as the IMM-PF composes them; `None` for another name.
pub fn linear_model(name: &str, pos_sd: f64, vel_sd: f64, acc_sd: f64) -> Option<KinematicParams> {
    let noise = |sd: f64| crate::noise::Noise2::diagonal(sd * sd, sd * sd);
    Some(match name.to_ascii_lowercase().as_str() {
        "cp" => KinematicParams::ConstantPosition {
            pos_noise: noise(pos_sd),
        },
        "cv" => KinematicParams::ConstantVelocity {
            pos_noise: noise(pos_sd),
            vel_noise: noise(vel_sd),
        },
        "ca" => KinematicParams::ConstantAcceleration {
            pos_noise: noise(pos_sd),
            vel_noise: noise(vel_sd),
            acc_noise: noise(acc_sd),
        },
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::Noise2;
    use sillage_core::{Point2, Vec2};

    fn models() -> Vec<KinematicModel> {
        ["cp", "cv", "ca"]
            .iter()
            .map(|name| {
                let params = linear_model(name, 1.0, 0.3, 0.1).unwrap();
                KinematicModel::new(name, &params).unwrap()
            })
            .collect()
    }

    fn spread(at: Point2) -> InitialSpread {
        let noise = Noise2::diagonal(4.0, 4.0).factor("init").unwrap();
        InitialSpread {
            pos_px: at,
            pos_noise: noise,
            vel_px_per_frame: Vec2::new(0.0, 0.0),
            vel_noise: Noise2::diagonal(1.0, 1.0).factor("init").unwrap(),
            mode: 0,
        }
    }

    fn weights(filter: &ImmParticleFilter) -> Vec<f64> {
        let mut w = vec![0.0; 3];
        filter.model_weights(&mut w);
        w
    }

    /// Runs `frames` steps of a target moving at `velocity` px/frame, observed through a
    /// Gaussian position likelihood (σ = 2 px).
    fn follow(filter: &mut ImmParticleFilter, velocity: Vec2, frames: u32) -> Point2 {
        let models = models();
        let mut truth = Point2::new(100.0, 100.0);
        for _ in 0..frames {
            truth = truth + velocity;
            filter.predict(&models);
            filter.weight(|p| -(p.pos_px - truth).norm().powi(2) / 8.0);
            filter.resample();
        }
        truth
    }

    #[test]
    fn births_split_particles_evenly_and_weights_sum_to_one() {
        let spec = ImmPfSpec::new(&ImmPfParams::default(), 3, 7).unwrap();
        let filter = spec.spawn(1, &spread(Point2::new(100.0, 100.0)));
        let w = weights(&filter);
        for share in &w {
            assert!((share - 1.0 / 3.0).abs() < 0.01, "{w:?}");
        }
        assert_eq!(filter.particles().len(), 200);
    }

    #[test]
    fn a_proposal_moves_its_share_of_particles_and_nothing_else() {
        let spec = ImmPfSpec::new(&ImmPfParams::default(), 3, 9).unwrap();
        let filter = spec.spawn(1, &spread(Point2::new(100.0, 100.0)));
        let mut moved = filter.clone();
        moved.propose_near(0.25, Point2::new(300.0, 50.0), 2.0);
        let (before, after) = (filter.particles(), moved.particles());
        let near = |i: usize| (after.pos_x()[i] - 300.0).hypot(after.pos_y()[i] - 50.0) < 10.0;
        assert_eq!((0..200).filter(|&i| near(i)).count(), 50);
        for i in 0..200 {
            let kept =
                after.pos_x()[i] == before.pos_x()[i] && after.pos_y()[i] == before.pos_y()[i];
            assert!(
                near(i) != kept,
                "particle {i} both moved and kept, or neither"
            );
        }
        assert_eq!(before.vel_x(), after.vel_x());
        assert_eq!(before.modes(), after.modes());
        assert_eq!(before.log_weights(), after.log_weights());
        let mut untouched = filter.clone();
        untouched.propose_near(0.0, Point2::new(300.0, 50.0), 2.0);
        assert_eq!(untouched.particles().pos_x(), before.pos_x());
    }

    #[test]
    fn a_walking_target_is_followed_and_a_standing_one_favours_constant_position() {
        let spec = ImmPfSpec::new(&ImmPfParams::default(), 3, 11).unwrap();
        let mut walker = spec.spawn(1, &spread(Point2::new(100.0, 100.0)));
        let truth = follow(&mut walker, Vec2::new(3.0, 1.0), 40);
        let mean = walker.estimate().mean;
        assert!(
            (mean.at(0) - truth.x).abs() < 2.0 && (mean.at(1) - truth.y).abs() < 2.0,
            "estimate ({}, {}) vs truth {truth:?}",
            mean.at(0),
            mean.at(1)
        );
        assert!((mean.at(2) - 3.0).abs() < 0.5, "velocity {}", mean.at(2));
        let walker_cp = weights(&walker)[0];

        let mut stander = spec.spawn(2, &spread(Point2::new(100.0, 100.0)));
        follow(&mut stander, Vec2::new(0.0, 0.0), 40);
        let stander_cp = weights(&stander)[0];
        assert!(
            stander_cp > walker_cp,
            "constant position weighs {stander_cp} for a standing target, {walker_cp} for a walker"
        );
    }

    #[test]
    fn per_model_resampling_keeps_gamma_particles_per_model() {
        let spec = ImmPfSpec::new(&ImmPfParams::default(), 3, 5).unwrap();
        let mut filter = spec.spawn(3, &spread(Point2::new(50.0, 50.0)));
        let models = models();
        // A likelihood that only constant-velocity particles (label 1) satisfy starves the
        // others at the global resampling.
        for _ in 0..4 {
            filter.predict(&models);
            filter.weight(|p| if p.mode == 1 { 0.0 } else { -50.0 });
        }
        assert_eq!(filter.resample(), ImmResampling::AllParticles);
        let count = |f: &ImmParticleFilter, m: u8| {
            f.particles().modes().iter().filter(|&&x| x == m).count()
        };
        assert!(count(&filter, 0) < 20 && count(&filter, 2) < 20);
        filter.predict(&models);
        filter.weight(|_| 0.0);
        assert_eq!(filter.resample(), ImmResampling::PerModel);
        for m in 0..3 {
            assert!(
                count(&filter, m) >= 20,
                "model {m} has {}",
                count(&filter, m)
            );
        }
        assert_eq!(filter.particles().len(), 200);
        let w = weights(&filter);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-9);
        assert!(w[0] >= 0.09 && w[2] >= 0.09, "{w:?}");
    }

    #[test]
    fn the_same_seed_gives_the_same_filter() {
        let spec = ImmPfSpec::new(&ImmPfParams::default(), 3, 99).unwrap();
        let run = || {
            let mut f = spec.spawn(4, &spread(Point2::new(10.0, 10.0)));
            follow(&mut f, Vec2::new(1.0, 0.0), 12);
            f.particles().pos_x().to_vec()
        };
        assert_eq!(run(), run());
    }

    #[test]
    fn parameters_out_of_range_name_their_key() {
        let bad = ImmPfParams {
            min_model_fraction: 0.5,
            ..Default::default()
        };
        let err = ImmPfSpec::new(&bad, 3, 1).unwrap_err().to_string();
        assert!(err.contains("min_model_fraction"), "{err}");
        let bad = ImmPfParams {
            resample_all_every: 0,
            ..Default::default()
        };
        assert!(
            ImmPfSpec::new(&bad, 3, 1)
                .unwrap_err()
                .to_string()
                .contains("resample_all_every")
        );
        assert!(ImmPfSpec::new(&ImmPfParams::default(), 0, 1).is_err());
    }
}

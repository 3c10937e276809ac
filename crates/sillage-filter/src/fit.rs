//! Learning the bedload motion parameters from ground truth (§4.3 of the MMPF+ paper): the
//! transition table π of Eq. (11) and each state's process-noise covariances of Eq. (3),
//! estimated on trajectories whose points carry a motion state, over the first part of the
//! sequence only ("the first halves of the studied sequences", §4.3).
//!
//! - **Transitions.** Every pair of consecutive frames `t − 1, t` of one track whose two states
//!   are known counts one transition `sₜ₋₁ → sₜ`; a missing frame breaks the chain and an
//!   `Unknown` state is skipped. Each row of π is its counts' frequencies (the maximum-likelihood
//!   estimate of a Markov chain), then floored at [`FitOptions::min_probability`] (see
//!   [`apply_min_probability`]).
//! - **Process noises.** Velocities are finite differences `uₜ = xₜ − xₜ₋₁` (px/frame, Δt = 1
//!   frame). The step `t − 1 → t` belongs to the state at `t` (the state a particle draws before
//!   it moves, §3.5.1), and its residual is what Eq. (3) leaves to the noise:
//!   resting `xₜ − xₜ₋₁`; rolling `xₜ − xₜ₋₁ − (uₜ₋₁, 0)` (needs frame `t − 2`); saltating the
//!   smaller, in squared norm, of the constant residual `xₜ − xₜ₋₁ − (uₜ₋₁, vₜ₋₁)` and the
//!   rebound residual `xₜ − xₜ₋₁ − (uₜ₋₁, −vₜ₋₁)` (ties go to constant). Eq. (3)'s noises are
//!   zero-mean, so each covariance is the second moment about zero, `Σ r rᵀ / n`, which is
//!   unbiased for a known zero mean; the mean residual is reported beside it as a check of that
//!   assumption (a mean far from zero says the motion model misses a drift).
//! - **Velocity noises.** With finite-difference velocities the velocity residual of rolling,
//!   `uₜ − (uₜ₋₁, 0)`, is the position residual itself (and likewise for saltating), so
//!   `roll_vel_noise = roll_pos_noise` and `salt_vel_noise = salt_pos_noise`: the two cannot be
//!   told apart from positions alone, which is also why [`BedloadParams`] defaults each
//!   velocity noise to the position noise. The estimator is exact for Eq. (3) with that
//!   coupling (`ε^(u,v) ≡ ε^(x,y)`, the velocity being the displacement, as in the authors'
//!   code, `../shared/reference/beadtracking.md` §4 item 11); for independent noises it gives
//!   the variance of the one-frame position prediction error, the quantity a tracker's
//!   prediction needs.
//!
//! Everything else ([`BedloadParams::rebound_probability`], the unknown row, the young-track
//! and initial spreads, the flow velocity) is copied from the base parameters; so is a
//! transition row or a state's noises with fewer than [`FitOptions::min_samples`] samples, and
//! the report lists those keys.

use serde::Serialize;
use sillage_core::{Error, FrameIndex, MotionState, Point2, Result, TrackId, Vec2};

use crate::noise::Noise2;
use crate::params::BedloadParams;

/// Floor of every fitted variance, px² (a standard deviation of 0.01 px): far below the
/// quantisation of integer-pixel ground truth (1/12 px² per rounded coordinate), it only
/// matters when every residual of a state is zero, and keeps the covariance positive definite.
pub const MIN_VARIANCE: f64 = 1e-4;

/// Largest |correlation| of a fitted covariance: a sample covariance at |ρ| = 1 (collinear
/// residuals) is shrunk to this so that its Cholesky factor has a positive diagonal.
pub const MAX_CORRELATION: f64 = 0.999;

/// The state names in the order of the rows and columns of π: resting, rolling, saltating.
pub const STATE_NAMES: [&str; 3] = ["resting", "rolling", "saltating"];

/// Training frames are the first ⌊`train_fraction` · n⌋ of the n frames, within this tolerance
/// on the product (so 0.3 · 10 is 3, not 2).
const FRACTION_TOLERANCE: f64 = 1e-9;

/// One ground-truth point of a trajectory: where the object is in a frame, and its motion state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StatePoint {
    /// 0-based frame.
    pub frame: FrameIndex,
    /// Position, px.
    pub pos_px: Point2,
    /// Motion state; `Unknown` points give positions but no state (BeadTracking labels the
    /// first point of every track unknown).
    pub motion_state: MotionState,
}

/// One ground-truth trajectory: its points in strictly increasing frame order (a frame may be
/// missing: the gap breaks the chain of transitions and of velocities).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StateTrack {
    /// Trajectory id (named in errors).
    pub track_id: TrackId,
    /// The points, frames strictly increasing.
    pub points: Vec<StatePoint>,
}

/// How [`fit_bedload`] learns; validated by [`FitOptions::validate`], errors name the option.
#[derive(Debug, Clone, PartialEq)]
pub struct FitOptions {
    /// Share of the sequence's frame range used for training, in (0, 1]: the first
    /// ⌊`train_fraction` · n⌋ of its n frames (a middle frame of an odd range is left out);
    /// default 0.5, the first half (§4.3).
    pub train_fraction: f64,
    /// Minimal transition probability in [0, 1/3], imposed on each fitted row by
    /// [`apply_min_probability`]; default 0.05, our reading of §4.3's "imposing a minimal
    /// probability of 0.05" that turned Eq. (11) into Eq. (12); 0 keeps the raw estimate.
    pub min_probability: f64,
    /// Fewest samples (transitions out of a state for its row of π, residuals of a state for its
    /// noises) for a value to be fitted, at least 2; below it the base value is kept and the
    /// report says so. Default 30: a variance from n samples has a relative standard error of
    /// √(2/n), 26 % at 30.
    pub min_samples: u64,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            train_fraction: 0.5,
            min_probability: 0.05,
            min_samples: 30,
        }
    }
}

impl FitOptions {
    /// Checks every option; the error names it and its allowed range.
    pub fn validate(&self) -> Result<()> {
        if !(self.train_fraction > 0.0 && self.train_fraction <= 1.0) {
            return Err(Error::parameter(
                "train_fraction",
                self.train_fraction,
                "must be in (0, 1] (the paper trains on the first half: 0.5)",
            ));
        }
        if !(0.0..=1.0 / 3.0).contains(&self.min_probability) {
            return Err(Error::parameter(
                "min_probability",
                self.min_probability,
                "must be in [0, 1/3] (the paper imposes 0.05; 0 keeps the raw estimate)",
            ));
        }
        if self.min_samples < 2 {
            return Err(Error::parameter(
                "min_samples",
                self.min_samples,
                "must be at least 2 (a covariance needs two samples; the default is 30)",
            ));
        }
        Ok(())
    }
}

/// What [`fit_bedload`] returns: the fitted parameters and how they were obtained.
#[derive(Debug, Clone, PartialEq)]
pub struct BedloadFit {
    /// The base parameters with π and the five process noises of Eq. (3) replaced where there
    /// were enough samples; valid ([`BedloadParams::validate`]).
    pub params: BedloadParams,
    /// Counts and diagnostics.
    pub report: FitReport,
}

/// How a fit was obtained (states in the order resting, rolling, saltating).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitReport {
    /// First and last frame of the input, 0-based, inclusive.
    pub frame_range: [FrameIndex; 2],
    /// First and last training frame, 0-based, inclusive.
    pub training_frames: [FrameIndex; 2],
    /// Transitions `sₜ₋₁ → sₜ` counted in the training frames, `[from][to]` (Eq. (11)'s data).
    pub transition_counts: [[u64; 3]; 3],
    /// Residuals of Eq. (3) per state (the steps whose state at `t` it is).
    pub samples: [u64; 3],
    /// Saltating steps whose rebound residual was the smaller.
    pub rebound_samples: u64,
    /// Mean residual per state, px (None without samples): near zero if Eq. (3)'s zero-mean
    /// noises fit the data.
    pub mean_residual_px: [Option<Vec2>; 3],
    /// The keys kept from the base parameters for too few samples: `transition[i]` (row `i` of
    /// π) and noise names such as `salt_pos_noise`.
    pub kept: Vec<&'static str>,
}

impl FitReport {
    /// Transitions out of each state: the row sums of [`FitReport::transition_counts`].
    pub fn transitions_from(&self) -> [u64; 3] {
        self.transition_counts.map(|row| row.iter().sum())
    }
}

/// Imposes a minimal probability `min_probability` (in [0, 1/3]) on one row of π: every entry
/// is raised to at least `min_probability`, then the row is divided by its new sum. This is our
/// reading of how §4.3 went from Eq. (11) to Eq. (12) "by imposing a minimal probability of
/// 0.05"; the paper printed no rule, and Eq. (12) also lowers the diagonal further (0.80, where
/// this gives 0.905, 0.885 and 0.867 from Eq. (11)).
///
/// Guarantees, for a row of non-negative entries summing to 1: the result sums to 1 (within
/// rounding), keeps the order of the entries, and every entry is at least
/// `min_probability / (1 + 2·min_probability)` (0.0455 at 0.05), since at most two entries are
/// raised. `min_probability = 0` returns the row unchanged.
pub fn apply_min_probability(row: [f64; 3], min_probability: f64) -> [f64; 3] {
    if min_probability <= 0.0 {
        return row;
    }
    let floored = row.map(|p| p.max(min_probability));
    let sum: f64 = floored.iter().sum();
    floored.map(|p| p / sum)
}

/// Row and column of π for a motion state; `None` for `Unknown`.
fn state_index(state: MotionState) -> Option<usize> {
    match state {
        MotionState::Resting => Some(REST),
        MotionState::Rolling => Some(ROLL),
        MotionState::Saltating => Some(SALT),
        MotionState::Unknown => None,
    }
}

const REST: usize = 0;
const ROLL: usize = 1;
const SALT: usize = 2;

/// Running sums of one state's residuals `r`: count, Σr, Σ r rᵀ.
#[derive(Debug, Clone, Copy, Default)]
struct Moments {
    n: u64,
    sum_x: f64,
    sum_y: f64,
    sum_xx: f64,
    sum_yy: f64,
    sum_xy: f64,
}

impl Moments {
    fn add(&mut self, r: Vec2) {
        self.n += 1;
        self.sum_x += r.x;
        self.sum_y += r.y;
        self.sum_xx += r.x * r.x;
        self.sum_yy += r.y * r.y;
        self.sum_xy += r.x * r.y;
    }

    fn mean(&self) -> Option<Vec2> {
        (self.n > 0).then(|| Vec2::new(self.sum_x, self.sum_y) / self.n as f64)
    }

    /// The second moment about zero, variances floored at [`MIN_VARIANCE`] and the correlation
    /// bounded by [`MAX_CORRELATION`].
    fn covariance(&self) -> Noise2 {
        let n = self.n as f64;
        let var_x = (self.sum_xx / n).max(MIN_VARIANCE);
        let var_y = (self.sum_yy / n).max(MIN_VARIANCE);
        let bound = MAX_CORRELATION * (var_x * var_y).sqrt();
        Noise2 {
            var_x,
            var_y,
            cov_xy: (self.sum_xy / n).clamp(-bound, bound),
        }
    }
}

/// Estimates π (Eq. (11), floored as Eq. (12)) and the process noises of Eq. (3) from
/// ground-truth `tracks` with motion states, on the first `options.train_fraction` of the
/// frame range, starting from `base` (module doc). Errors: invalid options or base (naming the
/// key), a track whose frames do not increase, no known motion state, fewer than two training
/// frames, or too few samples to fit anything.
pub fn fit_bedload(
    tracks: &[StateTrack],
    base: &BedloadParams,
    options: &FitOptions,
) -> Result<BedloadFit> {
    options.validate()?;
    base.validate()?;
    let mut range: Option<[FrameIndex; 2]> = None;
    let mut known_states = 0usize;
    for track in tracks {
        for (k, point) in track.points.iter().enumerate() {
            if k > 0 && point.frame <= track.points[k - 1].frame {
                return Err(Error::input(format!(
                    "track {}: frame {} follows frame {}; list each track's frames once, in \
                     increasing order",
                    track.track_id,
                    point.frame,
                    track.points[k - 1].frame
                )));
            }
            if !point.pos_px.is_finite() {
                return Err(Error::input(format!(
                    "track {}, frame {}: the position is not finite; remove the point",
                    track.track_id, point.frame
                )));
            }
            known_states += usize::from(state_index(point.motion_state).is_some());
            range = Some(match range {
                None => [point.frame, point.frame],
                Some([first, last]) => [first.min(point.frame), last.max(point.frame)],
            });
        }
    }
    let Some(frame_range @ [first, last]) = range else {
        return Err(Error::input(
            "no trajectory points to learn from; give ground truth with motion states",
        ));
    };
    if known_states == 0 {
        return Err(Error::input(
            "no point has a motion state (all unknown): the fit needs ground truth labelled \
             resting (0), rolling (1) or saltating (2), such as BeadTracking's `motion_state` \
             column",
        ));
    }
    let frames = last - first + 1;
    let train_frames =
        ((options.train_fraction * frames as f64 + FRACTION_TOLERANCE).floor() as u64).min(frames);
    if train_frames < 2 {
        return Err(Error::parameter(
            "train_fraction",
            options.train_fraction,
            format!(
                "keeps {train_frames} of the {frames} frames ({first}..={last}); the fit needs \
                 at least 2 consecutive frames (3 for the rolling and saltating noises): raise \
                 it or give a longer sequence"
            ),
        ));
    }
    let train_end = first + train_frames;

    let mut counts = [[0u64; 3]; 3];
    let mut moments = [Moments::default(); 3];
    let mut rebound_samples = 0u64;
    for track in tracks {
        let points = &track.points;
        let used = points.partition_point(|p| p.frame < train_end);
        for t in 1..used {
            let (prev, here) = (&points[t - 1], &points[t]);
            if here.frame != prev.frame + 1 {
                continue;
            }
            let to = state_index(here.motion_state);
            if let (Some(from), Some(to)) = (state_index(prev.motion_state), to) {
                counts[from][to] += 1;
            }
            let Some(state) = to else {
                continue;
            };
            let step = here.pos_px - prev.pos_px;
            if state == REST {
                moments[REST].add(step);
                continue;
            }
            // Rolling and saltating predict with the previous frame's velocity.
            if t < 2 || points[t - 2].frame + 1 != prev.frame {
                continue;
            }
            let vel = prev.pos_px - points[t - 2].pos_px;
            let residual = if state == ROLL {
                step - Vec2::new(vel.x, 0.0)
            } else {
                let constant = step - vel;
                let rebound = step - Vec2::new(vel.x, -vel.y);
                if norm2(rebound) < norm2(constant) {
                    rebound_samples += 1;
                    rebound
                } else {
                    constant
                }
            };
            moments[state].add(residual);
        }
    }
    let transitions: u64 = counts.iter().flatten().sum();
    let samples = moments.map(|m| m.n);
    if transitions == 0 && samples.iter().all(|&n| n == 0) {
        return Err(Error::input(format!(
            "no two consecutive training frames ({first}..={}) of one track have a known \
             motion state; the fit needs tracks labelled on consecutive frames (raise \
             train_fraction if the labels start later)",
            train_end - 1
        )));
    }

    let mut params = base.clone();
    let mut kept = Vec::new();
    const ROW_KEYS: [&str; 3] = ["transition[0]", "transition[1]", "transition[2]"];
    for (s, row) in counts.iter().enumerate() {
        let total: u64 = row.iter().sum();
        if total < options.min_samples {
            kept.push(ROW_KEYS[s]);
            continue;
        }
        let raw = row.map(|c| c as f64 / total as f64);
        params.transition[s] = apply_min_probability(raw, options.min_probability);
    }
    if samples[REST] >= options.min_samples {
        params.rest_pos_noise = moments[REST].covariance();
    } else {
        kept.push("rest_pos_noise");
    }
    if samples[ROLL] >= options.min_samples {
        params.roll_pos_noise = moments[ROLL].covariance();
        params.roll_vel_noise = params.roll_pos_noise;
    } else {
        kept.extend(["roll_pos_noise", "roll_vel_noise"]);
    }
    if samples[SALT] >= options.min_samples {
        params.salt_pos_noise = moments[SALT].covariance();
        params.salt_vel_noise = params.salt_pos_noise;
    } else {
        kept.extend(["salt_pos_noise", "salt_vel_noise"]);
    }
    if kept.len() == ROW_KEYS.len() + 5 {
        let from = counts.map(|row| row.iter().sum::<u64>());
        return Err(Error::parameter(
            "min_samples",
            options.min_samples,
            format!(
                "no state has that many samples in the training frames {first}..={} \
                 (transitions from resting/rolling/saltating: {}/{}/{}; residuals: {}/{}/{}), \
                 so nothing could be fitted: lower it, raise train_fraction or give more \
                 ground truth",
                train_end - 1,
                from[REST],
                from[ROLL],
                from[SALT],
                samples[REST],
                samples[ROLL],
                samples[SALT]
            ),
        ));
    }
    params.validate()?;
    Ok(BedloadFit {
        params,
        report: FitReport {
            frame_range,
            training_frames: [first, train_end - 1],
            transition_counts: counts,
            samples,
            rebound_samples,
            mean_residual_px: moments.map(|m| m.mean()),
            kept,
        },
    })
}

fn norm2(v: Vec2) -> f64 {
    v.x * v.x + v.y * v.y
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::TRANSITION_EQ11;
    use rand::RngExt;
    use rand_distr::StandardNormal;
    use sillage_core::{RngStream, rng_stream};

    const STATES: [MotionState; 3] = [
        MotionState::Resting,
        MotionState::Rolling,
        MotionState::Saltating,
    ];

    /// One draw of the zero-mean Gaussian with covariance `noise` (Cholesky factor).
    fn draw(noise: &Noise2, rng: &mut RngStream) -> Vec2 {
        let (z1, z2): (f64, f64) = (rng.sample(StandardNormal), rng.sample(StandardNormal));
        let l11 = noise.var_x.sqrt();
        let l21 = noise.cov_xy / l11;
        let l22 = (noise.var_y - l21 * l21).sqrt();
        Vec2::new(l11 * z1, l21 * z1 + l22 * z2)
    }

    /// Draws the next state from a row of π.
    fn next_state(row: &[f64; 3], rng: &mut RngStream) -> usize {
        let u: f64 = rng.random();
        let mut running = 0.0;
        for (s, p) in row.iter().enumerate() {
            running += p;
            if u < running {
                return s;
            }
        }
        2
    }

    /// Trajectories of Eq. (3) with finite-difference velocities (the velocity is the last
    /// displacement, `ε^(u,v) ≡ ε^(x,y)`): each step draws `sₜ` from π, predicts resting 0,
    /// rolling `(u, 0)`, saltating `(u, ±v)` (rebound with probability 0.5), and adds the
    /// state's noise. Tracks start in `start` with velocity `vel0`.
    fn simulate(
        params: &BedloadParams,
        tracks: usize,
        frames: u64,
        start: Option<usize>,
        vel0: Vec2,
        seed: u64,
    ) -> Vec<StateTrack> {
        let noises = [
            params.rest_pos_noise,
            params.roll_pos_noise,
            params.salt_pos_noise,
        ];
        (0..tracks)
            .map(|k| {
                let mut rng = rng_stream(seed, k as u64);
                let mut state = start.unwrap_or_else(|| rng.random_range(0..3));
                let mut pos = Point2::new(rng.random_range(0.0..1000.0), 100.0);
                let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
                let mut vel = Vec2::new(vel0.x, sign * vel0.y);
                let mut points = vec![StatePoint {
                    frame: 0,
                    pos_px: pos,
                    motion_state: STATES[state],
                }];
                for frame in 1..frames {
                    state = next_state(&params.transition[state], &mut rng);
                    let predicted = match state {
                        REST => Vec2::ZERO,
                        ROLL => Vec2::new(vel.x, 0.0),
                        _ if rng.random::<f64>() < 0.5 => Vec2::new(vel.x, -vel.y),
                        _ => vel,
                    };
                    let step = predicted + draw(&noises[state], &mut rng);
                    pos = pos + step;
                    vel = step;
                    points.push(StatePoint {
                        frame,
                        pos_px: pos,
                        motion_state: STATES[state],
                    });
                }
                StateTrack {
                    track_id: k as u64,
                    points,
                }
            })
            .collect()
    }

    fn truth_params() -> BedloadParams {
        BedloadParams {
            // Symmetric, so doubly stochastic: a third of the steps in each state.
            transition: [[0.90, 0.08, 0.02], [0.08, 0.86, 0.06], [0.02, 0.06, 0.92]],
            rest_pos_noise: Noise2 {
                var_x: 0.30,
                var_y: 0.20,
                cov_xy: 0.05,
            },
            roll_pos_noise: Noise2 {
                var_x: 3.0,
                var_y: 2.0,
                cov_xy: 0.8,
            },
            salt_pos_noise: Noise2 {
                var_x: 2.0,
                var_y: 2.5,
                cov_xy: -1.0,
            },
            ..BedloadParams::default()
        }
    }

    /// Variances within 5 % (4 standard errors √(2/n) for n ≥ 12,800) and the covariance
    /// within 0.05·√(var_x·var_y) (its standard error is ≤ √(2/n)·√(var_x·var_y)).
    fn assert_noise_close(key: &str, got: &Noise2, want: &Noise2, n: u64) {
        assert!(n >= 12_800, "{key}: only {n} samples");
        for (what, g, w) in [
            ("var_x", got.var_x, want.var_x),
            ("var_y", got.var_y, want.var_y),
        ] {
            assert!((g / w - 1.0).abs() <= 0.05, "{key}.{what}: {g} vs {w}");
        }
        let scale = (want.var_x * want.var_y).sqrt();
        assert!(
            (got.cov_xy - want.cov_xy).abs() <= 0.05 * scale,
            "{key}.cov_xy: {} vs {}",
            got.cov_xy,
            want.cov_xy
        );
    }

    fn raw_options() -> FitOptions {
        FitOptions {
            train_fraction: 1.0,
            min_probability: 0.0,
            ..FitOptions::default()
        }
    }

    #[test]
    fn recovers_the_transition_table_and_the_resting_and_rolling_noises() {
        let truth = truth_params();
        // 1000 tracks of 101 frames: 100,000 steps, about a third in each state.
        let tracks = simulate(&truth, 1000, 101, None, Vec2::new(-5.0, 0.0), 7);
        let fit = fit_bedload(&tracks, &BedloadParams::default(), &raw_options()).unwrap();
        let report = &fit.report;
        assert!(report.kept.is_empty(), "{:?}", report.kept);
        let from = report.transitions_from();
        assert_eq!(from.iter().sum::<u64>(), 100_000);
        for (s, &n) in from.iter().enumerate() {
            // Each estimated probability within 4 binomial standard errors of the truth.
            for to in 0..3 {
                let (p, got) = (truth.transition[s][to], fit.params.transition[s][to]);
                let tolerance = 4.0 * (p * (1.0 - p) / n as f64).sqrt();
                assert!(
                    (got - p).abs() <= tolerance,
                    "π[{s}][{to}] = {got}, truth {p}"
                );
            }
        }
        // Every step into resting has a residual; rolling and saltating need frame t − 2.
        let into = |to: usize| report.transition_counts.iter().map(|r| r[to]).sum::<u64>();
        assert_eq!(report.samples[REST], into(REST));
        assert!(report.samples[ROLL] < into(ROLL) && report.samples[ROLL] + 1000 >= into(ROLL));
        assert_noise_close(
            "rest_pos_noise",
            &fit.params.rest_pos_noise,
            &truth.rest_pos_noise,
            report.samples[REST],
        );
        assert_noise_close(
            "roll_pos_noise",
            &fit.params.roll_pos_noise,
            &truth.roll_pos_noise,
            report.samples[ROLL],
        );
        assert_eq!(fit.params.roll_vel_noise, fit.params.roll_pos_noise);
        assert_eq!(fit.params.salt_vel_noise, fit.params.salt_pos_noise);
        // Zero-mean noises: mean residuals within 4 standard errors of zero.
        for s in [REST, ROLL] {
            let mean = report.mean_residual_px[s].unwrap();
            let n = report.samples[s] as f64;
            assert!(mean.x.abs() < 4.0 * (3.0 / n).sqrt(), "{mean:?}");
            assert!(mean.y.abs() < 4.0 * (3.0 / n).sqrt(), "{mean:?}");
        }
        // Everything not fitted is the base's.
        let base = BedloadParams::default();
        assert_eq!(fit.params.unknown_transition, base.unknown_transition);
        assert_eq!(fit.params.flow_vel_px_per_frame, base.flow_vel_px_per_frame);
        fit.params.validate().unwrap();
    }

    #[test]
    fn recovers_the_saltating_noise_and_keeps_the_base_where_samples_are_few() {
        let truth = BedloadParams {
            transition: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            ..truth_params()
        };
        // Flights fast enough vertically (|v| ≈ 30 px/frame against σ_y ≈ 1.6) that the smaller
        // residual is the true sub-state's: 1000 tracks of 21 frames, 19,000 residuals.
        let tracks = simulate(&truth, 1000, 21, Some(SALT), Vec2::new(-15.0, 30.0), 11);
        let base = BedloadParams::default();
        let fit = fit_bedload(&tracks, &base, &raw_options()).unwrap();
        let report = &fit.report;
        assert_eq!(
            report.transition_counts,
            [[0, 0, 0], [0, 0, 0], [0, 0, 20_000]]
        );
        assert_eq!(report.samples, [0, 0, 19_000]);
        assert_noise_close(
            "salt_pos_noise",
            &fit.params.salt_pos_noise,
            &truth.salt_pos_noise,
            report.samples[SALT],
        );
        assert_eq!(fit.params.salt_vel_noise, fit.params.salt_pos_noise);
        // Rebounds are drawn with probability 0.5: within 4 binomial standard errors.
        let share = report.rebound_samples as f64 / 19_000.0;
        assert!(
            (share - 0.5).abs() < 4.0 * (0.25f64 / 19_000.0).sqrt(),
            "{share}"
        );
        assert_eq!(fit.params.transition[SALT], [0.0, 0.0, 1.0]);
        // Resting and rolling have no samples: their values are the base's, and reported.
        assert_eq!(
            report.kept,
            [
                "transition[0]",
                "transition[1]",
                "rest_pos_noise",
                "roll_pos_noise",
                "roll_vel_noise"
            ]
        );
        assert_eq!(fit.params.transition[REST], base.transition[REST]);
        assert_eq!(fit.params.transition[ROLL], base.transition[ROLL]);
        assert_eq!(fit.params.rest_pos_noise, base.rest_pos_noise);
        assert_eq!(fit.params.roll_vel_noise, base.roll_vel_noise);
        assert_eq!(report.mean_residual_px[REST], None);
        // The default floor turns the absorbing row into a valid table with every entry ≥ 0.05/1.1.
        let floored = fit_bedload(
            &tracks,
            &base,
            &FitOptions {
                train_fraction: 1.0,
                ..FitOptions::default()
            },
        )
        .unwrap();
        let row = floored.params.transition[SALT];
        assert!((row[0] - 0.05 / 1.1).abs() < 1e-12 && (row[2] - 1.0 / 1.1).abs() < 1e-12);
        crate::TransitionTable::new("transition", &floored.params.transition).unwrap();
    }

    #[test]
    fn only_the_training_frames_are_used() {
        let truth = truth_params();
        let tracks = simulate(&truth, 200, 100, None, Vec2::new(-5.0, 0.0), 3);
        // Poison the second half (frames 50..=99): jumps of kilometres, every state saltating.
        let mut poisoned = tracks.clone();
        for track in &mut poisoned {
            for p in track.points.iter_mut().filter(|p| p.frame >= 50) {
                p.pos_px = p.pos_px + Vec2::new(1e3 * p.frame as f64, -7e2 * (p.frame % 3) as f64);
                p.motion_state = MotionState::Saltating;
            }
        }
        let half = FitOptions {
            train_fraction: 0.5,
            ..raw_options()
        };
        let clean = fit_bedload(&tracks, &BedloadParams::default(), &half).unwrap();
        let dirty = fit_bedload(&poisoned, &BedloadParams::default(), &half).unwrap();
        assert_eq!(clean, dirty);
        assert_eq!(clean.report.frame_range, [0, 99]);
        assert_eq!(clean.report.training_frames, [0, 49]);
        // Identical to fitting frames 0..=49 alone, all of them.
        let first_half: Vec<StateTrack> = tracks
            .iter()
            .map(|t| StateTrack {
                track_id: t.track_id,
                points: t.points.iter().filter(|p| p.frame < 50).copied().collect(),
            })
            .collect();
        let alone = fit_bedload(&first_half, &BedloadParams::default(), &raw_options()).unwrap();
        assert_eq!(alone.params, clean.params);
        assert_eq!(
            alone.report.transition_counts,
            clean.report.transition_counts
        );
        assert_eq!(alone.report.samples, clean.report.samples);
        assert_eq!(
            clean.report.transitions_from().iter().sum::<u64>(),
            200 * 49
        );
        // The whole range does see the poison.
        let all = fit_bedload(&poisoned, &BedloadParams::default(), &raw_options()).unwrap();
        assert_ne!(all.params, clean.params);
        // An odd range leaves its middle frame out; ⌊0.3 · 10⌋ is 3, not 2.
        let cut = |frames: u64| -> Vec<StateTrack> {
            tracks
                .iter()
                .map(|t| StateTrack {
                    track_id: t.track_id,
                    points: t.points[..frames as usize].to_vec(),
                })
                .collect()
        };
        let odd = fit_bedload(&cut(11), &BedloadParams::default(), &half).unwrap();
        assert_eq!(odd.report.training_frames, [0, 4]);
        let tenth = FitOptions {
            train_fraction: 0.3,
            ..raw_options()
        };
        let three = fit_bedload(&cut(10), &BedloadParams::default(), &tenth).unwrap();
        assert_eq!(three.report.training_frames, [0, 2]);
    }

    fn point(frame: FrameIndex, x: f64, y: f64, motion_state: MotionState) -> StatePoint {
        StatePoint {
            frame,
            pos_px: Point2::new(x, y),
            motion_state,
        }
    }

    #[test]
    fn gaps_and_unknown_states_break_the_chains() {
        use MotionState::{Resting as Re, Rolling as Ro, Saltating as Sa, Unknown as Un};
        // Frame 3 is missing from track 1; track 2 has an unknown state in frame 1.
        let gap = StateTrack {
            track_id: 1,
            points: vec![
                point(0, 0.0, 0.0, Un),
                point(1, 1.0, 0.0, Re),
                point(2, 3.0, 1.0, Ro),
                point(4, 10.0, 0.0, Ro),
                point(5, 12.0, -2.0, Ro),
                point(6, 15.0, 1.0, Sa),
            ],
        };
        let still = StateTrack {
            track_id: 2,
            points: vec![
                point(0, 50.0, 50.0, Re),
                point(1, 50.0, 50.0, Un),
                point(2, 50.0, 50.0, Re),
                point(3, 50.0, 50.0, Re),
            ],
        };
        let options = FitOptions {
            min_samples: 2,
            ..raw_options()
        };
        let base = BedloadParams::default();
        let fit = fit_bedload(&[gap.clone(), still.clone()], &base, &options).unwrap();
        let report = &fit.report;
        // Counted: 1→2 rest→roll, 4→5 roll→roll, 5→6 roll→salt (track 1); 2→3 rest→rest
        // (track 2). Not counted: anything with the unknown states, and 2→4 across the gap.
        assert_eq!(report.transition_counts, [[1, 1, 0], [0, 1, 1], [0, 0, 0]]);
        // Residuals: resting at frame 1 (1, 0) and frames 2, 3 of track 2 (0, 0); rolling at
        // frame 2 only, (2, 1) − (1, 0) = (1, 1) (frames 4 and 5 lack frame 3); saltating at 6:
        // step (3, 3), velocity (2, −2), rebound residual (1, 1) beats constant (1, 5).
        assert_eq!(report.samples, [3, 1, 1]);
        assert_eq!(report.rebound_samples, 1);
        assert_eq!(
            report.mean_residual_px,
            [
                Some(Vec2::new(1.0 / 3.0, 0.0)),
                Some(Vec2::new(1.0, 1.0)),
                Some(Vec2::new(1.0, 1.0))
            ]
        );
        // Resting's and rolling's rows have 2 transitions (fitted), saltating's none (kept);
        // resting has 3 residuals (fitted), the others 1 (kept).
        assert_eq!(fit.params.transition[REST], [0.5, 0.5, 0.0]);
        assert_eq!(fit.params.transition[ROLL], [0.0, 0.5, 0.5]);
        assert_eq!(fit.params.transition[SALT], base.transition[SALT]);
        assert_eq!(
            report.kept,
            [
                "transition[2]",
                "roll_pos_noise",
                "roll_vel_noise",
                "salt_pos_noise",
                "salt_vel_noise"
            ]
        );
        // The resting covariance is the second moment about zero: ((1, 0)ᵀ(1, 0) + 0 + 0) / 3.
        assert_eq!(fit.params.rest_pos_noise.var_x, 1.0 / 3.0);
        assert_eq!(fit.params.rest_pos_noise.var_y, MIN_VARIANCE);
        assert_eq!(fit.params.rest_pos_noise.cov_xy, 0.0);

        // Closing the gap (frames 4, 5, 6 → 3, 4, 5) links the chain and adds two rolling
        // residuals: (7, −1) − (2, 0) and (2, −2) − (7, 0).
        let mut closed = gap;
        for p in closed.points.iter_mut().skip(3) {
            p.frame -= 1;
        }
        let fit = fit_bedload(&[closed, still], &base, &options).unwrap();
        assert_eq!(
            fit.report.transition_counts,
            [[1, 1, 0], [0, 2, 1], [0, 0, 0]]
        );
        assert_eq!(fit.report.samples, [3, 3, 1]);
        assert_eq!(
            fit.report.mean_residual_px[ROLL],
            Some(Vec2::new((1.0 + 5.0 - 5.0) / 3.0, (1.0 - 1.0 - 2.0) / 3.0))
        );
    }

    #[test]
    fn the_minimal_probability_keeps_rows_stochastic_and_bounded() {
        let rows = [
            TRANSITION_EQ11[0],
            TRANSITION_EQ11[1],
            TRANSITION_EQ11[2],
            [1.0, 0.0, 0.0],
            [0.5, 0.5, 0.0],
            [1.0 / 3.0; 3],
            [0.97, 0.02, 0.01],
            [0.2, 0.3, 0.5],
        ];
        for m in [0.0, 0.01, 0.05, 0.2, 1.0 / 3.0] {
            let bound = m / (1.0 + 2.0 * m);
            for row in rows {
                let floored = apply_min_probability(row, m);
                assert!(
                    (floored.iter().sum::<f64>() - 1.0).abs() < 1e-12,
                    "{floored:?}"
                );
                for i in 0..3 {
                    assert!(floored[i] >= bound * (1.0 - 1e-12), "{m}: {floored:?}");
                    for j in 0..3 {
                        if row[i] <= row[j] {
                            assert!(floored[i] <= floored[j], "{row:?} → {floored:?}");
                        }
                    }
                }
                if m == 0.0 {
                    assert_eq!(floored, row);
                }
            }
        }
        // The bound is reached when two entries are raised.
        let one_hot = apply_min_probability([1.0, 0.0, 0.0], 0.05);
        assert!((one_hot[1] - 0.05 / 1.1).abs() < 1e-15);
        // Eq. (11) floored at 0.05 is not the printed Eq. (12), which also lowers the diagonal.
        let eq11 = TRANSITION_EQ11.map(|row| apply_min_probability(row, 0.05));
        let expected = [
            [0.95 / 1.05, 0.05 / 1.05, 0.05 / 1.05],
            [0.07 / 1.04, 0.92 / 1.04, 0.05 / 1.04],
            [0.05 / 1.05, 0.09 / 1.05, 0.91 / 1.05],
        ];
        for (got, want) in eq11.iter().flatten().zip(expected.iter().flatten()) {
            assert!((got - want).abs() < 1e-15);
        }
    }

    #[test]
    fn degenerate_residuals_give_valid_positive_definite_noises() {
        use MotionState::{Resting, Rolling};
        // Integer-pixel truth of beads that never move, and rolling residuals all on y = x.
        let resting: Vec<StateTrack> = (0..40)
            .map(|k| StateTrack {
                track_id: k,
                points: (0..4).map(|f| point(f, k as f64, 7.0, Resting)).collect(),
            })
            .collect();
        let rolling = StateTrack {
            track_id: 99,
            points: (0..40)
                .map(|f| {
                    // Displacements 0, 1, 3, 6, ...: each residual is (k, k)-shaped on x,
                    // with y following x.
                    let x = (f * (f + 1) / 2) as f64;
                    point(f, x, x, Rolling)
                })
                .collect(),
        };
        let mut tracks = resting;
        tracks.push(rolling);
        let fit = fit_bedload(&tracks, &BedloadParams::default(), &raw_options()).unwrap();
        let p = &fit.params;
        assert_eq!(
            p.rest_pos_noise,
            Noise2::diagonal(MIN_VARIANCE, MIN_VARIANCE)
        );
        assert!(
            p.roll_pos_noise.cov_xy.abs()
                <= MAX_CORRELATION * (p.roll_pos_noise.var_x * p.roll_pos_noise.var_y).sqrt()
        );
        p.validate().unwrap();
        for (key, noise) in p.noises() {
            noise.factor_positive_definite(key).unwrap();
        }
    }

    #[test]
    fn options_and_inputs_out_of_range_are_rejected_naming_the_option() {
        let tracks = simulate(&truth_params(), 20, 10, None, Vec2::new(-5.0, 0.0), 5);
        let base = BedloadParams::default();
        let bad = [
            (
                "train_fraction",
                FitOptions {
                    train_fraction: 0.0,
                    ..FitOptions::default()
                },
            ),
            (
                "train_fraction",
                FitOptions {
                    train_fraction: 1.5,
                    ..FitOptions::default()
                },
            ),
            (
                "train_fraction",
                FitOptions {
                    train_fraction: f64::NAN,
                    ..FitOptions::default()
                },
            ),
            // Keeps ⌊0.15 · 10⌋ = 1 frame: no step to learn from.
            (
                "train_fraction",
                FitOptions {
                    train_fraction: 0.15,
                    ..FitOptions::default()
                },
            ),
            (
                "min_probability",
                FitOptions {
                    min_probability: -0.01,
                    ..FitOptions::default()
                },
            ),
            (
                "min_probability",
                FitOptions {
                    min_probability: 0.34,
                    ..FitOptions::default()
                },
            ),
            (
                "min_probability",
                FitOptions {
                    min_probability: f64::NAN,
                    ..FitOptions::default()
                },
            ),
            (
                "min_samples",
                FitOptions {
                    min_samples: 1,
                    ..FitOptions::default()
                },
            ),
            // 20 tracks × 4 steps: no state reaches 1000 samples.
            (
                "min_samples",
                FitOptions {
                    min_samples: 1000,
                    ..FitOptions::default()
                },
            ),
        ];
        for (key, options) in bad {
            let error = fit_bedload(&tracks, &base, &options)
                .unwrap_err()
                .to_string();
            assert!(error.contains(&format!("`{key}`")), "{key}: {error}");
        }
        FitOptions::default().validate().unwrap();
        let invalid_base = BedloadParams {
            rebound_probability: 2.0,
            ..BedloadParams::default()
        };
        let error = fit_bedload(&tracks, &invalid_base, &FitOptions::default()).unwrap_err();
        assert!(
            error.to_string().contains("`rebound_probability`"),
            "{error}"
        );
    }

    #[test]
    fn inputs_that_cannot_be_fitted_say_why() {
        let options = FitOptions::default();
        let base = BedloadParams::default();
        let error = fit_bedload(&[], &base, &options).unwrap_err().to_string();
        assert!(error.contains("no trajectory points"), "{error}");
        let unlabelled = StateTrack {
            track_id: 3,
            points: (0..10)
                .map(|f| point(f, f as f64, 0.0, MotionState::Unknown))
                .collect(),
        };
        let error = fit_bedload(&[unlabelled], &base, &options)
            .unwrap_err()
            .to_string();
        assert!(error.contains("no point has a motion state"), "{error}");
        let repeated = StateTrack {
            track_id: 5,
            points: vec![
                point(3, 0.0, 0.0, MotionState::Resting),
                point(3, 1.0, 0.0, MotionState::Resting),
            ],
        };
        let error = fit_bedload(&[repeated], &base, &options)
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("track 5: frame 3 follows frame 3"),
            "{error}"
        );
        // Labelled points, but never two consecutive labelled frames.
        let sparse = StateTrack {
            track_id: 8,
            points: (0..10)
                .map(|f| point(2 * f, f as f64, 0.0, MotionState::Resting))
                .collect(),
        };
        let error = fit_bedload(&[sparse], &base, &options)
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("no two consecutive training frames"),
            "{error}"
        );
    }
}

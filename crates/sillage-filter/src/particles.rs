//! The particles of one target as a structure of arrays: one column per state variable, so the
//! motion models, the likelihood and the resampling gather stream through contiguous memory.
//!
//! The state of a particle is `cᵢ = {xᵢ, uᵢ, sᵢ}` (§3.5 of the MMPF+ paper): position,
//! velocity and a motion-state index, plus an optional acceleration for the constant
//! acceleration model, and its log weight.

use sillage_core::{Point2, RngStream, Vec2};

use crate::linalg::{Gaussian, Matrix, Vector};
use crate::noise::Gauss2;
use crate::normal::Normals;
use crate::weights::sanitise_log_likelihood;

/// One particle as the likelihood sees it (read-only copy of its columns).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Particle {
    /// Position, px.
    pub pos_px: Point2,
    /// Velocity, px/frame.
    pub vel_px_per_frame: Vec2,
    /// Motion-state index (the model's own numbering; 0 for single-model filters).
    pub mode: u8,
}

/// Mutable views of every state column at once, for motion models (disjoint borrows).
/// All slices have the particle count as length, except `acc_x`/`acc_y`, which are empty
/// until [`Particles::enable_acceleration`] is called.
#[derive(Debug)]
pub struct Columns<'a> {
    /// Positions along x, px.
    pub pos_x: &'a mut [f64],
    /// Positions along y, px.
    pub pos_y: &'a mut [f64],
    /// Velocities along x, px/frame.
    pub vel_x: &'a mut [f64],
    /// Velocities along y, px/frame.
    pub vel_y: &'a mut [f64],
    /// Accelerations along x, px/frame² (empty unless enabled).
    pub acc_x: &'a mut [f64],
    /// Accelerations along y, px/frame² (empty unless enabled).
    pub acc_y: &'a mut [f64],
    /// Motion-state indices.
    pub mode: &'a mut [u8],
}

/// How a target's particles start: Gaussian around a detection (§4.3: "positions centered at
/// the detection center and velocities centered to null velocity"), all in one motion state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InitialSpread {
    /// Centre of the positions, px.
    pub pos_px: Point2,
    /// Spread of the positions.
    pub pos_noise: Gauss2,
    /// Centre of the velocities, px/frame.
    pub vel_px_per_frame: Vec2,
    /// Spread of the velocities.
    pub vel_noise: Gauss2,
    /// Motion-state index of every particle (the bedload model's "unknown").
    pub mode: u8,
}

/// The N particles of one target, with their log weights and the scratch buffers the
/// resampling gather reuses from step to step.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Particles {
    pos_x: Vec<f64>,
    pos_y: Vec<f64>,
    vel_x: Vec<f64>,
    vel_y: Vec<f64>,
    acc_x: Vec<f64>,
    acc_y: Vec<f64>,
    mode: Vec<u8>,
    log_weights: Vec<f64>,
    /// True when every weight is known to be 1/N (after resampling or initialisation).
    uniform: bool,
    scratch: Vec<f64>,
    scratch_mode: Vec<u8>,
}

impl Particles {
    /// `n` particles at the origin, at rest, in mode 0, with uniform weights.
    pub fn new(n: usize) -> Self {
        Self {
            pos_x: vec![0.0; n],
            pos_y: vec![0.0; n],
            vel_x: vec![0.0; n],
            vel_y: vec![0.0; n],
            acc_x: Vec::new(),
            acc_y: Vec::new(),
            mode: vec![0; n],
            log_weights: vec![-(n.max(1) as f64).ln(); n],
            uniform: true,
            scratch: Vec::with_capacity(n),
            scratch_mode: Vec::with_capacity(n),
        }
    }

    /// The particle count N.
    pub fn len(&self) -> usize {
        self.pos_x.len()
    }

    /// True when there are no particles.
    pub fn is_empty(&self) -> bool {
        self.pos_x.is_empty()
    }

    /// Particle `i` (panics when `i ≥ len()`, a bug).
    #[inline]
    pub fn get(&self, i: usize) -> Particle {
        Particle {
            pos_px: Point2::new(self.pos_x[i], self.pos_y[i]),
            vel_px_per_frame: Vec2::new(self.vel_x[i], self.vel_y[i]),
            mode: self.mode[i],
        }
    }

    /// Positions along x, px.
    pub fn pos_x(&self) -> &[f64] {
        &self.pos_x
    }

    /// Positions along y, px.
    pub fn pos_y(&self) -> &[f64] {
        &self.pos_y
    }

    /// Velocities along x, px/frame.
    pub fn vel_x(&self) -> &[f64] {
        &self.vel_x
    }

    /// Velocities along y, px/frame.
    pub fn vel_y(&self) -> &[f64] {
        &self.vel_y
    }

    /// Accelerations along x, px/frame² (empty unless enabled).
    pub fn acc_x(&self) -> &[f64] {
        &self.acc_x
    }

    /// Accelerations along y, px/frame² (empty unless enabled).
    pub fn acc_y(&self) -> &[f64] {
        &self.acc_y
    }

    /// Motion-state indices.
    pub fn modes(&self) -> &[u8] {
        &self.mode
    }

    /// Normalised log weights (`Σ exp = 1`).
    pub fn log_weights(&self) -> &[f64] {
        &self.log_weights
    }

    /// Adds acceleration columns (zero) if they are absent; the constant-acceleration model
    /// calls it, so a set starts with zero acceleration whatever created it.
    pub fn enable_acceleration(&mut self) {
        if self.acc_x.len() != self.len() {
            self.acc_x = vec![0.0; self.len()];
            self.acc_y = vec![0.0; self.len()];
        }
    }

    /// Every state column at once, for a motion model.
    pub fn columns_mut(&mut self) -> Columns<'_> {
        Columns {
            pos_x: &mut self.pos_x,
            pos_y: &mut self.pos_y,
            vel_x: &mut self.vel_x,
            vel_y: &mut self.vel_y,
            acc_x: &mut self.acc_x,
            acc_y: &mut self.acc_y,
            mode: &mut self.mode,
        }
    }

    /// Sets every particle's velocity to `vel` (§3.5.2: "set each velocity component of the
    /// state to u_obs at the weighting step").
    pub fn set_velocity(&mut self, vel: Vec2) {
        self.vel_x.fill(vel.x);
        self.vel_y.fill(vel.y);
    }

    /// Draws every particle from `spread` and makes the weights uniform.
    pub fn initialise(&mut self, spread: &InitialSpread, rng: &mut RngStream) {
        let mut normals = Normals::new(rng);
        for i in 0..self.len() {
            let (dx, dy) = spread.pos_noise.sample(1.0, &mut normals);
            let (du, dv) = spread.vel_noise.sample(1.0, &mut normals);
            self.pos_x[i] = spread.pos_px.x + dx;
            self.pos_y[i] = spread.pos_px.y + dy;
            self.vel_x[i] = spread.vel_px_per_frame.x + du;
            self.vel_y[i] = spread.vel_px_per_frame.y + dv;
        }
        self.acc_x.fill(0.0);
        self.acc_y.fill(0.0);
        self.mode.fill(spread.mode);
        self.set_uniform_weights();
    }

    /// Adds `log_likelihood(particle)` to each log weight (left unnormalised): the weighting of
    /// Eq. (6). NaN counts as −∞, +∞ as the largest finite value.
    pub(crate) fn add_log_likelihood(&mut self, log_likelihood: impl FnMut(Particle) -> f64) {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU supports AVX-512F, checked just above.
            unsafe { self.add_log_likelihood_avx512(log_likelihood) };
            return;
        }
        self.add_log_likelihood_with(log_likelihood);
    }

    /// [`Particles::add_log_likelihood`] compiled for AVX-512, so that a likelihood the
    /// compiler can see through runs eight particles at a time (same values).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    fn add_log_likelihood_avx512(&mut self, log_likelihood: impl FnMut(Particle) -> f64) {
        self.add_log_likelihood_with(log_likelihood);
    }

    /// The body of [`Particles::add_log_likelihood`].
    #[inline(always)]
    fn add_log_likelihood_with(&mut self, mut log_likelihood: impl FnMut(Particle) -> f64) {
        self.uniform = false;
        for (i, lw) in self.log_weights.iter_mut().enumerate() {
            let particle = Particle {
                pos_px: Point2::new(self.pos_x[i], self.pos_y[i]),
                vel_px_per_frame: Vec2::new(self.vel_x[i], self.vel_y[i]),
                mode: self.mode[i],
            };
            *lw += sanitise_log_likelihood(log_likelihood(particle));
        }
    }

    /// The log weights, for normalisation in place (crate-internal).
    pub(crate) fn log_weights_mut(&mut self) -> &mut [f64] {
        self.uniform = false;
        &mut self.log_weights
    }

    /// Makes every weight 1/N.
    pub(crate) fn set_uniform_weights(&mut self) {
        let uniform = -(self.len().max(1) as f64).ln();
        self.log_weights.fill(uniform);
        self.uniform = true;
    }

    /// Replaces the set by the particles `ancestors` names (one entry per new particle, each
    /// < N) and makes the weights uniform: the gather step of resampling.
    pub(crate) fn select(&mut self, ancestors: &[u32]) {
        debug_assert_eq!(ancestors.len(), self.len());
        let scratch = &mut self.scratch;
        for column in [
            &mut self.pos_x,
            &mut self.pos_y,
            &mut self.vel_x,
            &mut self.vel_y,
            &mut self.acc_x,
            &mut self.acc_y,
        ] {
            if column.is_empty() {
                continue;
            }
            scratch.resize(ancestors.len(), 0.0);
            gather_widest(column, ancestors, scratch);
            std::mem::swap(column, scratch);
        }
        // One motion state throughout (a single-model filter) stays as it is.
        if let Some((&first, rest)) = self.mode.split_first()
            && rest.iter().any(|&m| m != first)
        {
            self.scratch_mode.clear();
            self.scratch_mode
                .extend(ancestors.iter().map(|&a| self.mode[a as usize]));
            std::mem::swap(&mut self.mode, &mut self.scratch_mode);
        }
        self.set_uniform_weights();
    }

    /// The weighted mean and covariance of `(x, y, u, v)`: the target's estimate and its
    /// particle spread (§3.5.3, "averaging the resampled particles"); the covariance is the
    /// weighted population one. One pass over the columns, with sums taken about the first
    /// particle (shifted data), which keeps the covariance accurate far from the origin.
    pub fn estimate(&self) -> Gaussian<4> {
        if self.is_empty() {
            return Gaussian {
                mean: Vector::ZERO,
                cov: Matrix::ZERO,
            };
        }
        let (sum_w, sum, sum_sq) = if self.uniform {
            self.moment_sums(|_| 1.0)
        } else {
            self.moment_sums(|lw| lw.exp())
        };
        let centred = sum.map(|s| s / sum_w);
        let shift = [self.pos_x[0], self.pos_y[0], self.vel_x[0], self.vel_y[0]];
        let mut cov = [[0.0; 4]; 4];
        for r in 0..4 {
            for c in r..4 {
                let value = sum_sq[r][c] / sum_w - centred[r] * centred[c];
                cov[r][c] = value;
                cov[c][r] = value;
            }
        }
        Gaussian {
            mean: Vector::from_array([0, 1, 2, 3].map(|k| shift[k] + centred[k])),
            cov: Matrix(cov),
        }
    }

    /// `Σw`, `Σw·d` and the upper triangle of `Σw·d·dᵀ` for `d` = state − first particle's
    /// state, with `w = weight(log weight)`.
    fn moment_sums(&self, weight: impl Fn(f64) -> f64) -> (f64, [f64; 4], [[f64; 4]; 4]) {
        let shift = [self.pos_x[0], self.pos_y[0], self.vel_x[0], self.vel_y[0]];
        let (mut sum_w, mut sum, mut sum_sq) = (0.0, [0.0; 4], [[0.0; 4]; 4]);
        let states = self
            .pos_x
            .iter()
            .zip(&self.pos_y)
            .zip(self.vel_x.iter().zip(&self.vel_y))
            .zip(&self.log_weights);
        for (((&x, &y), (&u, &v)), &lw) in states {
            let w = weight(lw);
            let d = [x - shift[0], y - shift[1], u - shift[2], v - shift[3]];
            sum_w += w;
            for r in 0..4 {
                let wd = w * d[r];
                sum[r] += wd;
                for c in r..4 {
                    sum_sq[r][c] += wd * d[c];
                }
            }
        }
        (sum_w, sum, sum_sq)
    }

    /// Adds each particle's weight to `probabilities[mode]`, after zeroing it: the weighted
    /// share of each motion state (modes beyond the slice are ignored).
    pub fn mode_probabilities(&self, probabilities: &mut [f64]) {
        probabilities.fill(0.0);
        let uniform_weight = 1.0 / self.len().max(1) as f64;
        for (i, &mode) in self.mode.iter().enumerate() {
            if let Some(p) = probabilities.get_mut(mode as usize) {
                *p += if self.uniform {
                    uniform_weight
                } else {
                    self.log_weights[i].exp()
                };
            }
        }
    }
}

/// `out[k] = column[ancestors[k]]`. Each index is clamped to the column (a no-op for valid
/// ancestors) so that no bounds check is left in the loop, which the compiler then turns into
/// vector gathers.
#[inline(always)]
fn gather(column: &[f64], ancestors: &[u32], out: &mut [f64]) {
    let Some(last) = column.len().checked_sub(1) else {
        return;
    };
    for (value, &a) in out.iter_mut().zip(ancestors) {
        *value = column[(a as usize).min(last)];
    }
}

/// [`gather`] on the fastest path the CPU offers (the same values on every path).
fn gather_widest(column: &[f64], ancestors: &[u32], out: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx512f") {
        // SAFETY: the CPU supports AVX-512F, checked just above.
        unsafe { gather_sorted_avx512(column, ancestors, out) };
        return;
    }
    gather_vectorised(column, ancestors, out);
}

sillage_core::multiversion! {
    /// [`gather`] compiled for AVX2 where the CPU has it (vector gathers), else the baseline.
    fn gather_vectorised(column: &[f64], ancestors: &[u32], out: &mut [f64]) => gather
}

/// [`gather`] for ancestors that mostly come sorted, as resampling draws them: eight
/// ancestors within sixteen consecutive particles (nearly always, as copies of one particle
/// follow each other) are served by two vector loads and one permutation instead of a
/// gather of eight scattered loads; other blocks fall back to [`gather`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn gather_sorted_avx512(column: &[f64], ancestors: &[u32], out: &mut [f64]) {
    use std::arch::x86_64::{
        _mm256_loadu_si256, _mm512_cmplt_epu64_mask, _mm512_cvtepu32_epi64, _mm512_loadu_pd,
        _mm512_permutex2var_pd, _mm512_set1_epi64, _mm512_storeu_pd, _mm512_sub_epi64,
    };
    const LANES: usize = 8;
    let n = ancestors.len().min(out.len());
    let Some(last_base) = column.len().checked_sub(2 * LANES) else {
        gather(column, ancestors, out);
        return;
    };
    let blocks = n / LANES;
    for b in 0..blocks {
        let (a, o) = (
            &ancestors[b * LANES..(b + 1) * LANES],
            &mut out[b * LANES..(b + 1) * LANES],
        );
        let base = (a[0] as usize).min(last_base);
        // SAFETY: the loads read 8 u32 from `a` (8 long) and 16 f64 from `column` at
        // `base ≤ len − 16`; the store writes 8 f64 to `o` (8 long).
        let served = unsafe {
            let offsets = _mm512_sub_epi64(
                _mm512_cvtepu32_epi64(_mm256_loadu_si256(a.as_ptr().cast())),
                _mm512_set1_epi64(base as i64),
            );
            // Every ancestor in base..base + 16 (an ancestor below base wraps around).
            let within = _mm512_cmplt_epu64_mask(offsets, _mm512_set1_epi64(2 * LANES as i64));
            if within == u8::MAX {
                let low = _mm512_loadu_pd(column.as_ptr().add(base));
                let high = _mm512_loadu_pd(column.as_ptr().add(base + LANES));
                _mm512_storeu_pd(o.as_mut_ptr(), _mm512_permutex2var_pd(low, offsets, high));
                true
            } else {
                false
            }
        };
        if !served {
            gather(column, a, o);
        }
    }
    let rest = blocks * LANES..n;
    gather(column, &ancestors[rest.clone()], &mut out[rest]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;
    use sillage_core::rng_stream;

    /// The vector paths give the values of the plain loop, for sorted ancestors (the
    /// permutation), scattered ones (the fallback), columns shorter than two vectors and
    /// lengths that leave a remainder.
    #[test]
    fn every_gather_path_gives_the_plain_values() {
        let mut rng = rng_stream(8, 9);
        for n in [1, 7, 15, 16, 17, 40, 500, 503] {
            let column: Vec<f64> = (0..n).map(|i| i as f64 * 1.5 - 3.0).collect();
            for sorted in [true, false] {
                let mut ancestors: Vec<u32> =
                    (0..n).map(|_| rng.random_range(0..n as u32)).collect();
                if sorted {
                    ancestors.sort_unstable();
                }
                let mut fast = vec![0.0; n];
                gather_widest(&column, &ancestors, &mut fast);
                let plain: Vec<f64> = ancestors.iter().map(|&a| column[a as usize]).collect();
                assert_eq!(fast, plain, "n = {n}, sorted = {sorted}");
            }
        }
    }
}

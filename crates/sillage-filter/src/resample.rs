//! Resampling: which particles survive, in proportion to their weights (§3.5.2 of the MMPF+
//! paper, "normalizing and resampling").
//!
//! Every scheme is unbiased (particle `i` is drawn `N·wᵢ` times on average) and runs in O(N):
//! the ordered positions in `[0, total)` are merged once with the running sum of the weights,
//! so the ancestors come out sorted, which keeps the gather that follows cache-friendly.
//! Schemes from Douc & Cappé 2005, "Comparison of resampling schemes for particle filtering".

use rand::RngExt;
use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result, RngStream};

use crate::fast_math::ln_unit_f32;
use crate::lanes::{LANES, LaneGenerators};
use crate::sums::{accumulate, lane_sum};

/// A resampling scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ResampleScheme {
    /// N independent draws from the weights: the paper's choice (§3.5.2, "multinomial
    /// resampling based on the bootstrap method"). Ordered uniforms come from normalised
    /// cumulative exponential spacings, so no search is needed.
    #[default]
    Multinomial,
    /// One uniform offset, then evenly spaced positions: the lowest variance, each count is
    /// ⌊N·wᵢ⌋ or ⌈N·wᵢ⌉.
    Systematic,
    /// One uniform draw in each of the N strata `[k/N, (k+1)/N)`.
    Stratified,
    /// ⌊N·wᵢ⌋ copies of each particle, the remainder drawn multinomially from the residuals.
    Residual,
}

/// When and how to resample: every step (the paper), or only when the effective sample size
/// falls below a fraction of N (the ESS-triggered wrapper).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Resampling {
    /// The scheme; default multinomial (§3.5.2).
    pub scheme: ResampleScheme,
    /// Resample only when `ESS < ess_fraction · N`, with `ess_fraction` in (0, 1]; absent
    /// (the default, the paper's behaviour) resamples at every step.
    pub ess_fraction: Option<f64>,
}

impl Resampling {
    /// Checks `ess_fraction`; the error names the key.
    pub fn validate(&self) -> Result<()> {
        if let Some(fraction) = self.ess_fraction
            && !(fraction > 0.0 && fraction <= 1.0)
        {
            return Err(Error::parameter(
                "resampling.ess_fraction",
                fraction,
                "must be a number in (0, 1] (0.5 is common), or absent to resample at every \
                 step as the paper does",
            ));
        }
        Ok(())
    }

    /// Whether a set of `n` particles with effective sample size `ess` is resampled.
    pub fn triggers(&self, ess: f64, n: usize) -> bool {
        match self.ess_fraction {
            None => true,
            Some(fraction) => ess < fraction * n as f64,
        }
    }
}

/// Draws ancestor indices; owns its buffers so that a filter reuses them at every step.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct Resampler {
    ancestors: Vec<u32>,
    positions: Vec<f64>,
    cumulative: Vec<f64>,
}

impl Resampler {
    /// `weights.len()` ancestor indices drawn by `scheme` from `weights` (non-negative, any
    /// positive sum; they are overwritten by the residual scheme). A set whose sum is not a
    /// positive finite number is treated as uniform. Indices are < 2³².
    pub fn draw(
        &mut self,
        scheme: ResampleScheme,
        weights: &mut [f64],
        rng: &mut RngStream,
    ) -> &[u32] {
        let n = weights.len();
        self.draw_count(scheme, weights, n, rng)
    }

    /// As [`Resampler::draw`], but `n` ancestors, whatever the number of weights: a set that
    /// grows or shrinks (the per-model resampling of the IMM particle filter, §4.4 of the
    /// IMM-PF paper). No ancestor is drawn from an empty weight set.
    pub fn draw_count(
        &mut self,
        scheme: ResampleScheme,
        weights: &mut [f64],
        n: usize,
        rng: &mut RngStream,
    ) -> &[u32] {
        self.ancestors.clear();
        self.positions.clear();
        if n == 0 || weights.is_empty() {
            return &self.ancestors;
        }
        let mut total = lane_sum(weights);
        if !(total > 0.0 && total.is_finite()) {
            weights.fill(1.0);
            total = weights.len() as f64;
        }
        let step = total / n as f64;
        match scheme {
            ResampleScheme::Multinomial => self.multinomial_positions(total, n, rng),
            ResampleScheme::Systematic => {
                let offset: f64 = rng.random();
                let positions = (0..n).map(|k| (k as f64 + offset) * step);
                self.positions.extend(positions);
            }
            ResampleScheme::Stratified => {
                let positions = (0..n).map(|k| (k as f64 + rng.random::<f64>()) * step);
                self.positions.extend(positions);
            }
            ResampleScheme::Residual => {
                let scale = 1.0 / step;
                for (i, w) in weights.iter_mut().enumerate() {
                    let expected = *w * scale;
                    let copies = expected.floor();
                    self.ancestors
                        .extend(std::iter::repeat_n(i as u32, copies as usize));
                    *w = expected - copies;
                }
                // Rounding can make the copies overshoot n by one.
                self.ancestors.truncate(n);
                let rest = n - self.ancestors.len();
                let residual_total = lane_sum(weights);
                if rest > 0 && residual_total > 0.0 {
                    self.multinomial_positions(residual_total, rest, rng);
                }
            }
        }
        merge(
            weights,
            &self.positions,
            &mut self.cumulative,
            &mut self.ancestors,
        );
        // A draw left with no residual mass by rounding: keep exactly n ancestors.
        while self.ancestors.len() < n {
            let last = self.ancestors.last().copied().unwrap_or(0);
            self.ancestors.push(last);
        }
        &self.ancestors
    }

    /// `count` ordered multinomial positions in `[0, total)`: ordered uniforms `Sₖ / S_{count+1}`
    /// from cumulative standard exponentials (Devroye 1986, §V.3), so no search is needed
    /// afterwards. (Measured faster here than inverting unsorted uniforms through a guide
    /// table.) The exponentials are drawn a block at a time from lane generators seeded from
    /// `rng`.
    fn multinomial_positions(&mut self, total: f64, count: usize, rng: &mut RngStream) {
        self.positions.resize(count + 1, 0.0);
        let mut generators = LaneGenerators::seeded(rng);
        exponentials_widest(&mut generators, &mut self.positions);
        accumulate(&mut self.positions);
        let end = self.positions.pop().unwrap_or(1.0);
        let scale = total / end;
        self.positions.iter_mut().for_each(|p| *p *= scale);
    }
}

/// Fills `out` with standard exponential draws `−ln U`, `U = (w + 1)·2⁻³²` uniform on
/// `(0, 1]` for each 32-bit word `w`, in single precision (so every draw is below 22.2; a
/// larger one has probability 2⁻³²).
#[inline(always)]
fn exponentials(generators: &mut LaneGenerators, out: &mut [f64]) {
    const WORD_STEP: f32 = 1.0 / 4_294_967_296.0;
    for chunk in out.chunks_mut(LANES) {
        let words = generators.next();
        // Single precision throughout first (twice the lanes), then widened. An indexed loop,
        // not `array::map`, whose closure the compiler outlines without the caller's SIMD.
        let mut draws = [0.0f32; LANES];
        for (draw, &word) in draws.iter_mut().zip(&words) {
            *draw = -ln_unit_f32((word as f32 + 1.0) * WORD_STEP);
        }
        for (value, &draw) in chunk.iter_mut().zip(&draws) {
            *value = f64::from(draw);
        }
    }
}

sillage_core::multiversion! {
    /// [`exponentials`] on the widest SIMD the CPU offers.
    fn exponentials_widest(generators: &mut LaneGenerators, out: &mut [f64]) => exponentials
}

/// Independent merges [`merge`] runs side by side, each over a quarter of the positions.
const MERGE_LANES: usize = 4;
/// Running sums a merge step compares with its position at once (one AVX-512 vector).
const WINDOW: usize = 8;

/// Appends, for each of the non-decreasing `positions` in `[0, Σw)`, the index whose
/// cumulative-weight interval holds it: the number of running sums at or below the position.
/// Zero-weight particles are never chosen, even when rounding pushes a position past the last
/// cumulative sum.
///
/// Each step compares one position with the next [`WINDOW`] running sums at once: they are
/// sorted, so the sums at or below it are a prefix of the window, and its length is the
/// number of trailing ones of the comparison mask. A prefix shorter than the window gives the
/// ancestor and moves to the next position; a full one moves on by a window. Steps are
/// branch-free, and there are about as many as positions (a merge stepping one running sum at
/// a time takes twice as many, each one a dependent load). A merge is still one chain of
/// dependent steps, so the positions are cut into [`MERGE_LANES`] runs, each started by a
/// binary search, and the runs step in turn: the processor overlaps them. The last positive
/// weight's running sum and the window's padding after it are +∞, so that no step needs to
/// check the end of the weights, and the runs step together for as many steps as the shortest
/// has positions left, so that no step checks the end of the positions either.
fn merge(weights: &[f64], positions: &[f64], cumulative: &mut Vec<f64>, out: &mut Vec<u32>) {
    merge_with(weights, positions, cumulative, out, merge_runs_widest);
}

/// [`merge`] with the runs stepped by `runs`.
fn merge_with(
    weights: &[f64],
    positions: &[f64],
    cumulative: &mut Vec<f64>,
    out: &mut Vec<u32>,
    runs: fn(&[f64], &[f64], &mut [u32], MergeState),
) {
    let Some(last_positive) = weights.iter().rposition(|&w| w > 0.0) else {
        return;
    };
    cumulative.clear();
    cumulative.extend_from_slice(&weights[..=last_positive]);
    accumulate(cumulative);
    let m = positions.len();
    let start = out.len();
    out.resize(start + m, 0);
    let out = &mut out[start..];
    let k: [usize; MERGE_LANES] = std::array::from_fn(|lane| lane * m / MERGE_LANES);
    let end: [usize; MERGE_LANES] = std::array::from_fn(|lane| (lane + 1) * m / MERGE_LANES);
    // Where a merge from the first weight would stand at each run's first position.
    let j = k.map(|first| match positions.get(first) {
        Some(&p) => cumulative[..last_positive].partition_point(|&c| c <= p),
        None => 0,
    });
    cumulative[last_positive] = f64::INFINITY;
    cumulative.resize(last_positive + WINDOW, f64::INFINITY);
    runs(cumulative, positions, out, (j, k, end));
}

/// Bit `t` set when `window[t] ≤ p`.
type AtOrBelow = fn(&[f64; WINDOW], f64) -> u32;

/// [`AtOrBelow`] element by element.
#[inline(always)]
fn at_or_below(window: &[f64; WINDOW], p: f64) -> u32 {
    let mut below = 0;
    for (t, &c) in window.iter().enumerate() {
        below |= u32::from(c <= p) << t;
    }
    below
}

/// The runs of [`merge`], from running sums at `j` and positions at `k` to `end` (per run);
/// `cumulative` ends in at least [`WINDOW`] values of +∞. `mask` compares a window.
#[inline(always)]
fn merge_runs(
    cumulative: &[f64],
    positions: &[f64],
    out: &mut [u32],
    (mut j, mut k, end): MergeState,
    mask: AtOrBelow,
) {
    let step = |lane: usize,
                j: &mut [usize; MERGE_LANES],
                k: &mut [usize; MERGE_LANES],
                out: &mut [u32]| {
        let (jl, kl) = (j[lane], k[lane]);
        let window: &[f64; WINDOW] = cumulative[jl..jl + WINDOW]
            .try_into()
            .expect("the running sums end in a window of +∞");
        // The length of the prefix at or below the position, at most WINDOW.
        let taken = (!mask(window, positions[kl]) | (1 << WINDOW)).trailing_zeros() as usize;
        out[kl] = (jl + taken) as u32;
        j[lane] = jl + taken;
        k[lane] = kl + usize::from(taken < WINDOW);
    };
    loop {
        let steps = (0..MERGE_LANES).map(|lane| end[lane] - k[lane]).min();
        let steps = steps.unwrap_or(0);
        if steps == 0 {
            break;
        }
        for _ in 0..steps {
            for lane in 0..MERGE_LANES {
                step(lane, &mut j, &mut k, out);
            }
        }
    }
    for lane in 0..MERGE_LANES {
        while k[lane] < end[lane] {
            step(lane, &mut j, &mut k, out);
        }
    }
}

/// Each run's running-sum index, position index and end.
type MergeState = (
    [usize; MERGE_LANES],
    [usize; MERGE_LANES],
    [usize; MERGE_LANES],
);

/// [`merge_runs`] with one vector comparison per window where the CPU has AVX-512 (the same
/// ancestors on every path).
fn merge_runs_widest(cumulative: &[f64], positions: &[f64], out: &mut [u32], state: MergeState) {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx512f") {
        // SAFETY: the CPU supports AVX-512F, checked just above.
        unsafe { merge_runs_avx512(cumulative, positions, out, state) };
        return;
    }
    merge_runs(cumulative, positions, out, state, at_or_below);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn merge_runs_avx512(cumulative: &[f64], positions: &[f64], out: &mut [u32], state: MergeState) {
    use std::arch::x86_64::{_CMP_LE_OQ, _mm512_cmp_pd_mask, _mm512_loadu_pd, _mm512_set1_pd};
    #[inline(always)]
    fn vector_at_or_below(window: &[f64; WINDOW], p: f64) -> u32 {
        // SAFETY: AVX-512F is enabled in the only caller, and the eight doubles are read
        // from a borrowed array of eight.
        unsafe {
            let sums = _mm512_loadu_pd(window.as_ptr());
            u32::from(_mm512_cmp_pd_mask::<_CMP_LE_OQ>(sums, _mm512_set1_pd(p)))
        }
    }
    merge_runs(cumulative, positions, out, state, vector_at_or_below);
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_core::rng_stream;

    #[test]
    fn zero_weights_are_never_drawn_and_counts_are_complete() {
        let mut rng = rng_stream(1, 2);
        let mut resampler = Resampler::default();
        for scheme in [
            ResampleScheme::Multinomial,
            ResampleScheme::Systematic,
            ResampleScheme::Stratified,
            ResampleScheme::Residual,
        ] {
            for _ in 0..200 {
                let mut w = [0.0, 0.5, 0.0, 0.25, 0.25, 0.0];
                let drawn = resampler.draw(scheme, &mut w, &mut rng);
                assert_eq!(drawn.len(), 6);
                assert!(drawn.iter().all(|&i| [1, 3, 4].contains(&i)), "{scheme:?}");
            }
            // A degenerate set is treated as uniform rather than refused.
            let mut w = [0.0; 3];
            assert_eq!(resampler.draw(scheme, &mut w, &mut rng).len(), 3);
        }
    }

    /// The definition: the first index whose running sum exceeds the position, capped at the
    /// last positive weight.
    fn ancestors_by_search(weights: &[f64], positions: &[f64]) -> Vec<u32> {
        let last = weights.iter().rposition(|&w| w > 0.0).unwrap_or(0);
        let mut cumulative = weights[..=last].to_vec();
        accumulate(&mut cumulative);
        positions
            .iter()
            .map(|&p| cumulative[..last].iter().take_while(|&&c| c <= p).count() as u32)
            .collect()
    }

    #[test]
    fn the_merge_gives_the_ancestors_a_search_gives() {
        let mut rng = rng_stream(5, 6);
        let mut cumulative = Vec::new();
        for trial in 0..300 {
            let n = 1 + trial % 40;
            // Peaked weights with exact zeros and ties, as likelihoods leave them.
            let weights: Vec<f64> = (0..n)
                .map(|_| match rng.random_range(0..4) {
                    0 => 0.0,
                    1 => 0.25,
                    _ => rng.random::<f64>().powi(8),
                })
                .collect();
            // Cumulative sums as the merge forms them (up to the last positive weight).
            let last = weights.iter().rposition(|&w| w > 0.0).unwrap_or(0);
            let mut running = weights[..=last].to_vec();
            accumulate(&mut running);
            let total = running[last];
            let m = 1 + trial % 37;
            let mut positions: Vec<f64> = (0..m)
                .map(|k| match k % 5 {
                    // Positions on a cumulative sum, and past the end by rounding.
                    0 => running[k % (last + 1)],
                    1 => total * (1.0 + 1e-15),
                    _ => rng.random::<f64>() * total,
                })
                .collect();
            positions.sort_by(f64::total_cmp);
            let mut out = vec![7];
            merge(&weights, &positions, &mut cumulative, &mut out);
            // The element-by-element comparison gives the same ancestors as the vector one.
            let mut portable = vec![7];
            merge_with(
                &weights,
                &positions,
                &mut cumulative,
                &mut portable,
                |c, p, o, s| merge_runs(c, p, o, s, at_or_below),
            );
            assert_eq!(portable, out);
            if total > 0.0 {
                assert_eq!(out[0], 7);
                assert_eq!(out[1..], ancestors_by_search(&weights, &positions)[..]);
                assert!(out[1..].iter().all(|&a| weights[a as usize] > 0.0));
            } else {
                assert_eq!(out, [7]);
            }
        }
    }

    #[test]
    fn a_set_can_grow_or_shrink() {
        let mut rng = rng_stream(3, 4);
        let mut resampler = Resampler::default();
        for scheme in [ResampleScheme::Systematic, ResampleScheme::Residual] {
            let mut w = [0.0, 0.75, 0.25];
            let drawn = resampler.draw_count(scheme, &mut w, 8, &mut rng).to_vec();
            assert_eq!(drawn.len(), 8);
            let ones = drawn.iter().filter(|&&i| i == 1).count();
            assert_eq!(ones, 6, "{scheme:?}: {drawn:?}");
            assert!(drawn.iter().all(|&i| i == 1 || i == 2));
            assert!(
                resampler
                    .draw_count(scheme, &mut [], 5, &mut rng)
                    .is_empty()
            );
            assert_eq!(resampler.draw_count(scheme, &mut w, 1, &mut rng).len(), 1);
        }
    }

    #[test]
    fn ess_trigger() {
        let always = Resampling::default();
        assert!(always.triggers(100.0, 100));
        let half = Resampling {
            ess_fraction: Some(0.5),
            ..Default::default()
        };
        assert!(half.triggers(49.9, 100) && !half.triggers(50.0, 100));
        let bad = Resampling {
            ess_fraction: Some(1.5),
            ..Default::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .contains("`resampling.ess_fraction`")
        );
    }
}

//! Sums, maxima and running sums over the particles in fixed lanes: several independent
//! chains of additions instead of one, so that the processor overlaps them (one chain of 500
//! dependent additions costs ~2,000 cycles). The lanes are fixed, so the result is the same on
//! every machine and for any vector width.

/// Independent chains per reduction.
const CHAINS: usize = 8;

sillage_core::multiversion! {
    /// `Σ values`, summed in [`CHAINS`] lanes combined pairwise.
    pub(crate) fn lane_sum(values: &[f64]) -> f64 => sum_in_lanes
}

sillage_core::multiversion! {
    /// The largest value, NaN ignored (−∞ for none), as `f64::max` folds it, in [`CHAINS`]
    /// lanes.
    pub(crate) fn lane_max(values: &[f64]) -> f64 => max_in_lanes
}

/// The body of [`lane_sum`].
#[inline(always)]
fn sum_in_lanes(values: &[f64]) -> f64 {
    let mut sums = [0.0; CHAINS];
    let mut chunks = values.chunks_exact(CHAINS);
    for chunk in &mut chunks {
        for lane in 0..CHAINS {
            sums[lane] += chunk[lane];
        }
    }
    for (lane, &v) in chunks.remainder().iter().enumerate() {
        sums[lane] += v;
    }
    pairwise(sums, |a, b| a + b)
}

/// The body of [`lane_max`].
#[inline(always)]
fn max_in_lanes(values: &[f64]) -> f64 {
    let mut maxima = [f64::NEG_INFINITY; CHAINS];
    let mut chunks = values.chunks_exact(CHAINS);
    for chunk in &mut chunks {
        for lane in 0..CHAINS {
            maxima[lane] = maxima[lane].max(chunk[lane]);
        }
    }
    for (lane, &v) in chunks.remainder().iter().enumerate() {
        maxima[lane] = maxima[lane].max(v);
    }
    pairwise(maxima, f64::max)
}

/// Combines the lanes as a balanced tree, always in the same order.
fn pairwise(mut lanes: [f64; CHAINS], combine: impl Fn(f64, f64) -> f64) -> f64 {
    let mut width = CHAINS;
    while width > 1 {
        width /= 2;
        for lane in 0..width {
            lanes[lane] = combine(lanes[lane], lanes[lane + width]);
        }
    }
    lanes[0]
}

/// Replaces `values` by their running sums (`values[i] ← Σⱼ≤ᵢ values[j]`): [`CHAINS`]
/// consecutive runs are summed side by side, then each run is offset by the total of the runs
/// before it. The result is non-decreasing for non-negative values.
pub(crate) fn accumulate(values: &mut [f64]) {
    let n = values.len();
    let run = n.div_ceil(CHAINS);
    // The last run may be shorter: every chain steps through `full` elements, then all but
    // the last through the rest of `run`.
    let full = n.saturating_sub((CHAINS - 1) * run).min(run);
    let mut totals = [0.0; CHAINS];
    let mut step = |i: usize, chains: usize, totals: &mut [f64; CHAINS]| {
        for (chain, total) in totals.iter_mut().enumerate().take(chains) {
            let k = chain * run + i;
            *total += values[k];
            values[k] = *total;
        }
    };
    for i in 0..full {
        step(i, CHAINS, &mut totals);
    }
    for i in full..run {
        let chains = (0..CHAINS).filter(|&c| c * run + i < n).count();
        step(i, chains, &mut totals);
    }
    let mut offset = 0.0;
    for (chain, total) in totals.iter().enumerate() {
        let start = (chain * run).min(n);
        let end = ((chain + 1) * run).min(n);
        if chain > 0 {
            values[start..end].iter_mut().for_each(|v| *v += offset);
        }
        offset += total;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_agree_with_the_plain_reductions() {
        for n in [0, 1, 3, 7, 8, 9, 15, 16, 17, 63, 100, 501] {
            let values: Vec<f64> = (0..n).map(|i| ((i * 37 % 11) as f64) * 0.25).collect();
            assert_eq!(lane_sum(&values), values.iter().sum::<f64>(), "n = {n}");
            let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            assert_eq!(lane_max(&values), max, "n = {n}");
            let mut running = values.clone();
            accumulate(&mut running);
            let mut total = 0.0;
            for (i, &v) in values.iter().enumerate() {
                total += v;
                assert_eq!(running[i], total, "n = {n}, i = {i}");
            }
        }
        assert_eq!(lane_max(&[f64::NAN, -1.0, f64::NAN]), -1.0);
        assert_eq!(lane_max(&[f64::NAN]), f64::NEG_INFINITY);
    }
}

//! Image statistics for thresholds, deterministic whatever the thread count: mean and standard
//! deviation ([`mean_std`]), and a robust noise level, median and scaled MAD of a fixed
//! subsample ([`median_mad`]).

use rayon::prelude::*;
use sillage_core::GrayImage;

/// Values summed sequentially per leaf of the reduction tree.
const LEAF: usize = 1 << 14;

/// Mean and (population, `ddof = 0` as NumPy's `std`) standard deviation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeanStd {
    /// Arithmetic mean.
    pub mean: f64,
    /// Population standard deviation.
    pub std: f64,
}

/// Mean and std of all pixels of `image`; `None` when it is empty. NaN pixels make both NaN.
///
/// Sums run in f64 over a binary tree whose shape depends only on the number of pixels (leaves
/// of 16 384 values summed in a fixed order, halves joined with `rayon::join`), so the result
/// is bit-identical whatever the number of threads, unlike a rayon `sum()`, and nothing is
/// allocated.
pub fn mean_std(image: &GrayImage) -> Option<MeanStd> {
    let values = image.as_slice();
    if values.is_empty() {
        return None;
    }
    let (sum, sum_sq) = sums(values);
    let n = values.len() as f64;
    let mean = sum / n;
    let var = (sum_sq / n - mean * mean).max(0.0);
    Some(MeanStd {
        mean,
        std: var.sqrt(),
    })
}

/// `(Σv, Σv²)` over a fixed-shape tree.
fn sums(values: &[f32]) -> (f64, f64) {
    if values.len() <= LEAF {
        return leaf_sums(values);
    }
    // Split at a multiple of LEAF so the leaves are the same whatever the recursion.
    let mid = values.len().div_ceil(2 * LEAF) * LEAF;
    let (a, b) = values.split_at(mid);
    let ((sa, qa), (sb, qb)) = rayon::join(|| sums(a), || sums(b));
    (sa + sb, qa + qb)
}

/// Sequential sums with 8 interleaved accumulators (vectorisable, fixed order).
fn leaf_sums(values: &[f32]) -> (f64, f64) {
    let mut s = [0.0f64; 8];
    let mut q = [0.0f64; 8];
    let chunks = values.chunks_exact(8);
    let tail = chunks.remainder();
    for chunk in chunks {
        for i in 0..8 {
            let v = f64::from(chunk[i]);
            s[i] += v;
            q[i] += v * v;
        }
    }
    for (i, &v) in tail.iter().enumerate() {
        let v = f64::from(v);
        s[i] += v;
        q[i] += v * v;
    }
    (s.iter().sum(), q.iter().sum())
}

/// Most values [`median_mad`] looks at.
pub const MAX_SAMPLES: usize = 1 << 16;

/// `1 / Φ⁻¹(3/4)`: scales a median absolute deviation to the standard deviation of a normal.
const MAD_TO_SIGMA: f64 = 1.4826;

/// Median and robust standard deviation of an image's values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MedianMad {
    /// Median of the samples.
    pub median: f64,
    /// `1.4826 · MAD`, the median absolute deviation from the median scaled to a standard
    /// deviation (exact for normal noise).
    pub sigma: f64,
}

/// Robust noise statistics of `image`: median and `1.4826 · MAD` of a deterministic subsample,
/// or `None` when the image is empty. Insensitive to up to half the pixels being outliers
/// (blobs, in a filtered frame), unlike [`mean_std`].
///
/// Fast method: at most [`MAX_SAMPLES`] pixels, every `stride`-th one in memory order with
/// `stride = ceil(len / MAX_SAMPLES)` made odd (so that the samples do not fall on the same
/// columns row after row), copied into `samples` (reused, so nothing is allocated once it has
/// grown) in parallel chunks, each read missing the cache; two `select_nth_unstable` passes
/// (expected linear time) give the median and the MAD. The same samples, so the same result,
/// whatever the number of threads. NaN pixels sort above every number.
pub fn median_mad(image: &GrayImage, samples: &mut Vec<f32>) -> Option<MedianMad> {
    let values = image.as_slice();
    if values.is_empty() {
        return None;
    }
    let stride = values.len().div_ceil(MAX_SAMPLES) | 1;
    const CHUNK: usize = 4096;
    samples.clear();
    samples.resize(values.len().div_ceil(stride), 0.0);
    samples
        .par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(chunk, out)| {
            let first = chunk * CHUNK * stride;
            for (o, &v) in out.iter_mut().zip(values[first..].iter().step_by(stride)) {
                *o = v;
            }
        });
    median_mad_of(samples)
}

/// Median and `1.4826 · MAD` of `values` (reordered, then overwritten by their absolute
/// deviations from the median), or `None` when there are none: two `select_nth_unstable`
/// passes.
pub fn median_mad_of(values: &mut [f32]) -> Option<MedianMad> {
    if values.is_empty() {
        return None;
    }
    let median = f64::from(median_of(values));
    for v in values.iter_mut() {
        *v = (f64::from(*v) - median).abs() as f32;
    }
    let mad = f64::from(median_of(values));
    Some(MedianMad {
        median,
        sigma: MAD_TO_SIGMA * mad,
    })
}

/// The lower median of non-empty `values` (reordered).
fn median_of(values: &mut [f32]) -> f32 {
    let mid = (values.len() - 1) / 2;
    *values.select_nth_unstable_by(mid, f32::total_cmp).1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_two_pass_reference() {
        let data: Vec<f32> = (0..100_003)
            .map(|i| ((i * 7919) % 1000) as f32 / 999.0)
            .collect();
        let image = GrayImage::from_vec(100_003, 1, data.clone()).unwrap();
        let got = mean_std(&image).unwrap();
        let mean = data.iter().map(|&v| f64::from(v)).sum::<f64>() / data.len() as f64;
        let var = data
            .iter()
            .map(|&v| (f64::from(v) - mean).powi(2))
            .sum::<f64>()
            / data.len() as f64;
        assert!((got.mean - mean).abs() < 1e-12);
        assert!((got.std - var.sqrt()).abs() < 1e-9);
        assert!(mean_std(&GrayImage::new(0, 0)).is_none());
    }

    #[test]
    fn median_mad_ignores_a_minority_of_outliers() {
        // Values 0..999 repeated (median ≈ 499.5, MAD ≈ 250), then 30 % huge outliers.
        let mut data: Vec<f32> = (0..200_000).map(|i| (i % 1000) as f32).collect();
        let clean = GrayImage::from_vec(1000, 200, data.clone()).unwrap();
        let got = median_mad(&clean, &mut Vec::new()).unwrap();
        assert!((got.median - 499.5).abs() < 15.0, "{got:?}");
        assert!((got.sigma - 1.4826 * 250.0).abs() < 15.0, "{got:?}");
        for v in data.iter_mut().skip(3).step_by(3) {
            *v = 1e6;
        }
        let spoiled = GrayImage::from_vec(1000, 200, data).unwrap();
        let robust = median_mad(&spoiled, &mut Vec::new()).unwrap();
        assert!(
            robust.median < 1000.0 && robust.sigma < 1000.0,
            "{robust:?}"
        );
        assert!(median_mad(&GrayImage::new(0, 0), &mut Vec::new()).is_none());
    }
}

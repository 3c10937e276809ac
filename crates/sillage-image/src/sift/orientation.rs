//! Keypoint orientation (Lowe 2004 §5, OpenCV's `calcOrientationHist`): a 36-bin histogram of
//! gradient directions around the keypoint, each sample weighted by its magnitude and by a
//! Gaussian of σ = 1.5 × the keypoint's scale, over a square of radius `round(3 × 1.5σ)`,
//! smoothed once by `[1 4 6 4 1]/16` (circular); every local peak within 80 % of the highest
//! gives an orientation, refined by a parabola through the peak and its two neighbours.
//!
//! Directions are measured from +x towards +y with y down (clockwise on screen), in `[0, 2π)`:
//! the same angle as OpenCV's `KeyPoint::angle` (in degrees there).

use std::f32::consts::TAU;

use sillage_core::GrayImage;

/// Histogram bins (Lowe 2004 §5; OpenCV's `SIFT_ORI_HIST_BINS`).
pub(crate) const ORIENTATION_BINS: usize = 36;

/// Gaussian weight σ, in keypoint scales (OpenCV's `SIFT_ORI_SIG_FCTR`).
const WEIGHT_SIGMA_FACTOR: f32 = 1.5;

/// Window radius, in weight σ (OpenCV's `SIFT_ORI_RADIUS = 3 × 1.5`).
const RADIUS_FACTOR: f32 = 3.0;

/// A peak within this fraction of the highest gives an orientation (Lowe 2004 §5).
const PEAK_RATIO: f32 = 0.8;

/// Largest window radius, octave px: keypoint scales stay below `σ₀ · 2^((s + ½)/s)` octave
/// px (3.6 px at the defaults, a radius of 16), so only an [`orientation_at`]-style query far
/// beyond the coarsest level can reach it; its window is then cut to this radius.
///
/// [`orientation_at`]: super::SiftDetector::orientation_at
pub(crate) const MAX_ORIENTATION_RADIUS: usize = 64;

/// The smoothed orientation histogram of gradient images `(magnitude, direction)` of one
/// level around sample `(col, row)` (may lie outside the image) at scale `scale` octave px.
pub(crate) fn orientation_histogram(
    magnitude: &GrayImage,
    direction: &GrayImage,
    col: i64,
    row: i64,
    scale: f32,
) -> [f32; ORIENTATION_BINS] {
    let weight_sigma = WEIGHT_SIGMA_FACTOR * scale;
    let radius = ((RADIUS_FACTOR * weight_sigma).round() as i64).min(MAX_ORIENTATION_RADIUS as i64);
    let mut weights = [0f32; 2 * MAX_ORIENTATION_RADIUS + 1];
    let exp_scale = -1.0 / (2.0 * weight_sigma * weight_sigma);
    for (k, w) in weights[..(2 * radius + 1) as usize].iter_mut().enumerate() {
        let offset = k as f32 - radius as f32;
        *w = (offset * offset * exp_scale).exp();
    }
    let (width, height) = magnitude.dimensions();
    let mut raw = [0f32; ORIENTATION_BINS];
    let bins_per_radian = ORIENTATION_BINS as f32 / TAU;
    // The outer one-pixel frame has no gradient (OpenCV skips it too).
    let rows = (row - radius).max(1)..=(row + radius).min(height as i64 - 2);
    let cols = (col - radius).max(1)..=(col + radius).min(width as i64 - 2);
    for y in rows {
        let row_weight = weights[(y - row + radius) as usize];
        let start = y as usize * width;
        for x in cols.clone() {
            let i = start + x as usize;
            let weight = row_weight * weights[(x - col + radius) as usize];
            // Directions are ≥ 0: adding ½ and truncating rounds (no libm call).
            let bin = (direction.as_slice()[i] * bins_per_radian + 0.5) as usize % ORIENTATION_BINS;
            raw[bin] += weight * magnitude.as_slice()[i];
        }
    }
    let n = ORIENTATION_BINS;
    std::array::from_fn(|i| {
        let at = |d: isize| raw[(i as isize + d).rem_euclid(n as isize) as usize];
        (at(-2) + at(2)) * (1.0 / 16.0) + (at(-1) + at(1)) * (4.0 / 16.0) + at(0) * (6.0 / 16.0)
    })
}

/// The orientations of a histogram's peaks within [`PEAK_RATIO`] of its maximum, in bin
/// order, radians in `[0, 2π)`; at most `ORIENTATION_BINS / 2`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Peaks {
    /// `(peak height, orientation)` of each peak.
    peaks: [(f32, f32); ORIENTATION_BINS / 2],
    len: usize,
    next: usize,
}

impl Peaks {
    /// Peaks of `hist` (strict local maxima, circularly) with a parabolic fit of each.
    pub fn of(hist: &[f32; ORIENTATION_BINS]) -> Self {
        let n = ORIENTATION_BINS;
        let highest = hist.iter().copied().fold(0f32, f32::max);
        let threshold = highest * PEAK_RATIO;
        let mut peaks = Self {
            peaks: [(0.0, 0.0); ORIENTATION_BINS / 2],
            len: 0,
            next: 0,
        };
        for j in 0..n {
            let (left, centre, right) = (hist[(j + n - 1) % n], hist[j], hist[(j + 1) % n]);
            if centre > left && centre > right && centre >= threshold {
                let bin = j as f32 + 0.5 * (left - right) / (left - 2.0 * centre + right);
                let angle = bin.rem_euclid(n as f32) * (TAU / n as f32);
                peaks.peaks[peaks.len] = (centre, if angle >= TAU { 0.0 } else { angle });
                peaks.len += 1;
            }
        }
        peaks
    }

    /// The orientation of the highest peak (the first in bin order on a tie); `None` for an
    /// empty (all-zero) histogram.
    pub fn dominant(&self) -> Option<f32> {
        let mut best: Option<(f32, f32)> = None;
        for &(height, angle) in &self.peaks[..self.len] {
            if best.is_none_or(|(h, _)| height > h) {
                best = Some((height, angle));
            }
        }
        best.map(|(_, angle)| angle)
    }
}

impl Iterator for Peaks {
    type Item = f32;

    fn next(&mut self) -> Option<f32> {
        (self.next < self.len).then(|| {
            self.next += 1;
            self.peaks[self.next - 1].1
        })
    }
}

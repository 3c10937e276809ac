//! The SIFT descriptor (Lowe 2004 §6.1, OpenCV's `calcSIFTDescriptor`): a 4×4 grid of 8-bin
//! gradient-direction histograms over a square window rotated to the keypoint's orientation.
//!
//! Each grid cell is `3σ` wide (σ the keypoint's scale in octave px); a sample at offset
//! `(dx, dy)` from the keypoint is rotated into the keypoint's frame, weighted by its gradient
//! magnitude and a Gaussian of σ = half the window width (2 cells), and spread trilinearly
//! over the two nearest cells along each axis and the two nearest direction bins. Samples come
//! from a square of radius `round(3σ · √2 · (4 + 1) / 2)` around the keypoint, so that the
//! rotated window and its interpolation margin fit; those outside the image are left out.
//! The 128 values are normalised to unit length, clipped at 0.2 and normalised again (§6.1).
//!
//! The layout and the direction convention are OpenCV's, so that descriptors compare bin for
//! bin: value `(r·4 + c)·8 + o` holds row cell `r` (along the keypoint direction turned by
//! +90°, i.e. clockwise on screen), column cell `c` (along the keypoint direction), and
//! direction bin `o` of `θ_keypoint − θ_gradient` (directions measured as in
//! `orientation`). One departure: OpenCV centres the window on the
//! keypoint rounded to whole octave px; here it sits at the exact position, so a descriptor
//! varies smoothly with the position (the particle filter of SIFT-PF samples positions).

use std::f32::consts::{SQRT_2, TAU};

use sillage_core::GrayImage;

/// Cells per side of the grid (Lowe 2004's `d`).
const GRID: usize = 4;

/// Direction bins per cell (Lowe 2004's `n`).
const DIRECTION_BINS: usize = 8;

/// Values in a descriptor, `GRID² × DIRECTION_BINS`.
pub const DESCRIPTOR_LEN: usize = GRID * GRID * DIRECTION_BINS;

/// Cell width in keypoint scales (OpenCV's `SIFT_DESCR_SCL_FCTR`).
const CELL_SCALES: f32 = 3.0;

/// Clip of the normalised values (Lowe 2004 §6.1; OpenCV's `SIFT_DESCR_MAG_THR`).
const CLIP: f32 = 0.2;

/// Largest sampling radius, octave px: keypoint scales give at most 38 (σ < 3.6 px at the
/// defaults); a `describe_at` far beyond the coarsest level has its window cut to this.
pub(crate) const MAX_DESCRIPTOR_RADIUS: usize = 96;

/// A 128-value SIFT descriptor, unit length (or all zero where the window has no gradient).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SiftDescriptor(pub [f32; DESCRIPTOR_LEN]);

impl SiftDescriptor {
    /// Euclidean distance, the dissimilarity of SIFT-PF's particle weight (Souded et al. 2011,
    /// Eq. (5)) and of Lowe's nearest-neighbour matching.
    pub fn distance(&self, other: &Self) -> f32 {
        self.0
            .iter()
            .zip(&other.0)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f32>()
            .sqrt()
    }
}

/// The descriptor from the gradient images `(magnitude, direction)` of one level, at
/// `(x, y)` octave px, scale `scale` octave px and orientation `orientation` radians; `None`
/// when no sample of the window falls inside the image.
pub(crate) fn describe(
    magnitude: &GrayImage,
    direction: &GrayImage,
    x: f32,
    y: f32,
    scale: f32,
    orientation: f32,
) -> Option<SiftDescriptor> {
    let (width, height) = magnitude.dimensions();
    let d = GRID as f32;
    let cell_width = CELL_SCALES * scale;
    let radius = ((cell_width * SQRT_2 * (d + 1.0) * 0.5).round() as i64)
        .clamp(0, MAX_DESCRIPTOR_RADIUS as i64);
    let (col, row) = (x.round() as i64, y.round() as i64);
    let (frac_x, frac_y) = (x - col as f32, y - row as f32);
    // The outer one-pixel frame has no gradient (OpenCV skips it too).
    let rows = (row - radius).max(1)..=(row + radius).min(height as i64 - 2);
    let cols = (col - radius).max(1)..=(col + radius).min(width as i64 - 2);
    if rows.is_empty() || cols.is_empty() {
        return None;
    }
    // Gaussian of σ = d/2 cells, separable since the rotation keeps distances.
    let exp_scale = -1.0 / (0.5 * d * d * cell_width * cell_width);
    let gaussian = |offset: f32| (offset * offset * exp_scale).exp();
    let mut column_weights = [0f32; 2 * MAX_DESCRIPTOR_RADIUS + 1];
    for x in cols.clone() {
        column_weights[(x - cols.start()) as usize] = gaussian((x - col) as f32 - frac_x);
    }
    let orientation = orientation.rem_euclid(TAU);
    let (cos_t, sin_t) = (
        orientation.cos() / cell_width,
        orientation.sin() / cell_width,
    );
    let bins_per_radian = DIRECTION_BINS as f32 / TAU;
    let centre = d / 2.0 - 0.5;
    let mut hist = CellHistograms::default();
    let mut samples = 0usize;
    for y in rows {
        let dy = (y - row) as f32 - frac_y;
        let row_weight = gaussian(dy);
        // Columns whose cell coordinates can fall in (−1, d): the rotated window's chord.
        let (col_lo, col_hi) = inside(cos_t, dy * sin_t + centre, d);
        let (row_lo, row_hi) = inside(-sin_t, dy * cos_t + centre, d);
        let first = (col as f32 + frac_x + col_lo.max(row_lo)).floor() as i64 - 1;
        let last = (col as f32 + frac_x + col_hi.min(row_hi)).ceil() as i64 + 1;
        let start = y as usize * width;
        for x in first.max(*cols.start())..=last.min(*cols.end()) {
            let dx = (x - col) as f32 - frac_x;
            let col_bin = dx * cos_t + dy * sin_t + centre;
            let row_bin = -dx * sin_t + dy * cos_t + centre;
            if !(row_bin > -1.0 && row_bin < d && col_bin > -1.0 && col_bin < d) {
                continue;
            }
            samples += 1;
            let i = start + x as usize;
            let weight = row_weight * column_weights[(x - cols.start()) as usize];
            let dir_bin = (orientation - direction.as_slice()[i]) * bins_per_radian;
            hist.add(row_bin, col_bin, dir_bin, weight * magnitude.as_slice()[i]);
        }
    }
    (samples > 0).then(|| hist.normalised())
}

/// The offsets `t` with `slope · t + intercept` in `(−1, d)`, as `(lowest, highest)` (the
/// whole line when `slope` is 0 and the intercept inside, nothing when outside).
fn inside(slope: f32, intercept: f32, d: f32) -> (f32, f32) {
    if slope == 0.0 {
        return if intercept > -1.0 && intercept < d {
            (f32::NEG_INFINITY, f32::INFINITY)
        } else {
            (f32::INFINITY, f32::NEG_INFINITY)
        };
    }
    let (a, b) = ((-1.0 - intercept) / slope, (d - intercept) / slope);
    (a.min(b), a.max(b))
}

/// The trilinear accumulator: `(GRID + 2)²` cells (a margin cell on each side) of
/// `DIRECTION_BINS + 2` bins (two wrap-around bins).
struct CellHistograms([f32; (GRID + 2) * (GRID + 2) * (DIRECTION_BINS + 2)]);

impl Default for CellHistograms {
    fn default() -> Self {
        Self([0.0; (GRID + 2) * (GRID + 2) * (DIRECTION_BINS + 2)])
    }
}

impl CellHistograms {
    /// Spreads `value` over the 8 nearest `(row cell, column cell, direction bin)` by
    /// trilinear interpolation; cell coordinates in `(−1, GRID)`, direction bin in
    /// `(−DIRECTION_BINS, DIRECTION_BINS)` (floors by truncating positive values: no libm
    /// call on the baseline x86-64 target).
    #[inline]
    fn add(&mut self, row_bin: f32, col_bin: f32, dir_bin: f32, value: f32) {
        let n = DIRECTION_BINS as i32;
        // For a coordinate just below GRID, `x + 1` may round up to GRID + 1 (the f32 spacing
        // doubles at GRID): the clamp keeps such a sample on the last cell and the margin.
        let (r1, c1) = (
            ((row_bin + 1.0) as usize).min(GRID),
            ((col_bin + 1.0) as usize).min(GRID),
        );
        let o0 = (dir_bin + n as f32) as i32 - n;
        let (fr, fc, fo) = (
            row_bin + 1.0 - r1 as f32,
            col_bin + 1.0 - c1 as f32,
            dir_bin - o0 as f32,
        );
        let o0 = o0.rem_euclid(n) as usize;
        let stride_c = DIRECTION_BINS + 2;
        let stride_r = (GRID + 2) * stride_c;
        let base = r1 * stride_r + c1 * stride_c + o0;
        let v_r1 = value * fr;
        let v_r0 = value - v_r1;
        for (row_offset, v_r) in [(0, v_r0), (stride_r, v_r1)] {
            let v_rc1 = v_r * fc;
            let v_rc0 = v_r - v_rc1;
            for (col_offset, v_rc) in [(0, v_rc0), (stride_c, v_rc1)] {
                let v_rco1 = v_rc * fo;
                let cell = base + row_offset + col_offset;
                self.0[cell] += v_rc - v_rco1;
                self.0[cell + 1] += v_rco1;
            }
        }
    }

    /// Folds the wrap-around bins back, drops the margin cells, and applies Lowe's
    /// normalise–clip–normalise.
    fn normalised(mut self) -> SiftDescriptor {
        let mut out = [0f32; DESCRIPTOR_LEN];
        let stride_c = DIRECTION_BINS + 2;
        for r in 0..GRID {
            for c in 0..GRID {
                let cell = ((r + 1) * (GRID + 2) + c + 1) * stride_c;
                self.0[cell] += self.0[cell + DIRECTION_BINS];
                self.0[cell + 1] += self.0[cell + DIRECTION_BINS + 1];
                let dst = (r * GRID + c) * DIRECTION_BINS;
                out[dst..dst + DIRECTION_BINS]
                    .copy_from_slice(&self.0[cell..cell + DIRECTION_BINS]);
            }
        }
        let norm = |v: &[f32]| v.iter().map(|x| x * x).sum::<f32>().sqrt();
        let clip = CLIP * norm(&out);
        out.iter_mut().for_each(|v| *v = v.min(clip));
        let scale = 1.0 / norm(&out).max(f32::EPSILON);
        out.iter_mut().for_each(|v| *v *= scale);
        SiftDescriptor(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_at_the_window_edge_stay_in_the_accumulator() {
        let below = f32::from_bits((GRID as f32).to_bits() - 1);
        let mut hist = CellHistograms::default();
        hist.add(below, below, 7.999_999, 1.0);
        hist.add(-0.999_999_9, -0.999_999_9, -7.999_999, 1.0);
        let total: f32 = hist.0.iter().sum();
        assert!((total - 2.0).abs() < 1e-5, "{total}");
    }
}

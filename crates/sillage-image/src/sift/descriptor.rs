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

/// Samples in a row of the window at most.
const ROW_SAMPLES: usize = 2 * MAX_DESCRIPTOR_RADIUS + 1;

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
    let mut column_weights = [0f32; ROW_SAMPLES];
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
    let mut spread = RowSpread::default();
    let mut samples = 0usize;
    for y in rows {
        let dy = (y - row) as f32 - frac_y;
        let row_weight = gaussian(dy);
        // Columns whose cell coordinates can fall in (−1, d): the rotated window's chord.
        let (col_lo, col_hi) = inside(cos_t, dy * sin_t + centre, d);
        let (row_lo, row_hi) = inside(-sin_t, dy * cos_t + centre, d);
        let first = (col as f32 + frac_x + col_lo.max(row_lo)).floor() as i64 - 1;
        let last = (col as f32 + frac_x + col_hi.min(row_hi)).ceil() as i64 + 1;
        let (first, last) = (first.max(*cols.start()), last.min(*cols.end()));
        if first > last {
            continue;
        }
        let start = y as usize * width;
        let span = first as usize..last as usize + 1;
        let sample = RowSample {
            first_offset: (first - col) as i32,
            frac_x,
            dy,
            cos_t,
            sin_t,
            centre,
            row_weight,
            orientation,
            bins_per_radian,
        };
        spread.fill(
            &sample,
            &column_weights[(first - cols.start()) as usize..][..span.len()],
            &direction.as_slice()[start..][span.clone()],
            &magnitude.as_slice()[start..][span],
        );
        samples += spread.add_to(&mut hist);
    }
    (samples > 0).then(|| hist.normalised())
}

/// What every sample of one row of the window shares: the first sample's column from the
/// keypoint's rounded column (the others follow one px apart) and the keypoint's fraction
/// of a px, the row's offset `dy` and weight, and the window's rotation (`cos_t`, `sin_t`
/// per cell width), centre and orientation.
struct RowSample {
    first_offset: i32,
    frac_x: f32,
    dy: f32,
    cos_t: f32,
    sin_t: f32,
    centre: f32,
    row_weight: f32,
    orientation: f32,
    bins_per_radian: f32,
}

/// One row's samples spread over the histograms' bins, in two passes: first each sample's
/// first bin and its eight trilinear shares (a loop without dependencies, which the compiler
/// vectorises), then the shares added in the samples' order (the same sums, bit for bit, as
/// adding each sample as it is computed).
struct RowSpread {
    len: usize,
    /// Per sample: inside the rotated window (its cell coordinates in `(−1, GRID)`).
    inside: [bool; ROW_SAMPLES],
    /// Per sample: the index of its first bin (row cell, column cell, direction bin).
    base: [u32; ROW_SAMPLES],
    /// Per share `j`, per sample: its share of the bin `base + SHARE_OFFSETS[j]`.
    shares: [[f32; ROW_SAMPLES]; 8],
}

impl Default for RowSpread {
    fn default() -> Self {
        Self {
            len: 0,
            inside: [false; ROW_SAMPLES],
            base: [0; ROW_SAMPLES],
            shares: [[0.0; ROW_SAMPLES]; 8],
        }
    }
}

/// Bins of one column cell of the accumulator (the direction bins and two wrap-around).
const STRIDE_C: usize = DIRECTION_BINS + 2;
/// Bins of one row cell of the accumulator (its column cells and two margin cells).
const STRIDE_R: usize = (GRID + 2) * STRIDE_C;
/// The eight bins of a trilinear spread, from its first: (row cell, column cell, direction
/// bin) each this one or the next.
const SHARE_OFFSETS: [usize; 8] = [
    0,
    1,
    STRIDE_C,
    STRIDE_C + 1,
    STRIDE_R,
    STRIDE_R + 1,
    STRIDE_R + STRIDE_C,
    STRIDE_R + STRIDE_C + 1,
];

/// Per sample of a row: [`RowSpread::fill`]'s body.
#[inline(always)]
fn fill_row(
    row: &RowSample,
    weights: &[f32],
    direction: &[f32],
    magnitude: &[f32],
    inside: &mut [bool; ROW_SAMPLES],
    base: &mut [u32; ROW_SAMPLES],
    shares: &mut [[f32; ROW_SAMPLES]; 8],
) {
    let d = GRID as f32;
    let len = weights.len().min(direction.len()).min(magnitude.len());
    for k in 0..len {
        let dx = (row.first_offset + k as i32) as f32 - row.frac_x;
        let col_bin = dx * row.cos_t + row.dy * row.sin_t + row.centre;
        let row_bin = -dx * row.sin_t + row.dy * row.cos_t + row.centre;
        inside[k] = row_bin > -1.0 && row_bin < d && col_bin > -1.0 && col_bin < d;
        let weight = row.row_weight * weights[k];
        let dir_bin = (row.orientation - direction[k]) * row.bins_per_radian;
        let value = weight * magnitude[k];
        let (first, spread) = trilinear(row_bin, col_bin, dir_bin, value);
        base[k] = first;
        for (shares, share) in shares.iter_mut().zip(spread) {
            shares[k] = share;
        }
    }
}

sillage_core::multiversion! {
    /// [`fill_row`] on the widest SIMD the CPU offers.
    fn fill_widest(row: &RowSample, weights: &[f32], direction: &[f32], magnitude: &[f32], inside: &mut [bool; ROW_SAMPLES], base: &mut [u32; ROW_SAMPLES], shares: &mut [[f32; ROW_SAMPLES]; 8]) => fill_row
}

/// A sample's trilinear spread over the 8 nearest `(row cell, column cell, direction bin)`:
/// the index of the first bin and the shares of `value` of the bins `SHARE_OFFSETS` from it.
/// Cell coordinates in `(−1, GRID)`, direction bin in `(−DIRECTION_BINS, DIRECTION_BINS)`
/// (floors by truncating positive values: no libm call on the baseline x86-64 target).
#[inline(always)]
fn trilinear(row_bin: f32, col_bin: f32, dir_bin: f32, value: f32) -> (u32, [f32; 8]) {
    let n = DIRECTION_BINS as i32;
    // For a coordinate just below GRID, `x + 1` may round up to GRID + 1 (the f32 spacing
    // doubles at GRID): the clamp keeps such a sample on the last cell and the margin.
    let r1 = truncate_within(row_bin + 1.0, GRID as f32);
    let c1 = truncate_within(col_bin + 1.0, GRID as f32);
    let o0 = truncate_within(dir_bin + n as f32, 2.0 * n as f32) - n;
    let (fr, fc, fo) = (
        row_bin + 1.0 - r1 as f32,
        col_bin + 1.0 - c1 as f32,
        dir_bin - o0 as f32,
    );
    let o0 = o0.rem_euclid(n);
    let base = (r1 as usize * STRIDE_R + c1 as usize * STRIDE_C + o0 as usize) as u32;
    let v_r1 = value * fr;
    let v_r0 = value - v_r1;
    let (v_r0c1, v_r1c1) = (v_r0 * fc, v_r1 * fc);
    let (v_r0c0, v_r1c0) = (v_r0 - v_r0c1, v_r1 - v_r1c1);
    let mut shares = [0.0; 8];
    for (c, v) in [v_r0c0, v_r0c1, v_r1c0, v_r1c1].into_iter().enumerate() {
        let v1 = v * fo;
        (shares[2 * c], shares[2 * c + 1]) = (v - v1, v1);
    }
    (base, shares)
}

/// `x` truncated towards zero, held within `[0, high]` (NaN gives 0): `(x as i32).clamp(0,
/// high)` in a form that vectorises (a saturating cast does not).
#[inline(always)]
fn truncate_within(x: f32, high: f32) -> i32 {
    let held = x.max(0.0).min(high);
    // SAFETY: `held` is finite and within [0, high], and `high` (at most 16 here) fits an
    // i32. `max` returns 0 for a NaN `x`.
    unsafe { held.to_int_unchecked() }
}

impl RowSpread {
    /// Computes the bins and shares of the samples of one row: `weights` the column
    /// Gaussian's, `direction` and `magnitude` the gradient's, one value per sample.
    fn fill(&mut self, row: &RowSample, weights: &[f32], direction: &[f32], magnitude: &[f32]) {
        let len = weights.len();
        self.len = len;
        fill_widest(
            row,
            weights,
            direction,
            magnitude,
            &mut self.inside,
            &mut self.base,
            &mut self.shares,
        );
    }

    /// Adds the shares of the samples inside the window to `hist`, in order; the number of
    /// them.
    fn add_to(&self, hist: &mut CellHistograms) -> usize {
        let mut added = 0;
        for k in 0..self.len {
            if !self.inside[k] {
                continue;
            }
            added += 1;
            let base = self.base[k] as usize;
            for (offset, shares) in SHARE_OFFSETS.iter().zip(&self.shares) {
                hist.0[base + offset] += shares[k];
            }
        }
        added
    }
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
    /// Folds the wrap-around bins back, drops the margin cells, and applies Lowe's
    /// normalise–clip–normalise.
    fn normalised(mut self) -> SiftDescriptor {
        let mut out = [0f32; DESCRIPTOR_LEN];
        for r in 0..GRID {
            for c in 0..GRID {
                let cell = ((r + 1) * (GRID + 2) + c + 1) * STRIDE_C;
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

    /// [`describe`] one sample at a time, each spread over its bins as it is computed.
    fn describe_one_sample_at_a_time(
        magnitude: &GrayImage,
        direction: &GrayImage,
        (x, y): (f32, f32),
        scale: f32,
        orientation: f32,
    ) -> SiftDescriptor {
        let (width, height) = magnitude.dimensions();
        let d = GRID as f32;
        let cell_width = CELL_SCALES * scale;
        let radius = ((cell_width * SQRT_2 * (d + 1.0) * 0.5).round() as i64)
            .clamp(0, MAX_DESCRIPTOR_RADIUS as i64);
        let (col, row) = (x.round() as i64, y.round() as i64);
        let (frac_x, frac_y) = (x - col as f32, y - row as f32);
        let exp_scale = -1.0 / (0.5 * d * d * cell_width * cell_width);
        let gaussian = |offset: f32| (offset * offset * exp_scale).exp();
        let orientation = orientation.rem_euclid(TAU);
        let (cos_t, sin_t) = (
            orientation.cos() / cell_width,
            orientation.sin() / cell_width,
        );
        let centre = d / 2.0 - 0.5;
        let mut hist = CellHistograms::default();
        for y in (row - radius).max(1)..=(row + radius).min(height as i64 - 2) {
            let dy = (y - row) as f32 - frac_y;
            for x in (col - radius).max(1)..=(col + radius).min(width as i64 - 2) {
                let dx = (x - col) as f32 - frac_x;
                let col_bin = dx * cos_t + dy * sin_t + centre;
                let row_bin = -dx * sin_t + dy * cos_t + centre;
                if !(row_bin > -1.0 && row_bin < d && col_bin > -1.0 && col_bin < d) {
                    continue;
                }
                let i = y as usize * width + x as usize;
                let weight = gaussian(dy) * gaussian(dx);
                let dir_bin =
                    (orientation - direction.as_slice()[i]) * (DIRECTION_BINS as f32 / TAU);
                let value = weight * magnitude.as_slice()[i];
                let (base, shares) = trilinear(row_bin, col_bin, dir_bin, value);
                for (offset, share) in SHARE_OFFSETS.iter().zip(shares) {
                    hist.0[base as usize + offset] += share;
                }
            }
        }
        hist.normalised()
    }

    #[test]
    fn rows_in_two_passes_give_the_bits_of_one_sample_at_a_time() {
        let (width, height) = (64, 48);
        let texture = |k: usize, a: f32| ((k * 7919 % 1013) as f32 * a).sin();
        let magnitude: Vec<f32> = (0..width * height)
            .map(|k| texture(k, 0.37).abs())
            .collect();
        let direction: Vec<f32> = (0..width * height)
            .map(|k| 3.1 * texture(k, 0.11))
            .collect();
        let magnitude = GrayImage::from_vec(width, height, magnitude).unwrap();
        let direction = GrayImage::from_vec(width, height, direction).unwrap();
        // Inside, astride the edges and the corner; scales and orientations of every kind.
        let positions = [
            (31.3, 22.8),
            (2.6, 40.1),
            (60.9, 3.4),
            (0.2, 0.7),
            (45.5, 46.5),
        ];
        for (p, &position) in positions.iter().enumerate() {
            for (scale, orientation) in [(1.1, 0.0), (1.9, 1.3), (2.7, -2.2), (0.6, 6.0)] {
                let orientation = orientation + p as f32 * 0.41;
                let want = describe_one_sample_at_a_time(
                    &magnitude,
                    &direction,
                    position,
                    scale,
                    orientation,
                );
                let (x, y) = position;
                let got = describe(&magnitude, &direction, x, y, scale, orientation).unwrap();
                for (a, b) in got.0.iter().zip(want.0) {
                    assert_eq!(a.to_bits(), b.to_bits(), "at {position:?}, scale {scale}");
                }
            }
        }
    }

    #[test]
    fn samples_at_the_window_edge_stay_in_the_accumulator() {
        let below = f32::from_bits((GRID as f32).to_bits() - 1);
        let mut hist = CellHistograms::default();
        for (bin, dir_bin) in [(below, 7.999_999), (-0.999_999_9, -7.999_999)] {
            let (base, shares) = trilinear(bin, bin, dir_bin, 1.0);
            for (offset, share) in SHARE_OFFSETS.iter().zip(shares) {
                hist.0[base as usize + offset] += share;
            }
        }
        let total: f32 = hist.0.iter().sum();
        assert!((total - 2.0).abs() < 1e-5, "{total}");
    }
}

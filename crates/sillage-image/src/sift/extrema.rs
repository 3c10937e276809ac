//! Scale-space extrema of the DoG and their refinement (Lowe 2004 §3.1 and §4, OpenCV's
//! `findScaleSpaceExtrema` and `adjustLocalExtrema`).
//!
//! A candidate is a DoG pixel of layers `1..=s`, at least [`BORDER`] px from the octave's sides,
//! with `|D| >` the pre-filter threshold that is `≥` (maxima) or `≤` (minima) all of its 26
//! neighbours in its own and the two adjacent layers. Refinement fits the quadratic
//! `D(x̂) = D + ∇Dᵀx̂ + ½x̂ᵀHx̂` (Lowe 2004 Eq. (2)) with central differences and solves
//! `H x̂ = −∇D` (Eq. (3)); while an offset component exceeds ½ the sample moves by the rounded
//! offset and the fit starts again, at most [`MAX_REFINE_STEPS`] times, leaving the octave's
//! border or the layers `1..=s` rejects it. Kept are extrema with `|D(x̂)| · s ≥ contrast
//! threshold` (Eq. (3)'s contrast, OpenCV's scaling by `s`) whose 2×2 spatial Hessian has
//! `det > 0` and `tr²/det < (r+1)²/r` (§4.1).

use std::ops::Range;

use super::pyramid::{BORDER, Octave};
use sillage_core::multiversion;

/// Columns tested at once by [`RowCandidates`].
const STRIP: usize = 64;

/// Fits per extremum before giving up (OpenCV's `SIFT_MAX_INTERP_STEPS`).
pub(crate) const MAX_REFINE_STEPS: usize = 5;

/// A refined extremum, in the coordinates of its octave.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Extremum {
    /// Layer of the final sample, in `1..=s`.
    pub layer: usize,
    /// Column of the final sample.
    pub col: usize,
    /// Row of the final sample.
    pub row: usize,
    /// Sub-sample offset `x̂ = (column, row, layer)`, each in `(−½, ½)`.
    pub offset: [f32; 3],
    /// `|D(x̂)|`, grey levels in `[0, 1]`.
    pub contrast: f32,
    /// `tr(H)²/det(H)` of the 2×2 spatial Hessian.
    pub edge_ratio: f32,
}

/// The thresholds of the search, from the parameters.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ExtremumTest {
    /// Layers per octave `s`.
    pub layers: usize,
    /// Pre-filter on `|D|` of the sample: OpenCV's `floor(0.5 · threshold / s · 255) / 255`.
    pub prefilter: f32,
    /// Contrast threshold on `|D(x̂)| · s`.
    pub contrast_threshold: f32,
    /// Edge threshold `r`.
    pub edge_threshold: f32,
}

impl ExtremumTest {
    /// OpenCV's thresholds for `layers` layers.
    pub fn new(layers: usize, contrast_threshold: f32, edge_threshold: f32) -> Self {
        let prefilter = (0.5 * contrast_threshold / layers as f32 * 255.0).floor() / 255.0;
        Self {
            layers,
            prefilter,
            contrast_threshold,
            edge_threshold,
        }
    }

    /// The candidate columns of DoG row `row` of `layer` within `cols` (which must keep one
    /// sample away from the sides), in order.
    pub fn candidates<'a>(
        &self,
        octave: &'a Octave,
        layer: usize,
        row: usize,
        cols: Range<usize>,
    ) -> RowCandidates<'a> {
        let rows = std::array::from_fn(|k| {
            let (l, r) = (layer + k / 3 - 1, row + k % 3 - 1);
            let image = &octave.dog[l];
            &image.row(r)[cols.start - 1..cols.end + 1]
        });
        RowCandidates {
            rows,
            threshold: self.prefilter,
            first_col: cols.start,
            strip_start: 0,
            strip_end: 0,
            flags: [0; STRIP],
            strip_len: 0,
            next: 0,
        }
    }

    /// Refines candidate `(col, row, layer)` and applies the contrast and edge tests; `None`
    /// when it is rejected.
    pub fn refine(
        &self,
        octave: &Octave,
        mut layer: usize,
        mut col: usize,
        mut row: usize,
    ) -> Option<Extremum> {
        let (width, height) = octave.dimensions();
        let mut converged = None;
        for _ in 0..MAX_REFINE_STEPS {
            let fit = QuadraticFit::at(octave, layer, col, row);
            let step = fit.offset()?;
            if step.iter().all(|v| v.abs() < 0.5) {
                converged = Some((fit, step));
                break;
            }
            if step.iter().any(|v| v.abs() > (i32::MAX / 3) as f32) {
                return None;
            }
            let moved = |at: usize, by: f32| at as i64 + by.round() as i64;
            let (c, r, l) = (
                moved(col, step[0]),
                moved(row, step[1]),
                moved(layer, step[2]),
            );
            if l < 1
                || l > self.layers as i64
                || c < BORDER as i64
                || c >= (width - BORDER) as i64
                || r < BORDER as i64
                || r >= (height - BORDER) as i64
            {
                return None;
            }
            (col, row, layer) = (c as usize, r as usize, l as usize);
        }
        let (fit, offset) = converged?;
        let contrast = (fit.value + 0.5 * dot(&fit.gradient, &offset)).abs();
        if contrast * (self.layers as f32) < self.contrast_threshold {
            return None;
        }
        let [[dxx, dxy, _], [_, dyy, _], _] = fit.hessian;
        let (trace, det) = (dxx + dyy, dxx * dyy - dxy * dxy);
        let r = self.edge_threshold;
        if det <= 0.0 || trace * trace * r >= (r + 1.0) * (r + 1.0) * det {
            return None;
        }
        Some(Extremum {
            layer,
            col,
            row,
            offset,
            contrast,
            edge_ratio: trace * trace / det,
        })
    }
}

/// The candidates of one DoG row, found [`STRIP`] columns at a time by a branch-free pass
/// (vectorised) that compares each sample with the maximum and minimum of its 3×3×3
/// neighbourhood (itself included, so that ties count, as OpenCV's `≥`).
pub(crate) struct RowCandidates<'a> {
    /// The 9 rows of the neighbourhood (layer-major: layer − 1, layer, layer + 1; rows
    /// above, at, below), each from one column before the range to one after.
    rows: [&'a [f32]; 9],
    threshold: f32,
    first_col: usize,
    strip_start: usize,
    /// End of the last strip filled (relative to the range).
    strip_end: usize,
    flags: [u8; STRIP],
    strip_len: usize,
    next: usize,
}

impl RowCandidates<'_> {
    /// Flags the columns of the strip starting at `start` (relative to the range).
    fn fill(&mut self, start: usize) {
        fill_widest(self, start);
    }
}

multiversion! {
    /// [`fill_strip`] on the widest SIMD the CPU offers (the same flags on every path: only
    /// exact comparisons).
    fn fill_widest(candidates: &mut RowCandidates<'_>, start: usize) => fill_strip
}

/// The flags of one strip: none when no sample passes the pre-filter (most strips of the
/// doubled octave, whose DoG is small), else the 3×3×3 maximum and minimum from running maxima
/// and minima of three adjacent samples in each of the 9 rows, in loops the compiler
/// vectorises.
#[inline(always)]
fn fill_strip(candidates: &mut RowCandidates<'_>, start: usize) {
    let rows = candidates.rows;
    let len = (rows[4].len() - 2 - start).min(STRIP);
    candidates.strip_start = start;
    candidates.next = 0;
    let centre = &rows[4][start + 1..start + len + 1];
    let threshold = candidates.threshold;
    let above = centre
        .iter()
        .fold(false, |any, &value| any | (value.abs() > threshold));
    if !above {
        candidates.strip_len = 0;
        return;
    }
    let mut high = [f32::NEG_INFINITY; STRIP];
    let mut low = [f32::INFINITY; STRIP];
    for row in rows {
        let row = &row[start..start + len + 2];
        let triples = row.iter().zip(&row[1..]).zip(&row[2..]);
        for ((h, l), ((&a, &b), &c)) in high.iter_mut().zip(&mut low).zip(triples) {
            *h = max(*h, max(a, max(b, c)));
            *l = min(*l, min(a, min(b, c)));
        }
    }
    for (((flag, &value), &h), &l) in candidates.flags.iter_mut().zip(centre).zip(&high).zip(&low) {
        let maximum = value > threshold && value >= h;
        let minimum = value < -threshold && value <= l;
        *flag = u8::from(maximum | minimum);
    }
    candidates.strip_len = len;
}

/// `a.max(b)` without NaN handling (one `maxps`).
#[inline]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// `a.min(b)` without NaN handling (one `minps`).
#[inline]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

impl Iterator for RowCandidates<'_> {
    type Item = usize;

    fn next(&mut self) -> Option<usize> {
        let width = self.rows[4].len() - 2;
        loop {
            while self.next < self.strip_len {
                let k = self.next;
                self.next += 1;
                if self.flags[k] != 0 {
                    return Some(self.first_col + self.strip_start + k);
                }
            }
            let start = self.strip_end;
            if start >= width {
                return None;
            }
            self.strip_end = (start + STRIP).min(width);
            self.fill(start);
        }
    }
}

/// Central-difference gradient and Hessian of the DoG at one sample, in `(column, row, layer)`
/// order (OpenCV's scaling: first derivatives ½·difference, mixed ¼·difference).
struct QuadraticFit {
    value: f32,
    gradient: [f32; 3],
    hessian: [[f32; 3]; 3],
}

impl QuadraticFit {
    fn at(octave: &Octave, layer: usize, col: usize, row: usize) -> Self {
        let width = octave.dog[layer].width();
        let [prev, cur, next] = [layer - 1, layer, layer + 1].map(|l| octave.dog[l].as_slice());
        let i = row * width + col;
        let (up, down) = (i - width, i + width);
        let value = cur[i];
        let gradient = [
            0.5 * (cur[i + 1] - cur[i - 1]),
            0.5 * (cur[down] - cur[up]),
            0.5 * (next[i] - prev[i]),
        ];
        let dxx = cur[i + 1] + cur[i - 1] - 2.0 * value;
        let dyy = cur[down] + cur[up] - 2.0 * value;
        let dss = next[i] + prev[i] - 2.0 * value;
        let dxy = 0.25 * (cur[down + 1] - cur[down - 1] - cur[up + 1] + cur[up - 1]);
        let dxs = 0.25 * (next[i + 1] - next[i - 1] - prev[i + 1] + prev[i - 1]);
        let dys = 0.25 * (next[down] - next[up] - prev[down] + prev[up]);
        Self {
            value,
            gradient,
            hessian: [[dxx, dxy, dxs], [dxy, dyy, dys], [dxs, dys, dss]],
        }
    }

    /// `x̂ = −H⁻¹∇D` (Lowe 2004 Eq. (3)); `None` when `H` is singular.
    fn offset(&self) -> Option<[f32; 3]> {
        let rhs = self.gradient.map(|g| -g);
        solve3(self.hessian, rhs)
    }
}

fn dot(a: &[f32; 3], b: &[f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Solves `a x = b` by Gaussian elimination with partial pivoting (OpenCV's `DECOMP_LU`);
/// `None` when a pivot is zero or the result is not finite.
fn solve3(mut a: [[f32; 3]; 3], mut b: [f32; 3]) -> Option<[f32; 3]> {
    for k in 0..3 {
        let pivot = (k..3)
            .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()).then(j.cmp(&i)))
            .unwrap_or(k);
        if a[pivot][k] == 0.0 {
            return None;
        }
        a.swap(k, pivot);
        b.swap(k, pivot);
        let (pivot_rows, lower_rows) = a.split_at_mut(k + 1);
        let pivot_row = &pivot_rows[k];
        for (i, lower) in lower_rows.iter_mut().enumerate() {
            let factor = lower[k] / pivot_row[k];
            for (value, &p) in lower[k..].iter_mut().zip(&pivot_row[k..]) {
                *value -= factor * p;
            }
            b[k + 1 + i] -= factor * b[k];
        }
    }
    let mut x = [0f32; 3];
    for k in (0..3).rev() {
        let tail: f32 = (k + 1..3).map(|j| a[k][j] * x[j]).sum();
        x[k] = (b[k] - tail) / a[k][k];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solve3_inverts_a_pivoting_system() {
        let a = [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 1.0]];
        let x = [1.0, -2.0, 0.5];
        let b = [0, 1, 2].map(|i| dot(&a[i], &x));
        let solved = solve3(a, b).unwrap();
        for (s, e) in solved.iter().zip(&x) {
            assert!((s - e).abs() < 1e-6, "{solved:?}");
        }
        assert_eq!(
            solve3([[1.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 0.0, 1.0]], b),
            None
        );
    }

    #[test]
    fn opencv_prefilter_is_floored_to_grey_levels() {
        assert_eq!(ExtremumTest::new(3, 0.04, 10.0).prefilter, 1.0 / 255.0);
        assert_eq!(ExtremumTest::new(3, 0.005, 7.5).prefilter, 0.0);
    }
}

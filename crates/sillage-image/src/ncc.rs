//! Normalised cross-correlation with a ring template: the matched filter of the MMPF+ paper's
//! transparent-bead detector (§3.3.1: "a normalized cross-correlation with a ring-shape
//! model"), with MATLAB `normxcorr2`'s conventions as BeadTracking uses it (the template
//! centred on each pixel, zeros outside the image).
//!
//! Fast method: a ring template takes two values, so with `t'` the zero-mean template the
//! numerator `Σ t'·f` is `β·S_window − S_ring` (NCC is invariant to an affine change of the
//! template, so the values are taken as 0 on the ring and 1 elsewhere, `β = 1 − mean`): two
//! sums over fixed pixel sets, read from column prefix sums (running sums down each column,
//! Lewis 1995, "Fast normalized cross-correlation"): the ring sum costs two reads per vertical
//! run of ring pixels (34 runs for BeadTracking's 21×21 template) instead of 441 products,
//! the window sums of `f` and `f²` one difference per column and a sum along the row. Every
//! read is contiguous along the row, so everything vectorises and no step waits on the
//! pixel before it. Sums are in `f64`, so flat windows give 0, not rounding noise; each
//! output row is computed on its own, so results do not depend on the number of threads.

use rayon::prelude::*;
use sillage_core::{Error, GrayImage, Result};

/// Largest template radius accepted (a side of 201 px).
pub const MAX_TEMPLATE_RADIUS_PX: usize = 100;

/// Output rows per parallel job.
const BAND_ROWS: usize = 16;

/// A window's variance sum `Σ(f − mean)²` below this many times its pixel count is flat: its
/// correlation is 0 (a standard deviation under 10⁻⁶ grey levels; `normxcorr2` likewise
/// zeroes windows whose denominator is within rounding of 0).
const FLAT_VARIANCE_PER_PIXEL: f64 = 1e-12;

/// A ring-shaped correlation template: a square of odd side whose pixels take two values,
/// the lower one on a ring around the centre.
///
/// What counts as a ring (checked by [`RingTemplate::from_image`]): exactly two distinct
/// finite values; the lower-valued (ring) pixels do not include the centre; the ring is
/// symmetric under the eight symmetries of the square (mirrors in x and y, transposition);
/// and with `d_min`, `d_max` the smallest and largest distance of a ring pixel from the
/// centre, every pixel whose distance lies in `[d_min + 1, d_max − 1]` is on the ring (no
/// holes). BeadTracking's template (`template_transparent_bead_rOut10_rIn6`: 21×21, −0.593
/// on the 204 pixels at 6.3–10.05 px, 1 elsewhere) passes.
#[derive(Debug, Clone, PartialEq)]
pub struct RingTemplate {
    radius: usize,
    /// Ring pixels as vertical runs relative to the centre, grouped by their rows: each
    /// `((dy0, dy1), columns)` covers rows `dy0..=dy1` in each of `columns` (a column and its
    /// mirror, for a symmetric ring).
    runs: Vec<((isize, isize), Vec<isize>)>,
    ring_pixels: usize,
}

impl RingTemplate {
    /// The ring of pixels at a distance `d` from the centre with `inner < d ≤ outer`, in a
    /// square of side `2·floor(outer) + 1`. Needs `0 < inner`, `inner + 1 ≤ outer` and
    /// `outer ≤ MAX_TEMPLATE_RADIUS_PX`.
    pub fn annulus(inner_radius_px: f64, outer_radius_px: f64) -> Result<Self> {
        let max = MAX_TEMPLATE_RADIUS_PX as f64;
        if !(outer_radius_px.is_finite() && (2.0..=max).contains(&outer_radius_px)) {
            return Err(Error::parameter(
                "outer_radius_px",
                outer_radius_px,
                format!("must be a number in [2, {max}] px"),
            ));
        }
        if !(inner_radius_px > 0.0 && inner_radius_px + 1.0 <= outer_radius_px) {
            return Err(Error::parameter(
                "inner_radius_px",
                inner_radius_px,
                format!("must be > 0 and at least 1 px below the outer radius {outer_radius_px}"),
            ));
        }
        let radius = outer_radius_px.floor() as usize;
        let side = 2 * radius + 1;
        let ring = (0..side * side)
            .map(|i| {
                let d = distance(i, side);
                d > inner_radius_px && d <= outer_radius_px
            })
            .collect::<Vec<_>>();
        Self::from_ring(side, &ring)
    }

    /// The template in `image` (square, odd side `≥ 3`, radius up to
    /// `MAX_TEMPLATE_RADIUS_PX`), after checking that it is a ring (see the type's doc);
    /// the error says which condition fails.
    pub fn from_image(image: &GrayImage) -> Result<Self> {
        let (width, height) = image.dimensions();
        if width != height
            || width.is_multiple_of(2)
            || width < 3
            || width / 2 > MAX_TEMPLATE_RADIUS_PX
        {
            return Err(not_a_ring(format!(
                "it is {width}×{height} px; a template is a square of odd side from 3 to {} px",
                2 * MAX_TEMPLATE_RADIUS_PX + 1
            )));
        }
        let values = image.as_slice();
        if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            return Err(not_a_ring(format!("it holds the non-finite value {v}")));
        }
        let low = values.iter().copied().fold(f32::INFINITY, f32::min);
        let high = values.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        if let Some(v) = values.iter().find(|&&v| v != low && v != high) {
            return Err(not_a_ring(format!(
                "it holds a third value {v} besides {low} and {high}; a ring template has two \
                 values, the lower on the ring"
            )));
        }
        if low == high {
            return Err(not_a_ring(format!("all its pixels are {low}")));
        }
        let ring: Vec<bool> = values.iter().map(|&v| v == low).collect();
        Self::from_ring(width, &ring)
    }

    /// Half-side of the template, px.
    pub fn radius(&self) -> usize {
        self.radius
    }

    /// Number of ring pixels.
    pub fn ring_pixels(&self) -> usize {
        self.ring_pixels
    }

    /// Checks the ring conditions on the `side × side` set and stores it as runs.
    fn from_ring(side: usize, ring: &[bool]) -> Result<Self> {
        let radius = side / 2;
        let at = |x: usize, y: usize| ring[y * side + x];
        if at(radius, radius) {
            return Err(not_a_ring(
                "its centre pixel has the lower value; the ring must surround a centre of the \
                 higher value (a dark ring, not a dark disk)"
                    .into(),
            ));
        }
        let mirrored = (0..side).all(|y| {
            (0..side).all(|x| {
                let v = at(x, y);
                v == at(side - 1 - x, y) && v == at(x, side - 1 - y) && v == at(y, x)
            })
        });
        if !mirrored {
            return Err(not_a_ring(
                "its lower-valued pixels are not symmetric about the centre (mirrors in x and \
                 y, transposition)"
                    .into(),
            ));
        }
        let distances = ring
            .iter()
            .enumerate()
            .filter(|&(_, &r)| r)
            .map(|(i, _)| distance(i, side));
        let (d_min, d_max) = distances.fold((f64::INFINITY, 0.0f64), |(lo, hi), d| {
            (lo.min(d), hi.max(d))
        });
        if let Some(hole) = (0..side * side).find(|&i| {
            let d = distance(i, side);
            !ring[i] && d >= d_min + 1.0 && d <= d_max - 1.0
        }) {
            return Err(not_a_ring(format!(
                "the ring ({d_min:.2} to {d_max:.2} px from the centre) has a hole at pixel \
                 ({}, {})",
                hole % side,
                hole / side
            )));
        }
        let mut runs: Vec<((isize, isize), Vec<isize>)> = Vec::new();
        let c = radius as isize;
        for x in 0..side {
            let mut y = 0;
            while y < side {
                if !at(x, y) {
                    y += 1;
                    continue;
                }
                let y0 = y;
                while y < side && at(x, y) {
                    y += 1;
                }
                let rows = (y0 as isize - c, y as isize - 1 - c);
                let column = x as isize - c;
                match runs
                    .iter_mut()
                    .find(|(r, _): &&mut (_, Vec<isize>)| *r == rows)
                {
                    Some((_, columns)) => columns.push(column),
                    None => runs.push((rows, vec![column])),
                }
            }
        }
        Ok(Self {
            radius,
            runs,
            ring_pixels: ring.iter().filter(|&&r| r).count(),
        })
    }
}

/// Distance of pixel `i` of a `side × side` square from its centre, px.
fn distance(i: usize, side: usize) -> f64 {
    let c = (side / 2) as f64;
    ((i % side) as f64 - c).hypot((i / side) as f64 - c)
}

fn not_a_ring(why: String) -> Error {
    Error::input(format!(
        "the transparent-bead template is not a ring: {why}. Give a square template with two \
         values, the lower on a ring around the centre (BeadTracking's \
         template_transparent_bead_rOut10_rIn6)"
    ))
}

/// The normalised cross-correlation of images with one [`RingTemplate`], with reusable
/// buffers.
#[derive(Debug, Clone)]
pub struct RingCorrelator {
    template: RingTemplate,
    /// Column prefix sums of the zero-padded image and of its square: row `k` holds, for each
    /// padded column, the sum over the image rows above `k`; `(height + 1) × (width + 2R)`.
    prefix: Vec<f64>,
    prefix_sq: Vec<f64>,
    /// Per band: the window's column sums of `f` and `f²` and one difference of two prefix
    /// rows (each `width + 2R`), and one row each of window sums of `f` and `f²` and of ring
    /// sums (`width`).
    band_scratch: Vec<f64>,
}

impl RingCorrelator {
    /// A correlator for `template`.
    pub fn new(template: RingTemplate) -> Self {
        Self {
            template,
            prefix: Vec::new(),
            prefix_sq: Vec::new(),
            band_scratch: Vec::new(),
        }
    }

    /// The template.
    pub fn template(&self) -> &RingTemplate {
        &self.template
    }

    /// `dst(p)` (reshaped) = the NCC in `[−1, 1]` between the template centred on `p` and the
    /// image under it, zeros outside the image (MATLAB `normxcorr2` on the image zero-padded
    /// by the template radius, cropped back); 0 on flat windows.
    pub fn apply(&mut self, src: &GrayImage, dst: &mut GrayImage) {
        let (width, height) = src.dimensions();
        dst.reshape(width, height);
        if width == 0 || height == 0 {
            return;
        }
        let r = self.template.radius;
        let padded_w = width + 2 * r;
        let len = (height + 1) * padded_w;
        self.prefix.resize(len, 0.0);
        self.prefix_sq.resize(len, 0.0);
        self.prefix[..padded_w].fill(0.0);
        self.prefix_sq[..padded_w].fill(0.0);
        for y in 0..height {
            let (above, below) = self.prefix.split_at_mut((y + 1) * padded_w);
            let (above_sq, below_sq) = self.prefix_sq.split_at_mut((y + 1) * padded_w);
            accumulate_row(
                &above[y * padded_w..],
                &above_sq[y * padded_w..],
                src.row(y),
                r,
                &mut below[..padded_w],
                &mut below_sq[..padded_w],
            );
        }
        let per_band = 3 * padded_w + 3 * width;
        let bands = height.div_ceil(BAND_ROWS);
        if self.band_scratch.len() < per_band * bands {
            self.band_scratch.resize(per_band * bands, 0.0);
        }
        let sums = PrefixSums {
            template: &self.template,
            prefix: &self.prefix,
            prefix_sq: &self.prefix_sq,
            width,
            height,
        };
        dst.as_mut_slice()
            .par_chunks_mut(BAND_ROWS * width)
            .zip(self.band_scratch.par_chunks_mut(per_band))
            .enumerate()
            .for_each(|(band, (out, scratch))| {
                correlate_band_dispatch(&sums, band * BAND_ROWS, out, scratch);
            });
    }
}

/// `next = above + row` (and the same for squares), `row` placed at padded column `r` and the
/// padding columns copied (they stay 0).
fn accumulate_row(
    above: &[f64],
    above_sq: &[f64],
    row: &[f32],
    r: usize,
    next: &mut [f64],
    next_sq: &mut [f64],
) {
    let n = next.len();
    // The padding columns keep their zeros.
    for range in [0..r, r + row.len()..n] {
        next[range.clone()].copy_from_slice(&above[range.clone()]);
        next_sq[range.clone()].copy_from_slice(&above_sq[range]);
    }
    for ((((s, q), &a), &aq), &v) in next[r..]
        .iter_mut()
        .zip(&mut next_sq[r..])
        .zip(&above[r..])
        .zip(&above_sq[r..])
        .zip(row)
    {
        let v = f64::from(v);
        *s = a + v;
        *q = aq + v * v;
    }
}

/// `out[x] = Σ values[x..x + window]` for each `x` of `out`, by binary decomposition of
/// `window`: sums of blocks of 1, 2, 4, … values are doubled from one buffer into the other
/// (`values` and `spare`, both destroyed) and the blocks of the set bits added: `O(log
/// window)` vectorised passes instead of `window`.
#[inline(always)]
fn sliding_sum(values: &mut [f64], spare: &mut [f64], window: usize, out: &mut [f64]) {
    let n = out.len();
    out.fill(0.0);
    let (mut current, mut next) = (values, spare);
    let (mut block, mut offset, mut bits) = (1, 0, window);
    loop {
        if bits & 1 == 1 {
            for (o, &v) in out.iter_mut().zip(&current[offset..offset + n]) {
                *o += v;
            }
            offset += block;
        }
        bits >>= 1;
        if bits == 0 {
            return;
        }
        // Sums of 2·block values, for every start where they fit.
        let valid = current.len() + 1 - 2 * block;
        for ((d, &a), &b) in next[..valid]
            .iter_mut()
            .zip(&current[..valid])
            .zip(&current[block..])
        {
            *d = a + b;
        }
        std::mem::swap(&mut current, &mut next);
        block *= 2;
    }
}

/// The column prefix sums of one image, shared by the bands.
struct PrefixSums<'a> {
    template: &'a RingTemplate,
    prefix: &'a [f64],
    prefix_sq: &'a [f64],
    width: usize,
    height: usize,
}

/// [`correlate_band`] compiled for AVX-512 when the CPU has it (wider vectors; the same
/// operations in the same order, so the same bits).
fn correlate_band_dispatch(sums: &PrefixSums<'_>, y0: usize, out: &mut [f32], scratch: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU supports AVX-512F, checked just above.
            unsafe { correlate_band_avx512(sums, y0, out, scratch) };
            return;
        }
    }
    correlate_band(sums, y0, out, scratch);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn correlate_band_avx512(sums: &PrefixSums<'_>, y0: usize, out: &mut [f32], scratch: &mut [f64]) {
    correlate_band(sums, y0, out, scratch);
}

/// The NCC of the rows of `out`, from row `y0`. Every sum is a difference of two column
/// prefixes, so each output row is computed on its own, vectorised along the row.
#[inline(always)]
fn correlate_band(sums: &PrefixSums<'_>, y0: usize, out: &mut [f32], scratch: &mut [f64]) {
    let PrefixSums {
        template,
        prefix,
        prefix_sq,
        width,
        height,
    } = *sums;
    let r = template.radius;
    let side = 2 * r + 1;
    let n = (side * side) as f64;
    let padded_w = width + 2 * r;
    let ring_n = template.ring_pixels as f64;
    // Template values 0 on the ring, 1 elsewhere: mean m, t' = −m on the ring, β = 1 − m off.
    let mean = (n - ring_n) / n;
    let beta = 1.0 - mean;
    let template_energy = ring_n * mean * mean + (n - ring_n) * beta * beta;
    let (col_sum, rest) = scratch.split_at_mut(padded_w);
    let (col_sq, rest) = rest.split_at_mut(padded_w);
    let (rows_diff, rest) = rest.split_at_mut(padded_w);
    let (window_sum, rest) = rest.split_at_mut(width);
    let (window_sq, rest) = rest.split_at_mut(width);
    let ring_sum = &mut rest[..width];
    let prefix_row = |k: usize| &prefix[k * padded_w..][..padded_w];
    let prefix_sq_row = |k: usize| &prefix_sq[k * padded_w..][..padded_w];
    // Clamps a row index of the padded image to the image rows `0..=height` of the prefix.
    let clamp = |y: isize| y.clamp(0, height as isize) as usize;
    for (row_index, out_row) in out.chunks_exact_mut(width).enumerate() {
        let y = (y0 + row_index) as isize;
        let (top, bottom) = (clamp(y - r as isize), clamp(y + r as isize + 1));
        for (((c, q), (&b, &t)), (&bq, &tq)) in col_sum
            .iter_mut()
            .zip(col_sq.iter_mut())
            .zip(prefix_row(bottom).iter().zip(prefix_row(top)))
            .zip(prefix_sq_row(bottom).iter().zip(prefix_sq_row(top)))
        {
            *c = b - t;
            *q = bq - tq;
        }
        sliding_sum(col_sum, rows_diff, side, window_sum);
        sliding_sum(col_sq, rows_diff, side, window_sq);
        // Ring sums: per group of runs sharing their rows, one difference of two prefix rows,
        // then one read per column (a column and its mirror in one sweep).
        ring_sum.fill(0.0);
        for ((dy0, dy1), columns) in &template.runs {
            let (k0, k1) = (clamp(y + dy0), clamp(y + dy1 + 1));
            if k1 <= k0 {
                continue;
            }
            for ((d, &h), &l) in rows_diff.iter_mut().zip(prefix_row(k1)).zip(prefix_row(k0)) {
                *d = h - l;
            }
            // Padded column of a run for output x = 0 is r + dx ≥ 0.
            let at = |dx: isize| &rows_diff[(r as isize + dx) as usize..][..width];
            match columns.as_slice() {
                [a, b] => {
                    for ((acc, &p), &q) in ring_sum.iter_mut().zip(at(*a)).zip(at(*b)) {
                        *acc += p + q;
                    }
                }
                _ => {
                    for &dx in columns {
                        for (acc, &p) in ring_sum.iter_mut().zip(at(dx)) {
                            *acc += p;
                        }
                    }
                }
            }
        }
        for (((o, &sum), &sq), &ring) in out_row
            .iter_mut()
            .zip(window_sum.iter())
            .zip(window_sq.iter())
            .zip(ring_sum.iter())
        {
            let variance_sum = sq - sum * sum / n;
            let numerator = (beta * sum - ring) as f32;
            let denominator = ((template_energy * variance_sum) as f32).sqrt();
            *o = if variance_sum > FLAT_VARIANCE_PER_PIXEL * n {
                numerator / denominator
            } else {
                0.0
            };
        }
    }
}

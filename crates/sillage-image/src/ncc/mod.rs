//! Normalised cross-correlation with a ring template: the matched filter of the MMPF+ paper's
//! transparent-bead detector (§3.3.1: "a normalized cross-correlation with a ring-shape
//! model"), with MATLAB `normxcorr2`'s conventions as BeadTracking uses it (the template
//! centred on each pixel, zeros outside the image).
//!
//! Fast method: a ring template takes two values, so with `t'` the zero-mean template the
//! numerator `Σ t'·f` is `β·S_window − S_ring` (NCC is invariant to an affine change of the
//! template, so the values are taken as 0 on the ring and 1 elsewhere, `β = 1 − mean`): two
//! sums over fixed pixel sets. The image is cut into bands of rows, each computed on its own
//! (so results do not depend on the number of threads), every loop vectorised along the row:
//!
//! - the window sums of `f` and `f²`, which give the variance and decide which windows are
//!   flat, are kept in `f64`: column sums over the window rows updated from row to row (one
//!   row in, one out), then a sliding sum along the row by binary decomposition;
//! - the ring sum, the costly part, is read in `f32` from column prefix sums (running sums down
//!   each column, Lewis 1995, "Fast normalized cross-correlation") local to the band and taken
//!   on values centred on the image mean — the numerator does not change, since `t'` sums to
//!   0, but the prefixes stay small: two reads per vertical run of ring pixels (36 runs for
//!   BeadTracking's 21×21 template) instead of 204 reads, accumulated in registers over
//!   chunks of 64 pixels. [`RingCorrelator::apply`] states the resulting error bound.
//!
//! 8-bit levels: [`RingCorrelator::apply_levels`] computes every sum exactly in integers (the
//! ring sums in wrapping 16-bit lanes), see `levels.rs`.

mod levels;

use std::num::Wrapping;
use std::ops::{Add, Mul, Sub};

use rayon::prelude::*;
use sillage_core::{Error, GrayImage, Result};

/// Largest template radius accepted (a side of 201 px).
pub const MAX_TEMPLATE_RADIUS_PX: usize = 100;

/// Output rows per parallel job.
const BAND_ROWS: usize = 32;

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
    /// Per band: running column sums of `f` and `f²`, a working copy and a spare for the
    /// sliding sums (each `width + 2R`), window sums of `f` and `f²` (`width` each).
    band_f64: Vec<f64>,
    /// Per band: the column prefix sums of the band's mean-centred rows
    /// (`(BAND_ROWS + 2R + 1) × (width + 2R)`), one difference of two prefix rows
    /// (`width + 2R`) and the ring sums of one row (`width`).
    band_f32: Vec<f32>,
    /// The levels path's per-band buffers (see [`RingCorrelator::apply_levels`]).
    band_i32: Vec<i32>,
    band_u16: Vec<Wrapping<u16>>,
    /// See [`BandInput::reads`].
    reads: Vec<(usize, usize)>,
}

impl RingCorrelator {
    /// A correlator for `template`.
    pub fn new(template: RingTemplate) -> Self {
        Self {
            template,
            band_f64: Vec::new(),
            band_f32: Vec::new(),
            band_i32: Vec::new(),
            band_u16: Vec::new(),
            reads: Vec::new(),
        }
    }

    /// The template.
    pub fn template(&self) -> &RingTemplate {
        &self.template
    }

    /// `dst(p)` (reshaped) = the NCC in `[−1, 1]` between the template centred on `p` and the
    /// image under it, zeros outside the image (MATLAB `normxcorr2` on the image zero-padded
    /// by the template radius, cropped back); 0 on flat windows.
    ///
    /// The window sums of `f` and `f²` (hence the variance and the flat-window test) are exact
    /// to `f64` rounding; the ring sum is an `f32` sum of mean-centred values, so the result
    /// differs from an all-`f64` computation by at most `2k · 2⁻²⁴ · (BAND_ROWS + 2R) ·
    /// max|f − mean|` (`k` prefix reads: 72 for BeadTracking's template) divided by the
    /// denominator `√(Σt'² · Σ(f − f̄)²)`, plus the final `f32` rounding (see the tests):
    /// below 10⁻⁵ on `[0, 1]` noise; at worst 2·10⁻³ on a window of the detector's maps (max
    /// 44/255) whose only contrast is one 8-bit step, where the NCC is at most 0.05.
    pub fn apply(&mut self, src: &GrayImage, dst: &mut GrayImage) {
        let (width, height) = src.dimensions();
        dst.reshape(width, height);
        if width == 0 || height == 0 {
            return;
        }
        let r = self.template.radius;
        let padded_w = width + 2 * r;
        let bands = height.div_ceil(BAND_ROWS);
        let per_band_f64 = 4 * padded_w + 2 * width;
        let per_band_f32 = (BAND_ROWS + 2 * r + 1) * padded_w + width;
        if self.band_f64.len() < per_band_f64 * bands {
            self.band_f64.resize(per_band_f64 * bands, 0.0);
        }
        if self.band_f32.len() < per_band_f32 * bands {
            self.band_f32.resize(per_band_f32 * bands, 0.0);
        }
        // Centring the ring sums on the image mean keeps their f32 prefixes small; the
        // numerator is invariant to it (the zero-mean template sums to 0 over the window).
        let mean = lane_sum(src.as_slice()) / (width * height) as f64;
        self.set_reads(padded_w);
        let input = BandInput {
            template: &self.template,
            reads: &self.reads,
            src,
            centre: mean as f32,
        };
        dst.as_mut_slice()
            .par_chunks_mut(BAND_ROWS * width)
            .zip(self.band_f64.par_chunks_mut(per_band_f64))
            .zip(self.band_f32.par_chunks_mut(per_band_f32))
            .enumerate()
            .for_each(|(band, ((out, s64), s32))| {
                correlate_band_dispatch(&input, band * BAND_ROWS, out, s64, s32);
            });
    }
}

impl RingCorrelator {
    /// Sets [`BandInput::reads`] for band buffers `padded_w` wide: run rows `y + dy0 ..= y +
    /// dy1` of output row `y = y0 + j` are the prefix rows `j + r + dy0 .. j + r + dy1 + 1`
    /// of its band; its column `x + dx` is padded column `x + r + dx`.
    fn set_reads(&mut self, padded_w: usize) {
        let r = self.template.radius as isize;
        self.reads.clear();
        for &((dy0, dy1), ref columns) in &self.template.runs {
            for &dx in columns {
                let at = |k: isize| (k as usize) * padded_w + (r + dx) as usize;
                self.reads.push((at(r + dy0), at(r + dy1 + 1)));
            }
        }
    }
}

/// `out[x] = Σ values[x..x + window]` for each `x` of `out`, by binary decomposition of
/// `window`: sums of blocks of 2, 4, 8, … values are doubled from one scratch buffer into the
/// other (`a`, `b`, as long as `values`) and the blocks of the set bits added: `O(log window)`
/// vectorised passes instead of `window`.
#[inline(always)]
fn sliding_sum<T: Copy + Add<Output = T>>(
    values: &[T],
    a: &mut [T],
    b: &mut [T],
    window: usize,
    out: &mut [T],
) {
    let n = out.len();
    let (mut current, mut spare): (&mut [T], &mut [T]) = (a, b);
    let (mut block, mut offset, mut bits, mut first) = (1, 0, window, true);
    loop {
        if bits & 1 == 1 {
            let blocks = if block == 1 { values } else { &*current };
            let blocks = &blocks[offset..offset + n];
            if first {
                out.copy_from_slice(blocks);
                first = false;
            } else {
                for (o, &v) in out.iter_mut().zip(blocks) {
                    *o = *o + v;
                }
            }
            offset += block;
        }
        bits >>= 1;
        if bits == 0 {
            return;
        }
        // Sums of 2·block values, for every start where they fit.
        let source = if block == 1 { values } else { &*current };
        let valid = source.len() + 1 - 2 * block;
        for ((d, &x), &y) in spare[..valid]
            .iter_mut()
            .zip(&source[..valid])
            .zip(&source[block..])
        {
            *d = x + y;
        }
        std::mem::swap(&mut current, &mut spare);
        block *= 2;
    }
}

/// `Σ values` in `f64`, over 16 lanes (so that it vectorises), in a fixed order.
fn lane_sum(values: &[f32]) -> f64 {
    const LANES: usize = 16;
    let mut lanes = [0.0f64; LANES];
    let chunks = values.chunks_exact(LANES);
    let tail: f64 = chunks.remainder().iter().map(|&v| f64::from(v)).sum();
    for chunk in chunks {
        for (l, &v) in lanes.iter_mut().zip(chunk) {
            *l += f64::from(v);
        }
    }
    lanes.iter().sum::<f64>() + tail
}

/// What every band reads.
struct BandInput<'a> {
    template: &'a RingTemplate,
    /// Per vertical run of ring pixels, the offsets in a band's prefix buffer of the two
    /// prefix values whose difference is the run's sum for output pixel 0 of the band's
    /// first row.
    reads: &'a [(usize, usize)],
    src: &'a GrayImage,
    /// The value subtracted from every pixel (the padding included) for the ring sums.
    centre: f32,
}

/// [`correlate_band`] compiled for AVX-512 when the CPU has it (wider vectors; the same
/// operations in the same order, so the same bits).
fn correlate_band_dispatch(
    input: &BandInput<'_>,
    y0: usize,
    out: &mut [f32],
    s64: &mut [f64],
    s32: &mut [f32],
) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU supports AVX-512F, checked just above.
            unsafe { correlate_band_avx512(input, y0, out, s64, s32) };
            return;
        }
    }
    correlate_band(input, y0, out, s64, s32);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn correlate_band_avx512(
    input: &BandInput<'_>,
    y0: usize,
    out: &mut [f32],
    s64: &mut [f64],
    s32: &mut [f32],
) {
    correlate_band(input, y0, out, s64, s32);
}

/// `col += enter − leave` and `col_sq += enter² − leave²` in `S` (`f64` for `f32` pixels,
/// `i32` for 8-bit levels), for the rows present.
#[inline(always)]
fn update_columns<P: Copy, S>(
    col: &mut [S],
    col_sq: &mut [S],
    enter: Option<&[P]>,
    leave: Option<&[P]>,
) where
    S: Copy + From<P> + Add<Output = S> + Sub<Output = S> + Mul<Output = S>,
{
    match (enter, leave) {
        (Some(enter), Some(leave)) => {
            for (((c, q), &a), &b) in col.iter_mut().zip(col_sq.iter_mut()).zip(enter).zip(leave) {
                let (a, b) = (S::from(a), S::from(b));
                *c = *c + (a - b);
                *q = *q + (a * a - b * b);
            }
        }
        (Some(enter), None) => {
            for ((c, q), &a) in col.iter_mut().zip(col_sq.iter_mut()).zip(enter) {
                let a = S::from(a);
                *c = *c + a;
                *q = *q + a * a;
            }
        }
        (None, Some(leave)) => {
            for ((c, q), &b) in col.iter_mut().zip(col_sq.iter_mut()).zip(leave) {
                let b = S::from(b);
                *c = *c - b;
                *q = *q - b * b;
            }
        }
        (None, None) => {}
    }
}

/// Output pixels whose ring sums are accumulated in registers at once.
const RING_CHUNK: usize = 64;

/// `ring[x] = Σ over reads (lo, hi) of prefix[hi + x] − prefix[lo + x]`, the reads in their
/// order for every pixel, from 0 (`T::default()`); chunks of [`RING_CHUNK`] pixels keep their
/// sums in registers across all the reads.
#[inline(always)]
fn ring_sums<T>(prefix: &[T], reads: &[(usize, usize)], ring: &mut [T])
where
    T: Copy + Default + Add<Output = T> + Sub<Output = T>,
{
    let n = ring.len();
    let full = n / RING_CHUNK * RING_CHUNK;
    for x in (0..full).step_by(RING_CHUNK) {
        let mut acc = [T::default(); RING_CHUNK];
        for &(lo, hi) in reads {
            let high: &[T; RING_CHUNK] = prefix[hi + x..][..RING_CHUNK].try_into().unwrap();
            let low: &[T; RING_CHUNK] = prefix[lo + x..][..RING_CHUNK].try_into().unwrap();
            for i in 0..RING_CHUNK {
                acc[i] = acc[i] + (high[i] - low[i]);
            }
        }
        ring[x..x + RING_CHUNK].copy_from_slice(&acc);
    }
    for (x, out) in ring.iter_mut().enumerate().skip(full) {
        *out = reads.iter().fold(T::default(), |acc, &(lo, hi)| {
            acc + (prefix[hi + x] - prefix[lo + x])
        });
    }
}

/// The NCC of the rows of `out`, from row `y0`, each output row on its own and vectorised
/// along the row:
///
/// - window sums of `f` and `f²` in `f64`: column sums over the `2R + 1` window rows, kept
///   up to date from row to row by adding the row entering and subtracting the row leaving
///   (exact to `f64` rounding, a few dozen operations deep), then summed along the row;
/// - ring sums in `f32` from column prefix sums local to the band (`BAND_ROWS + 2R` rows) of
///   the mean-centred padded image, two reads per vertical run of ring pixels.
#[inline(always)]
fn correlate_band(
    input: &BandInput<'_>,
    y0: usize,
    out: &mut [f32],
    s64: &mut [f64],
    s32: &mut [f32],
) {
    let BandInput {
        template,
        reads,
        src,
        centre,
    } = *input;
    let (width, height) = src.dimensions();
    let r = template.radius;
    let side = 2 * r + 1;
    let n = (side * side) as f64;
    let padded_w = width + 2 * r;
    let rows = out.len() / width;
    let ring_n = template.ring_pixels as f64;
    // Template values 0 on the ring, 1 elsewhere: mean m, t' = −m on the ring, β = 1 − m off.
    let mean = (n - ring_n) / n;
    let beta = 1.0 - mean;
    let template_energy = ring_n * mean * mean + (n - ring_n) * beta * beta;
    let (col_sum, rest) = s64.split_at_mut(padded_w);
    let (col_sq, rest) = rest.split_at_mut(padded_w);
    let (a, rest) = rest.split_at_mut(padded_w);
    let (b, rest) = rest.split_at_mut(padded_w);
    let (window_sum, rest) = rest.split_at_mut(width);
    let window_sq = &mut rest[..width];
    let local_rows = rows + 2 * r;
    let (prefix, rest) = s32.split_at_mut((local_rows + 1) * padded_w);
    let ring_sum = &mut rest[..width];
    // An image row, if `y` is one.
    let image_row = |y: isize| {
        (0..height as isize)
            .contains(&y)
            .then(|| src.row(y as usize))
    };

    // Prefix rows: prefix[k] sums the padded rows y0 − r .. y0 − r + k, centred.
    prefix[..padded_w].fill(0.0);
    for k in 0..local_rows {
        let (above, below) = prefix.split_at_mut((k + 1) * padded_w);
        let (above, next) = (&above[k * padded_w..], &mut below[..padded_w]);
        match image_row((y0 + k) as isize - r as isize) {
            Some(row) => {
                for range in [0..r, r + width..padded_w] {
                    for (p, &a) in next[range.clone()].iter_mut().zip(&above[range]) {
                        *p = a - centre;
                    }
                }
                for ((p, &a), &v) in next[r..r + width].iter_mut().zip(&above[r..]).zip(row) {
                    *p = a + (v - centre);
                }
            }
            None => {
                for (p, &a) in next.iter_mut().zip(above.iter()) {
                    *p = a - centre;
                }
            }
        }
    }

    // Column sums of the first output row's window (padding columns stay 0).
    col_sum.fill(0.0);
    col_sq.fill(0.0);
    let inner = r..r + width;
    for y in y0 as isize - r as isize..=(y0 + r) as isize {
        update_columns(
            &mut col_sum[inner.clone()],
            &mut col_sq[inner.clone()],
            image_row(y),
            None,
        );
    }
    let inv_n = 1.0 / n;
    let centred_offset = n * f64::from(centre);
    for (j, out_row) in out.chunks_exact_mut(width).enumerate() {
        let y = (y0 + j) as isize;
        if j > 0 {
            update_columns(
                &mut col_sum[inner.clone()],
                &mut col_sq[inner.clone()],
                image_row(y + r as isize),
                image_row(y - r as isize - 1),
            );
        }
        sliding_sum(col_sum, a, b, side, window_sum);
        sliding_sum(col_sq, a, b, side, window_sq);
        // The reads are relative to output row 0 of the band.
        ring_sums(&prefix[j * padded_w..], reads, ring_sum);
        for (((o, &sum), &sq), &ring) in out_row
            .iter_mut()
            .zip(window_sum.iter())
            .zip(window_sq.iter())
            .zip(ring_sum.iter())
        {
            let variance_sum = sq - sum * sum * inv_n;
            let numerator = (beta * (sum - centred_offset) - f64::from(ring)) as f32;
            let denominator = ((template_energy * variance_sum) as f32).sqrt();
            *o = if variance_sum > FLAT_VARIANCE_PER_PIXEL * n {
                numerator / denominator
            } else {
                0.0
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Direct NCC in `f64`, the template centred on each pixel, zeros outside the image;
    /// returns the value and the denominator `√(Σt'² · Σ(f − f̄)²)` (0 on flat windows).
    pub(super) fn direct(
        src: &GrayImage,
        template: &RingTemplate,
        x: usize,
        y: usize,
    ) -> (f64, f64) {
        let r = template.radius as isize;
        let (w, h) = src.dimensions();
        let mut ring = vec![false; ((2 * r + 1) * (2 * r + 1)) as usize];
        for ((dy0, dy1), columns) in &template.runs {
            for &dx in columns {
                for dy in *dy0..=*dy1 {
                    ring[((dy + r) * (2 * r + 1) + dx + r) as usize] = true;
                }
            }
        }
        let n = ring.len() as f64;
        let t_mean = ring.iter().filter(|&&v| !v).count() as f64 / n;
        let (mut f, mut t) = (Vec::new(), Vec::new());
        for dy in -r..=r {
            for dx in -r..=r {
                let (xx, yy) = (x as isize + dx, y as isize + dy);
                let inside = xx >= 0 && yy >= 0 && xx < w as isize && yy < h as isize;
                f.push(if inside {
                    f64::from(src.get(xx as usize, yy as usize))
                } else {
                    0.0
                });
                let on_ring = ring[((dy + r) * (2 * r + 1) + dx + r) as usize];
                t.push(if on_ring { 0.0 } else { 1.0 } - t_mean);
            }
        }
        let f_mean = f.iter().sum::<f64>() / n;
        let (mut num, mut tt, mut ff) = (0.0, 0.0, 0.0);
        for (a, b) in t.iter().zip(&f) {
            num += a * (b - f_mean);
            tt += a * a;
            ff += (b - f_mean).powi(2);
        }
        if ff > FLAT_VARIANCE_PER_PIXEL * n {
            let denominator = (tt * ff).sqrt();
            (num / denominator, denominator)
        } else {
            (0.0, 0.0)
        }
    }

    /// Images like the detector's h-concave maps (mostly exactly 0, bumps of 8-bit levels up
    /// to 44/255, dark rings) and bright 8-bit noise, over several bands: every pixel within
    /// the `f32` error bound of the ring sums, `2 · reads · 2⁻²⁴ · (BAND_ROWS + 2R) · M`
    /// (each of the `reads` prefix values is a sum of at most `BAND_ROWS + 2R` terms of
    /// magnitude at most `M = max|f − mean|`, each rounding at most one unit of `2⁻²⁴`
    /// relative to that bound), divided by the denominator; flat windows exactly 0.
    #[test]
    fn f32_ring_sums_stay_within_their_error_bound_of_the_direct_f64_ncc() {
        let template = RingTemplate::annulus(6.0, 10.0).unwrap();
        let r = template.radius;
        let reads = 2 * template.runs.iter().map(|(_, c)| c.len()).sum::<usize>();
        let mut state = 11u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as u32
        };
        let (w, h) = (97, 3 * BAND_ROWS + 9);
        let sparse: Vec<f32> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64, (i / w) as f64);
                let d = (x - 40.0).hypot(y - 50.0);
                if d > 6.0 && d <= 10.0 {
                    40.0 / 255.0
                } else if next().is_multiple_of(7)
                    && (x as usize / 20 + y as usize / 20).is_multiple_of(2)
                {
                    f32::from((next() % 45) as u8) / 255.0
                } else {
                    0.0
                }
            })
            .collect();
        let bright: Vec<f32> = (0..w * h)
            .map(|_| f32::from((180 + next() % 60) as u8) / 255.0)
            .collect();
        let mut correlator = RingCorrelator::new(template.clone());
        for data in [sparse, bright] {
            let src = GrayImage::from_vec(w, h, data).unwrap();
            let mean = src.as_slice().iter().map(|&v| f64::from(v)).sum::<f64>() / (w * h) as f64;
            let m = src
                .as_slice()
                .iter()
                .fold(mean, |m, &v| m.max((f64::from(v) - mean).abs()));
            let ring_error =
                2.0 * reads as f64 * (BAND_ROWS + 2 * r) as f64 * m / (1u64 << 24) as f64;
            let mut ncc = GrayImage::default();
            correlator.apply(&src, &mut ncc);
            let mut worst = 0.0f64;
            for y in 0..h {
                for x in 0..w {
                    let (want, denominator) = direct(&src, &template, x, y);
                    let got = f64::from(ncc.get(x, y));
                    if denominator == 0.0 {
                        assert_eq!(got, 0.0, "flat window at ({x}, {y})");
                        continue;
                    }
                    // Plus the final f32 rounding of the quotient.
                    let bound = ring_error / denominator + 1e-6;
                    let error = (got - want).abs();
                    assert!(error <= bound, "({x}, {y}): {got} vs {want}, bound {bound}");
                    worst = worst.max(error / bound);
                }
            }
            assert!(worst > 0.0);
        }
    }
}

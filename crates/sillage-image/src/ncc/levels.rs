//! The ring NCC on 8-bit levels, with exact integer sums.
//!
//! NCC is invariant to the scale of the image, so the levels `k` give the correlation of the
//! grey levels `k / 255`. On levels every sum is an exact integer: the window sums of `k` and
//! `k²` in `i32` (running column sums, then a sliding sum along the row, as the `f32` path
//! does in `f64`), and the ring sums in wrapping `u16` from column prefix sums local to the
//! band — prefixes wrap, but a ring sum (at most `255 ×` the ring's pixels) is below 2¹⁶, so
//! differences and sums modulo 2¹⁶ give it exactly, 32 lanes per AVX-512 vector. With `n`
//! the window's pixels, `n_r` the ring's, `S`, `Q`, `S_r` the sums of `k`, `k²` and of `k`
//! on the ring:
//!
//! `NCC = (n_r·S − n·S_r) / √(n_r·(n − n_r) · (n·Q − S²))`,
//!
//! the numerator exact in `i32`, the product under the root exact in `f64` (below 2⁵³), so
//! the only roundings are the final `f32` conversion, square root and division; a window is
//! flat exactly when `n·Q = S²`.

use std::num::Wrapping;

use rayon::prelude::*;
use sillage_core::{GrayImage, Image};

use super::{BAND_ROWS, RingCorrelator, ring_sums, sliding_sum, update_columns};

/// What every band reads.
struct LevelsInput<'a> {
    /// See [`super::BandInput::reads`].
    reads: &'a [(usize, usize)],
    src: &'a Image<u8>,
    radius: usize,
    ring_pixels: usize,
}

impl RingCorrelator {
    /// [`RingCorrelator::apply`] on 8-bit levels `k` (the image `k / 255`), with exact integer
    /// sums: `dst` (reshaped) is the NCC rounded to `f32` (within a relative `4·2⁻²⁴` of the
    /// exact value), 0 exactly on flat windows. Needs a template of at most 257 ring pixels
    /// (BeadTracking's has 204; the built-in ones up to a radius of 10 px), so that ring sums
    /// fit in 16 bits; panics otherwise.
    pub fn apply_levels(&mut self, src: &Image<u8>, dst: &mut GrayImage) {
        let ring_pixels = self.template.ring_pixels;
        assert!(
            ring_pixels * 255 <= usize::from(u16::MAX),
            "ring sums of {ring_pixels} levels do not fit in 16 bits"
        );
        let (width, height) = src.dimensions();
        dst.reshape(width, height);
        if width == 0 || height == 0 {
            return;
        }
        let radius = self.template.radius;
        let padded_w = width + 2 * radius;
        let bands = height.div_ceil(BAND_ROWS);
        let per_band_i32 = 4 * padded_w + 2 * width;
        let per_band_u16 = (BAND_ROWS + 2 * radius + 1) * padded_w + width;
        if self.band_i32.len() < per_band_i32 * bands {
            self.band_i32.resize(per_band_i32 * bands, 0);
        }
        if self.band_u16.len() < per_band_u16 * bands {
            self.band_u16.resize(per_band_u16 * bands, Wrapping(0));
        }
        self.set_reads(padded_w);
        let input = LevelsInput {
            reads: &self.reads,
            src,
            radius,
            ring_pixels,
        };
        dst.as_mut_slice()
            .par_chunks_mut(BAND_ROWS * width)
            .zip(self.band_i32.par_chunks_mut(per_band_i32))
            .zip(self.band_u16.par_chunks_mut(per_band_u16))
            .enumerate()
            .for_each(|(band, ((out, s32), s16))| {
                correlate_band_dispatch(&input, band * BAND_ROWS, out, s32, s16);
            });
    }
}

/// [`correlate_band`] compiled for AVX-512 (with its 16-bit lanes) when the CPU has it; the
/// sums are exact, so every path gives the same bits.
fn correlate_band_dispatch(
    input: &LevelsInput<'_>,
    y0: usize,
    out: &mut [f32],
    s32: &mut [i32],
    s16: &mut [Wrapping<u16>],
) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx512bw") {
            // SAFETY: the CPU supports AVX-512F and AVX-512BW, checked just above.
            unsafe { correlate_band_avx512(input, y0, out, s32, s16) };
            return;
        }
    }
    correlate_band(input, y0, out, s32, s16);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw")]
fn correlate_band_avx512(
    input: &LevelsInput<'_>,
    y0: usize,
    out: &mut [f32],
    s32: &mut [i32],
    s16: &mut [Wrapping<u16>],
) {
    correlate_band(input, y0, out, s32, s16);
}

/// The NCC of the rows of `out`, from row `y0` (see the module doc), each row vectorised.
#[inline(always)]
fn correlate_band(
    input: &LevelsInput<'_>,
    y0: usize,
    out: &mut [f32],
    s32: &mut [i32],
    s16: &mut [Wrapping<u16>],
) {
    let LevelsInput {
        reads,
        src,
        radius: r,
        ring_pixels,
    } = *input;
    let (width, height) = src.dimensions();
    let side = 2 * r + 1;
    let n = (side * side) as i32;
    let ring_n = ring_pixels as i32;
    let energy = f64::from(ring_n) * f64::from(n - ring_n);
    let padded_w = width + 2 * r;
    let rows = out.len() / width;
    let (col_sum, rest) = s32.split_at_mut(padded_w);
    let (col_sq, rest) = rest.split_at_mut(padded_w);
    let (a, rest) = rest.split_at_mut(padded_w);
    let (b, rest) = rest.split_at_mut(padded_w);
    let (window_sum, rest) = rest.split_at_mut(width);
    let window_sq = &mut rest[..width];
    let local_rows = rows + 2 * r;
    let (prefix, rest) = s16.split_at_mut((local_rows + 1) * padded_w);
    let ring_sum = &mut rest[..width];
    let image_row = |y: isize| {
        (0..height as isize)
            .contains(&y)
            .then(|| src.row(y as usize))
    };

    // Prefix rows: prefix[k] sums the padded rows y0 − r .. y0 − r + k (0 on the padding).
    prefix[..padded_w].fill(Wrapping(0));
    for k in 0..local_rows {
        let (above, below) = prefix.split_at_mut((k + 1) * padded_w);
        let (above, next) = (&above[k * padded_w..], &mut below[..padded_w]);
        next.copy_from_slice(above);
        if let Some(row) = image_row((y0 + k) as isize - r as isize) {
            for (p, &v) in next[r..r + width].iter_mut().zip(row) {
                *p += Wrapping(u16::from(v));
            }
        }
    }

    // Column sums of the first output row's window (padding columns stay 0).
    col_sum.fill(0);
    col_sq.fill(0);
    let inner = r..r + width;
    for y in y0 as isize - r as isize..=(y0 + r) as isize {
        update_columns(
            &mut col_sum[inner.clone()],
            &mut col_sq[inner.clone()],
            image_row(y),
            None,
        );
    }
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
            let numerator = ring_n * sum - n * i32::from(ring.0);
            let (sum, sq) = (f64::from(sum), f64::from(sq));
            let variance = f64::from(n) * sq - sum * sum;
            let denominator = ((energy * variance) as f32).sqrt();
            *o = if variance > 0.0 {
                numerator as f32 / denominator
            } else {
                0.0
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::RingTemplate;
    use crate::ncc::tests::direct;

    /// Sparse maps like the detector's h-concave levels (mostly 0, bumps up to 44, a ring),
    /// full-range noise and a flat image, over several bands and with a tail of columns:
    /// every pixel within `4·2⁻²⁴` (relative) of the direct `f64` NCC of the levels (that of
    /// `k / 255`: NCC does not depend on the scale), flat windows exactly 0.
    #[test]
    fn levels_match_the_direct_f64_ncc() {
        let template = RingTemplate::annulus(6.0, 10.0).unwrap();
        let mut state = 5u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as u32
        };
        let (w, h) = (83, 2 * BAND_ROWS + 13);
        let sparse: Vec<u8> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64, (i / w) as f64);
                let d = (x - 40.0).hypot(y - 30.0);
                if d > 6.0 && d <= 10.0 {
                    40
                } else if next().is_multiple_of(5)
                    && (x as usize / 25 + y as usize / 25).is_multiple_of(2)
                {
                    (next() % 45) as u8
                } else {
                    0
                }
            })
            .collect();
        let noise: Vec<u8> = (0..w * h).map(|_| (next() % 256) as u8).collect();
        let mut correlator = RingCorrelator::new(template.clone());
        for data in [sparse, noise, vec![7; w * h]] {
            let levels = Image::from_vec(w, h, data).unwrap();
            // Integers, exact in `f32` (`k / 255` in `f32` would add its own rounding).
            let exact = levels.as_slice().iter().map(|&k| f32::from(k));
            let exact = GrayImage::from_vec(w, h, exact.collect()).unwrap();
            let mut ncc = GrayImage::default();
            correlator.apply_levels(&levels, &mut ncc);
            for y in 0..h {
                for x in 0..w {
                    let (want, denominator) = direct(&exact, &template, x, y);
                    let got = f64::from(ncc.get(x, y));
                    if denominator == 0.0 {
                        assert_eq!(got, 0.0, "flat window at ({x}, {y})");
                        continue;
                    }
                    let bound = 4.0 * want.abs() / (1u64 << 24) as f64 + 1e-12;
                    assert!((got - want).abs() <= bound, "({x}, {y}): {got} vs {want}");
                }
            }
        }
    }
}

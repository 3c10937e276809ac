//! The 3×3 mean filter with zeros outside the image (MATLAB's
//! `imfilter(f, fspecial('average', 3))`), which BeadTracking applies twice to the
//! transparent-bead correlation map before looking for maxima.

use rayon::prelude::*;
use sillage_core::GrayImage;

/// Pixels summed per stack chunk.
const CHUNK: usize = 128;

/// Output rows per parallel job; fixed, and every pixel is computed the same way whatever the
/// job, so results do not depend on the number of threads.
const BAND_ROWS: usize = 32;

/// `dst(p)` (reshaped) = the mean of the 3×3 window around `p`, pixels outside the image
/// counting as 0: `((v(x−1) + v(x)) + v(x+1)) / 9` where `v = (f(y) + f(y−1)) + f(y+1)` is
/// the vertical sum of the rows present. Parallel over bands of rows, vectorised along them.
pub fn box_mean_3x3(src: &GrayImage, dst: &mut GrayImage) {
    let (width, height) = src.dimensions();
    dst.reshape(width, height);
    if width == 0 || height == 0 {
        return;
    }
    dst.as_mut_slice()
        .par_chunks_mut(BAND_ROWS * width)
        .enumerate()
        .for_each(|(band, out)| mean_band_dispatch(src, band * BAND_ROWS, out));
}

/// [`mean_band`] compiled for AVX-512 when the CPU has it (the same operations, so the same
/// bits).
fn mean_band_dispatch(src: &GrayImage, y0: usize, out: &mut [f32]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU supports AVX-512F, checked just above.
            unsafe { mean_band_avx512(src, y0, out) };
            return;
        }
    }
    mean_band(src, y0, out);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn mean_band_avx512(src: &GrayImage, y0: usize, out: &mut [f32]) {
    mean_band(src, y0, out);
}

/// The output rows `y0..` held by `out`: per chunk of the row, the vertical sums (and the one
/// on each side of the chunk) go to a stack buffer, then the horizontal sums of three.
#[inline(always)]
fn mean_band(src: &GrayImage, y0: usize, out: &mut [f32]) {
    let (width, height) = src.dimensions();
    for (j, out_row) in out.chunks_exact_mut(width).enumerate() {
        let y = y0 + j;
        let centre = src.row(y);
        let up = (y > 0).then(|| src.row(y - 1));
        let down = (y + 1 < height).then(|| src.row(y + 1));
        let vertical = |x: usize| {
            let mut v = centre[x];
            if let Some(up) = up {
                v += up[x];
            }
            if let Some(down) = down {
                v += down[x];
            }
            v
        };
        for start in (0..width).step_by(CHUNK) {
            let n = CHUNK.min(width - start);
            let mut buffer = [0.0f32; CHUNK + 2];
            buffer[0] = if start > 0 { vertical(start - 1) } else { 0.0 };
            buffer[n + 1] = if start + n < width {
                vertical(start + n)
            } else {
                0.0
            };
            let sums = &mut buffer[1..=n];
            sums.copy_from_slice(&centre[start..start + n]);
            for row in [up, down].into_iter().flatten() {
                for (s, &v) in sums.iter_mut().zip(&row[start..start + n]) {
                    *s += v;
                }
            }
            for (i, o) in out_row[start..start + n].iter_mut().enumerate() {
                *o = (buffer[i] + buffer[i + 1] + buffer[i + 2]) / 9.0;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The direct 3×3 sum (in the same order of additions) on images with one row, one
    /// column, chunk tails and several bands.
    #[test]
    fn matches_the_direct_window_sum() {
        for (w, h) in [(1, 1), (1, 7), (9, 1), (130, 70), (300, 3)] {
            let data = (0..w * h)
                .map(|i| ((i * 7919 + 11) % 1013) as f32 / 1012.0)
                .collect();
            let src = GrayImage::from_vec(w, h, data).unwrap();
            let mut got = GrayImage::default();
            box_mean_3x3(&src, &mut got);
            let at = |x: isize, y: isize| {
                if x < 0 || y < 0 || x >= w as isize || y >= h as isize {
                    return 0.0;
                }
                let v = |yy: isize| {
                    if yy < 0 || yy >= h as isize {
                        None
                    } else {
                        Some(src.get(x as usize, yy as usize))
                    }
                };
                let mut s = v(y).unwrap();
                for extra in [v(y - 1), v(y + 1)].into_iter().flatten() {
                    s += extra;
                }
                s
            };
            for y in 0..h as isize {
                for x in 0..w as isize {
                    let want = (at(x - 1, y) + at(x, y) + at(x + 1, y)) / 9.0;
                    assert_eq!(got.get(x as usize, y as usize), want, "{w}×{h} ({x}, {y})");
                }
            }
        }
    }
}

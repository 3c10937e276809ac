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
    let source = Rows::whole(src);
    dst.as_mut_slice()
        .par_chunks_mut(BAND_ROWS * width)
        .enumerate()
        .for_each(|(band, out)| mean_band_dispatch(source, band * BAND_ROWS, out));
}

/// [`box_mean_3x3`] applied several times in one pass over the image, with its scratch rows.
///
/// Each band of output rows computes the earlier passes on the rows it needs only (one more
/// on each side per remaining pass) in scratch rows that stay in cache, so the image is read
/// and written once whatever the number of passes; every pixel of every pass is computed by
/// the same operations as [`box_mean_3x3`] does, so the result is the repeated filter bit for
/// bit, whatever the number of threads.
#[derive(Debug, Clone, Default)]
pub struct BoxMean {
    scratch: Vec<f32>,
}

impl BoxMean {
    /// A filter with no scratch rows yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// `dst` (reshaped) = `src` filtered `passes` times by the 3×3 mean (a copy for 0).
    pub fn apply(&mut self, src: &GrayImage, passes: usize, dst: &mut GrayImage) {
        let (width, height) = src.dimensions();
        dst.reshape(width, height);
        match passes {
            0 => return dst.as_mut_slice().copy_from_slice(src.as_slice()),
            1 => return box_mean_3x3(src, dst),
            _ if width == 0 || height == 0 => return,
            _ => {}
        }
        // Two ping-pong buffers per band, each the band's rows and `passes − 1` on each side.
        let per_band = 2 * (BAND_ROWS + 2 * (passes - 1)) * width;
        let bands = height.div_ceil(BAND_ROWS);
        if self.scratch.len() < per_band * bands {
            self.scratch.resize(per_band * bands, 0.0);
        }
        let source = Rows::whole(src);
        dst.as_mut_slice()
            .par_chunks_mut(BAND_ROWS * width)
            .zip(self.scratch.par_chunks_mut(per_band))
            .enumerate()
            .for_each(|(band, (out, scratch))| {
                let y0 = band * BAND_ROWS;
                let y1 = y0 + out.len() / width;
                let (mut previous, mut next) = scratch.split_at_mut(per_band / 2);
                let mut input = source;
                for pass in 1..passes {
                    // Rows of this pass: the band widened by the passes still to come.
                    let margin = passes - pass;
                    let (lo, hi) = (y0.saturating_sub(margin), (y1 + margin).min(height));
                    let rows = &mut next[..(hi - lo) * width];
                    mean_band_dispatch(input, lo, rows);
                    std::mem::swap(&mut previous, &mut next);
                    input = Rows {
                        data: &previous[..(hi - lo) * width],
                        first: lo,
                        width,
                        height,
                    };
                }
                mean_band_dispatch(input, y0, out);
            });
    }
}

/// Consecutive rows `first..` of an image of `height` rows, `width` pixels each: the whole
/// image, or the scratch rows of one band.
#[derive(Debug, Clone, Copy)]
struct Rows<'a> {
    data: &'a [f32],
    first: usize,
    width: usize,
    height: usize,
}

impl<'a> Rows<'a> {
    /// All the rows of `image`.
    fn whole(image: &'a GrayImage) -> Self {
        let (width, height) = image.dimensions();
        Self {
            data: image.as_slice(),
            first: 0,
            width,
            height,
        }
    }

    /// Row `y` of the image (it must be one of these rows).
    #[inline(always)]
    fn row(&self, y: usize) -> &'a [f32] {
        &self.data[(y - self.first) * self.width..][..self.width]
    }
}

/// [`mean_band`] compiled for AVX-512 when the CPU has it (the same operations, so the same
/// bits).
fn mean_band_dispatch(src: Rows<'_>, y0: usize, out: &mut [f32]) {
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
fn mean_band_avx512(src: Rows<'_>, y0: usize, out: &mut [f32]) {
    mean_band(src, y0, out);
}

/// The output rows `y0..` held by `out`, from the rows of `src` around them: per chunk of the
/// row, the vertical sums (and the one on each side of the chunk) go to a stack buffer, then
/// the horizontal sums of three.
#[inline(always)]
fn mean_band(src: Rows<'_>, y0: usize, out: &mut [f32]) {
    let (width, height) = (src.width, src.height);
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

    /// Several passes in one are the passes one after another, bit for bit, with 1 or 3
    /// threads, on images of one or several bands (bands widened past both image edges).
    #[test]
    fn repeated_passes_match_passes_in_turn() {
        for (w, h) in [(1, 1), (9, 1), (1, 70), (130, 70), (40, 33)] {
            let data = (0..w * h)
                .map(|i| ((i * 7919 + 11) % 1013) as f32 / 1012.0)
                .collect();
            let src = GrayImage::from_vec(w, h, data).unwrap();
            for passes in 0..=3 {
                let mut expected = src.clone();
                for _ in 0..passes {
                    let mut next = GrayImage::default();
                    box_mean_3x3(&expected, &mut next);
                    expected = next;
                }
                for threads in [1, 3] {
                    let pool = rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .unwrap();
                    let mut got = GrayImage::default();
                    pool.install(|| BoxMean::new().apply(&src, passes, &mut got));
                    assert_eq!(got, expected, "{w}×{h}, {passes} passes, {threads} threads");
                }
            }
        }
    }
}

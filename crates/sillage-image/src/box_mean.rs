//! The 3×3 mean filter with zeros outside the image (MATLAB's
//! `imfilter(f, fspecial('average', 3))`), which BeadTracking applies twice to the
//! transparent-bead correlation map before looking for maxima.

use rayon::prelude::*;
use sillage_core::GrayImage;

/// Pixels summed per stack chunk.
const CHUNK: usize = 128;

/// `dst(p)` (reshaped) = the mean of the 3×3 window around `p`, pixels outside the image
/// counting as 0. Separable: a vertical sum of three rows, then a horizontal sum of three
/// values in place; parallel over rows, the same operations whatever the thread count.
pub fn box_mean_3x3(src: &GrayImage, dst: &mut GrayImage) {
    let (width, height) = src.dimensions();
    dst.reshape(width, height);
    if width == 0 || height == 0 {
        return;
    }
    dst.as_mut_slice()
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(y, out)| {
            out.copy_from_slice(src.row(y));
            for yy in [y.wrapping_sub(1), y + 1] {
                if yy < height {
                    for (o, &v) in out.iter_mut().zip(src.row(yy)) {
                        *o += v;
                    }
                }
            }
            // Horizontal sums in place, in chunks copied with their two neighbours to a
            // stack buffer so that the sums vectorise.
            let mut before = 0.0;
            for start in (0..width).step_by(CHUNK) {
                let n = CHUNK.min(width - start);
                let mut buffer = [0.0f32; CHUNK + 2];
                buffer[0] = before;
                buffer[1..=n].copy_from_slice(&out[start..start + n]);
                buffer[n + 1] = out.get(start + n).copied().unwrap_or(0.0);
                before = buffer[n];
                for (i, o) in out[start..start + n].iter_mut().enumerate() {
                    *o = (buffer[i] + buffer[i + 1] + buffer[i + 2]) / 9.0;
                }
            }
        });
}

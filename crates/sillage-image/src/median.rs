//! Median filters of size 3×3 and 5×5 (TracTrac's optional `noise` step, §3.1.1), border
//! replicated, parallel over rows.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sillage_core::GrayImage;

/// Window of the median filter. Written `3` or `5` in configuration files (OpenCV's float
/// `medianBlur`, which TracTrac calls, supports only these two).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(try_from = "u8", into = "u8")]
pub enum MedianSize {
    /// 3×3 window (the paper's default).
    #[default]
    Three,
    /// 5×5 window.
    Five,
}

impl MedianSize {
    /// Half-width of the window (1 or 2).
    pub fn radius(self) -> usize {
        match self {
            MedianSize::Three => 1,
            MedianSize::Five => 2,
        }
    }
}

impl TryFrom<u8> for MedianSize {
    type Error = String;
    fn try_from(side: u8) -> Result<Self, String> {
        match side {
            3 => Ok(MedianSize::Three),
            5 => Ok(MedianSize::Five),
            other => Err(format!("median size must be 3 or 5, got {other}")),
        }
    }
}

impl From<MedianSize> for u8 {
    fn from(size: MedianSize) -> u8 {
        (2 * size.radius() + 1) as u8
    }
}

/// Median of each `size` window of `src` into `dst` (reshaped); pixels beyond the border
/// take the value of the nearest border pixel.
pub fn median_filter(src: &GrayImage, size: MedianSize, dst: &mut GrayImage) {
    match size {
        MedianSize::Three => filter_rows::<1, 9>(src, dst, median9),
        MedianSize::Five => filter_rows::<2, 25>(src, dst, |window| {
            *window.select_nth_unstable_by(12, f32::total_cmp).1
        }),
    }
}

/// Gathers each `(2R+1)²` window (`N` values, border replicated) and reduces it with `median`.
fn filter_rows<const R: usize, const N: usize>(
    src: &GrayImage,
    dst: &mut GrayImage,
    median: impl Fn(&mut [f32; N]) -> f32 + Sync,
) {
    let (width, height) = src.dimensions();
    dst.reshape(width, height);
    if width == 0 {
        return;
    }
    let clamp = |i: isize, n: usize| i.clamp(0, n as isize - 1) as usize;
    dst.as_mut_slice()
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(y, out)| {
            let rows: [&[f32]; 5] = std::array::from_fn(|j| {
                src.row(clamp(y as isize + j as isize - R as isize, height))
            });
            let mut window = [0.0f32; N];
            for (x, o) in out.iter_mut().enumerate() {
                let mut k = 0;
                for row in &rows[..2 * R + 1] {
                    for dx in 0..=2 * R {
                        window[k] = row[clamp(x as isize + dx as isize - R as isize, width)];
                        k += 1;
                    }
                }
                *o = median(&mut window);
            }
        });
}

/// Median of 9 values with the 19-exchange network of Paeth (Graphics Gems, 1990).
fn median9(p: &mut [f32; 9]) -> f32 {
    const PAIRS: [(usize, usize); 19] = [
        (1, 2),
        (4, 5),
        (7, 8),
        (0, 1),
        (3, 4),
        (6, 7),
        (1, 2),
        (4, 5),
        (7, 8),
        (0, 3),
        (5, 8),
        (4, 7),
        (3, 6),
        (1, 4),
        (2, 5),
        (4, 7),
        (4, 2),
        (6, 4),
        (4, 2),
    ];
    for (a, b) in PAIRS {
        let (lo, hi) = (p[a].min(p[b]), p[a].max(p[b]));
        p[a] = lo;
        p[b] = hi;
    }
    p[4]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_size_parses_3_and_5_only() {
        assert_eq!(MedianSize::try_from(5).unwrap(), MedianSize::Five);
        assert!(MedianSize::try_from(4).is_err());
        assert_eq!(u8::from(MedianSize::Three), 3);
    }

    #[test]
    fn network_gives_the_median_of_every_permutation_sample() {
        let mut state = 12345u64;
        for _ in 0..2000 {
            let mut v = [0.0f32; 9];
            for x in &mut v {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                *x = (state >> 40) as f32 % 7.0; // many ties
            }
            let mut sorted = v;
            sorted.sort_by(f32::total_cmp);
            assert_eq!(median9(&mut v), sorted[4]);
        }
    }
}

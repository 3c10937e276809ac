//! The share of a box covered by the background subtraction's foreground, in O(1) per box
//! from a summed-area table: the foreground term of the pedestrian likelihood (an addition to
//! the paper's colour and motion histograms, see [`super::AppearanceParams::foreground_weight`]).

use sillage_core::Image;

use sillage_core::BoundingBox;

/// A summed-area table of a foreground mask: `sums[(y)(w+1) + x]` counts the foreground
/// pixels above and left of `(x, y)`.
#[derive(Debug, Clone, Default)]
pub struct ForegroundShare {
    width: usize,
    height: usize,
    sums: Vec<u32>,
}

impl ForegroundShare {
    /// Rebuilds the table from `mask`, reusing its buffer.
    pub fn fill(&mut self, mask: &Image<bool>) {
        let (width, height) = mask.dimensions();
        self.width = width;
        self.height = height;
        self.sums.clear();
        self.sums.resize((width + 1) * (height + 1), 0);
        for y in 0..height {
            let mut row = 0u32;
            for (x, &on) in mask.row(y).iter().enumerate() {
                row += u32::from(on);
                self.sums[(y + 1) * (width + 1) + x + 1] = self.sums[y * (width + 1) + x + 1] + row;
            }
        }
    }

    /// The share of the pixels of `b` (clipped to the image; pixel `(x, y)` inside when
    /// `left ≤ x < right`) that are foreground; `None` when no pixel is inside.
    pub fn share(&self, b: &BoundingBox) -> Option<f64> {
        let clip = |v: f64, n: usize| v.ceil().clamp(0.0, n as f64) as usize;
        let (x0, x1) = (clip(b.left_px, self.width), clip(b.right_px(), self.width));
        let (y0, y1) = (
            clip(b.top_px, self.height),
            clip(b.bottom_px(), self.height),
        );
        if x0 >= x1 || y0 >= y1 {
            return None;
        }
        let at = |x: usize, y: usize| i64::from(self.sums[y * (self.width + 1) + x]);
        let count = at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0);
        Some(count as f64 / ((x1 - x0) * (y1 - y0)) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn share_matches_a_pixel_count() {
        let (w, h) = (13, 9);
        let pixels: Vec<bool> = (0..w * h).map(|i| (i * 7 + i / 5) % 3 == 0).collect();
        let mask = Image::from_vec(w, h, pixels.clone()).unwrap();
        let mut table = ForegroundShare::default();
        table.fill(&mask);
        let b = BoundingBox {
            left_px: 2.5,
            top_px: -1.0,
            width_px: 6.0,
            height_px: 7.2,
        };
        let (mut on, mut all) = (0, 0);
        for y in 0..h {
            for x in 3..9 {
                if (y as f64) < 6.2 {
                    all += 1;
                    on += usize::from(pixels[y * w + x]);
                }
            }
        }
        let share = table.share(&b).unwrap();
        assert!(
            (share - on as f64 / all as f64).abs() < 1e-12,
            "{share} vs {on}/{all}"
        );
        let outside = BoundingBox { left_px: 20.0, ..b };
        assert_eq!(table.share(&outside), None);
    }
}

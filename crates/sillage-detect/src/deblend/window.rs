//! The square window of the frame a detection is examined in.

use super::model::{Profiles, linear_fit};
use sillage_core::{GrayImage, Point2, Vec2};

/// The pixels of a square window of the frame, particles positive, and their sum of squares.
pub(super) struct Window<'v> {
    pub(super) x0: usize,
    pub(super) y0: usize,
    pub(super) side: usize,
    pub(super) values: &'v [f64],
    pub(super) sum_sq: f64,
}

impl<'v> Window<'v> {
    /// The window of half-width `half` around the pixel nearest `p`, if it lies inside the
    /// image, its values times `sign` (stored in `values`).
    pub(super) fn around(
        image: &GrayImage,
        sign: f64,
        p: Point2,
        half: usize,
        values: &'v mut Vec<f64>,
    ) -> Option<Self> {
        let (width, height) = image.dimensions();
        let (cx, cy) = (p.x.round(), p.y.round());
        if cx < half as f64 || cy < half as f64 {
            return None;
        }
        let (cx, cy) = (cx as usize, cy as usize);
        if cx + half >= width || cy + half >= height {
            return None;
        }
        let side = 2 * half + 1;
        let (x0, y0) = (cx - half, cy - half);
        values.clear();
        for y in y0..y0 + side {
            values.extend(
                image.row(y)[x0..x0 + side]
                    .iter()
                    .map(|&v| sign * f64::from(v)),
            );
        }
        Some(Self {
            x0,
            y0,
            side,
            sum_sq: sum_of_squares(values),
            values,
        })
    }

    pub(super) fn len(&self) -> usize {
        self.values.len()
    }

    /// This window with the particles at `others` subtracted: Gaussians of std `sigma` with
    /// the amplitudes of the linear fit of a background and particles at `p` and `others`
    /// (stored in `cleaned`); `None` when that fit is singular.
    pub(super) fn without_neighbours<'c>(
        &self,
        centres: &[Point2],
        sigma: f64,
        cleaned: &'c mut Vec<f64>,
        profiles: &mut Profiles,
    ) -> Option<Window<'c>> {
        let (_, solution) = linear_fit(self, centres, sigma, profiles)?;
        let side = self.side;
        cleaned.clear();
        cleaned.extend_from_slice(self.values);
        // Component 0 is the examined particle; the neighbours follow, amplitudes after the
        // background and the particle's.
        for c in 1..centres.len() {
            let amplitude = solution[1 + c];
            let (gx, gy) = profiles.gaussian(c);
            for (row, &fy) in cleaned.chunks_exact_mut(side).zip(gy) {
                for (v, &fx) in row.iter_mut().zip(gx) {
                    *v -= amplitude * fy * fx;
                }
            }
        }
        Some(Window {
            x0: self.x0,
            y0: self.y0,
            side,
            sum_sq: sum_of_squares(cleaned),
            values: cleaned,
        })
    }

    /// The unit direction along which the window's signal above its median spreads most
    /// about `p` (the major axis of its second moments); `sorted` is a reused buffer.
    pub(super) fn major_axis(&self, p: Point2, sorted: &mut Vec<f64>) -> Vec2 {
        sorted.clear();
        sorted.extend_from_slice(self.values);
        let mid = sorted.len() / 2;
        let floor = *sorted.select_nth_unstable_by(mid, f64::total_cmp).1;
        let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
        for (k, &v) in self.values.iter().enumerate() {
            let w = (v - floor).max(0.0);
            let dx = (self.x0 + k % self.side) as f64 - p.x;
            let dy = (self.y0 + k / self.side) as f64 - p.y;
            sxx += w * dx * dx;
            syy += w * dy * dy;
            sxy += w * dx * dy;
        }
        let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        Vec2::new(angle.cos(), angle.sin())
    }
}

fn sum_of_squares(values: &[f64]) -> f64 {
    values.iter().map(|v| v * v).sum()
}

//! The square window of the frame a detection is examined in.

use super::model::{Amplitudes, Profiles, linear_fit};
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

    /// This window with the particles at `centres[1..]` subtracted: Gaussians of std `sigma`
    /// with the amplitudes of the linear fit of a background and particles at `centres` (the
    /// examined one first; stored in `cleaned`); `None` when that fit is singular.
    pub(super) fn without_neighbours<'c>(
        &self,
        centres: &[Point2],
        sigma: f64,
        cleaned: &'c mut Vec<f64>,
        profiles: &mut Profiles,
    ) -> Option<Window<'c>> {
        let (_, amplitudes) = linear_fit(self, centres, sigma, profiles)?;
        Some(self.with_neighbours_subtracted(centres, &amplitudes, cleaned, profiles))
    }

    /// This window with the particles at `centres[1..]` subtracted, with the `amplitudes`
    /// (background, then one per centre) of the linear fit that left their Gaussians in
    /// `profiles` (stored in `cleaned`).
    pub(super) fn with_neighbours_subtracted<'c>(
        &self,
        centres: &[Point2],
        amplitudes: &Amplitudes,
        cleaned: &'c mut Vec<f64>,
        profiles: &Profiles,
    ) -> Window<'c> {
        let side = self.side;
        cleaned.clear();
        cleaned.extend_from_slice(self.values);
        // Component 0 is the examined particle; the neighbours follow, amplitudes after the
        // background and the particle's.
        for c in 1..centres.len() {
            let amplitude = amplitudes[1 + c];
            let (gx, gy) = profiles.gaussian(c);
            for (row, &fy) in cleaned.chunks_exact_mut(side).zip(gy) {
                for (v, &fx) in row.iter_mut().zip(gx) {
                    *v -= amplitude * fy * fx;
                }
            }
        }
        Window {
            x0: self.x0,
            y0: self.y0,
            side,
            sum_sq: sum_of_squares(cleaned),
            values: cleaned,
        }
    }

    /// How the window's signal above its median spreads about `p`: the major axis of its
    /// second moments and how much further it spreads along that axis than across it;
    /// `sorted` is a reused buffer.
    pub(super) fn spread(&self, p: Point2, sorted: &mut Vec<f64>) -> Spread {
        sorted.clear();
        sorted.extend_from_slice(self.values);
        let mid = sorted.len() / 2;
        let floor = *sorted.select_nth_unstable_by(mid, f64::total_cmp).1;
        let (mut sw, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0);
        for (k, &v) in self.values.iter().enumerate() {
            let w = (v - floor).max(0.0);
            let dx = (self.x0 + k % self.side) as f64 - p.x;
            let dy = (self.y0 + k / self.side) as f64 - p.y;
            sw += w;
            sxx += w * dx * dx;
            syy += w * dy * dy;
            sxy += w * dx * dy;
        }
        let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        // The difference of the moments' eigenvalues, per unit of signal.
        let excess = (0.25 * (sxx - syy).powi(2) + sxy * sxy).sqrt() * 2.0;
        Spread {
            axis: Vec2::new(angle.cos(), angle.sin()),
            excess_px2: if sw > 0.0 { excess / sw } else { 0.0 },
        }
    }
}

/// The spread of a window's signal ([`Window::spread`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Spread {
    /// The unit direction along which the signal spreads most.
    pub(super) axis: Vec2,
    /// Its second moment along that axis minus across it, px²: h² for two equal particles
    /// at ±h along the axis, 0 for a round one.
    pub(super) excess_px2: f64,
}

fn sum_of_squares(values: &[f64]) -> f64 {
    values.iter().map(|v| v * v).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 13 × 13 window at (24, 34) of a background 0.1 and two particles of σ 2 px and
    /// amplitude 0.5 at ±`h` from (30.3, 40.6) along the direction `angle`.
    fn pair(h: f64, angle: f64) -> Vec<f64> {
        let (cx, cy) = (30.3, 40.6);
        let (ux, uy) = (angle.cos(), angle.sin());
        let g = |x: f64, y: f64, px: f64, py: f64| {
            0.5 * (-((x - px).powi(2) + (y - py).powi(2)) / 8.0).exp()
        };
        let mut values = Vec::new();
        for y in 34..47 {
            for x in 24..37 {
                let (x, y) = (x as f64, y as f64);
                values.push(
                    0.1 + g(x, y, cx + h * ux, cy + h * uy) + g(x, y, cx - h * ux, cy - h * uy),
                );
            }
        }
        values
    }

    #[test]
    fn the_spread_measures_the_half_separation_of_a_pair_and_little_for_one_particle() {
        let p = Point2::new(30.3, 40.6);
        let mut sorted = Vec::new();
        let spread_of = |values: &[f64], sorted: &mut Vec<f64>| {
            let window = Window {
                x0: 24,
                y0: 34,
                side: 13,
                values,
                sum_sq: sum_of_squares(values),
            };
            window.spread(p, sorted)
        };
        let single = spread_of(&pair(0.0, 0.0), &mut sorted);
        assert!(single.excess_px2.sqrt() < 0.15, "{single:?}");
        for h in [1.0, 1.6, 2.0] {
            for angle in [0.0, 0.7, 2.0] {
                let s = spread_of(&pair(h, angle), &mut sorted);
                let estimate = s.excess_px2.sqrt();
                assert!((estimate / h - 1.0).abs() < 0.15, "h {h}: {estimate}");
                // The axis is a direction: ±.
                let along = (s.axis.x * angle.cos() + s.axis.y * angle.sin()).abs();
                assert!(along > 0.999, "h {h}, angle {angle}: {s:?}");
            }
        }
    }
}

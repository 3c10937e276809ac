//! Sub-pixel refinement of an integer peak by separable 3-point fits along x and y
//! (TracTrac paper Eqs. (3)–(4)).
//!
//! Eqs. (3)–(4) as printed have the sign of the offset flipped; the code (and this module)
//! use `d = (L₋₁ − L₊₁) / (2 (L₋₁ − 2L₀ + L₊₁))`, the vertex of the parabola through the three
//! points, with `L = F'` (quadratic fit) or `L = ln F'` (Gaussian fit, exact for a sampled
//! Gaussian spot).

use serde::{Deserialize, Serialize};
use sillage_core::{GrayImage, Point2};

/// The function fitted through the three samples along each axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SubpixelFit {
    /// Parabola through `ln` of the values (TracTrac's default `peak_subpix = 1`).
    #[default]
    Gaussian,
    /// Parabola through the values (`peak_subpix = 0`).
    Quadratic,
}

/// Vertex offset of the parabola through `(-1, left)`, `(0, centre)`, `(1, right)`, in
/// `[-0.5, 0.5]`. Returns 0 when the centre is not above its neighbours' mean (flat or not a
/// maximum along this axis). Offsets are **clamped** to ±0.5 rather than rejected as TracTrac
/// does: for a window maximum |d| ≤ 0.5 always, with equality only on a two-pixel plateau,
/// whose true centre is indeed half-way; rejecting it would lose that object.
pub fn parabola_offset(left: f64, centre: f64, right: f64) -> f64 {
    let curvature = left - 2.0 * centre + right;
    if curvature < 0.0 {
        ((left - right) / (2.0 * curvature)).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

/// Relative offset added before taking logarithms, as a fraction of the peak height above the
/// shift: keeps `ln` finite and the log contrast bounded (≈ 13.8) when a sample sits at the
/// shift itself.
const LOG_EPSILON: f64 = 1e-6;

/// Sub-pixel position of the peak at integer `(x, y)`, from the 3×3 neighbourhood; `None` when
/// that neighbourhood is not inside the image.
///
/// Gaussian fit: `ln` needs positive values. When the 3×3 neighbourhood has values `≤ 0`
/// (typical of a DoG ring) all nine are shifted by its **local** minimum `m` so that they are
/// `≥ 0`, then a relative epsilon is added. TracTrac shifts by the **global** minimum of the
/// filtered image, which makes each object's position depend on pixels far away (the deepest
/// DoG trough of the frame) and flattens the log-parabola toward the quadratic one. A positive
/// local minimum is not subtracted: a Gaussian spot on zero background is then fitted exactly.
pub fn refine_peak(image: &GrayImage, x: usize, y: usize, fit: SubpixelFit) -> Option<Point2> {
    let (width, height) = image.dimensions();
    if x == 0 || y == 0 || x + 1 >= width || y + 1 >= height {
        return None;
    }
    let at = |dx: isize, dy: isize| {
        f64::from(image.get((x as isize + dx) as usize, (y as isize + dy) as usize))
    };
    let (left, centre, right) = (at(-1, 0), at(0, 0), at(1, 0));
    let (up, down) = (at(0, -1), at(0, 1));
    let (dx, dy) = match fit {
        SubpixelFit::Quadratic => (
            parabola_offset(left, centre, right),
            parabola_offset(up, centre, down),
        ),
        SubpixelFit::Gaussian => {
            let mut local_min = f64::INFINITY;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    local_min = local_min.min(at(dx, dy));
                }
            }
            let shift = local_min.min(0.0);
            let height_above = centre - shift;
            if height_above.is_nan() || height_above <= 0.0 {
                return Some(Point2::new(x as f64, y as f64));
            }
            let epsilon = LOG_EPSILON * height_above;
            let ln = |v: f64| (v - shift + epsilon).ln();
            let ln_centre = ln(centre);
            (
                parabola_offset(ln(left), ln_centre, ln(right)),
                parabola_offset(ln(up), ln_centre, ln(down)),
            )
        }
    };
    Some(Point2::new(x as f64 + dx, y as f64 + dy))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parabola_vertex_is_exact_and_clamped() {
        // y = -(x - 0.3)^2 sampled at -1, 0, 1
        let f = |x: f64| -(x - 0.3) * (x - 0.3);
        assert!((parabola_offset(f(-1.0), f(0.0), f(1.0)) - 0.3).abs() < 1e-12);
        assert_eq!(parabola_offset(1.0, 1.0, 1.0), 0.0);
        assert_eq!(parabola_offset(1.0, 1.0, 0.0), -0.5);
        assert_eq!(parabola_offset(0.0, 1.0, 1.5), 0.5);
    }
}

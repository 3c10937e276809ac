//! Flat structuring elements for grey-level morphology, stored as a Minkowski sum of
//! three-point line segments so that [`crate::Morphology`] pays a few comparisons per pixel
//! per factor, whatever the size of the element.
//!
//! A disk is Adams' radial decomposition into periodic lines (R. Adams, "Radial decomposition
//! of discs and spheres", CVGIP: Graphical Models and Image Processing 55(5), 1993), exactly as
//! MATLAB's `strel('disk', r, 8)` builds it, since that is the disk BeadTracking (the MMPF+
//! paper's code) uses: eight periodic lines plus the horizontal and vertical lines that bring
//! the extent to `r − 1`. Each line of `2p + 1` points is then split into three-point segments
//! `{−s·v, 0, +s·v}` with steps `s = 1, 3, 9, …` (a balanced-ternary, logarithmic
//! decomposition), so a 19-point line costs three factors, not eighteen comparisons.

use sillage_core::{Error, Result};

/// The step `v = (dx, dy)` of a three-point segment `{−v, 0, +v}`, px.
pub(crate) type Step = (isize, isize);

/// Largest disk radius and square half-side accepted, px.
pub const MAX_ELEMENT_RADIUS_PX: usize = 500;

/// A flat structuring element, symmetric about its centre: the Minkowski sum of factors, each
/// factor the union of the three-point segments of its steps.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StructuringElement {
    factors: Vec<Vec<Step>>,
}

/// The cross `{(0,0), (±1,0), (0,±1)}`: the union of the two unit segments.
const CROSS: [Step; 2] = [(1, 0), (0, 1)];

impl StructuringElement {
    /// The disk of radius `radius_px` in `1..=MAX_ELEMENT_RADIUS_PX` as MATLAB's
    /// `strel('disk', r, 8)` (BeadTracking's disks): exact Euclidean disks for `r ≤ 2`, Adams'
    /// eight-line approximation of extent `±(r − 1)` above (673 pixels at `r = 15`, where the
    /// Euclidean disk has 709).
    pub fn disk(radius_px: usize) -> Result<Self> {
        check_radius("radius_px", radius_px, 1)?;
        let factors = match radius_px {
            1 => vec![CROSS.to_vec()],
            // x² + y² ≤ 4 is the diamond |x| + |y| ≤ 2, the cross summed with itself.
            2 => vec![CROSS.to_vec(), CROSS.to_vec()],
            r => adams_disk(r),
        };
        Ok(Self { factors })
    }

    /// The square of odd side `side_px` (`1..=2·MAX_ELEMENT_RADIUS_PX + 1`): a horizontal line
    /// summed with a vertical one.
    pub fn square(side_px: usize) -> Result<Self> {
        if side_px.is_multiple_of(2) {
            return Err(Error::parameter(
                "side_px",
                side_px,
                "must be odd (the square is centred on a pixel)",
            ));
        }
        let half = side_px / 2;
        check_radius("side_px", half, 0)?;
        let mut factors = line((1, 0), half);
        factors.extend(line((0, 1), half));
        Ok(Self { factors })
    }

    /// Half-widths `(x, y)` of the element's bounding box, px.
    pub fn extent(&self) -> (usize, usize) {
        self.factors.iter().fold((0, 0), |(ex, ey), factor| {
            let fx = factor.iter().map(|s| s.0.unsigned_abs()).max().unwrap_or(0);
            let fy = factor.iter().map(|s| s.1.unsigned_abs()).max().unwrap_or(0);
            (ex + fx, ey + fy)
        })
    }

    /// Every offset `(dx, dy)` of the element, sorted by row then column: its neighbourhood,
    /// for painting it and for reference implementations.
    pub fn offsets(&self) -> Vec<(isize, isize)> {
        let mut set = vec![(0isize, 0isize)];
        for factor in &self.factors {
            let mut next = Vec::with_capacity(set.len() * (1 + 2 * factor.len()));
            for &(x, y) in &set {
                next.push((x, y));
                for &(dx, dy) in factor {
                    next.push((x + dx, y + dy));
                    next.push((x - dx, y - dy));
                }
            }
            next.sort_unstable_by_key(|&(x, y)| (y, x));
            next.dedup();
            set = next;
        }
        set
    }

    /// The factors, applied one after the other.
    pub(crate) fn factors(&self) -> &[Vec<Step>] {
        &self.factors
    }
}

fn check_radius(key: &str, value: usize, min: usize) -> Result<()> {
    if (min..=MAX_ELEMENT_RADIUS_PX).contains(&value) {
        Ok(())
    } else {
        Err(Error::parameter(
            key,
            value,
            format!("the radius must be in {min}..={MAX_ELEMENT_RADIUS_PX} px"),
        ))
    }
}

/// A line of `2·half + 1` points of step `v` as three-point factors of steps `s·v`: after
/// steps summing to `c` the points `−c..=c` are covered, and a next step `s ≤ 2c + 1` keeps
/// them contiguous; `s = min(2c + 1, half − c)` reaches `half` in `O(log₃ half)` factors.
fn line(v: Step, half: usize) -> Vec<Vec<Step>> {
    let mut factors = Vec::new();
    let mut covered = 0;
    while covered < half {
        let s = (2 * covered + 1).min(half - covered);
        factors.push(vec![(v.0 * s as isize, v.1 * s as isize)]);
        covered += s;
    }
    factors
}

/// MATLAB's `strel('disk', r, 8)` for `r ≥ 3` (Adams 1993): periodic lines along eight
/// directions, each with `floor(k / |v|)` repetitions where `k = 2r / (cot θ + 1/sin θ)`,
/// `θ = π/16`, then horizontal and vertical lines of `2(r − rd) − 1` points when the lines'
/// extent `rd` falls short of `r`. Collinear lines are merged before splitting.
fn adams_disk(r: usize) -> Vec<Vec<Step>> {
    const DIRECTIONS: [Step; 8] = [
        (1, 0),
        (2, 1),
        (1, 1),
        (1, 2),
        (0, 1),
        (-1, 2),
        (-1, 1),
        (-2, 1),
    ];
    let theta = std::f64::consts::PI / 16.0;
    let k = 2.0 * r as f64 / (1.0 / theta.tan() + 1.0 / theta.sin());
    let mut repetitions: Vec<usize> = DIRECTIONS
        .iter()
        .map(|&(x, y)| (k / ((x * x + y * y) as f64).sqrt()).floor() as usize)
        .collect();
    let reach: usize = DIRECTIONS
        .iter()
        .zip(&repetitions)
        .map(|(v, &p)| p * v.0.unsigned_abs())
        .sum();
    if reach < r {
        // Lines of 2(r − rd) − 1 points: half-length r − rd − 1, added to the axis lines.
        let extra = r - reach - 1;
        repetitions[0] += extra;
        repetitions[4] += extra;
    }
    DIRECTIONS
        .iter()
        .zip(repetitions)
        .flat_map(|(&v, p)| line(v, p))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_cover_their_points_once_each() {
        for half in 0..40 {
            let se = StructuringElement {
                factors: line((1, 0), half),
            };
            let xs: Vec<isize> = se.offsets().iter().map(|o| o.0).collect();
            let expected: Vec<isize> = (-(half as isize)..=half as isize).collect();
            assert_eq!(xs, expected, "half {half}");
            assert!(se.factors.len() <= 1 + (half as f64 + 1.0).log(3.0).ceil() as usize);
        }
    }

    #[test]
    fn bad_sizes_name_the_key() {
        assert!(
            StructuringElement::disk(0)
                .unwrap_err()
                .to_string()
                .contains("radius_px")
        );
        let err = StructuringElement::square(4).unwrap_err().to_string();
        assert!(err.contains("side_px") && err.contains("odd"), "{err}");
        assert_eq!(
            StructuringElement::square(1).unwrap().offsets(),
            vec![(0, 0)]
        );
    }
}

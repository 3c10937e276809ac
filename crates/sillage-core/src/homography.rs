//! The plane-to-plane projective map between the image (px) and the ground plane (m).
//!
//! The pedestrian IMM particle filter of Madrigal & Hayet (§4, state of Eq. (5)) keeps the
//! real size of a pedestrian's box fixed to that of an adult, in world units, and projects it
//! into the image "by supposing that the camera projection matrix is known": the box around a
//! foot point is as many pixels tall as the adult height times the local image scale. For
//! points on the ground that projection is a homography, which [`Homography::fit`] learns from
//! four or more image ↔ ground point pairs (the normalised DLT of Hartley & Zisserman,
//! *Multiple View Geometry*, 2nd ed., Alg. 4.2) and [`Homography::px_per_metre_across`] turns
//! into that scale.
//!
//! ```
//! use sillage_core::{Homography, Point2};
//! // 40 px per metre, ground origin at pixel (100, 50).
//! let h = Homography::from_image_from_ground([[40.0, 0.0, 100.0], [0.0, 40.0, 50.0], [0.0, 0.0, 1.0]])
//!     .unwrap();
//! let foot = h.image_from_ground(Point2::new(1.0, 2.0)).unwrap();
//! assert!(foot.distance(Point2::new(140.0, 130.0)) < 1e-9);
//! assert!((h.px_per_metre_across(foot).unwrap() - 40.0).abs() < 1e-9);
//! ```

use serde::{Deserialize, Serialize};

use crate::{Error, Point2, Result};

/// A 3×3 matrix, rows first.
pub type Matrix3 = [[f64; 3]; 3];

/// Relative determinant below which a matrix counts as singular: |det H| ≤ 1e-12·‖H‖³
/// (‖·‖ the Frobenius norm, so the test does not depend on the matrix's arbitrary scale).
const SINGULAR_RELATIVE_DET: f64 = 1e-12;

/// A non-singular homography between image pixels and ground-plane metres, kept in both
/// directions. Homogeneous: `(u, v, 1)ᵀ ∝ H·(x, y, 1)ᵀ` with `H` the image-from-ground matrix.
///
/// Serialised as one table with the direction in the key, `image_from_ground = [[..], [..],
/// [..]]` (written) or `ground_from_image = [[..], [..], [..]]` (also read).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "HomographySpec", into = "HomographySpec")]
pub struct Homography {
    image_from_ground: Matrix3,
    ground_from_image: Matrix3,
}

/// The file layout of a [`Homography`]: exactly one of the two directions.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct HomographySpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    image_from_ground: Option<Matrix3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    ground_from_image: Option<Matrix3>,
}

impl TryFrom<HomographySpec> for Homography {
    type Error = Error;
    fn try_from(spec: HomographySpec) -> Result<Self> {
        match (spec.image_from_ground, spec.ground_from_image) {
            (Some(m), None) => Homography::from_image_from_ground(m),
            (None, Some(m)) => Homography::from_ground_from_image(m),
            _ => Err(Error::parameter(
                "image_from_ground",
                "(none or both directions)",
                "give exactly one of `image_from_ground = [[..],[..],[..]]` (ground metres → \
                 image px) or `ground_from_image = [[..],[..],[..]]`",
            )),
        }
    }
}

impl From<Homography> for HomographySpec {
    fn from(h: Homography) -> Self {
        Self {
            image_from_ground: Some(h.image_from_ground),
            ground_from_image: None,
        }
    }
}

impl Homography {
    /// The homography whose image-from-ground matrix is `m` (ground metres → image px).
    /// A non-finite entry or a singular matrix (|det| ≤ 1e-12·‖m‖³) is an error.
    pub fn from_image_from_ground(m: Matrix3) -> Result<Self> {
        let inverse = checked_inverse("image_from_ground", &m)?;
        Ok(Self {
            image_from_ground: normalised(m),
            ground_from_image: normalised(inverse),
        })
    }

    /// The homography whose ground-from-image matrix is `m` (image px → ground metres); the
    /// same checks as [`Homography::from_image_from_ground`].
    pub fn from_ground_from_image(m: Matrix3) -> Result<Self> {
        let inverse = checked_inverse("ground_from_image", &m)?;
        Ok(Self {
            image_from_ground: normalised(inverse),
            ground_from_image: normalised(m),
        })
    }

    /// The image-from-ground matrix (scaled to unit Frobenius norm).
    pub fn image_from_ground_matrix(&self) -> Matrix3 {
        self.image_from_ground
    }

    /// The ground-from-image matrix (scaled to unit Frobenius norm).
    pub fn ground_from_image_matrix(&self) -> Matrix3 {
        self.ground_from_image
    }

    /// The image point (px) of a ground point (m); `None` on the camera's horizon line,
    /// where the point maps to infinity.
    pub fn image_from_ground(&self, ground_m: Point2) -> Option<Point2> {
        apply(&self.image_from_ground, ground_m)
    }

    /// The ground point (m) under an image point (px); `None` on the image's horizon line.
    pub fn ground_from_image(&self, image_px: Point2) -> Option<Point2> {
        apply(&self.ground_from_image, image_px)
    }

    /// The image-horizontal scale, px per metre, at the ground point seen at `image_px`:
    /// `1/‖J⁻¹·(1, 0)ᵀ‖` with `J` the Jacobian of image-from-ground there. A pedestrian
    /// standing at foot point `image_px` is `height_m × scale` px tall and `width_m × scale`
    /// px wide (§4: the adult's real size projected at its distance). `None` where the map
    /// is not defined (horizon line) or not finite.
    pub fn px_per_metre_across(&self, image_px: Point2) -> Option<f64> {
        let g = self.ground_from_image(image_px)?;
        let h = &self.image_from_ground;
        let w = h[2][0] * g.x + h[2][1] * g.y + h[2][2];
        let u = h[0][0] * g.x + h[0][1] * g.y + h[0][2];
        let v = h[1][0] * g.x + h[1][1] * g.y + h[1][2];
        // ∂(u/w)/∂x = (h00·w − u·h20)/w², and so on.
        let w2 = w * w;
        let j = [
            [
                (h[0][0] * w - u * h[2][0]) / w2,
                (h[0][1] * w - u * h[2][1]) / w2,
            ],
            [
                (h[1][0] * w - v * h[2][0]) / w2,
                (h[1][1] * w - v * h[2][1]) / w2,
            ],
        ];
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        // J⁻¹·(1, 0)ᵀ = (j11, −j10)/det: the ground step (m) of one image px along x.
        let metres_per_px = j[1][1].hypot(j[1][0]) / det.abs();
        let scale = 1.0 / metres_per_px;
        (scale.is_finite() && scale > 0.0).then_some(scale)
    }

    /// The root mean square distance, px, between each image point and the projection of its
    /// ground point (pairs `(image_px, ground_m)`); infinite when a ground point projects to
    /// infinity, `0` for no pairs.
    pub fn rms_reprojection_px(&self, pairs: &[(Point2, Point2)]) -> f64 {
        if pairs.is_empty() {
            return 0.0;
        }
        let sum: f64 = pairs
            .iter()
            .map(|&(image, ground)| match self.image_from_ground(ground) {
                Some(p) => (p - image).norm_squared(),
                None => f64::INFINITY,
            })
            .sum();
        (sum / pairs.len() as f64).sqrt()
    }

    /// Least-squares homography from `(image_px, ground_m)` pairs by the normalised DLT
    /// (Hartley & Zisserman Alg. 4.2): each point set is moved to its centroid and scaled to a
    /// mean distance of √2, the 2n×9 DLT system is solved for the unit vector minimising its
    /// algebraic residual (the eigenvector of AᵀA with the smallest eigenvalue), then
    /// denormalised. Fewer than 4 pairs, non-finite coordinates, points all on one line (in
    /// either plane) or a singular result are errors saying what to do.
    pub fn fit(pairs: &[(Point2, Point2)]) -> Result<Self> {
        if pairs.len() < 4 {
            return Err(Error::input(format!(
                "{} point pair(s) given; a homography needs at least 4 image ↔ ground pairs, \
                 no three of them on one line: add pairs",
                pairs.len()
            )));
        }
        if let Some(k) = pairs
            .iter()
            .position(|(a, b)| !(a.is_finite() && b.is_finite()))
        {
            return Err(Error::input(format!(
                "point pair {} is not finite; fix or remove it",
                k + 1
            )));
        }
        let image: Vec<Point2> = pairs.iter().map(|p| p.0).collect();
        let ground: Vec<Point2> = pairs.iter().map(|p| p.1).collect();
        let t_image = similarity_normaliser("image", &image)?;
        let t_ground = similarity_normaliser("ground", &ground)?;
        // AᵀA accumulated row by row (no 2n×9 matrix). Rows of the DLT (H&Z Eq. 4.3) for
        // ĝ = (x, y, 1) ↦ î = (u, v, 1): [0ᵀ, −ĝᵀ, v·ĝᵀ] and [ĝᵀ, 0ᵀ, −u·ĝᵀ].
        let mut ata = [[0.0f64; 9]; 9];
        for (&i, &g) in image.iter().zip(&ground) {
            let i = apply_affine(&t_image, i);
            let g = apply_affine(&t_ground, g);
            let gh = [g.x, g.y, 1.0];
            let mut r1 = [0.0; 9];
            let mut r2 = [0.0; 9];
            for k in 0..3 {
                r1[3 + k] = -gh[k];
                r1[6 + k] = i.y * gh[k];
                r2[k] = gh[k];
                r2[6 + k] = -i.x * gh[k];
            }
            for (a, row) in ata.iter_mut().enumerate() {
                for (b, entry) in row.iter_mut().enumerate() {
                    *entry += r1[a] * r1[b] + r2[a] * r2[b];
                }
            }
        }
        let (values, vectors) = symmetric_eigen(ata);
        let smallest = (0..9)
            .min_by(|&a, &b| values[a].total_cmp(&values[b]))
            .unwrap_or(0);
        let h = &vectors[smallest];
        let normalised_h = [[h[0], h[1], h[2]], [h[3], h[4], h[5]], [h[6], h[7], h[8]]];
        // H = T_image⁻¹ · Ĥ · T_ground.
        let m = mul(
            &mul(&inverse_similarity(&t_image), &normalised_h),
            &t_ground,
        );
        Homography::from_image_from_ground(m).map_err(|_| {
            Error::input(
                "the point pairs give a singular homography (degenerate configuration); use at \
                 least 4 pairs spread over the ground plane, no three on one line",
            )
        })
    }
}

/// The real size of a pedestrian's box, m: the paper fixes it "to the average size of an
/// adult (in world coordinates)" and projects it at the target's distance (§4).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PedestrianSize {
    /// Box height, m.
    pub height_m: f64,
    /// Box width, m.
    pub width_m: f64,
}

impl PedestrianSize {
    /// Checks both sizes are finite and > 0; the error names the key.
    pub fn validate(&self) -> Result<()> {
        for (key, value) in [("height_m", self.height_m), ("width_m", self.width_m)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::parameter(
                    key,
                    value,
                    "must be a finite size > 0 m (`sillage fit homography` measures it from \
                     ground truth boxes)",
                ));
            }
        }
        Ok(())
    }

    /// The box (width, height) in px of a pedestrian whose foot point is `foot_px`: each size
    /// times [`Homography::px_per_metre_across`] there; `None` where the scale is undefined.
    pub fn box_size_px(&self, homography: &Homography, foot_px: Point2) -> Option<(f64, f64)> {
        let scale = homography.px_per_metre_across(foot_px)?;
        Some((self.width_m * scale, self.height_m * scale))
    }
}

/// `[s, 0, tx; 0, s, ty; 0, 0, 1]` taking `points` to centroid 0 and mean distance √2
/// (H&Z §4.4.4); points all at one place or on one line are an error naming `plane`.
fn similarity_normaliser(plane: &str, points: &[Point2]) -> Result<Matrix3> {
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(sx, sy), p| (sx + p.x, sy + p.y));
    let centre = Point2::new(sx / n, sy / n);
    let mean_distance = points.iter().map(|p| p.distance(centre)).sum::<f64>() / n;
    // Spread along the weakest axis, from the 2×2 scatter's smallest eigenvalue.
    let (mut cxx, mut cxy, mut cyy) = (0.0, 0.0, 0.0);
    for p in points {
        let d = *p - centre;
        cxx += d.x * d.x;
        cxy += d.x * d.y;
        cyy += d.y * d.y;
    }
    let half_trace = 0.5 * (cxx + cyy);
    let root = (0.25 * (cxx - cyy).powi(2) + cxy * cxy).sqrt();
    let (largest, smallest) = (half_trace + root, half_trace - root);
    if mean_distance.is_nan() || mean_distance <= 0.0 || smallest <= 1e-12 * largest {
        return Err(Error::input(format!(
            "the {plane} points all lie on one line (or at one place); a homography needs at \
             least 4 pairs spread over the plane, no three on one line: add pairs off that line"
        )));
    }
    let s = std::f64::consts::SQRT_2 / mean_distance;
    Ok([
        [s, 0.0, -s * centre.x],
        [0.0, s, -s * centre.y],
        [0.0, 0.0, 1.0],
    ])
}

fn inverse_similarity(t: &Matrix3) -> Matrix3 {
    let s = t[0][0];
    [
        [1.0 / s, 0.0, -t[0][2] / s],
        [0.0, 1.0 / s, -t[1][2] / s],
        [0.0, 0.0, 1.0],
    ]
}

fn apply_affine(t: &Matrix3, p: Point2) -> Point2 {
    Point2::new(
        t[0][0] * p.x + t[0][1] * p.y + t[0][2],
        t[1][0] * p.x + t[1][1] * p.y + t[1][2],
    )
}

fn apply(m: &Matrix3, p: Point2) -> Option<Point2> {
    let w = m[2][0] * p.x + m[2][1] * p.y + m[2][2];
    let out = Point2::new(
        (m[0][0] * p.x + m[0][1] * p.y + m[0][2]) / w,
        (m[1][0] * p.x + m[1][1] * p.y + m[1][2]) / w,
    );
    out.is_finite().then_some(out)
}

fn mul(a: &Matrix3, b: &Matrix3) -> Matrix3 {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..3).map(|k| a[r][k] * b[k][c]).sum()))
}

fn frobenius(m: &Matrix3) -> f64 {
    m.iter().flatten().map(|v| v * v).sum::<f64>().sqrt()
}

/// `m` scaled to unit Frobenius norm, with a non-negative bottom-right entry (the same map).
fn normalised(m: Matrix3) -> Matrix3 {
    let norm = frobenius(&m);
    let sign = if m[2][2] < 0.0 { -1.0 } else { 1.0 };
    m.map(|row| row.map(|v| sign * v / norm))
}

/// The inverse of `m` by its adjugate, after the finiteness and relative-determinant tests;
/// errors name `key` and say how to fix the matrix.
fn checked_inverse(key: &str, m: &Matrix3) -> Result<Matrix3> {
    if m.iter().flatten().any(|v| !v.is_finite()) {
        return Err(Error::parameter(
            key,
            format!("{m:?}"),
            "every entry must be a finite number; rewrite the matrix, or fit it from point \
             pairs with `sillage fit homography`",
        ));
    }
    let cof =
        |r0: usize, r1: usize, c0: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    // Adjugate (transposed cofactors).
    let adj = [
        [cof(1, 2, 1, 2), -cof(0, 2, 1, 2), cof(0, 1, 1, 2)],
        [-cof(1, 2, 0, 2), cof(0, 2, 0, 2), -cof(0, 1, 0, 2)],
        [cof(1, 2, 0, 1), -cof(0, 2, 0, 1), cof(0, 1, 0, 1)],
    ];
    let det = m[0][0] * adj[0][0] + m[0][1] * adj[1][0] + m[0][2] * adj[2][0];
    let norm = frobenius(m);
    // Entries are finite, so det and norm are numbers (or ±∞ on overflow, caught below).
    let singular = det.abs() <= SINGULAR_RELATIVE_DET * norm.powi(3);
    if singular || !det.is_finite() || det == 0.0 {
        return Err(Error::parameter(
            key,
            format!("{m:?}"),
            format!(
                "the matrix is singular (|det| = {:.3e} ≤ 1e-12·‖H‖³): it flattens the plane \
                 onto a line; check for a row typed twice or a zero row, or fit it from at \
                 least 4 point pairs with `sillage fit homography`",
                det.abs()
            ),
        ));
    }
    Ok(adj.map(|row| row.map(|v| v / det)))
}

/// Eigen-decomposition of a symmetric 9×9 matrix by cyclic Jacobi rotations (Golub & Van
/// Loan §8.5): eigenvalues and the matching unit eigenvectors (`vectors[k]` for
/// `values[k]`).
fn symmetric_eigen(mut a: [[f64; 9]; 9]) -> ([f64; 9], [[f64; 9]; 9]) {
    const N: usize = 9;
    // v holds the eigenvectors as columns.
    let mut v = [[0.0f64; N]; N];
    for (k, row) in v.iter_mut().enumerate() {
        row[k] = 1.0;
    }
    let total: f64 = a.iter().flatten().map(|x| x * x).sum::<f64>();
    for _sweep in 0..100 {
        let off: f64 = (0..N)
            .flat_map(|p| (0..N).filter(move |&q| q != p).map(move |q| (p, q)))
            .map(|(p, q)| a[p][q] * a[p][q])
            .sum();
        if off <= 1e-30 * total || off == 0.0 {
            break;
        }
        for p in 0..N - 1 {
            for q in p + 1..N {
                let apq = a[p][q];
                if apq == 0.0 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                let (row_p, row_q) = (a[p], a[q]);
                for k in 0..N {
                    a[p][k] = c * row_p[k] - s * row_q[k];
                    a[q][k] = s * row_p[k] + c * row_q[k];
                }
                for row in v.iter_mut() {
                    let (vkp, vkq) = (row[p], row[q]);
                    row[p] = c * vkp - s * vkq;
                    row[q] = s * vkp + c * vkq;
                }
            }
        }
    }
    let values = std::array::from_fn(|k| a[k][k]);
    let vectors = std::array::from_fn(|k| std::array::from_fn(|r| v[r][k]));
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng_stream;
    use rand::RngExt;

    /// A camera looking down a ground plane at an angle: strong perspective.
    const TRUE_H: Matrix3 = [[30.0, -12.0, 380.0], [2.0, 8.0, 150.0], [0.004, -0.05, 1.0]];

    fn ground_grid() -> Vec<Point2> {
        let mut points = Vec::new();
        for i in 0..6 {
            for j in 0..5 {
                points.push(Point2::new(-8.0 + 3.0 * i as f64, -10.0 + 2.5 * j as f64));
            }
        }
        points
    }

    fn pairs(h: &Homography, noise_px: f64, seed: u64) -> Vec<(Point2, Point2)> {
        let mut rng = rng_stream(seed, 0);
        ground_grid()
            .into_iter()
            .map(|g| {
                let i = h.image_from_ground(g).unwrap();
                let n = Point2::new(
                    noise_px * (rng.random::<f64>() - 0.5),
                    noise_px * (rng.random::<f64>() - 0.5),
                );
                (Point2::new(i.x + n.x, i.y + n.y), g)
            })
            .collect()
    }

    fn max_image_error(a: &Homography, b: &Homography) -> f64 {
        ground_grid()
            .into_iter()
            .map(|g| {
                a.image_from_ground(g)
                    .unwrap()
                    .distance(b.image_from_ground(g).unwrap())
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn directions_invert_each_other() {
        let h = Homography::from_image_from_ground(TRUE_H).unwrap();
        let g = Point2::new(1.5, -2.0);
        let back = h
            .ground_from_image(h.image_from_ground(g).unwrap())
            .unwrap();
        assert!(back.distance(g) < 1e-12, "{back:?}");
        let same = Homography::from_ground_from_image(h.ground_from_image_matrix()).unwrap();
        assert!(max_image_error(&h, &same) < 1e-9);
    }

    #[test]
    fn fit_recovers_an_exact_projective_map() {
        let truth = Homography::from_image_from_ground(TRUE_H).unwrap();
        let fitted = Homography::fit(&pairs(&truth, 0.0, 1)).unwrap();
        assert!(max_image_error(&truth, &fitted) < 1e-8);
        assert!(fitted.rms_reprojection_px(&pairs(&truth, 0.0, 1)) < 1e-8);
        // Four pairs are enough.
        let four = pairs(&truth, 0.0, 1);
        let four = [four[0], four[4], four[25], four[29]];
        let fitted = Homography::fit(&four).unwrap();
        assert!(max_image_error(&truth, &fitted) < 1e-7);
    }

    #[test]
    fn fit_with_noise_stays_close() {
        let truth = Homography::from_image_from_ground(TRUE_H).unwrap();
        // Uniform noise of ±0.5 px (σ ≈ 0.29 px).
        let noisy = pairs(&truth, 1.0, 7);
        let fitted = Homography::fit(&noisy).unwrap();
        let rms = fitted.rms_reprojection_px(&noisy);
        assert!(rms > 0.05 && rms < 0.5, "rms {rms}");
        assert!(max_image_error(&truth, &fitted) < 1.0);
    }

    #[test]
    fn scale_across_matches_a_numerical_derivative() {
        let h = Homography::from_image_from_ground(TRUE_H).unwrap();
        let foot = Point2::new(400.0, 300.0);
        let scale = h.px_per_metre_across(foot).unwrap();
        // Move 1e-3 px along image x, measure the ground step.
        let g0 = h.ground_from_image(foot).unwrap();
        let g1 = h
            .ground_from_image(Point2::new(foot.x + 1e-3, foot.y))
            .unwrap();
        let numeric = 1e-3 / g0.distance(g1);
        assert!(
            (scale - numeric).abs() < 1e-5 * numeric,
            "{scale} {numeric}"
        );
        // Pure scaling: the scale is the factor.
        let s = Homography::from_image_from_ground([
            [25.0, 0.0, 3.0],
            [0.0, 25.0, 4.0],
            [0.0, 0.0, 1.0],
        ])
        .unwrap();
        assert!((s.px_per_metre_across(Point2::new(10.0, 10.0)).unwrap() - 25.0).abs() < 1e-9);
    }

    #[test]
    fn pedestrian_boxes_scale_with_the_map() {
        let h = Homography::from_image_from_ground([
            [25.0, 0.0, 3.0],
            [0.0, 25.0, 4.0],
            [0.0, 0.0, 1.0],
        ])
        .unwrap();
        let adult = PedestrianSize {
            height_m: 1.8,
            width_m: 0.5,
        };
        adult.validate().unwrap();
        let (w, hgt) = adult.box_size_px(&h, Point2::new(50.0, 60.0)).unwrap();
        assert!(
            (w - 12.5).abs() < 1e-9 && (hgt - 45.0).abs() < 1e-9,
            "{w} {hgt}"
        );
        let err = PedestrianSize {
            height_m: 0.0,
            width_m: 0.5,
        }
        .validate()
        .unwrap_err();
        assert!(err.to_string().contains("`height_m`"), "{err}");
    }

    #[test]
    fn singular_and_non_finite_matrices_are_errors_with_a_fix() {
        let err =
            Homography::from_image_from_ground([[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]])
                .unwrap_err()
                .to_string();
        assert!(
            err.contains("`image_from_ground`") && err.contains("singular"),
            "{err}"
        );
        assert!(err.contains("sillage fit homography"), "{err}");
        let err = Homography::from_ground_from_image([[f64::NAN; 3]; 3])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("`ground_from_image`") && err.contains("finite"),
            "{err}"
        );
        // Scale does not matter: a tiny but regular matrix is fine.
        let tiny = TRUE_H.map(|r| r.map(|v| v * 1e-30));
        assert!(Homography::from_image_from_ground(tiny).is_ok());
    }

    #[test]
    fn too_few_or_collinear_pairs_are_errors() {
        let truth = Homography::from_image_from_ground(TRUE_H).unwrap();
        let all = pairs(&truth, 0.0, 1);
        let err = Homography::fit(&all[..3]).unwrap_err().to_string();
        assert!(
            err.contains("3 point pair(s)") && err.contains("at least 4"),
            "{err}"
        );
        // Ground points on the line x = −8 (the first column of the grid).
        let collinear: Vec<_> = all[..5].to_vec();
        let err = Homography::fit(&collinear).unwrap_err().to_string();
        assert!(err.contains("one line"), "{err}");
        let mut bad = all.clone();
        bad[2].0.x = f64::INFINITY;
        assert!(
            Homography::fit(&bad)
                .unwrap_err()
                .to_string()
                .contains("pair 3")
        );
    }

    #[test]
    fn serde_names_the_direction() {
        let h = Homography::from_image_from_ground(TRUE_H).unwrap();
        let json = serde_json::to_string(&h).unwrap();
        assert!(json.starts_with("{\"image_from_ground\":[["), "{json}");
        let back: Homography = serde_json::from_str(&json).unwrap();
        assert!(max_image_error(&h, &back) < 1e-9);
        let text = "ground_from_image = [[0.04, 0, -4], [0, 0.04, -2], [0, 0, 1]]\n";
        let g: Homography = toml::from_str(text).unwrap();
        let p = g.image_from_ground(Point2::new(0.0, 0.0)).unwrap();
        assert!(p.distance(Point2::new(100.0, 50.0)) < 1e-9, "{p:?}");
        let err = toml::from_str::<Homography>("matrix = [[1,0,0],[0,1,0],[0,0,1]]\n")
            .unwrap_err()
            .to_string();
        assert!(err.contains("matrix"), "{err}");
        let err = toml::from_str::<Homography>("image_from_ground = [[1,0,0],[1,0,0],[0,0,1]]\n")
            .unwrap_err()
            .to_string();
        assert!(err.contains("singular"), "{err}");
    }
}

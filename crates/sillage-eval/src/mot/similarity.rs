//! Object shapes and the similarity of a true and an estimated object, in `[0, 1]`
//! (1 = identical), as TrackEval defines it: box IoU (`_calculate_box_ious`), Euclidean
//! similarity (`_calculate_euclidean_similarity`), and the IoU of two discs for beads.

use serde::{Deserialize, Serialize};
use sillage_core::{BoundingBox, Error, Point2, Result};

/// The geometry of one object in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// A bounding box (pedestrians, MOTChallenge).
    Box(BoundingBox),
    /// A disc with its own radius (beads: the MMPF+ paper, §5.3).
    Disc {
        /// Centre, px.
        centre_px: Point2,
        /// Radius, px (≥ 0).
        radius_px: f64,
    },
    /// A point (particles).
    Point(Point2),
}

impl Shape {
    /// The centre of the shape (what [`Similarity::Distance`] compares).
    pub fn centre(&self) -> Point2 {
        match *self {
            Shape::Box(b) => b.centre(),
            Shape::Disc { centre_px, .. } => centre_px,
            Shape::Point(p) => p,
        }
    }

    /// Why the shape is unusable (a non-finite coordinate, a negative size), if it is.
    pub(crate) fn defect(&self) -> Option<&'static str> {
        let finite = |values: &[f64]| values.iter().all(|v| v.is_finite());
        match *self {
            Shape::Box(b) if !finite(&[b.left_px, b.top_px, b.width_px, b.height_px]) => {
                Some("the box has a coordinate that is not finite")
            }
            Shape::Box(b) if b.width_px < 0.0 || b.height_px < 0.0 => {
                Some("the box has a negative width or height")
            }
            Shape::Disc {
                centre_px,
                radius_px,
            } if !finite(&[centre_px.x, centre_px.y, radius_px]) => {
                Some("the disc has a coordinate or radius that is not finite")
            }
            Shape::Disc { radius_px, .. } if radius_px < 0.0 => {
                Some("the disc has a negative radius")
            }
            Shape::Point(p) if !p.is_finite() => {
                Some("the point has a coordinate that is not finite")
            }
            _ => None,
        }
    }
}

/// How the similarity of a true and an estimated object is measured.
///
/// Matching thresholds (CLEAR MOT and Identity's 0.5, HOTA's α) apply to this similarity.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Similarity {
    /// Intersection over union of two boxes ([`box_iou`]); both shapes must be boxes.
    BoxIou,
    /// Intersection over union of two discs ([`disc_iou`]); both shapes must be discs. For
    /// two discs of radius `r`, IoU ≥ 0.43 (the MMPF+ paper's threshold, §5.3) holds for
    /// centres up to 0.637 r apart, so every accepted estimate has its centre inside the
    /// true bead.
    DiscIou,
    /// `max(0, 1 − d / zero_distance_px)` for the distance `d` between centres
    /// ([`distance_similarity`]); any shapes. With the default threshold 0.5, a match needs
    /// `d ≤ zero_distance_px / 2`; HOTA's α sweeps `d ≤ (1 − α) zero_distance_px`.
    Distance {
        /// The distance at which the similarity reaches 0, px (TrackEval's `zero_distance`).
        zero_distance_px: f64,
    },
}

impl Similarity {
    /// Checks the parameters: a `zero_distance_px` that is finite and > 0.
    pub fn validate(&self) -> Result<()> {
        match *self {
            Similarity::Distance { zero_distance_px }
                if !(zero_distance_px.is_finite() && zero_distance_px > 0.0) =>
            {
                Err(Error::parameter(
                    "zero_distance_px",
                    zero_distance_px,
                    "must be a finite distance > 0 (px)",
                ))
            }
            _ => Ok(()),
        }
    }

    /// Whether this measure can compare `shape` (boxes for box IoU, discs for disc IoU).
    pub fn accepts(&self, shape: &Shape) -> bool {
        matches!(
            (self, shape),
            (Similarity::BoxIou, Shape::Box(_))
                | (Similarity::DiscIou, Shape::Disc { .. })
                | (Similarity::Distance { .. }, _)
        )
    }

    /// The similarity of `truth` and `estimate`, or 0 when the measure does not accept them
    /// (see [`Similarity::accepts`]; the evaluation checks shapes up front).
    pub fn between(&self, truth: &Shape, estimate: &Shape) -> f64 {
        match (*self, truth, estimate) {
            (Similarity::BoxIou, Shape::Box(a), Shape::Box(b)) => box_iou(a, b),
            (
                Similarity::DiscIou,
                &Shape::Disc {
                    centre_px: a,
                    radius_px: ra,
                },
                &Shape::Disc {
                    centre_px: b,
                    radius_px: rb,
                },
            ) => disc_iou(a, ra, b, rb),
            (Similarity::Distance { zero_distance_px }, t, e) => {
                distance_similarity(t.centre(), e.centre(), zero_distance_px)
            }
            _ => 0.0,
        }
    }

    /// A short name for tables: `IoU`, `disc IoU`, `dist(10 px)`.
    pub fn label(&self) -> String {
        match self {
            Similarity::BoxIou => "IoU".to_owned(),
            Similarity::DiscIou => "disc IoU".to_owned(),
            Similarity::Distance { zero_distance_px } => format!("dist({zero_distance_px} px)"),
        }
    }
}

/// Box intersection over union exactly as TrackEval's `_calculate_box_ious` (`xywh`):
/// corners `left + width`, areas from the corners, and 0 when either area or the union is
/// ≤ machine epsilon.
pub fn box_iou(a: &BoundingBox, b: &BoundingBox) -> f64 {
    let (ax2, ay2) = (a.left_px + a.width_px, a.top_px + a.height_px);
    let (bx2, by2) = (b.left_px + b.width_px, b.top_px + b.height_px);
    let overlap_x = (ax2.min(bx2) - a.left_px.max(b.left_px)).max(0.0);
    let overlap_y = (ay2.min(by2) - a.top_px.max(b.top_px)).max(0.0);
    let intersection = overlap_x * overlap_y;
    let area_a = (ax2 - a.left_px) * (ay2 - a.top_px);
    let area_b = (bx2 - b.left_px) * (by2 - b.top_px);
    let union = area_a + area_b - intersection;
    if area_a <= f64::EPSILON || area_b <= f64::EPSILON || union <= f64::EPSILON {
        return 0.0;
    }
    intersection / union
}

/// Intersection over union of two discs (centres `a`, `b`, radii `ra`, `rb`): the area of
/// their lens over the area of their union; 0 for a disc of radius 0.
pub fn disc_iou(a: Point2, ra: f64, b: Point2, rb: f64) -> f64 {
    if ra <= 0.0 || rb <= 0.0 {
        return 0.0;
    }
    let d = a.distance(b);
    if d >= ra + rb {
        return 0.0;
    }
    let (small, large) = (ra.min(rb), ra.max(rb));
    if d <= large - small {
        // One disc inside the other.
        return (small / large).powi(2);
    }
    // The lens: two circular segments (e.g. Weisstein, "Circle-Circle Intersection").
    let angle = |r: f64, other: f64| {
        ((d * d + r * r - other * other) / (2.0 * d * r))
            .clamp(-1.0, 1.0)
            .acos()
    };
    let kite = (-d + ra + rb) * (d + ra - rb) * (d - ra + rb) * (d + ra + rb);
    let intersection =
        ra * ra * angle(ra, rb) + rb * rb * angle(rb, ra) - 0.5 * kite.max(0.0).sqrt();
    let union = std::f64::consts::PI * (ra * ra + rb * rb) - intersection;
    (intersection / union).clamp(0.0, 1.0)
}

/// TrackEval's Euclidean similarity: `max(0, 1 − |a − b| / zero_distance_px)`.
pub fn distance_similarity(a: Point2, b: Point2, zero_distance_px: f64) -> f64 {
    let (dx, dy) = (a.x - b.x, a.y - b.y);
    (1.0 - (dx * dx + dy * dy).sqrt() / zero_distance_px).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bbox(left_px: f64, top_px: f64, width_px: f64, height_px: f64) -> BoundingBox {
        BoundingBox {
            left_px,
            top_px,
            width_px,
            height_px,
        }
    }

    #[test]
    fn box_iou_by_hand() {
        let a = bbox(0.0, 0.0, 2.0, 2.0);
        // Half overlap: intersection 2, union 6.
        assert!((box_iou(&a, &bbox(1.0, 0.0, 2.0, 2.0)) - 1.0 / 3.0).abs() < 1e-15);
        assert_eq!(box_iou(&a, &a), 1.0);
        assert_eq!(box_iou(&a, &bbox(2.0, 0.0, 2.0, 2.0)), 0.0);
        assert_eq!(box_iou(&a, &bbox(0.5, 0.5, 0.0, 1.0)), 0.0);
    }

    #[test]
    fn disc_iou_by_hand() {
        let o = Point2::new(0.0, 0.0);
        assert_eq!(disc_iou(o, 1.0, o, 1.0), 1.0);
        assert_eq!(disc_iou(o, 2.0, Point2::new(0.5, 0.0), 1.0), 0.25);
        assert_eq!(disc_iou(o, 1.0, Point2::new(2.0, 0.0), 1.0), 0.0);
        // Centres one radius apart: lens 2π/3 − √3/2, union 2π − lens.
        let lens = 2.0 * std::f64::consts::PI / 3.0 - 3f64.sqrt() / 2.0;
        let expected = lens / (2.0 * std::f64::consts::PI - lens);
        assert!((disc_iou(o, 1.0, Point2::new(0.0, 1.0), 1.0) - expected).abs() < 1e-14);
        // The MMPF+ threshold 0.43 sits at 0.637 r for equal discs.
        assert!(disc_iou(o, 1.0, Point2::new(0.636, 0.0), 1.0) > 0.43);
        assert!(disc_iou(o, 1.0, Point2::new(0.638, 0.0), 1.0) < 0.43);
    }

    #[test]
    fn distance_similarity_and_shapes() {
        let s = Similarity::Distance {
            zero_distance_px: 4.0,
        };
        let p = Shape::Point(Point2::new(0.0, 0.0));
        let b = Shape::Box(bbox(-1.0, 2.0, 2.0, 2.0)); // centre (0, 3)
        assert_eq!(s.between(&p, &b), 0.25);
        assert_eq!(s.between(&p, &Shape::Point(Point2::new(9.0, 0.0))), 0.0);
        assert!(
            !Similarity::BoxIou.accepts(&p)
                && Similarity::DiscIou.accepts(&Shape::Disc {
                    centre_px: Point2::new(0.0, 0.0),
                    radius_px: 1.0
                })
        );
        assert_eq!(Similarity::BoxIou.between(&p, &b), 0.0);
        assert!(
            Similarity::Distance {
                zero_distance_px: 0.0
            }
            .validate()
            .is_err()
        );
        assert!(Shape::Box(bbox(0.0, 0.0, -1.0, 1.0)).defect().is_some());
        assert!(Shape::Point(Point2::new(f64::NAN, 0.0)).defect().is_some());
        assert!(b.defect().is_none());
    }
}

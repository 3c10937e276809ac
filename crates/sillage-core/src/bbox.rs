//! The one box type of the toolkit: an axis-aligned box in the image, px, as MOTChallenge
//! writes it (`bb_left, bb_top, bb_width, bb_height`). Pedestrian trackers place it by its
//! foot point, the bottom centre that a ground-plane homography maps (§4 of the IMM-PF paper);
//! metrics compare boxes by IoU.

use serde::{Deserialize, Serialize};

use crate::Point2;

/// An axis-aligned box, px: left/top corner, width and height (MOTChallenge's
/// `bb_left, bb_top, bb_width, bb_height`, kept as written in a file).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BoundingBox {
    /// Left edge, px.
    pub left_px: f64,
    /// Top edge, px.
    pub top_px: f64,
    /// Width, px.
    pub width_px: f64,
    /// Height, px.
    pub height_px: f64,
}

impl BoundingBox {
    /// The box of `width_px × height_px` standing on `foot` (its bottom centre).
    pub fn standing_on(foot: Point2, width_px: f64, height_px: f64) -> Self {
        Self {
            left_px: foot.x - width_px / 2.0,
            top_px: foot.y - height_px,
            width_px,
            height_px,
        }
    }

    /// The bottom centre: where the person touches the ground.
    pub fn foot(&self) -> Point2 {
        Point2::new(
            self.left_px + self.width_px / 2.0,
            self.top_px + self.height_px,
        )
    }

    /// The box's centre.
    pub fn centre(&self) -> Point2 {
        Point2::new(
            self.left_px + self.width_px / 2.0,
            self.top_px + self.height_px / 2.0,
        )
    }

    /// Right edge, px.
    pub fn right_px(&self) -> f64 {
        self.left_px + self.width_px
    }

    /// Bottom edge, px.
    pub fn bottom_px(&self) -> f64 {
        self.top_px + self.height_px
    }

    /// Intersection over union with `other`, in `[0, 1]` (0 for empty boxes).
    pub fn iou(&self, other: &BoundingBox) -> f64 {
        let w = (self.right_px().min(other.right_px()) - self.left_px.max(other.left_px)).max(0.0);
        let h = (self.bottom_px().min(other.bottom_px()) - self.top_px.max(other.top_px)).max(0.0);
        let inter = w * h;
        let union = self.width_px * self.height_px + other.width_px * other.height_px - inter;
        if union > 0.0 { inter / union } else { 0.0 }
    }

    /// True when `point` lies inside the box (edges included).
    pub fn contains(&self, point: Point2) -> bool {
        point.x >= self.left_px
            && point.x <= self.right_px()
            && point.y >= self.top_px
            && point.y <= self.bottom_px()
    }

    /// The top or bottom half (the two colour histograms of §4.3).
    pub fn half(&self, top: bool) -> BoundingBox {
        let height_px = self.height_px / 2.0;
        BoundingBox {
            top_px: if top {
                self.top_px
            } else {
                self.top_px + height_px
            },
            height_px,
            ..*self
        }
    }

    /// True when every coordinate is finite and the sizes are positive.
    pub fn is_valid(&self) -> bool {
        [self.left_px, self.top_px, self.width_px, self.height_px]
            .iter()
            .all(|v| v.is_finite())
            && self.width_px > 0.0
            && self.height_px > 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn foot_iou_and_halves() {
        let b = BoundingBox::standing_on(Point2::new(50.0, 100.0), 20.0, 60.0);
        assert_eq!(b.left_px, 40.0);
        assert_eq!(b.top_px, 40.0);
        assert_eq!(b.foot(), Point2::new(50.0, 100.0));
        assert_eq!(b.centre(), Point2::new(50.0, 70.0));
        assert!((b.iou(&b) - 1.0).abs() < 1e-12);
        let shifted = BoundingBox { left_px: 50.0, ..b };
        assert!((b.iou(&shifted) - 1.0 / 3.0).abs() < 1e-12);
        assert_eq!(b.half(true).bottom_px(), 70.0);
        assert_eq!(b.half(false).top_px, 70.0);
        assert!(
            !BoundingBox {
                width_px: -1.0,
                ..b
            }
            .is_valid()
        );
        assert!(b.contains(Point2::new(50.0, 100.0)) && !b.contains(Point2::new(50.0, 101.0)));
    }
}

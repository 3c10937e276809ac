//! How big a person's box is at a foot point: "the real dimensions (h, w) of the bounding box
//! are fixed to the average size of an adult (in world coordinates) and projected into the
//! image plane" (§4 of the IMM-PF paper) through a ground-plane homography; or, without one,
//! the size of the blob or detection the tracker was born on.

use sillage_core::{Homography, PedestrianSize, Point2};

use sillage_core::BoundingBox;

/// The box-size rule of a run.
#[derive(Debug, Clone, PartialEq)]
pub enum BoxSizing {
    /// Each tracker keeps the size of the candidate it was born on (detections-only mode:
    /// the size then follows the matched detections).
    FromCandidate,
    /// An adult of `adult`'s size standing on the ground plane of `homography`.
    Ground {
        /// Image ↔ ground plane.
        homography: Homography,
        /// The adult's box, m (`sillage fit homography` measures the effective one).
        adult: PedestrianSize,
    },
}

impl BoxSizing {
    /// The box of a person standing on `foot`; `own_size_px` (width, height) is the
    /// tracker's own size, used without a ground plane or where it is undefined.
    pub fn box_at(&self, foot: Point2, own_size_px: (f64, f64)) -> BoundingBox {
        let (width, height) = match self {
            Self::FromCandidate => own_size_px,
            Self::Ground { homography, adult } => {
                adult.box_size_px(homography, foot).unwrap_or(own_size_px)
            }
        };
        BoundingBox::standing_on(foot, width, height)
    }

    /// The people a candidate box holds: itself without a ground plane; with one, the adults
    /// standing side by side along its bottom edge (a blob of a walking group is as wide as
    /// several adults: ⌊width / adult width + ¼⌋ of them), each sized by the ground plane. A
    /// candidate much shorter than an adult there (< 60 %: a torso without legs, whose bottom
    /// edge is no foot) holds nobody.
    pub fn people_in(&self, candidate: &BoundingBox) -> Vec<BoundingBox> {
        let foot = candidate.foot();
        let Self::Ground { .. } = self else {
            return vec![*candidate];
        };
        let adult = self.box_at(foot, (candidate.width_px, candidate.height_px));
        if candidate.height_px < 0.6 * adult.height_px || adult.width_px <= 0.0 {
            return Vec::new();
        }
        // A walking adult's blob is wider than its box (legs, arms, motion): 1.7 adult widths
        // still hold one person, two adults side by side are two.
        let count = (candidate.width_px / adult.width_px + 0.25)
            .floor()
            .clamp(1.0, 8.0) as usize;
        let step = candidate.width_px / count as f64;
        (0..count)
            .map(|k| {
                let x = candidate.left_px + step * (k as f64 + 0.5);
                self.box_at(Point2::new(x, foot.y), (adult.width_px, adult.height_px))
            })
            .collect()
    }
}

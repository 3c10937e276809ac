//! Which SIFT keypoints become tracked features on an object (§2.1 of Souded et al.): the box
//! divided into sub-regions sized by the box, a constant number of features per sub-region,
//! chosen by robustness (detection scale, curvature, contrast) and by lying on motion pixels;
//! or, for the paper's baselines (§3.1.1), every keypoint of Lowe's detector on the whole
//! object, or the first ones each sub-region detects.

use sillage_core::Point2;
use sillage_image::SiftKeypoint;

use super::feature::{FeatureFrame, FeatureSeed};
use super::params::{FeaturePlacementParams, FeatureSelection};
use sillage_core::BoundingBox;

/// The grid of sub-regions of a box: `columns × rows` cells of equal size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubregionGrid {
    bbox: BoundingBox,
    columns: usize,
    rows: usize,
}

impl SubregionGrid {
    /// The grid of `bbox` with cells of about `subregion_px` (at least one cell).
    pub fn new(bbox: BoundingBox, subregion_px: f64) -> Self {
        let cells = |extent: f64| ((extent / subregion_px).round() as usize).max(1);
        Self {
            bbox,
            columns: cells(bbox.width_px),
            rows: cells(bbox.height_px),
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.columns * self.rows
    }

    /// True for a grid without cells (never: a grid has at least one).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The cell holding `p`, if `p` lies in the box.
    pub fn cell_of(&self, p: Point2) -> Option<usize> {
        if !self.bbox.contains(p) {
            return None;
        }
        let fx = (p.x - self.bbox.left_px) / self.bbox.width_px;
        let fy = (p.y - self.bbox.top_px) / self.bbox.height_px;
        let column = ((fx * self.columns as f64) as usize).min(self.columns - 1);
        let row = ((fy * self.rows as f64) as usize).min(self.rows - 1);
        Some(row * self.columns + column)
    }

    /// The centre of cell `cell`.
    pub fn centre(&self, cell: usize) -> Point2 {
        let (column, row) = (cell % self.columns, cell / self.columns);
        Point2::new(
            self.bbox.left_px + (column as f64 + 0.5) * self.bbox.width_px / self.columns as f64,
            self.bbox.top_px + (row as f64 + 0.5) * self.bbox.height_px / self.rows as f64,
        )
    }
}

/// The robustness of a keypoint for tracking (§2.1), in `[0, 1]`: the geometric mean of its
/// contrast (relative to the strongest in the object), its corner-ness (1 for an isotropic
/// blob, tr²/det = 4, down to 0 at the edge limit `(r+1)²/r`) and its scale (σ/(σ + 1.6):
/// larger windows are steadier), times `c₀` off the motion pixels.
pub fn robustness(
    keypoint: &SiftKeypoint,
    max_contrast: f32,
    edge_threshold: f32,
    on_motion: bool,
    motion_confidence: f64,
) -> f64 {
    let contrast = f64::from(keypoint.contrast / max_contrast.max(f32::MIN_POSITIVE)).min(1.0);
    let limit = f64::from((edge_threshold + 1.0).powi(2) / edge_threshold);
    let corner = ((limit - f64::from(keypoint.edge_ratio)) / (limit - 4.0)).clamp(0.0, 1.0);
    let sigma = f64::from(keypoint.sigma);
    let scale = sigma / (sigma + 1.6);
    let c = if on_motion { 1.0 } else { motion_confidence };
    c * (contrast * corner * scale).cbrt()
}

/// What a selection needs to know about the object and its neighbours.
pub struct SelectionRequest<'a> {
    /// The object's box.
    pub bbox: BoundingBox,
    /// Positions of the features the object already has.
    pub existing: &'a [Point2],
    /// Boxes of the other objects: sub-regions whose centre lies in one are shared and not
    /// used (§2.3).
    pub others: &'a [BoundingBox],
    /// `c₀` of the object (Eq. (5)).
    pub motion_confidence: f64,
}

/// Chooses new features for one object; keypoint buffer reused between calls.
#[derive(Debug, Default)]
pub struct FeatureSelector {
    keypoints: Vec<SiftKeypoint>,
}

impl FeatureSelector {
    /// New features for `request.bbox` in the analysed `frame`, by `selection`, with their
    /// descriptors, first reliabilities and anchors; none closer than `min_spacing_px` to an
    /// existing feature or to each other.
    pub fn select(
        &mut self,
        selection: FeatureSelection,
        frame: FeatureFrame<'_>,
        request: &SelectionRequest<'_>,
        placement: &FeaturePlacementParams,
        edge_threshold: f32,
    ) -> Vec<FeatureSeed> {
        let bbox = request.bbox;
        self.keypoints.clear();
        frame
            .sift
            .keypoints(Some(pixel_box(&bbox)), &mut self.keypoints);
        self.keypoints.retain(|k| bbox.contains(point(k)));
        let max_contrast = self
            .keypoints
            .iter()
            .map(|k| k.contrast)
            .fold(0.0, f32::max);
        let mut taken: Vec<Point2> = request.existing.to_vec();
        let mut seeds = Vec::new();
        let spacing2 = placement.min_spacing_px * placement.min_spacing_px;
        let mut take = |k: &SiftKeypoint, reliability: f64, taken: &mut Vec<Point2>| {
            let p = point(k);
            if taken.iter().any(|q| (*q - p).norm_squared() < spacing2) {
                return false;
            }
            let Some(descriptor) = frame.sift.describe(k) else {
                return false;
            };
            taken.push(p);
            seeds.push(FeatureSeed {
                keypoint: *k,
                descriptor,
                reliability,
                anchor: anchor_in(&bbox, p),
            });
            true
        };
        if selection == FeatureSelection::WholeObject {
            for k in &self.keypoints {
                let r = robustness(
                    k,
                    max_contrast,
                    edge_threshold,
                    frame.is_moving(point(k)),
                    request.motion_confidence,
                );
                take(k, r, &mut taken);
            }
            return seeds;
        }
        let grid = SubregionGrid::new(bbox, placement.subregion_px);
        let mut per_cell = vec![0usize; grid.len()];
        for p in request.existing {
            if let Some(cell) = grid.cell_of(*p) {
                per_cell[cell] += 1;
            }
        }
        let mut candidates: Vec<(usize, f64, usize)> = self
            .keypoints
            .iter()
            .enumerate()
            .filter_map(|(i, k)| {
                let cell = grid.cell_of(point(k))?;
                let shared = request.others.iter().any(|o| o.contains(grid.centre(cell)));
                (!shared).then(|| {
                    let r = robustness(
                        k,
                        max_contrast,
                        edge_threshold,
                        frame.is_moving(point(k)),
                        request.motion_confidence,
                    );
                    (cell, r, i)
                })
            })
            .collect();
        if selection == FeatureSelection::Reliability {
            // Most robust first; ties keep detection order.
            candidates.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.2.cmp(&b.2)));
        }
        for (cell, reliability, i) in candidates {
            if per_cell[cell] < placement.features_per_subregion
                && take(&self.keypoints[i], reliability, &mut taken)
            {
                per_cell[cell] += 1;
            }
        }
        seeds
    }
}

/// A keypoint's position as a point.
fn point(k: &SiftKeypoint) -> Point2 {
    Point2::new(f64::from(k.x), f64::from(k.y))
}

/// Position inside `bbox` as shares of its width and height.
pub fn anchor_in(bbox: &BoundingBox, p: Point2) -> (f64, f64) {
    (
        (p.x - bbox.left_px) / bbox.width_px,
        (p.y - bbox.top_px) / bbox.height_px,
    )
}

/// The pixels a box covers (clamped at 0; the detector clips to the frame).
fn pixel_box(b: &BoundingBox) -> sillage_image::PixelBox {
    let floor = |v: f64| v.floor().max(0.0) as usize;
    let ceil = |v: f64| v.ceil().max(0.0) as usize + 1;
    sillage_image::PixelBox {
        x0: floor(b.left_px),
        y0: floor(b.top_px),
        x1: ceil(b.right_px()),
        y1: ceil(b.bottom_px()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keypoint(contrast: f32, edge_ratio: f32, sigma: f32) -> SiftKeypoint {
        SiftKeypoint {
            x: 0.0,
            y: 0.0,
            sigma,
            orientation: 0.0,
            contrast,
            edge_ratio,
            octave: 0,
            layer: 1.0,
        }
    }

    #[test]
    fn grid_cells_cover_the_box() {
        let b = BoundingBox {
            left_px: 10.0,
            top_px: 20.0,
            width_px: 24.0,
            height_px: 60.0,
        };
        let grid = SubregionGrid::new(b, 12.0);
        assert_eq!(grid.len(), 10);
        assert_eq!(grid.cell_of(Point2::new(10.0, 20.0)), Some(0));
        assert_eq!(grid.cell_of(Point2::new(34.0, 80.0)), Some(9));
        assert_eq!(grid.cell_of(Point2::new(35.0, 80.0)), None);
        assert_eq!(grid.centre(0), Point2::new(16.0, 26.0));
        assert_eq!(anchor_in(&b, Point2::new(22.0, 50.0)), (0.5, 0.5));
    }

    #[test]
    fn robustness_prefers_contrast_corners_scale_and_motion() {
        let strong = keypoint(0.1, 4.0, 3.0);
        let r = |k: &SiftKeypoint, moving| robustness(k, 0.1, 7.5, moving, 0.5);
        assert!(r(&strong, true) > r(&keypoint(0.05, 4.0, 3.0), true));
        assert!(r(&strong, true) > r(&keypoint(0.1, 8.0, 3.0), true));
        assert!(r(&strong, true) > r(&keypoint(0.1, 4.0, 1.6), true));
        assert!((r(&strong, false) - 0.5 * r(&strong, true)).abs() < 1e-12);
        assert_eq!(r(&keypoint(0.1, 20.0, 3.0), true), 0.0);
    }
}

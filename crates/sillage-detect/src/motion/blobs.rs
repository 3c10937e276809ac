//! From a cleaned foreground mask to person-sized blobs: 8-connected components, the small ones
//! dropped, those whose boxes lie within a gap of each other merged (a person's head, body and
//! legs often come apart), the merged ones kept when large enough.

use sillage_core::{Image, Point2};
use sillage_image::{Component, PixelBox};

/// One moving object: its box, its foreground pixels and where they are.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionBlob {
    /// The box around the merged components.
    pub bbox: PixelBox,
    /// Foreground pixels of the merged components, px².
    pub area: usize,
    /// Mean position of those pixels, px.
    pub centroid: Point2,
    /// The cleaned foreground inside `bbox` (`bbox.width() × bbox.height()`).
    pub mask: Image<bool>,
    /// For a piece of a group cut into people, the group blob's box (shared by all its
    /// pieces); `None` for a blob that was not cut. A tracker whose objects contradict the
    /// cut can join the pieces back.
    pub cut_from: Option<PixelBox>,
}

/// How components are grouped into blobs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Grouping {
    /// Components below this area (px²) are noise.
    pub min_component_px: usize,
    /// Components whose boxes are at most this many pixels apart belong together.
    pub merge_gap_px: usize,
    /// Merged groups below this area (px²) are dropped.
    pub min_blob_px: usize,
}

/// The blobs of `components` (of `foreground`), in the order of their first component.
pub(crate) fn group_components(
    components: &[Component],
    foreground: &Image<bool>,
    grouping: Grouping,
    out: &mut Vec<MotionBlob>,
) {
    out.clear();
    let kept: Vec<&Component> = components
        .iter()
        .filter(|c| c.area >= grouping.min_component_px)
        .collect();
    // Union–find over the kept components, joining boxes within the gap.
    let mut parent: Vec<usize> = (0..kept.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for i in 0..kept.len() {
        for j in i + 1..kept.len() {
            if kept[i].bbox.within(&kept[j].bbox, grouping.merge_gap_px) {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                if a != b {
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
    }
    // Each group's box, area and coordinate sums, indexed by its root (its first member).
    let mut groups: Vec<Option<(PixelBox, usize, f64, f64)>> = vec![None; kept.len()];
    for (i, c) in kept.iter().enumerate() {
        let r = root(&mut parent, i);
        let (sx, sy) = (c.centroid.x * c.area as f64, c.centroid.y * c.area as f64);
        groups[r] = Some(match groups[r] {
            None => (c.bbox, c.area, sx, sy),
            Some((bbox, area, gx, gy)) => (bbox.union(&c.bbox), area + c.area, gx + sx, gy + sy),
        });
    }
    out.extend(
        groups
            .into_iter()
            .flatten()
            .filter(|&(_, area, _, _)| area >= grouping.min_blob_px)
            .map(|(bbox, area, sx, sy)| MotionBlob {
                bbox,
                area,
                centroid: Point2::new(sx / area as f64, sy / area as f64),
                mask: crop(foreground, &bbox),
                cut_from: None,
            }),
    );
}

/// The pixels of `image` inside `bbox`.
pub(super) fn crop(image: &Image<bool>, bbox: &PixelBox) -> Image<bool> {
    let data = (bbox.y0..bbox.y1)
        .flat_map(|y| image.row(y)[bbox.x0..bbox.x1].iter().copied())
        .collect();
    Image::from_vec(bbox.width(), bbox.height(), data)
        .unwrap_or_else(|_| unreachable!("a box inside the image has its own size"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_image::ComponentLabeller;

    fn mask_with(rects: &[(usize, usize, usize, usize)]) -> Image<bool> {
        let mut mask = Image::new(60, 40);
        for &(x0, y0, x1, y1) in rects {
            for y in y0..y1 {
                for x in x0..x1 {
                    mask.set(x, y, true);
                }
            }
        }
        mask
    }

    #[test]
    fn parts_within_the_gap_merge_and_specks_are_dropped() {
        // A "head" 4 px above a "body", a speck, and a separate person far away.
        let mask = mask_with(&[
            (10, 2, 14, 6),
            (8, 10, 16, 30),
            (30, 5, 31, 6),
            (40, 8, 48, 30),
        ]);
        let mut components = Vec::new();
        ComponentLabeller::new().label(&mask, &mut components);
        let grouping = Grouping {
            min_component_px: 4,
            merge_gap_px: 5,
            min_blob_px: 50,
        };
        let mut blobs = Vec::new();
        group_components(&components, &mask, grouping, &mut blobs);
        assert_eq!(blobs.len(), 2);
        let person = &blobs[0];
        assert_eq!(
            person.bbox,
            PixelBox {
                x0: 8,
                y0: 2,
                x1: 16,
                y1: 30
            }
        );
        assert_eq!(person.area, 16 + 160);
        assert_eq!(person.mask.dimensions(), (8, 28));
        assert!(person.mask.get(3, 1) && !person.mask.get(0, 0));
        assert_eq!(blobs[1].bbox.x0, 40);
        // A smaller gap keeps the head apart, and alone it is too small.
        group_components(
            &components,
            &mask,
            Grouping {
                merge_gap_px: 2,
                ..grouping
            },
            &mut blobs,
        );
        // Raster order of the first pixel: the far person (row 8) before the body (row 10).
        let tops: Vec<(usize, usize)> = blobs.iter().map(|b| (b.bbox.x0, b.bbox.y0)).collect();
        assert_eq!(tops, [(40, 8), (8, 10)]);
    }
}

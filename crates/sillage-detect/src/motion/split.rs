//! Groups cut into people. People who walk side by side, or stand together, give one blob
//! from their first frame: on PETS 2009 S2.L1 the blobs are 1.8× wider than the true boxes in
//! median, and a tracker that follows blobs follows groups. A blob much wider than a standing
//! person (width > `group_aspect` × height) is cut into `round(width / (person_aspect ×
//! height))` people, each cut placed at the emptiest column (fewest foreground pixels,
//! smoothed) within a quarter of a person's width of where equal shares would put it: the gap
//! between two bodies, or between legs, is where the foreground is thinnest. Each piece is
//! then tightened to its own foreground.

use sillage_core::{Image, Point2};
use sillage_image::PixelBox;

use super::blobs::{MotionBlob, crop};

/// When and how blobs are cut into people.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GroupSplit {
    /// A blob wider than this × its height is a group.
    pub group_aspect: f64,
    /// One person's width / height, which counts the people in a group.
    pub person_aspect: f64,
    /// Pieces with fewer foreground pixels than this are dropped, px².
    pub min_blob_px: usize,
}

impl GroupSplit {
    /// Replaces each group in `blobs` by its people, keeping the order (a group's people left
    /// to right, where the group was).
    pub fn apply(&self, blobs: &mut Vec<MotionBlob>) {
        if !blobs.iter().any(|b| self.people_in(b) > 1) {
            return;
        }
        let mut out = Vec::with_capacity(blobs.len() + 4);
        for blob in blobs.drain(..) {
            match self.people_in(&blob) {
                0 | 1 => out.push(blob),
                people => out.extend(self.split(&blob, people)),
            }
        }
        *blobs = out;
    }

    /// How many people `blob` holds: 1 unless it is a group.
    fn people_in(&self, blob: &MotionBlob) -> usize {
        let (w, h) = (blob.bbox.width() as f64, blob.bbox.height() as f64);
        if self.person_aspect <= 0.0 || w <= self.group_aspect * h {
            return 1;
        }
        // At least 2 columns a person, so that cuts stay apart and inside the blob.
        ((w / (self.person_aspect * h)).round() as usize)
            .max(2)
            .min(blob.bbox.width() / 2)
    }

    /// `blob` cut into `people` pieces at the emptiest columns near equal shares.
    fn split(&self, blob: &MotionBlob, people: usize) -> Vec<MotionBlob> {
        let (w, h) = blob.mask.dimensions();
        let profile = smoothed_column_counts(&blob.mask, (0.03 * h as f64).round() as usize);
        let share = w as f64 / people as f64;
        let reach = (0.25 * share).floor() as usize;
        let mut cuts = vec![0];
        for k in 1..people {
            let nominal = (share * k as f64).round() as usize;
            let lo = nominal.saturating_sub(reach).max(cuts[cuts.len() - 1] + 1);
            let hi = (nominal + reach).min(w - 1);
            // The emptiest column; among equals, the one nearest the nominal cut.
            let cut = (lo..=hi)
                .min_by_key(|&x| (profile[x], x.abs_diff(nominal)))
                .unwrap_or(nominal.clamp(lo, hi.max(lo)));
            cuts.push(cut);
        }
        cuts.push(w);
        cuts.windows(2)
            .filter_map(|c| piece(blob, c[0], c[1]))
            .filter(|p| p.area >= self.min_blob_px)
            .collect()
    }
}

/// Foreground pixels per column of `mask`, summed over a window of `2·radius + 1` columns.
fn smoothed_column_counts(mask: &Image<bool>, radius: usize) -> Vec<usize> {
    let (w, _) = mask.dimensions();
    let mut counts = vec![0usize; w];
    for y in 0..mask.height() {
        for (c, &on) in counts.iter_mut().zip(mask.row(y)) {
            *c += usize::from(on);
        }
    }
    (0..w)
        .map(|x| {
            counts[x.saturating_sub(radius)..(x + radius + 1).min(w)]
                .iter()
                .sum()
        })
        .collect()
}

/// The part of `blob` in mask columns `x0..x1`, tightened to its foreground; `None` if empty.
fn piece(blob: &MotionBlob, x0: usize, x1: usize) -> Option<MotionBlob> {
    // Bounds of the piece's pixels in mask coordinates (inclusive), their count and sums.
    let (mut lo, mut hi) = ((usize::MAX, usize::MAX), (0, 0));
    let (mut area, mut sx, mut sy) = (0usize, 0.0, 0.0);
    for y in 0..blob.mask.height() {
        for (x, _) in blob.mask.row(y)[x0..x1]
            .iter()
            .enumerate()
            .filter(|(_, on)| **on)
        {
            let x = x0 + x;
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
            area += 1;
            sx += x as f64;
            sy += y as f64;
        }
    }
    if area == 0 {
        return None;
    }
    let local = PixelBox {
        x0: lo.0,
        y0: lo.1,
        x1: hi.0 + 1,
        y1: hi.1 + 1,
    };
    let mask = crop(&blob.mask, &local);
    let (bx, by) = (blob.bbox.x0, blob.bbox.y0);
    Some(MotionBlob {
        bbox: PixelBox {
            x0: bx + local.x0,
            y0: by + local.y0,
            x1: bx + local.x1,
            y1: by + local.y1,
        },
        area,
        centroid: Point2::new(bx as f64 + sx / area as f64, by as f64 + sy / area as f64),
        mask,
        cut_from: Some(blob.bbox),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A blob at (100, 50) whose mask holds the given rectangles (mask coordinates).
    fn blob(w: usize, h: usize, rects: &[(usize, usize, usize, usize)]) -> MotionBlob {
        let mut mask = Image::new(w, h);
        for &(x0, y0, x1, y1) in rects {
            for y in y0..y1 {
                for x in x0..x1 {
                    mask.set(x, y, true);
                }
            }
        }
        let area = mask.as_slice().iter().filter(|&&m| m).count();
        MotionBlob {
            bbox: PixelBox {
                x0: 100,
                y0: 50,
                x1: 100 + w,
                y1: 50 + h,
            },
            area,
            centroid: Point2::new(0.0, 0.0),
            mask,
            cut_from: None,
        }
    }

    const SPLIT: GroupSplit = GroupSplit {
        group_aspect: 0.65,
        person_aspect: 0.42,
        min_blob_px: 50,
    };

    #[test]
    fn a_pair_is_cut_at_the_gap_between_them_not_at_the_middle() {
        // Two bodies 18 and 22 px wide joined by a 2-px bridge at shoulder height; 50 px tall.
        let pair = blob(42, 50, &[(0, 0, 18, 50), (18, 10, 20, 12), (20, 5, 42, 50)]);
        let mut blobs = vec![pair];
        SPLIT.apply(&mut blobs);
        assert_eq!(blobs.len(), 2);
        let cut = blobs[0].bbox.x1;
        assert!(
            (118..=120).contains(&cut),
            "cut at {cut}, not in the bridge"
        );
        assert_eq!(
            (blobs[0].bbox.x0, blobs[1].bbox.x0, blobs[1].bbox.x1),
            (100, cut, 142)
        );
        assert_eq!(blobs[1].bbox.y0, 55, "the right body starts 5 rows lower");
        assert_eq!(blobs[1].mask.dimensions(), (142 - cut, 45));
        let group = PixelBox {
            x0: 100,
            y0: 50,
            x1: 142,
            y1: 100,
        };
        assert!(blobs.iter().all(|b| b.cut_from == Some(group)));
        let on = blobs.iter().map(|b| b.area).sum::<usize>();
        assert_eq!(
            on,
            18 * 50 + 4 + 22 * 45,
            "every foreground pixel is in a piece"
        );
        let left = &blobs[0];
        let sx: f64 = (0..50)
            .flat_map(|y| (0..left.bbox.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| left.mask.get(x, y))
            .map(|(x, _)| (100 + x) as f64)
            .sum();
        assert!((left.centroid.x - sx / left.area as f64).abs() < 1e-9);
    }

    #[test]
    fn single_people_and_a_disabled_split_leave_blobs_alone() {
        let person = blob(20, 50, &[(0, 0, 20, 50)]);
        let pair = blob(42, 50, &[(0, 0, 42, 50)]);
        let mut blobs = vec![person.clone()];
        SPLIT.apply(&mut blobs);
        assert_eq!(blobs, [person]);
        let off = GroupSplit {
            person_aspect: 0.0,
            ..SPLIT
        };
        let mut blobs = vec![pair.clone()];
        off.apply(&mut blobs);
        assert_eq!(blobs, [pair]);
    }

    #[test]
    fn a_flat_blob_and_a_tiny_person_aspect_give_pieces_inside_the_blob() {
        let strip = blob(100, 3, &[(0, 0, 100, 3)]);
        let tiny = GroupSplit {
            person_aspect: 0.01,
            group_aspect: 0.02,
            min_blob_px: 1,
        };
        let mut blobs = vec![strip];
        tiny.apply(&mut blobs);
        assert_eq!(blobs.len(), 50);
        assert!(blobs.windows(2).all(|p| p[0].bbox.x1 <= p[1].bbox.x0));
        assert_eq!(blobs.iter().map(|b| b.area).sum::<usize>(), 300);
    }

    #[test]
    fn a_wide_group_counts_its_people_and_drops_empty_pieces() {
        // 105 px wide, 50 tall: five people's widths (0.42 × 50 = 21 px); the fourth is absent.
        let group = blob(
            105,
            50,
            &[
                (0, 0, 20, 50),
                (21, 0, 41, 50),
                (42, 0, 62, 50),
                (84, 0, 105, 50),
            ],
        );
        let mut blobs = vec![group];
        SPLIT.apply(&mut blobs);
        let spans: Vec<(usize, usize)> = blobs.iter().map(|b| (b.bbox.x0, b.bbox.x1)).collect();
        assert_eq!(spans, [(100, 120), (121, 141), (142, 162), (184, 205)]);
    }
}

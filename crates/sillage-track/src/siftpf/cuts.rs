//! Cuts the tracker overrules. The motion detector cuts a blob much wider than a person into
//! people at its thinnest columns ([`DetectedObject::cut_from`]). When two tracked people
//! overlap, the thinnest column of their joint blob can lie inside the person in front, and a
//! tracker that took the pieces at their word would hand part of that person to the one
//! behind. The link scores of Eq. (6) show such a cut: an object that links (score at least
//! the minimum link score) to two pieces of one blob straddles it. Those pieces are joined back into their
//! blob, and the merge case of §2.3 (boxes from the features' layout) follows the people in
//! it, as in the paper, whose detector never cuts.

use sillage_image::PixelBox;

use super::association::{DetectedObject, LinkMatrix};

/// The detections with every cut straddled by an object joined back, or `None` when no
/// object straddles a cut. `scores` are link scores of objects (rows) against `detections`,
/// of which the `rows` listed are judged (objects with features); an object straddles a cut
/// when it scores at least `min_link` (and above 0) on two pieces of one blob. A joined
/// blob takes the place of its first piece.
pub(super) fn join_straddled_cuts(
    detections: &[DetectedObject],
    scores: &LinkMatrix,
    rows: &[usize],
    min_link: f64,
) -> Option<Vec<DetectedObject>> {
    let mut straddled: Vec<PixelBox> = Vec::new();
    for &i in rows {
        let parts: Vec<PixelBox> = (0..scores.cols())
            .filter(|&j| scores.score(i, j) >= min_link && scores.score(i, j) > 0.0)
            .filter_map(|j| detections[j].cut_from)
            .collect();
        for (k, group) in parts.iter().enumerate() {
            if parts[k + 1..].contains(group) && !straddled.contains(group) {
                straddled.push(*group);
            }
        }
    }
    if straddled.is_empty() {
        return None;
    }
    let mut joined = Vec::with_capacity(detections.len());
    let mut done: Vec<PixelBox> = Vec::new();
    for d in detections {
        match d.cut_from.filter(|g| straddled.contains(g)) {
            None => joined.push(d.clone()),
            Some(group) if !done.contains(&group) => {
                done.push(group);
                let pieces: Vec<&DetectedObject> = detections
                    .iter()
                    .filter(|p| p.cut_from == Some(group))
                    .collect();
                joined.push(DetectedObject::joined(&pieces));
            }
            Some(_) => {}
        }
    }
    Some(joined)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_core::Point2;

    fn piece(x0: usize, x1: usize, group: Option<PixelBox>) -> DetectedObject {
        DetectedObject {
            cut_from: group,
            ..DetectedObject::filled(PixelBox {
                x0,
                y0: 0,
                x1,
                y1: 10,
            })
        }
    }

    fn at(x: f64) -> (Point2, f64) {
        (Point2::new(x, 5.0), 1.0)
    }

    #[test]
    fn a_cut_an_object_straddles_is_joined_and_others_are_kept() {
        let group = PixelBox {
            x0: 0,
            y0: 0,
            x1: 30,
            y1: 10,
        };
        let other = PixelBox { x0: 40, ..group };
        let detections = [
            piece(0, 12, Some(group)),
            piece(12, 30, Some(group)),
            piece(40, 50, Some(other)),
            piece(50, 60, Some(other)),
        ];
        // The first object has 3 of its 4 features on one side of the first cut and the
        // fourth on the other; the second keeps 9 of 10 to one piece of the second blob.
        let straddling = [at(2.0), at(5.0), at(8.0), at(20.0)];
        let mut apart = vec![at(42.0); 9];
        apart.push(at(55.5));
        let scores = LinkMatrix::new([&straddling[..], &apart[..]], &detections);
        let joined = join_straddled_cuts(&detections, &scores, &[0, 1], 0.2).unwrap();
        assert_eq!(joined.len(), 3);
        assert_eq!(joined[0].bbox, group);
        assert!(joined[0].cut_from.is_none());
        assert!(joined[0].mask.as_slice().iter().all(|&m| m));
        assert_eq!(joined[1..], detections[2..]);
        // One feature in ten across the cut is below the 0.2 link score: no straddle.
        let scores = LinkMatrix::new([&apart[..]], &detections);
        assert!(join_straddled_cuts(&detections, &scores, &[0], 0.2).is_none());
        // Rows not listed are not judged.
        let scores = LinkMatrix::new([&straddling[..], &apart[..]], &detections);
        assert!(join_straddled_cuts(&detections, &scores, &[1], 0.2).is_none());
    }

    #[test]
    fn pieces_are_joined_with_their_own_motion_pixels_only() {
        let group = PixelBox {
            x0: 0,
            y0: 0,
            x1: 20,
            y1: 10,
        };
        let mut low = piece(10, 20, Some(group));
        low.bbox.y0 = 5;
        low.mask = sillage_core::Image::from_vec(10, 5, vec![true; 50]).unwrap();
        let pieces = [piece(0, 10, Some(group)), low];
        let joined = DetectedObject::joined(&pieces.iter().collect::<Vec<_>>());
        assert_eq!(joined.bbox, group);
        assert!(joined.holds(Point2::new(3.0, 2.0)));
        assert!(!joined.holds(Point2::new(15.0, 2.0)));
        assert!(joined.holds(Point2::new(15.0, 7.0)));
    }
}

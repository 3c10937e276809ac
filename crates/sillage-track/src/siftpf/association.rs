//! The link-score matrix of Eq. (6) of Souded et al. and the links it gives (§2.3): each
//! tracked object `to_i(t−1)` against each detected object `do_j(t)`, scored by the
//! reliability-weighted share of its features lying on the detection; the best links chosen
//! by the Hungarian algorithm; an object the assignment leaves out joins the detection it
//! scores best on (a merge).

use sillage_assoc::solve_assignment;
use sillage_core::{Image, Point2};
use sillage_image::PixelBox;

/// One detected object `do_j(t)`: a motion blob's box and its motion pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct DetectedObject {
    /// The blob's box.
    pub bbox: PixelBox,
    /// Its motion pixels inside `bbox` (`bbox.width() × bbox.height()`).
    pub mask: Image<bool>,
    /// For a piece of a blob the detector cut into people, that blob's box (shared by its
    /// pieces); `None` otherwise.
    pub cut_from: Option<PixelBox>,
}

impl DetectedObject {
    /// A detection covering all of `bbox`.
    pub fn filled(bbox: PixelBox) -> Self {
        let mask = Image::from_vec(
            bbox.width(),
            bbox.height(),
            vec![true; bbox.width() * bbox.height()],
        )
        .expect("the mask has the box's size");
        Self {
            bbox,
            mask,
            cut_from: None,
        }
    }

    /// One detection made of `pieces`: the union of their boxes and motion pixels, uncut.
    pub fn joined(pieces: &[&DetectedObject]) -> Self {
        let bbox = pieces
            .iter()
            .map(|p| p.bbox)
            .reduce(|a, b| a.union(&b))
            .unwrap_or_default();
        let mut mask = Image::new(bbox.width(), bbox.height());
        for p in pieces {
            for y in 0..p.bbox.height() {
                let row = &mut mask.row_mut(p.bbox.y0 - bbox.y0 + y)[p.bbox.x0 - bbox.x0..];
                for (m, &on) in row.iter_mut().zip(p.mask.row(y)) {
                    *m |= on;
                }
            }
        }
        Self {
            bbox,
            mask,
            cut_from: None,
        }
    }

    /// True when `p` falls on one of the detection's motion pixels ("geometrically belongs").
    pub fn holds(&self, p: Point2) -> bool {
        let (x, y) = (p.x.round(), p.y.round());
        if x < self.bbox.x0 as f64 || y < self.bbox.y0 as f64 {
            return false;
        }
        let (x, y) = (x as usize - self.bbox.x0, y as usize - self.bbox.y0);
        x < self.bbox.width()
            && y < self.bbox.height()
            && self.mask.as_slice()[y * self.bbox.width() + x]
    }
}

/// The `M × N` link scores `s(to_i, do_j)` of Eq. (6), row-major.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinkMatrix {
    rows: usize,
    cols: usize,
    scores: Vec<f64>,
}

impl LinkMatrix {
    /// Eq. (6): `s(i, j) = (1/P) Σ_k w_k(i, j)`, for each object `i` given as its features'
    /// positions and reliabilities `w_k ∈ [0, 1]`.
    pub fn new<'a>(
        objects: impl IntoIterator<Item = &'a [(Point2, f64)]>,
        detections: &[DetectedObject],
    ) -> Self {
        let cols = detections.len();
        let mut scores = Vec::new();
        let mut rows = 0;
        for features in objects {
            rows += 1;
            let start = scores.len();
            scores.resize(start + cols, 0.0);
            let p = features.len() as f64;
            for &(pos, reliability) in features {
                if let Some(j) = detections.iter().position(|d| d.holds(pos)) {
                    scores[start + j] += reliability / p;
                }
            }
        }
        Self { rows, cols, scores }
    }

    /// `s(i, j)`.
    pub fn score(&self, i: usize, j: usize) -> f64 {
        self.scores[i * self.cols + j]
    }

    /// Overwrites `s(i, j)` (an object without features is scored by box overlap).
    pub fn set_score(&mut self, i: usize, j: usize, score: f64) {
        self.scores[i * self.cols + j] = score;
    }

    /// True when detection `j` holds a large part of object `i`'s features: a score of at
    /// least `min_link` and at least `min_share` of the object's total. An object with large
    /// parts on two detections is split across them (§2.3).
    pub fn holds_part(&self, i: usize, j: usize, min_link: f64, min_share: f64) -> bool {
        let total: f64 = (0..self.cols).map(|k| self.score(i, k)).sum();
        let s = self.score(i, j);
        s > 0.0 && s >= min_link && s >= min_share * total
    }

    /// Objects (rows).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Detections (columns).
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// The detection each object links to: the Hungarian assignment maximising the total
    /// score over links of at least `min_link`, then each object left out joins the
    /// detection it scores best on (at least `min_link`; ties to the first), which makes
    /// the merges of §2.3. `None`: no detection holds enough of its features.
    pub fn targets(&self, min_link: f64) -> Vec<Option<usize>> {
        let costs: Vec<f64> = self
            .scores
            .iter()
            .map(|&s| {
                if s >= min_link && s > 0.0 {
                    1.0 - s
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        let assigned = solve_assignment(self.rows, self.cols, &costs);
        (0..self.rows)
            .map(|i| {
                assigned[i].or_else(|| {
                    (0..self.cols)
                        .filter(|&j| self.score(i, j) >= min_link && self.score(i, j) > 0.0)
                        .fold(None, |best: Option<usize>, j| match best {
                            Some(b) if self.score(i, b) >= self.score(i, j) => Some(b),
                            _ => Some(j),
                        })
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn detection(x0: usize, x1: usize) -> DetectedObject {
        DetectedObject::filled(PixelBox {
            x0,
            y0: 0,
            x1,
            y1: 10,
        })
    }

    fn at(x: f64) -> Point2 {
        Point2::new(x, 5.0)
    }

    #[test]
    fn scores_are_reliability_weighted_shares() {
        let detections = [detection(0, 10), detection(20, 30)];
        let a = [
            (at(1.0), 1.0),
            (at(2.0), 0.5),
            (at(25.0), 1.0),
            (at(50.0), 1.0),
        ];
        let s = LinkMatrix::new([&a[..]], &detections);
        assert!((s.score(0, 0) - 1.5 / 4.0).abs() < 1e-12);
        assert!((s.score(0, 1) - 0.25).abs() < 1e-12);
        let mut hole = detection(0, 10);
        hole.mask.as_mut_slice()[5 * 10 + 1] = false;
        assert!(!hole.holds(at(1.0)) && hole.holds(at(2.0)) && !hole.holds(at(10.0)));
    }

    #[test]
    fn one_to_one_merge_and_lost() {
        let detections = [detection(0, 10), detection(20, 30)];
        let a = [(at(1.0), 1.0), (at(2.0), 1.0)];
        let b = [(at(3.0), 1.0), (at(21.0), 0.2)];
        let c = [(at(22.0), 1.0)];
        let gone = [(at(50.0), 1.0)];
        let s = LinkMatrix::new([&a[..], &b[..], &c[..], &gone[..]], &detections);
        // a and c take their detections; b, left out, merges with a; the last is unlinked.
        assert_eq!(s.targets(0.1), [Some(0), Some(0), Some(1), None]);
    }
}

//! The obviously-correct reference index: every query scans every point.

use sillage_core::Point2;

use crate::index::{Neighbour, NeighbourIndex, dist2, finish_distances, offer, precedes};

/// Exhaustive O(n) search per query over borrowed points; the reference [`crate::PointIndex`]
/// is tested against, and a fine choice for a few dozen points.
#[derive(Debug, Clone, Copy)]
pub struct BruteForceIndex<'a> {
    points: &'a [Point2],
}

impl<'a> BruteForceIndex<'a> {
    /// An index over `points` (nothing is copied).
    pub fn new(points: &'a [Point2]) -> Self {
        Self { points }
    }

    fn candidates(&self, p: Point2) -> impl Iterator<Item = Neighbour> + '_ {
        let finite_query = p.is_finite();
        self.points
            .iter()
            .enumerate()
            .filter(move |(_, q)| finite_query && q.is_finite())
            .map(move |(i, q)| (i, dist2(p, q.x, q.y)))
    }
}

impl NeighbourIndex for BruteForceIndex<'_> {
    fn len(&self) -> usize {
        self.points.len()
    }

    fn nearest(&self, p: Point2) -> Option<Neighbour> {
        self.candidates(p)
            .reduce(|best, c| if precedes(c, best) { c } else { best })
            .map(|(i, d2)| (i, d2.sqrt()))
    }

    fn k_nearest(&self, p: Point2, k: usize, out: &mut Vec<Neighbour>) {
        out.clear();
        if k == 0 {
            return;
        }
        for c in self.candidates(p) {
            offer(out, k, c);
        }
        finish_distances(out);
    }
}

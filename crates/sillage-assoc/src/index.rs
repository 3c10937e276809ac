//! The neighbour-query trait shared by the fast index and its brute-force reference.

use rayon::prelude::*;
use sillage_core::Point2;

/// One neighbour: its index in the indexed set and its Euclidean distance (px).
pub type Neighbour = (usize, f64);

/// Fewest queries a rayon task handles in the batch queries (keeps task overhead small).
pub(crate) const MIN_QUERIES_PER_TASK: usize = 256;

/// Nearest and k-nearest neighbour queries over a fixed set of points.
///
/// Ties are broken by the lower index, points with a non-finite coordinate are never
/// returned and a non-finite query finds nothing, so every implementation gives the same
/// answer bit for bit (the property the tests check against [`crate::BruteForceIndex`]).
pub trait NeighbourIndex: Sync {
    /// Number of points the index was built over (non-finite ones included).
    fn len(&self) -> usize;

    /// True when the index holds no point.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The point closest to `p`, or `None` when there is none (empty set, non-finite `p`).
    fn nearest(&self, p: Point2) -> Option<Neighbour>;

    /// The `min(k, len)` points closest to `p` into `out` (cleared first), nearest first.
    fn k_nearest(&self, p: Point2, k: usize, out: &mut Vec<Neighbour>);

    /// [`NeighbourIndex::nearest`] for every query, in parallel; `out[i]` answers `queries[i]`.
    /// `out` is overwritten and its allocation reused.
    fn nearest_batch(&self, queries: &[Point2], out: &mut Vec<Option<Neighbour>>) {
        queries
            .par_iter()
            .with_min_len(MIN_QUERIES_PER_TASK)
            .map(|&q| self.nearest(q))
            .collect_into_vec(out);
    }

    /// [`NeighbourIndex::k_nearest`] for every query, in parallel; `out[i]` answers
    /// `queries[i]`. The inner vectors are reused from call to call.
    fn k_nearest_batch(&self, queries: &[Point2], k: usize, out: &mut Vec<Vec<Neighbour>>) {
        out.resize_with(queries.len(), Vec::new);
        out.par_iter_mut()
            .zip(queries.par_iter())
            .with_min_len(MIN_QUERIES_PER_TASK)
            .for_each(|(row, &q)| self.k_nearest(q, k, row));
    }
}

/// True when candidate `a = (index, squared distance)` ranks before `b`: closer, or as
/// close with a lower index.
#[inline]
pub(crate) fn precedes(a: Neighbour, b: Neighbour) -> bool {
    a.1 < b.1 || (a.1 == b.1 && a.0 < b.0)
}

/// Offers a candidate `(index, squared distance)` to `best`, which keeps the `k` best
/// sorted by [`precedes`].
#[inline]
pub(crate) fn offer(best: &mut Vec<Neighbour>, k: usize, candidate: Neighbour) {
    if best.len() == k {
        match best.last() {
            Some(&worst) if precedes(candidate, worst) => {
                best.pop();
            }
            _ => return,
        }
    }
    let at = best.partition_point(|&b| precedes(b, candidate));
    best.insert(at, candidate);
}

/// Turns the squared distances of `best` into distances.
pub(crate) fn finish_distances(best: &mut [Neighbour]) {
    for n in best {
        n.1 = n.1.sqrt();
    }
}

/// Squared distance, computed the same way by every index so that ties are exact.
#[inline]
pub(crate) fn dist2(a: Point2, bx: f64, by: f64) -> f64 {
    let dx = a.x - bx;
    let dy = a.y - by;
    dx * dx + dy * dy
}

//! Unequivocal (mutual) nearest-neighbour pairs between two point sets.

use rayon::prelude::*;
use sillage_core::Point2;

use crate::{Neighbour, NeighbourIndex, PointIndex};

/// For each `from[i]`: `Some(j)` iff `to[j]` is the nearest point of `to` to `from[i]` and
/// `from[i]` is the nearest point of `from` to `to[j]`, and (when `max_distance` is given)
/// they are at most that far apart. These are the "unequivocal pairs" of §3.1.2 of the
/// TracTrac paper; ambiguous points get `None`.
///
/// Builds one [`PointIndex`] per set; callers that already hold indexes (a tracker reusing
/// a frame's index) call [`mutual_pairs_from_forward`] (or [`mutual_pairs`]) on their own
/// nearest-neighbour answers.
pub fn mutual_nearest_neighbours(
    from: &[Point2],
    to: &[Point2],
    max_distance: Option<f64>,
) -> Vec<Option<usize>> {
    let (to_index, from_index) = (PointIndex::new(to), PointIndex::new(from));
    let (mut forward, mut out, mut to_links) = (Vec::new(), Vec::new(), Vec::new());
    to_index.nearest_batch(from, &mut forward);
    mutual_pairs_from_forward(&from_index, from, to, &forward, &mut out, &mut to_links);
    if let Some(limit) = max_distance {
        // As `mutual_pairs`: a NaN limit keeps nothing.
        let within = |d: f64| d <= limit;
        for (link, f) in out.iter_mut().zip(&forward) {
            if f.is_some_and(|(_, d)| !within(d)) {
                *link = None;
            }
        }
    }
    out
}

/// The mutual pairs seen from the `from` side, given `forward[i]` (the nearest `to` point
/// of `from[i]`) and `backward[j]` (the nearest `from` point of `to[j]`). Swap the two
/// arguments to get the pairs seen from the `to` side. `out` is overwritten (allocation
/// reused). A `max_distance` that is NaN rejects every pair.
pub fn mutual_pairs(
    forward: &[Option<Neighbour>],
    backward: &[Option<Neighbour>],
    max_distance: Option<f64>,
    out: &mut Vec<Option<usize>>,
) {
    out.clear();
    out.extend(forward.iter().enumerate().map(|(i, f)| {
        let (j, d) = (*f)?;
        let within = max_distance.is_none_or(|m| d <= m);
        let back = backward.get(j).copied().flatten().map(|b| b.0);
        (within && back == Some(i)).then_some(j)
    }));
}

/// The mutual pairs between `from` and `to` from the forward answers alone
/// (`forward[i]`: the nearest `to` point of `from[i]`): the pair `i → j` is mutual when
/// `from[i]` is also the nearest point of `from` to `to[j]`, which
/// [`PointIndex::is_nearest`] checks within their distance only. Writes the pairs seen from
/// both sides, `from_links[i] = Some(j)` and `to_links[j] = Some(i)`: the same pairs as
/// [`mutual_pairs`] on both nearest-neighbour batches, without the backward batch.
/// `from_index` must index exactly `from`. Both outputs are overwritten (allocations reused).
pub fn mutual_pairs_from_forward(
    from_index: &PointIndex,
    from: &[Point2],
    to: &[Point2],
    forward: &[Option<Neighbour>],
    from_links: &mut Vec<Option<usize>>,
    to_links: &mut Vec<Option<usize>>,
) {
    forward
        .par_iter()
        .enumerate()
        .with_min_len(MIN_CHECKS_PER_TASK)
        .map(|(i, f)| {
            let (j, _) = (*f)?;
            from_index.is_nearest(to[j], i, from[i]).then_some(j)
        })
        .collect_into_vec(from_links);
    to_links.clear();
    to_links.resize(to.len(), None);
    for (i, link) in from_links.iter().enumerate() {
        if let Some(j) = *link {
            to_links[j] = Some(i);
        }
    }
}

/// Fewest pair checks a rayon task handles in [`mutual_pairs_from_forward`].
const MIN_CHECKS_PER_TASK: usize = 1024;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_from_forward_answers_match_both_batches() {
        // Jittered lattices with repeated points and exact ties (points on a grid of
        // integers, equidistant from many others), one set moved slightly.
        let from: Vec<_> = (0..900)
            .map(|i| {
                let j = if i % 5 == 0 {
                    0.0
                } else {
                    (i * 7919 % 101) as f64 / 404.0
                };
                Point2::new((i % 30) as f64 * 2.0 + j, (i / 30) as f64 * 2.0 - j)
            })
            .chain([Point2::new(10.0, 10.0); 3])
            .collect();
        let to: Vec<_> = from
            .iter()
            .enumerate()
            .filter(|(i, _)| i % 7 != 0)
            .map(|(i, p)| Point2::new(p.x + (i % 3) as f64 * 0.5, p.y + 1.0 - (i % 4) as f64 * 0.5))
            .collect();
        let (from_index, to_index) = (PointIndex::new(&from), PointIndex::new(&to));
        let (mut forward, mut backward) = (Vec::new(), Vec::new());
        to_index.nearest_batch(&from, &mut forward);
        from_index.nearest_batch(&to, &mut backward);
        let (mut expected_from, mut expected_to) = (Vec::new(), Vec::new());
        mutual_pairs(&forward, &backward, None, &mut expected_from);
        mutual_pairs(&backward, &forward, None, &mut expected_to);
        let (mut from_links, mut to_links) = (Vec::new(), Vec::new());
        mutual_pairs_from_forward(
            &from_index,
            &from,
            &to,
            &forward,
            &mut from_links,
            &mut to_links,
        );
        assert_eq!(from_links, expected_from);
        assert_eq!(to_links, expected_to);
        assert!(
            from_links.iter().flatten().count() > 300,
            "a test with pairs"
        );
        assert!(
            from_links.iter().filter(|l| l.is_none()).count() > 50,
            "and without"
        );
    }

    #[test]
    fn ambiguous_points_are_dropped_and_gate_applies() {
        // Two `from` points compete for the same `to` point: only the closer one pairs.
        let from = [
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(50.0, 0.0),
        ];
        let to = [Point2::new(1.2, 0.0), Point2::new(55.0, 0.0)];
        assert_eq!(
            mutual_nearest_neighbours(&from, &to, None),
            vec![None, Some(0), Some(1)]
        );
        assert_eq!(
            mutual_nearest_neighbours(&from, &to, Some(1.0)),
            vec![None, Some(0), None]
        );
        assert_eq!(mutual_nearest_neighbours(&[], &to, None), vec![]);
        assert_eq!(mutual_nearest_neighbours(&from, &[], None), vec![None; 3]);
    }
}

//! Unequivocal (mutual) nearest-neighbour pairs between two point sets.

use sillage_core::Point2;

use crate::{Neighbour, NeighbourIndex, PointIndex};

/// For each `from[i]`: `Some(j)` iff `to[j]` is the nearest point of `to` to `from[i]` and
/// `from[i]` is the nearest point of `from` to `to[j]`, and (when `max_distance` is given)
/// they are at most that far apart. These are the "unequivocal pairs" of §3.1.2 of the
/// TracTrac paper; ambiguous points get `None`.
///
/// Builds one [`PointIndex`] per set; callers that already hold indexes (a tracker reusing
/// a frame's index) call [`mutual_pairs`] on their own nearest-neighbour answers.
pub fn mutual_nearest_neighbours(
    from: &[Point2],
    to: &[Point2],
    max_distance: Option<f64>,
) -> Vec<Option<usize>> {
    let (from_index, to_index) = (PointIndex::new(from), PointIndex::new(to));
    let (mut forward, mut backward, mut out) = (Vec::new(), Vec::new(), Vec::new());
    to_index.nearest_batch(from, &mut forward);
    from_index.nearest_batch(to, &mut backward);
    mutual_pairs(&forward, &backward, max_distance, &mut out);
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

#[cfg(test)]
mod tests {
    use super::*;

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

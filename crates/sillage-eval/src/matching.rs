//! Per-frame grouping and greedy one-to-one matching of estimated to true positions.
//!
//! Greedy by ascending distance is what the PTV and detection scores need; optimal
//! assignment (Hungarian / LAPJV) belongs to `sillage-assoc`.

use std::collections::BTreeMap;

use sillage_core::{Error, FrameIndex, Point2, Result};

/// The true and estimated items of one frame.
pub(crate) struct FramePair<'a, T, E> {
    pub truth: Vec<&'a T>,
    pub estimates: Vec<&'a E>,
}

/// Groups `truth` and `estimates` by frame, in increasing frame order (inputs need not be
/// sorted; order within a frame is kept).
pub(crate) fn by_frame<'a, T, E>(
    truth: impl IntoIterator<Item = (FrameIndex, &'a T)>,
    estimates: impl IntoIterator<Item = (FrameIndex, &'a E)>,
) -> BTreeMap<FrameIndex, FramePair<'a, T, E>>
where
    T: 'a,
    E: 'a,
{
    let mut frames: BTreeMap<FrameIndex, FramePair<'a, T, E>> = BTreeMap::new();
    for (frame, item) in truth {
        frames
            .entry(frame)
            .or_insert_with(FramePair::empty)
            .truth
            .push(item);
    }
    for (frame, item) in estimates {
        frames
            .entry(frame)
            .or_insert_with(FramePair::empty)
            .estimates
            .push(item);
    }
    frames
}

impl<T, E> FramePair<'_, T, E> {
    fn empty() -> Self {
        Self {
            truth: Vec::new(),
            estimates: Vec::new(),
        }
    }
}

/// One matched pair: indices into the truth and estimate slices, and their distance (px).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Match {
    pub truth: usize,
    pub estimate: usize,
    pub distance: f64,
}

/// Matches each estimate to at most one truth point and back, greedily by ascending
/// distance (ties: lower estimate index, then lower truth index), keeping only pairs strictly
/// closer than `max_distance`. Candidates come from a sweep over truth sorted by `x`.
pub(crate) fn greedy_match(
    truth: &[Point2],
    estimates: &[Point2],
    max_distance: f64,
) -> Vec<Match> {
    let mut by_x: Vec<usize> = (0..truth.len()).collect();
    by_x.sort_by(|&a, &b| truth[a].x.total_cmp(&truth[b].x));
    let mut candidates = Vec::new();
    for (estimate, &p) in estimates.iter().enumerate() {
        let first = by_x.partition_point(|&t| truth[t].x <= p.x - max_distance);
        for &t in by_x[first..]
            .iter()
            .take_while(|&&t| truth[t].x < p.x + max_distance)
        {
            let distance = truth[t].distance(p);
            if distance < max_distance {
                candidates.push(Match {
                    truth: t,
                    estimate,
                    distance,
                });
            }
        }
    }
    candidates.sort_by(|a, b| {
        a.distance
            .total_cmp(&b.distance)
            .then(a.estimate.cmp(&b.estimate))
            .then(a.truth.cmp(&b.truth))
    });
    let mut truth_used = vec![false; truth.len()];
    let mut estimate_used = vec![false; estimates.len()];
    candidates.retain(|m| {
        let free = !truth_used[m.truth] && !estimate_used[m.estimate];
        if free {
            truth_used[m.truth] = true;
            estimate_used[m.estimate] = true;
        }
        free
    });
    candidates
}

/// Checks a matching radius: finite and > 0.
pub(crate) fn check_radius(key: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::parameter(
            key,
            value,
            "must be a finite number > 0 (px)",
        ))
    }
}

/// Fails when `pos` is not finite, naming `what` (e.g. "track point"), the frame and the id.
pub(crate) fn check_finite(what: &str, frame: FrameIndex, id: u64, pos: Point2) -> Result<()> {
    if pos.is_finite() {
        Ok(())
    } else {
        Err(Error::input(format!(
            "{what} of frame {frame}, id {id}: position ({}, {}) is not finite; \
             remove or fix this point",
            pos.x, pos.y
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute_force(truth: &[Point2], estimates: &[Point2], max_distance: f64) -> Vec<Match> {
        let mut all = Vec::new();
        for (t, &a) in truth.iter().enumerate() {
            for (e, &b) in estimates.iter().enumerate() {
                all.push(Match {
                    truth: t,
                    estimate: e,
                    distance: a.distance(b),
                });
            }
        }
        all.retain(|m| m.distance < max_distance);
        all.sort_by(|a, b| {
            a.distance
                .total_cmp(&b.distance)
                .then(a.estimate.cmp(&b.estimate))
                .then(a.truth.cmp(&b.truth))
        });
        let mut kept: Vec<Match> = Vec::new();
        for m in all {
            if kept
                .iter()
                .all(|k| k.truth != m.truth && k.estimate != m.estimate)
            {
                kept.push(m);
            }
        }
        kept
    }

    #[test]
    fn sweep_equals_brute_force() {
        // A deterministic scatter with clusters, so that many pairs compete.
        let point = |i: u64| {
            let h = i.wrapping_mul(0x9E37_79B9_7F4A_7C15);
            Point2::new((h >> 40) as f64 % 23.0 / 2.0, (h >> 20) as f64 % 17.0 / 2.0)
        };
        let truth: Vec<Point2> = (0..60).map(point).collect();
        let estimates: Vec<Point2> = (100..170).map(point).collect();
        for radius in [0.3, 1.0, 2.5] {
            assert_eq!(
                greedy_match(&truth, &estimates, radius),
                brute_force(&truth, &estimates, radius)
            );
        }
    }

    #[test]
    fn the_closest_pair_wins_and_matching_is_one_to_one() {
        let truth = [Point2::new(0.0, 0.0)];
        let estimates = [Point2::new(0.5, 0.0), Point2::new(0.2, 0.0)];
        let matches = greedy_match(&truth, &estimates, 1.0);
        assert_eq!(matches.len(), 1);
        assert_eq!(matches[0].estimate, 1);
        assert!(greedy_match(&truth, &[Point2::new(1.0, 0.0)], 1.0).is_empty());
    }
}

//! The greedy data association of §3.4 of the MMPF+ paper, shared by every bedload tracker:
//! each tracker is paired with the detections of its class inside the search region around
//! its prediction, each pair costs Eq. (2),
//! `g(tr, d) = α‖x_d − x̂_tr‖/r_s + β|u_tr|/|u|max`, and the cheapest pair is linked first,
//! removing its tracker and detection from the others, until no pair is left.

use sillage_assoc::PointIndex;
use sillage_core::{Detection, ObjectClass, Point2};

use crate::bedload::params::AssociationParams;

/// A tracker as the association sees it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct Query {
    /// Predicted position x̂, px.
    pub pred_px: Point2,
    /// Class: only detections of the same class are candidates.
    pub class: ObjectClass,
    /// |u| at the previous frame, px/frame (0 for a tracker without a velocity yet: the
    /// velocity term is 0 on a tracker's first association, §3.4.2).
    pub speed: f64,
}

/// One candidate pair.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
struct Pair {
    cost: f64,
    tracker: u32,
    detection: u32,
}

/// The association of one frame (buffers reused frame to frame).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct GreedyAssociation {
    index: PointIndex,
    positions: Vec<Point2>,
    pairs: Vec<Pair>,
    detection_taken: Vec<bool>,
}

impl GreedyAssociation {
    /// Links `queries` to `detections`: `out[t]` is the detection of tracker `t`, if any.
    /// Ties in cost go to the lower tracker index, then the lower detection index.
    pub fn associate(
        &mut self,
        params: &AssociationParams,
        queries: &[Query],
        detections: &[Detection],
        out: &mut Vec<Option<usize>>,
    ) {
        out.clear();
        out.resize(queries.len(), None);
        self.positions.clear();
        self.positions.extend(detections.iter().map(|d| d.pos_px));
        self.index.rebuild(&self.positions);
        // |u|max, the highest speed at the previous frame; without one the term is 0.
        let max_speed = queries.iter().map(|q| q.speed).fold(0.0, f64::max);
        let speed_weight = if max_speed > 0.0 {
            params.beta / max_speed
        } else {
            0.0
        };
        let r_s = params.search_radius_px;
        self.pairs.clear();
        for (t, q) in queries.iter().enumerate() {
            let velocity_term = speed_weight * q.speed;
            self.index.for_each_within(q.pred_px, r_s, |d, d2| {
                if detections[d].class == q.class {
                    self.pairs.push(Pair {
                        cost: params.alpha * d2.sqrt() / r_s + velocity_term,
                        tracker: t as u32,
                        detection: d as u32,
                    });
                }
            });
        }
        self.pairs.sort_unstable_by(|a, b| {
            a.cost
                .total_cmp(&b.cost)
                .then(a.tracker.cmp(&b.tracker))
                .then(a.detection.cmp(&b.detection))
        });
        self.detection_taken.clear();
        self.detection_taken.resize(detections.len(), false);
        for pair in &self.pairs {
            let (t, d) = (pair.tracker as usize, pair.detection as usize);
            if out[t].is_none() && !self.detection_taken[d] {
                out[t] = Some(d);
                self.detection_taken[d] = true;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::cmp::Ordering;

    use super::*;

    /// Cost, then tracker, then detection.
    fn by_cost(a: &(f64, usize, usize), b: &(f64, usize, usize)) -> Ordering {
        a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2))
    }

    fn det(x: f64, y: f64, class: ObjectClass) -> Detection {
        Detection::of_class(Point2::new(x, y), 1.0, class)
    }

    /// The paper's formulation: repeatedly take the global minimum over all remaining pairs.
    fn reference(
        params: &AssociationParams,
        queries: &[Query],
        detections: &[Detection],
    ) -> Vec<Option<usize>> {
        let max_speed = queries.iter().map(|q| q.speed).fold(0.0, f64::max);
        let mut pairs = Vec::new();
        for (t, q) in queries.iter().enumerate() {
            for (d, det) in detections.iter().enumerate() {
                let dist = (det.pos_px - q.pred_px).norm();
                if det.class == q.class && dist <= params.search_radius_px {
                    let v = if max_speed > 0.0 {
                        params.beta * q.speed / max_speed
                    } else {
                        0.0
                    };
                    pairs.push((params.alpha * dist / params.search_radius_px + v, t, d));
                }
            }
        }
        let mut out = vec![None; queries.len()];
        while let Some(&best) = pairs.iter().min_by(|a, b| by_cost(a, b)) {
            out[best.1] = Some(best.2);
            pairs.retain(|p| p.1 != best.1 && p.2 != best.2);
        }
        out
    }

    #[test]
    fn slow_trackers_win_close_calls() {
        // Two trackers predicted at the same distance from one detection: the slower one
        // (velocity term, §3.4.2) gets it.
        let params = AssociationParams::default();
        let queries = [
            Query {
                pred_px: Point2::new(0.0, 0.0),
                class: 1,
                speed: 20.0,
            },
            Query {
                pred_px: Point2::new(10.0, 0.0),
                class: 1,
                speed: 2.0,
            },
        ];
        let detections = [det(5.0, 0.0, 1), det(5.0, 0.0, 0)];
        let mut out = Vec::new();
        GreedyAssociation::default().associate(&params, &queries, &detections, &mut out);
        assert_eq!(out, vec![None, Some(0)]);
    }

    #[test]
    fn matches_the_global_minimum_formulation() {
        let params = AssociationParams::default();
        let mut association = GreedyAssociation::default();
        let mut out = Vec::new();
        for seed in 0..200u64 {
            let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
            let mut next = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            let queries: Vec<_> = (0..30)
                .map(|_| Query {
                    pred_px: Point2::new(next() * 200.0, next() * 100.0),
                    class: (next() * 2.0) as ObjectClass,
                    speed: if seed % 5 == 0 { 0.0 } else { next() * 15.0 },
                })
                .collect();
            let detections: Vec<_> = (0..35)
                .map(|_| {
                    det(
                        next() * 200.0,
                        next() * 100.0,
                        (next() * 2.0) as ObjectClass,
                    )
                })
                .collect();
            association.associate(&params, &queries, &detections, &mut out);
            assert_eq!(
                out,
                reference(&params, &queries, &detections),
                "seed {seed}"
            );
        }
    }
}

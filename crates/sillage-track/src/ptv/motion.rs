//! The local-flow motion model: velocities averaged over the k nearest samples (Eqs. 8, 11).

use sillage_assoc::PointIndex;
use sillage_core::{Point2, Vec2};

/// Log error given to points whose model has no weight (TracTrac's fill value).
const UNKNOWN_LOG_ERR: f64 = 2.0;

/// Velocity samples of the flow: where, which velocity, and how well it was predicted.
#[derive(Debug, Clone, Default)]
pub(crate) struct Samples {
    pub pos: Vec<Point2>,
    pub vel: Vec<Vec2>,
    pub log_err: Vec<f64>,
}

impl Samples {
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    pub fn clear(&mut self) {
        self.pos.clear();
        self.vel.clear();
        self.log_err.clear();
    }

    pub fn push(&mut self, pos: Point2, vel: Vec2, log_err: f64) {
        self.pos.push(pos);
        self.vel.push(vel);
        self.log_err.push(log_err);
    }
}

/// One sample as the model averages it, laid out in the index's storage order.
#[derive(Debug, Clone, Copy, Default)]
struct Weighted {
    weight: f64,
    vel: Vec2,
    log_err: f64,
}

/// Evaluates the motion model at query points, reusing its index and buffers.
#[derive(Debug, Clone)]
pub(crate) struct MotionField {
    k: usize,
    stored_weight: f64,
    /// Index over `recent ++ stored` positions, rebuilt at every evaluation.
    index: PointIndex,
    /// The samples in the index's storage order, so that a query's neighbours are read
    /// from a few contiguous runs rather than at random.
    by_slot: Vec<Weighted>,
    /// Per query: the weighted mean velocity and log error (NaN when weightless).
    means: Vec<(Vec2, f64)>,
}

impl MotionField {
    /// A model averaging `k` samples; stored samples weigh `stored_weight`, recent ones 1.
    pub fn new(k: usize, stored_weight: f64) -> Self {
        Self {
            k,
            stored_weight,
            // About k/5 points per cell: measured fastest for k = 10 among 2, 3.3 and 5
            // (`cargo bench -p sillage-assoc --bench neighbours -- occupancy`).
            index: PointIndex::with_occupancy((k as f64 / 5.0).max(1.0)),
            by_slot: Vec::new(),
            means: Vec::new(),
        }
    }

    /// For every query: the weighted mean velocity `u` (Eq. 8) and log error `e` (Eq. 11)
    /// of its `k` nearest samples among `recent` (the good tracklets, weight 1) and `stored`
    /// (the model kept from the previous step, weight `filter_time`), as TracTrac's
    /// `Propagate_MotionModel_KdTree`. Queries whose neighbours weigh nothing get u = 0,
    /// e = 2; the others become the model to store, written to `next`.
    ///
    /// The two sample sets are indexed together in place (no copy), `recent` first, so the
    /// neighbours and their summation order (nearest first, ties to `recent` and then to
    /// the lower index) are exactly those of a k-d tree query over the concatenation.
    ///
    /// Eq. (8) as printed lost its bars; it reads
    /// v̄ᵢ(t) = 1/min(k, N̂) Σⱼ [α v̂ᵢⱼ(t−1) + (1−α) v̄ᵢⱼ(t−1)]: a mix of tracklet velocities
    /// and earlier model velocities. The code (and this function) averages the k nearest of
    /// the union of both sets instead, with weights 1 and `filter_time`.
    pub fn evaluate(
        &mut self,
        queries: &[Point2],
        recent: &Samples,
        stored: &Samples,
        u: &mut Vec<Vec2>,
        e: &mut Vec<f64>,
        next: &mut Samples,
    ) {
        self.index.rebuild_concat(&recent.pos, &stored.pos);
        let n_recent = recent.len();
        self.by_slot.clear();
        self.by_slot
            .extend(self.index.slot_indexes().iter().map(|&i| {
                let i = i as usize;
                if i < n_recent {
                    Weighted {
                        weight: 1.0,
                        vel: recent.vel[i],
                        log_err: recent.log_err[i],
                    }
                } else {
                    let j = i - n_recent;
                    Weighted {
                        weight: self.stored_weight,
                        vel: stored.vel[j],
                        log_err: stored.log_err[j],
                    }
                }
            }));
        let by_slot = &self.by_slot;
        self.index
            .map_k_nearest(queries, self.k, &mut self.means, |_, slots| {
                let (mut w_sum, mut v_sum, mut e_sum) = (0.0, Vec2::ZERO, 0.0);
                for &slot in slots {
                    let s = by_slot[slot as usize];
                    w_sum += s.weight;
                    v_sum = v_sum + s.vel * s.weight;
                    e_sum += s.log_err * s.weight;
                }
                if w_sum > 0.0 {
                    (v_sum / w_sum, e_sum / w_sum)
                } else {
                    (Vec2::new(f64::NAN, f64::NAN), f64::NAN)
                }
            });
        u.clear();
        e.clear();
        next.clear();
        for (&q, &(mean_u, mean_e)) in queries.iter().zip(&self.means) {
            if mean_u.is_finite() {
                next.push(q, mean_u, mean_e);
                u.push(mean_u);
                e.push(mean_e);
            } else {
                u.push(Vec2::ZERO);
                e.push(UNKNOWN_LOG_ERR);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weighted_mean_of_nearest_samples() {
        let mut recent = Samples::default();
        recent.push(Point2::new(0.0, 0.0), Vec2::new(1.0, 0.0), -1.0);
        let mut stored = Samples::default();
        stored.push(Point2::new(1.0, 0.0), Vec2::new(4.0, 0.0), 0.0);
        stored.push(Point2::new(100.0, 0.0), Vec2::new(100.0, 0.0), 5.0);
        let mut field = MotionField::new(2, 2.0);
        let (mut u, mut e, mut next) = (Vec::new(), Vec::new(), Samples::default());
        field.evaluate(
            &[Point2::new(0.2, 0.0)],
            &recent,
            &stored,
            &mut u,
            &mut e,
            &mut next,
        );
        // (1·1 + 2·4) / 3 = 3, (1·(−1) + 2·0) / 3 = −1/3.
        assert_eq!(u, vec![Vec2::new(3.0, 0.0)]);
        assert!((e[0] + 1.0 / 3.0).abs() < 1e-15);
        assert_eq!(next.len(), 1);

        // Weight 0 on stored samples and no recent one nearby: unknown, not stored.
        let mut field = MotionField::new(1, 0.0);
        field.evaluate(
            &[Point2::new(99.0, 0.0)],
            &recent,
            &stored,
            &mut u,
            &mut e,
            &mut next,
        );
        assert_eq!((u[0], e[0], next.len()), (Vec2::ZERO, UNKNOWN_LOG_ERR, 0));
    }
}

//! The local-flow motion model: velocities averaged over the k nearest samples (Eqs. 8, 11).

use rayon::prelude::*;
use sillage_assoc::PointIndex;
use sillage_core::{Point2, Vec2};

/// Fewest samples a rayon task lays out in [`MotionField::prepare`].
const PAR_MIN_SLOTS: usize = 4096;

/// Log error given to points whose model has no weight (TracTrac's fill value).
const UNKNOWN_LOG_ERR: f64 = 2.0;

/// Velocity samples of the flow: where, which velocity, and how well it was predicted.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
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

/// One sample as the model averages it.
#[derive(Debug, Clone, Copy, Default, serde::Serialize, serde::Deserialize)]
struct Weighted {
    weight: f64,
    vel: Vec2,
    log_err: f64,
}

/// The samples at one indexed position (one or two, [`MotionField`]'s `counts`), in the
/// order the k-nearest of `recent ++ stored` meets them: the recent one first (lower index),
/// then the stored one.
type Copies = [Weighted; 2];

/// Evaluates the motion model at query points, reusing its index and buffers.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct MotionField {
    k: usize,
    stored_weight: f64,
    /// Index over the samples' positions, rebuilt at every evaluation.
    index: PointIndex,
    /// The samples in the index's storage order, so that a query's neighbours are read
    /// from a few contiguous runs rather than at random, and how many each slot holds.
    by_slot: Vec<Copies>,
    counts: Vec<u8>,
    /// Per stored sample: the recent sample at the same position, if any.
    partners: Vec<Option<usize>>,
    /// Whether the last `prepare` indexed the stored positions with counts (steady state)
    /// rather than the concatenation of both sets.
    counted: bool,
    /// Per query: the weighted mean velocity and log error (NaN when weightless).
    means: Vec<(Vec2, f64)>,
}

impl MotionField {
    /// A model averaging `k` samples; stored samples weigh `stored_weight`, recent ones 1.
    pub fn new(k: usize, stored_weight: f64) -> Self {
        Self {
            k,
            stored_weight,
            // About k/8 positions per cell: in steady state the k samples come from ~k/2
            // positions (most hold two); k/8 stepped faster than k/5 (BENCHMARKS.md, "The
            // linking step").
            index: PointIndex::with_occupancy((k as f64 / 8.0).max(1.0)),
            by_slot: Vec::new(),
            counts: Vec::new(),
            partners: Vec::new(),
            counted: false,
            means: Vec::new(),
        }
    }

    /// Indexes the samples: `recent` (the good tracklets, weight 1) and `stored` (the model
    /// kept from the previous step, weight `filter_time`). Call before
    /// [`MotionField::evaluate`]; it is separate so that the tracker can run it beside the
    /// other index it builds at the start of a step.
    ///
    /// In steady state every recent sample sits exactly on a stored one (both are points of
    /// the same frame, in the same order): the stored positions alone are then indexed, each
    /// standing for one or two samples, which halves the index and the neighbours to find.
    pub fn prepare(&mut self, recent: &Samples, stored: &Samples) {
        let recent_sample = |i: usize| Weighted {
            weight: 1.0,
            vel: recent.vel[i],
            log_err: recent.log_err[i],
        };
        let stored_sample = |i: usize| Weighted {
            weight: self.stored_weight,
            vel: stored.vel[i],
            log_err: stored.log_err[i],
        };
        self.counted = pair_with_stored(recent, stored, &mut self.partners);
        if self.counted {
            self.index.rebuild(&stored.pos);
            let partners = &self.partners;
            let slots = self.index.slot_indexes();
            slots
                .par_iter()
                .with_min_len(PAR_MIN_SLOTS)
                .map(|&i| match partners[i as usize] {
                    Some(r) => [recent_sample(r), stored_sample(i as usize)],
                    None => [stored_sample(i as usize), Weighted::default()],
                })
                .collect_into_vec(&mut self.by_slot);
            slots
                .par_iter()
                .with_min_len(PAR_MIN_SLOTS)
                .map(|&i| if partners[i as usize].is_some() { 2 } else { 1 })
                .collect_into_vec(&mut self.counts);
        } else {
            self.index.rebuild_concat(&recent.pos, &stored.pos);
            let n_recent = recent.len();
            self.by_slot.clear();
            self.by_slot
                .extend(self.index.slot_indexes().iter().map(|&i| {
                    let i = i as usize;
                    let sample = if i < n_recent {
                        recent_sample(i)
                    } else {
                        stored_sample(i - n_recent)
                    };
                    [sample, Weighted::default()]
                }));
        }
    }

    /// For every query: the weighted mean velocity `u` (Eq. 8) and log error `e` (Eq. 11)
    /// of its `k` nearest samples among those of the last [`MotionField::prepare`], as
    /// TracTrac's `Propagate_MotionModel_KdTree`. Queries whose neighbours weigh nothing get
    /// u = 0, e = 2; the others become the model to store, written to `next`.
    ///
    /// The neighbours and their summation order (nearest first, ties to `recent` and then
    /// to the lower index) are those of a k-d tree query over the concatenation
    /// `recent ++ stored`; on the steady-state path of [`MotionField::prepare`], two
    /// different points at exactly the same distance from a query give their samples point
    /// by point rather than recent ones first.
    ///
    /// Eq. (8) as printed lost its bars; it reads
    /// v̄ᵢ(t) = 1/min(k, N̂) Σⱼ [α v̂ᵢⱼ(t−1) + (1−α) v̄ᵢⱼ(t−1)]: a mix of tracklet velocities
    /// and earlier model velocities. The code (and this function) averages the k nearest of
    /// the union of both sets instead, with weights 1 and `filter_time`.
    pub fn evaluate(
        &mut self,
        queries: &[Point2],
        u: &mut Vec<Vec2>,
        e: &mut Vec<f64>,
        next: &mut Samples,
    ) {
        let by_slot = &self.by_slot;
        if self.counted {
            let counts = &self.counts;
            self.index.map_k_nearest_counted(
                queries,
                self.k,
                counts,
                &mut self.means,
                |slots, last_taken| {
                    // Plain loops rather than one chained iterator: this runs per query.
                    let mut sum = WeightedSum::default();
                    if let Some((&last, before)) = slots.split_last() {
                        for &s in before {
                            let s = s as usize;
                            by_slot[s][..usize::from(counts[s])]
                                .iter()
                                .for_each(|w| sum.add(w));
                        }
                        by_slot[last as usize][..last_taken]
                            .iter()
                            .for_each(|w| sum.add(w));
                    }
                    sum.mean()
                },
            );
        } else {
            self.index
                .map_k_nearest(queries, self.k, &mut self.means, |_, slots| {
                    weighted_mean(slots.iter().map(|&s| &by_slot[s as usize][0]))
                });
        }
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

/// Weighted means of the samples' velocities and log errors, summed in the order given;
/// NaN when they weigh nothing.
fn weighted_mean<'a>(samples: impl Iterator<Item = &'a Weighted>) -> (Vec2, f64) {
    let mut sum = WeightedSum::default();
    samples.for_each(|s| sum.add(s));
    sum.mean()
}

/// Running sums of weights, weighted velocities and weighted log errors.
#[derive(Default)]
struct WeightedSum {
    weight: f64,
    vel: Vec2,
    log_err: f64,
}

impl WeightedSum {
    #[inline]
    fn add(&mut self, s: &Weighted) {
        self.weight += s.weight;
        self.vel = self.vel + s.vel * s.weight;
        self.log_err += s.log_err * s.weight;
    }

    /// The weighted means (NaN when the samples weigh nothing).
    #[inline]
    fn mean(&self) -> (Vec2, f64) {
        if self.weight > 0.0 {
            (self.vel / self.weight, self.log_err / self.weight)
        } else {
            (Vec2::new(f64::NAN, f64::NAN), f64::NAN)
        }
    }
}

/// Pairs each recent sample with the stored sample at exactly the same position, walking
/// both sets in order (`partners[j]` is the recent partner of stored sample `j`); true when
/// every recent sample found one, as when both sets are points of the same frame in the same
/// order (the tracker's steady state).
fn pair_with_stored(recent: &Samples, stored: &Samples, partners: &mut Vec<Option<usize>>) -> bool {
    partners.clear();
    let mut next = 0;
    for &p in &stored.pos {
        if next < recent.len() && recent.pos[next] == p {
            partners.push(Some(next));
            next += 1;
        } else {
            partners.push(None);
        }
    }
    next == recent.len()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;
    use sillage_core::rng_stream;

    /// The model by brute force: the k nearest of `recent ++ stored` sorted by (distance,
    /// index), summed in that order.
    fn brute_force(q: Point2, k: usize, recent: &Samples, stored: &Samples, w: f64) -> (Vec2, f64) {
        let mut all: Vec<(f64, usize, Weighted)> = Vec::new();
        for (i, set, weight) in [(0, recent, 1.0), (recent.len(), stored, w)] {
            for j in 0..set.len() {
                let d = set.pos[j] - q;
                let sample = Weighted {
                    weight,
                    vel: set.vel[j],
                    log_err: set.log_err[j],
                };
                all.push((d.x * d.x + d.y * d.y, i + j, sample));
            }
        }
        all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        weighted_mean(all.iter().take(k).map(|(_, _, s)| s))
    }

    #[test]
    fn steady_state_samples_give_the_union_model_exactly() {
        // Stored: every point of a frame; recent: two thirds of them, same positions, same
        // order (the tracker's steady state), then the same sets with one recent sample moved
        // (the general path).
        let mut rng = rng_stream(5, 0);
        let mut stored = Samples::default();
        let mut recent = Samples::default();
        for i in 0..400u32 {
            let p = Point2::new(rng.random::<f64>() * 100.0, rng.random::<f64>() * 100.0);
            let v = Vec2::new(rng.random::<f64>(), rng.random::<f64>());
            stored.push(p, v, rng.random::<f64>() - 1.0);
            if !i.is_multiple_of(3) {
                recent.push(p, v * 1.1, rng.random::<f64>() - 2.0);
            }
        }
        let queries: Vec<Point2> = (0..200)
            .map(|_| {
                Point2::new(
                    rng.random::<f64>() * 110.0 - 5.0,
                    rng.random::<f64>() * 110.0 - 5.0,
                )
            })
            .collect();
        let mut moved = recent.clone();
        moved.pos[7].x += 0.25;
        for (recent, k, w) in [(&recent, 10, 1.0), (&recent, 7, 0.5), (&moved, 10, 1.0)] {
            let mut field = MotionField::new(k, w);
            let (mut u, mut e, mut next) = (Vec::new(), Vec::new(), Samples::default());
            field.prepare(recent, &stored);
            field.evaluate(&queries, &mut u, &mut e, &mut next);
            for (i, &q) in queries.iter().enumerate() {
                let (bu, be) = brute_force(q, k, recent, &stored, w);
                assert_eq!((u[i], e[i]), (bu, be), "query {i}, k {k}");
            }
        }
    }

    #[test]
    fn weighted_mean_of_nearest_samples() {
        let mut recent = Samples::default();
        recent.push(Point2::new(0.0, 0.0), Vec2::new(1.0, 0.0), -1.0);
        let mut stored = Samples::default();
        stored.push(Point2::new(1.0, 0.0), Vec2::new(4.0, 0.0), 0.0);
        stored.push(Point2::new(100.0, 0.0), Vec2::new(100.0, 0.0), 5.0);
        let mut field = MotionField::new(2, 2.0);
        let (mut u, mut e, mut next) = (Vec::new(), Vec::new(), Samples::default());
        field.prepare(&recent, &stored);
        field.evaluate(&[Point2::new(0.2, 0.0)], &mut u, &mut e, &mut next);
        // (1·1 + 2·4) / 3 = 3, (1·(−1) + 2·0) / 3 = −1/3.
        assert_eq!(u, vec![Vec2::new(3.0, 0.0)]);
        assert!((e[0] + 1.0 / 3.0).abs() < 1e-15);
        assert_eq!(next.len(), 1);

        // Weight 0 on stored samples and no recent one nearby: unknown, not stored.
        let mut field = MotionField::new(1, 0.0);
        field.prepare(&recent, &stored);
        field.evaluate(&[Point2::new(99.0, 0.0)], &mut u, &mut e, &mut next);
        assert_eq!((u[0], e[0], next.len()), (Vec2::ZERO, UNKNOWN_LOG_ERR, 0));
    }
}

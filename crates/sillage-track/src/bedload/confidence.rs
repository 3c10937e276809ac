//! The detector-confidence density of Eq. (1) of the MMPF+ paper,
//! `d_c(x) = Σ_{d∈D} L(d) exp(−λ‖x − x_d‖)`, the likelihood of a tracker's particles when no
//! detection was associated to it (Eq. (8)). It is evaluated only where it is needed, at the
//! particles, over the candidates within the kernel's support found by a neighbour grid,
//! never as a full-frame map; `k_D` is left out, as it cancels when a tracker's weights are
//! normalised.

use sillage_assoc::PointIndex;
use sillage_core::{Detection, ObjectClass, Point2};

use crate::bedload::params::{ConfidenceSet, LikelihoodParams};

/// Candidates closer than this to an associated detection of their class are that detection
/// (px; detectors report a detection among their candidates at the same pixel).
const SAME_CANDIDATE_PX: f64 = 1.0;

/// The candidates of one class in one frame.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
struct ClassDensity {
    positions: Vec<Point2>,
    likelihoods: Vec<f64>,
    index: PointIndex,
}

/// The density of every class for one frame (buffers reused frame to frame).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct ConfidenceDensity {
    classes: Vec<ClassDensity>,
    claimed: PointIndex,
    claimed_positions: Vec<Point2>,
    claimed_classes: Vec<ObjectClass>,
    lambda: f64,
    support: f64,
}

impl ConfidenceDensity {
    /// Builds the density of each of `n_classes` classes from this frame's `candidates`, or,
    /// for a class without candidates, from its `detections` with `L(d) = 1` (the paper's
    /// rule for black beads). With [`ConfidenceSet::Unclaimed`], candidates at the detections
    /// `claimed` (associated to a tracker) are left out.
    pub fn rebuild(
        &mut self,
        params: &LikelihoodParams,
        n_classes: usize,
        candidates: &[Detection],
        detections: &[Detection],
        claimed: impl Iterator<Item = usize>,
    ) {
        self.lambda = params.lambda_per_px;
        self.support = params.support_px;
        self.claimed_positions.clear();
        self.claimed_classes.clear();
        if params.confidence_set == ConfidenceSet::Unclaimed {
            for k in claimed {
                self.claimed_positions.push(detections[k].pos_px);
                self.claimed_classes.push(detections[k].class);
            }
        }
        self.claimed.rebuild(&self.claimed_positions);
        self.classes.resize_with(n_classes, ClassDensity::default);
        for (class, density) in self.classes.iter_mut().enumerate() {
            let class = class as ObjectClass;
            let has_candidates = candidates.iter().any(|c| c.class == class);
            let source = if has_candidates {
                candidates
            } else {
                detections
            };
            density.positions.clear();
            density.likelihoods.clear();
            for d in source.iter().filter(|d| d.class == class) {
                let mut taken = false;
                self.claimed
                    .for_each_within(d.pos_px, SAME_CANDIDATE_PX, |j, _| {
                        taken |= self.claimed_classes[j] == class;
                    });
                if !taken {
                    density.positions.push(d.pos_px);
                    density.likelihoods.push(if has_candidates {
                        d.strength as f64
                    } else {
                        1.0
                    });
                }
            }
            density.index.rebuild(&density.positions);
        }
    }

    /// `ln d_c(x)` for class `class` (−∞ where no candidate is within the support).
    pub fn log_value(&self, class: ObjectClass, x: Point2) -> f64 {
        let Some(density) = self.classes.get(class as usize) else {
            return f64::NEG_INFINITY;
        };
        let mut sum = 0.0;
        density.index.for_each_within(x, self.support, |j, d2| {
            sum += density.likelihoods[j] * (-self.lambda * d2.sqrt()).exp();
        });
        sum.ln()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(set: ConfidenceSet) -> LikelihoodParams {
        LikelihoodParams {
            confidence_set: set,
            ..LikelihoodParams::default()
        }
    }

    #[test]
    fn eq1_sums_kernels_within_the_support() {
        let candidates = [
            Detection::of_class(Point2::new(10.0, 10.0), 0.25, 1),
            Detection::of_class(Point2::new(13.0, 14.0), 0.5, 1),
            Detection::of_class(Point2::new(40.0, 10.0), 0.9, 1),
        ];
        let mut density = ConfidenceDensity::default();
        density.rebuild(
            &params(ConfidenceSet::All),
            2,
            &candidates,
            &[],
            [].into_iter(),
        );
        let x = Point2::new(10.0, 10.0);
        let expected = 0.25 + 0.5 * (-5.0f64).exp();
        assert!((density.log_value(1, x) - expected.ln()).abs() < 1e-12);
        // Class 0 has neither candidates nor detections; class 7 does not exist.
        assert_eq!(density.log_value(0, x), f64::NEG_INFINITY);
        assert_eq!(density.log_value(7, x), f64::NEG_INFINITY);
        assert_eq!(
            density.log_value(1, Point2::new(25.0, 30.0)),
            f64::NEG_INFINITY
        );
    }

    #[test]
    fn black_beads_use_their_detections_and_claimed_ones_are_left_out() {
        let detections = [
            Detection::of_class(Point2::new(0.0, 0.0), 1.0, 0),
            Detection::of_class(Point2::new(3.0, 4.0), 1.0, 0),
        ];
        let mut density = ConfidenceDensity::default();
        let p = params(ConfidenceSet::Unclaimed);
        density.rebuild(&p, 1, &[], &detections, [].into_iter());
        let both = 1.0 + (-5.0f64).exp();
        assert!((density.log_value(0, Point2::new(0.0, 0.0)) - both.ln()).abs() < 1e-12);
        density.rebuild(&p, 1, &[], &detections, [0].into_iter());
        assert!((density.log_value(0, Point2::new(0.0, 0.0)) + 5.0).abs() < 1e-12);
    }
}

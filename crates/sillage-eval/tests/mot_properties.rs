//! Properties of CLEAR MOT, Identity and HOTA on seeded synthetic scenes.

mod common;

use common::scene::{Rng, SceneSpec, scene};
use proptest::prelude::*;
use sillage_eval::mot::{
    MotConvention, MotData, MotEstimate, MotMetrics, MotParams, MotTruth, Shape, Similarity,
    evaluate_mot,
};

fn evaluate(
    truth: &[MotTruth],
    estimates: &[MotEstimate],
    convention: MotConvention,
) -> MotMetrics {
    let data = MotData::new(truth, estimates, Similarity::BoxIou, None).unwrap();
    let params = MotParams {
        convention,
        ..MotParams::default()
    };
    evaluate_mot(&data, &params).unwrap()
}

fn spec() -> impl Strategy<Value = SceneSpec> {
    (
        1u64..40,
        1u64..12,
        1u64..30,
        0.0f64..0.4,
        0u64..4,
        0u64..15,
        0.0f64..8.0,
        any::<u64>(),
    )
        .prop_map(
            |(
                frames,
                objects_per_frame,
                lifetime,
                miss_rate,
                false_positives,
                switch_every,
                noise_px,
                seed,
            )| {
                SceneSpec {
                    frames,
                    objects_per_frame,
                    lifetime,
                    miss_rate,
                    false_positives,
                    switch_every,
                    noise_px,
                    seed,
                }
            },
        )
}

const BOTH: [MotConvention; 2] = [MotConvention::TrackEval, MotConvention::PyMotMetrics];

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// A tracker that reports the truth exactly, under other ids, scores 1 everywhere.
    #[test]
    fn a_perfect_tracker_scores_one(spec in spec()) {
        let (truth, _) = scene(&spec);
        let perfect: Vec<MotEstimate> = truth
            .iter()
            .map(|t| MotEstimate { frame: t.frame, id: t.id + 77, shape: t.shape })
            .collect();
        for convention in BOTH {
            let m = evaluate(&truth, &perfect, convention);
            prop_assert_eq!(m.clear.mota, 1.0);
            prop_assert_eq!(m.identity.idf1, 1.0);
            prop_assert_eq!(m.hota.hota, 1.0);
            prop_assert_eq!((m.hota.det_a, m.hota.ass_a, m.hota.loc_a), (1.0, 1.0, 1.0));
            prop_assert_eq!(m.clear.motp, 1.0);
            let c = m.clear;
            prop_assert_eq!((c.false_negatives, c.false_positives, c.id_switches, c.fragmentations), (0, 0, 0, 0));
        }
    }

    /// Renaming true and estimated ids (any bijection) changes nothing, bit for bit.
    #[test]
    fn renaming_ids_changes_nothing(spec in spec(), salt in any::<u64>()) {
        let (truth, estimates) = scene(&spec);
        // An odd multiplier is a bijection of u64; xor keeps it one.
        let rename = |id: u64| id.wrapping_mul(salt | 1) ^ 0x5555;
        let truth2: Vec<MotTruth> = truth.iter().map(|t| MotTruth { id: rename(t.id), ..*t }).collect();
        let estimates2: Vec<MotEstimate> =
            estimates.iter().map(|e| MotEstimate { id: rename(e.id).rotate_left(7), ..*e }).collect();
        for convention in BOTH {
            prop_assert_eq!(evaluate(&truth, &estimates, convention), evaluate(&truth2, &estimates2, convention));
        }
    }

    /// The order of the input rows does not matter (counts exact, scores to rounding).
    #[test]
    fn row_order_does_not_matter(spec in spec(), seed in any::<u64>()) {
        let (truth, estimates) = scene(&spec);
        let mut rng = Rng::new(seed);
        let shuffle = |n: usize, rng: &mut Rng| {
            let mut order: Vec<usize> = (0..n).collect();
            for i in (1..n).rev() {
                order.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
            }
            order
        };
        let truth2: Vec<MotTruth> = shuffle(truth.len(), &mut rng).into_iter().map(|i| truth[i]).collect();
        let estimates2: Vec<MotEstimate> =
            shuffle(estimates.len(), &mut rng).into_iter().map(|i| estimates[i]).collect();
        for convention in BOTH {
            let (a, b) = (evaluate(&truth, &estimates, convention), evaluate(&truth2, &estimates2, convention));
            prop_assert_eq!(
                (a.clear.true_positives, a.clear.false_positives, a.clear.id_switches, a.clear.fragmentations),
                (b.clear.true_positives, b.clear.false_positives, b.clear.id_switches, b.clear.fragmentations)
            );
            prop_assert_eq!(a.identity.idtp, b.identity.idtp);
            prop_assert_eq!(a.hota.per_alpha.true_positives, b.hota.per_alpha.true_positives);
            prop_assert!((a.hota.hota - b.hota.hota).abs() < 1e-12);
            prop_assert!((a.clear.motp - b.clear.motp).abs() < 1e-12);
        }
    }

    /// Shifting every estimate beyond any overlap leaves no match: MOTA = −FP / GT,
    /// IDF1 = HOTA = 0.
    #[test]
    fn estimates_beyond_the_threshold_match_nothing(spec in spec()) {
        let (truth, estimates) = scene(&spec);
        let shifted: Vec<MotEstimate> = estimates
            .iter()
            .map(|e| {
                let Shape::Box(mut b) = e.shape else { unreachable!() };
                b.left_px += 5000.0;
                MotEstimate { shape: Shape::Box(b), ..*e }
            })
            .collect();
        for convention in BOTH {
            let m = evaluate(&truth, &shifted, convention);
            prop_assert_eq!(m.clear.true_positives, 0);
            prop_assert_eq!(m.clear.mota, -(shifted.len() as f64) / truth.len() as f64);
            prop_assert_eq!((m.identity.idf1, m.hota.hota, m.hota.det_a), (0.0, 0.0, 0.0));
        }
    }

    /// Counts add up, scores stay in range, and detection at a stricter α finds no more.
    #[test]
    fn counts_add_up_and_scores_are_bounded(spec in spec()) {
        let (truth, estimates) = scene(&spec);
        for convention in BOTH {
            let m = evaluate(&truth, &estimates, convention);
            let c = m.clear;
            prop_assert_eq!(c.true_positives + c.false_negatives, truth.len() as u64);
            prop_assert_eq!(c.true_positives + c.false_positives, estimates.len() as u64);
            prop_assert_eq!(m.identity.idtp + m.identity.idfn, truth.len() as u64);
            prop_assert_eq!(m.identity.idtp + m.identity.idfp, estimates.len() as u64);
            prop_assert!(c.mota <= 1.0 && c.id_switches <= c.true_positives);
            for v in [m.identity.idf1, m.hota.hota, m.hota.det_a, m.hota.ass_a, m.hota.loc_a] {
                prop_assert!((0.0..=1.0).contains(&v), "{v}");
            }
            let tp = m.hota.per_alpha.true_positives;
            prop_assert!(tp.windows(2).all(|w| w[0] >= w[1]));
        }
    }
}

//! CLEAR MOT and Identity on hand-made sequences: where TrackEval and py-motmetrics differ,
//! the optimal identity assignment, MOTChallenge preprocessing, and input errors.

use sillage_core::BoundingBox;
use sillage_core::Point2;
use sillage_eval::mot::{
    FrameSimilarities, MotChallengeProtocol, MotConvention, MotData, MotEstimate, MotParams,
    MotTruth, Shape, Similarity, TruthRole, clear_events, clear_mot, identity,
};

/// Points compared by distance: similarity 1 − d / 2, so 0.5 ↔ d = 1 px.
const DISTANCE: Similarity = Similarity::Distance {
    zero_distance_px: 2.0,
};

fn truth(frame: u64, id: u64, x: f64) -> MotTruth {
    MotTruth {
        frame,
        id,
        shape: Shape::Point(Point2::new(x, 0.0)),
        role: TruthRole::Scored,
    }
}

fn estimate(frame: u64, id: u64, x: f64) -> MotEstimate {
    MotEstimate {
        frame,
        id,
        shape: Shape::Point(Point2::new(x, 0.0)),
    }
}

fn params(convention: MotConvention) -> MotParams {
    MotParams {
        convention,
        ..MotParams::default()
    }
}

const BOTH: [MotConvention; 2] = [MotConvention::TrackEval, MotConvention::PyMotMetrics];

/// Truth A at x = 0 in frames 0–2. Frame 0: x at 0.2 (similarity 0.9) → A–x. Frame 1: only
/// y, far away → A missed, y a false positive. Frame 2: x at 0.8 (0.6) and y at 0.2 (0.9).
///
/// TrackEval favours only the pair of the previous frame, which frame 1 broke: frame 2
/// takes the best similarity, A–y, a switch. py-motmetrics remembers A–x across the gap and
/// keeps it: no switch. Both: TP 2, FN 1, FP 2, and one fragmentation.
#[test]
fn continuation_across_a_gap_differs() {
    let t = [truth(0, 1, 0.0), truth(1, 1, 0.0), truth(2, 1, 0.0)];
    let e = [
        estimate(0, 10, 0.2),
        estimate(1, 20, 50.0),
        estimate(2, 10, 0.8),
        estimate(2, 20, 0.2),
    ];
    let data = MotData::new(&t, &e, DISTANCE, None).unwrap();
    for (convention, switches, frame_2_estimate) in [
        (MotConvention::TrackEval, 1, 20),
        (MotConvention::PyMotMetrics, 0, 10),
    ] {
        let c = clear_mot(&data, &params(convention)).unwrap();
        let counts = (c.true_positives, c.false_negatives, c.false_positives);
        assert_eq!(counts, (2, 1, 2), "{convention:?}");
        assert_eq!(
            (c.id_switches, c.fragmentations),
            (switches, 1),
            "{convention:?}"
        );
        // MOTA = (TP − FP − IDSW) / GT.
        assert_eq!(c.mota, (2.0 - 2.0 - switches as f64) / 3.0);
        let events = clear_events(&data, &params(convention)).unwrap();
        assert_eq!(events[2].matches[0].estimate_id, frame_2_estimate);
        assert_eq!(events[1].misses, vec![1]);
        assert_eq!(events[1].false_positives, vec![20]);
        let switched = events[2].matches[0].switched_from;
        assert_eq!(switched, (switches == 1).then_some(10));
    }
}

/// Truth A in frames 0–2, x on it in frames 0 and 2, no estimate at all in frame 1.
/// TrackEval skips frame 1 before resetting its previous-frame pairs, so tracking does not
/// restart in frame 2: Frag 0. py-motmetrics sees tracked, missed, tracked: Frag 1.
#[test]
fn a_frame_without_estimates_is_no_fragmentation_for_trackeval() {
    let t = [truth(0, 1, 0.0), truth(1, 1, 0.0), truth(2, 1, 0.0)];
    let e = [estimate(0, 10, 0.0), estimate(2, 10, 0.0)];
    let data = MotData::new(&t, &e, DISTANCE, None).unwrap();
    let frag = |convention| {
        clear_mot(&data, &params(convention))
            .unwrap()
            .fragmentations
    };
    assert_eq!(frag(MotConvention::TrackEval), 0);
    assert_eq!(frag(MotConvention::PyMotMetrics), 1);
    for convention in BOTH {
        let c = clear_mot(&data, &params(convention)).unwrap();
        assert_eq!((c.false_negatives, c.partially_tracked), (1, 1));
    }
}

/// Tracked in 4 of 5 frames (the fifth has a far estimate): ratio 0.8 is "mostly tracked"
/// for py-motmetrics (≥ 0.8) but "partially tracked" for TrackEval (> 0.8).
#[test]
fn mostly_tracked_boundary() {
    let t: Vec<MotTruth> = (0..5).map(|f| truth(f, 1, 0.0)).collect();
    let mut e: Vec<MotEstimate> = (0..4).map(|f| estimate(f, 10, 0.1)).collect();
    e.push(estimate(4, 10, 30.0));
    let data = MotData::new(&t, &e, DISTANCE, None).unwrap();
    let te = clear_mot(&data, &params(MotConvention::TrackEval)).unwrap();
    let py = clear_mot(&data, &params(MotConvention::PyMotMetrics)).unwrap();
    assert_eq!((te.mostly_tracked, te.partially_tracked), (0, 1));
    assert_eq!((py.mostly_tracked, py.partially_tracked), (1, 0));
    // MOTP: mean similarity 0.95 (TrackEval) and mean 1 − similarity 0.05 (py-motmetrics).
    assert!((te.motp - 0.95).abs() < 1e-12 && (te.motp_distance - 0.05).abs() < 1e-12);
    assert_eq!(te.motp, py.motp);
}

/// Within a frame the matching is optimal, not greedy: A at 0 and B at 0.8, x at 0.35 and
/// y at −0.6. Similarities: A–x 0.825, B–x 0.775, A–y 0.7, B–y 0.3 (below 0.5). Greedy by
/// similarity takes A–x and leaves B unmatched; the optimum (both conventions) pairs A–y
/// and B–x.
#[test]
fn matching_within_a_frame_is_optimal() {
    let t = [truth(0, 1, 0.0), truth(0, 2, 0.8)];
    let e = [estimate(0, 10, 0.35), estimate(0, 20, -0.6)];
    let data = MotData::new(&t, &e, DISTANCE, None).unwrap();
    for convention in BOTH {
        let events = clear_events(&data, &params(convention)).unwrap();
        let pairs: Vec<(u64, u64)> = events[0]
            .matches
            .iter()
            .map(|m| (m.truth_id, m.estimate_id))
            .collect();
        assert_eq!(pairs, vec![(1, 20), (2, 10)], "{convention:?}");
    }
}

/// Identity is one global assignment of trajectories: A meets x in 3 frames, A meets y and
/// B meets x in 2 frames each. Greedy (A–x first) gives IDTP 3; the optimum A–y + B–x gives
/// 4. Truth: A 5 + B 2 = 7 objects; estimates: x 5 + y 2 = 7. IDFN = IDFP = 7 − 4 = 3,
/// IDF1 = 4 / (4 + 1.5 + 1.5) = 4/7.
#[test]
fn identity_assignment_is_global_and_optimal() {
    let mut frames: Vec<FrameSimilarities> = (0..3)
        .map(|f| FrameSimilarities {
            frame: f,
            truth_ids: vec![1],
            estimate_ids: vec![10],
            similarity: vec![1.0],
        })
        .collect();
    for f in 3..5 {
        frames.push(FrameSimilarities {
            frame: f,
            truth_ids: vec![1, 2],
            estimate_ids: vec![10, 20],
            similarity: vec![0.0, 1.0, 1.0, 0.0],
        });
    }
    let data = MotData::from_similarities(&frames).unwrap();
    for convention in BOTH {
        let i = identity(&data, &params(convention)).unwrap();
        assert_eq!((i.idtp, i.idfp, i.idfn), (4, 3, 3));
        assert!((i.idf1 - 4.0 / 7.0).abs() < 1e-15);
        assert!((i.idp - 4.0 / 7.0).abs() < 1e-15 && (i.idr - 4.0 / 7.0).abs() < 1e-15);
    }
}

/// The threshold tests: TrackEval's CLEAR accepts `similarity ≥ 0.5 − ε`, its Identity
/// `≥ 0.5`, py-motmetrics `1 − similarity ≤ 0.5`. A similarity one ulp below 0.5 is a match
/// for TrackEval's CLEAR only.
#[test]
fn threshold_tests_at_the_boundary() {
    let just_below = 0.5 - f64::EPSILON / 2.0;
    let data = MotData::from_similarities(&[FrameSimilarities {
        frame: 0,
        truth_ids: vec![1],
        estimate_ids: vec![10],
        similarity: vec![just_below],
    }])
    .unwrap();
    let te = params(MotConvention::TrackEval);
    let py = params(MotConvention::PyMotMetrics);
    assert_eq!(clear_mot(&data, &te).unwrap().true_positives, 1);
    assert_eq!(identity(&data, &te).unwrap().idtp, 0);
    assert_eq!(clear_mot(&data, &py).unwrap().true_positives, 0);
    assert_eq!(identity(&data, &py).unwrap().idtp, 0);
}

fn bbox(left_px: f64) -> Shape {
    Shape::Box(BoundingBox {
        left_px,
        top_px: 0.0,
        width_px: 10.0,
        height_px: 20.0,
    })
}

/// MOT17 preprocessing: pedestrian P (scored), static person D (class 7, a distractor),
/// pedestrian Z marked 0 (skipped), a car C (class 3, skipped). Estimates on P, on D, on
/// Z, on C and on nothing. The one on D is removed; the ones on Z, C and nothing are false
/// positives; P is matched. Under the MOT15 rules, classes are ignored: D and C are scored.
#[test]
fn motchallenge_distractors_and_ignore_flags() {
    let rows = [
        (1, 0.0, 1.0, Some(1)),
        (2, 100.0, 1.0, Some(7)),
        (3, 200.0, 0.0, Some(1)),
        (4, 300.0, 1.0, Some(3)),
    ];
    let truth_for = |protocol: MotChallengeProtocol| -> Vec<MotTruth> {
        rows.iter()
            .map(|&(id, left, consider, class)| MotTruth {
                frame: 0,
                id,
                shape: bbox(left),
                role: protocol.truth_role(consider, class),
            })
            .collect()
    };
    let estimates: Vec<MotEstimate> = [0.5, 100.5, 200.5, 300.5, 400.0]
        .iter()
        .enumerate()
        .map(|(k, &left)| MotEstimate {
            frame: 0,
            id: 10 + k as u64,
            shape: bbox(left),
        })
        .collect();
    let data = MotData::new(
        &truth_for(MotChallengeProtocol::Mot17),
        &estimates,
        Similarity::BoxIou,
        None,
    )
    .unwrap();
    assert_eq!((data.unscored_truth(), data.removed_estimates()), (3, 1));
    let c = clear_mot(&data, &MotParams::default()).unwrap();
    assert_eq!(
        (c.true_positives, c.false_negatives, c.false_positives),
        (1, 0, 3)
    );
    let data = MotData::new(
        &truth_for(MotChallengeProtocol::Mot15),
        &estimates,
        Similarity::BoxIou,
        None,
    )
    .unwrap();
    assert_eq!((data.unscored_truth(), data.removed_estimates()), (1, 0));
    let c = clear_mot(&data, &MotParams::default()).unwrap();
    assert_eq!(
        (c.true_positives, c.false_negatives, c.false_positives),
        (3, 0, 2)
    );
    // MOT20 adds non-motorised vehicles (class 6) to the distractors.
    assert_eq!(
        MotChallengeProtocol::Mot17.truth_role(1.0, Some(6)),
        TruthRole::Skipped
    );
    assert_eq!(
        MotChallengeProtocol::Mot20.truth_role(1.0, Some(6)),
        TruthRole::Distractor
    );
    assert_eq!(
        MotChallengeProtocol::Mot17.truth_role(0.5, Some(1)),
        TruthRole::Skipped
    );
}

/// Discs: the MMPF+ threshold 0.43 accepts an estimate 0.6 r from the true centre and
/// rejects one at 0.7 r.
#[test]
fn disc_matching() {
    let disc = |x: f64| Shape::Disc {
        centre_px: Point2::new(x, 0.0),
        radius_px: 3.0,
    };
    let t = [MotTruth {
        frame: 0,
        id: 1,
        shape: disc(0.0),
        role: TruthRole::Scored,
    }];
    let p = MotParams {
        threshold: 0.43,
        ..MotParams::default()
    };
    for (x, tp) in [(1.8, 1), (2.1, 0)] {
        let e = [MotEstimate {
            frame: 0,
            id: 5,
            shape: disc(x),
        }];
        let data = MotData::new(&t, &e, Similarity::DiscIou, None).unwrap();
        assert_eq!(clear_mot(&data, &p).unwrap().true_positives, tp);
    }
}

#[test]
fn bad_input_is_reported_with_frame_and_id() {
    let t = [truth(0, 1, 0.0), truth(0, 1, 5.0)];
    let err = MotData::new(&t, &[], DISTANCE, None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("truth id 1 appears twice in frame 0"), "{err}");

    let e = [estimate(0, 3, 0.0), estimate(7, 3, 0.0)];
    let err = MotData::new(&[], &e, DISTANCE, Some(7))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("estimate id 3 is in frame 7") && err.contains("7 frames"),
        "{err}"
    );

    let err = MotData::new(&[truth(2, 4, 0.0)], &[], Similarity::BoxIou, None)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("truth id 4 in frame 2") && err.contains("IoU"),
        "{err}"
    );

    let err = MotData::new(&[truth(0, 1, f64::NAN)], &[], DISTANCE, None).unwrap_err();
    assert!(err.to_string().contains("not finite"), "{err}");

    let bad = Similarity::Distance {
        zero_distance_px: -1.0,
    };
    assert!(MotData::new(&[], &[], bad, None).is_err());

    let frames = [FrameSimilarities {
        frame: 0,
        truth_ids: vec![1],
        estimate_ids: vec![2, 3],
        similarity: vec![1.0],
    }];
    let err = MotData::from_similarities(&frames).unwrap_err().to_string();
    assert!(err.contains("give 2"), "{err}");

    let data = MotData::new(&[], &[], DISTANCE, None).unwrap();
    let err = clear_mot(
        &data,
        &MotParams {
            threshold: 0.0,
            ..MotParams::default()
        },
    )
    .unwrap_err();
    assert!(err.to_string().contains("threshold"), "{err}");
}

//! The papers' own scores (`sillage_eval::papers`) on tiny hand-made sequences whose values
//! are derived by hand in the comments, on the real bead ground truth of the MMPF+ paper's
//! code, and a perfect tracker scoring the ideal value everywhere.

mod common;

use common::scene::{SceneSpec, scene};
use proptest::prelude::*;
use sillage_core::{MotionState, Point2};
use sillage_eval::mot::{
    FrameEvents, FrameSimilarities, MotData, MotEstimate, MotParams, MotTruth, Shape, Similarity,
    TruthRole, clear_events, clear_mot,
};
use sillage_eval::papers::{
    BedloadScores, EtiseoMetrics, MotionStateScores, PaperMetrics, PapersReport, StateLabel,
    bedload_scores, etiseo, motion_state_scores, vace,
};
use sillage_io::{BeadCategory, BeadPoint, read_bead_csv, read_bead_sequence_params};

#[track_caller]
fn close(name: &str, actual: f64, expected: f64) {
    assert!(
        (actual - expected).abs() < 1e-12,
        "{name}: {actual} vs {expected}"
    );
}

/// Objects on a line, 100 px apart by slot, matched by distance (zero at 2 px): an estimate
/// in the slot of a true object matches it with similarity 1, nothing else overlaps.
fn point(slot: u64) -> Shape {
    Shape::Point(Point2::new(100.0 * slot as f64, 0.0))
}

fn truth(id: u64, slot: u64, frames: impl IntoIterator<Item = u64>) -> Vec<MotTruth> {
    frames
        .into_iter()
        .map(|frame| MotTruth {
            frame,
            id,
            shape: point(slot),
            role: TruthRole::Scored,
        })
        .collect()
}

fn estimate(id: u64, slot: u64, frames: impl IntoIterator<Item = u64>) -> Vec<MotEstimate> {
    frames
        .into_iter()
        .map(|frame| MotEstimate {
            frame,
            id,
            shape: point(slot),
        })
        .collect()
}

fn events_of(truth: &[MotTruth], estimates: &[MotEstimate]) -> (MotData, Vec<FrameEvents>) {
    let similarity = Similarity::Distance {
        zero_distance_px: 2.0,
    };
    let data = MotData::new(truth, estimates, similarity, None).unwrap();
    let events = clear_events(&data, &MotParams::default()).unwrap();
    (data, events)
}

/// Four true tracks (MMPF+ paper §5.3: correct when more than 95 % of its length has no FN
/// and no mismatch):
/// - A, 21 frames, missed once: 20/21 = 95.2 % > 95 % → correct;
/// - B, 20 frames, missed once: 19/20 = 95 %, not more → not correct;
/// - C, 10 frames, followed by z then w from frame 5: one mismatch, 9/10 → not correct;
/// - D, 5 frames, perfect → correct.
///
/// And one false positive far from everything in frame 0. Correct tracks 2/4; Σ g_t =
/// 21 + 20 + 10 + 5 = 56; FN 2, FP 1, IDSW 1; FN rate 2/56, FP rate 1/56, and
/// MOTA = (54 − 1 − 1)/56 = 1 − 2/56 − 1/56 − 1/56.
#[test]
fn correct_tracks_follow_the_95_percent_rule() {
    let mut t = truth(1, 0, 0..21);
    t.extend(truth(2, 1, 0..20));
    t.extend(truth(3, 2, 0..10));
    t.extend(truth(4, 3, 0..5));
    let mut e = estimate(10, 0, (0..21).filter(|&f| f != 7));
    e.extend(estimate(20, 1, 0..19));
    e.extend(estimate(30, 2, 0..5));
    e.extend(estimate(31, 2, 5..10));
    e.extend(estimate(40, 3, 0..5));
    e.extend(estimate(99, 50, [0]));
    let (data, events) = events_of(&t, &e);
    let s = bedload_scores(&events);
    assert_eq!((s.truth_tracks, s.correct_tracks), (4, 2));
    assert_eq!(s.correct_track_rate, 0.5);
    assert_eq!(s.truth_objects, 56);
    assert_eq!(
        (s.false_negatives, s.false_positives, s.id_switches),
        (2, 1, 1)
    );
    close("FN rate", s.false_negative_rate, 2.0 / 56.0);
    close("FP rate", s.false_positive_rate, 1.0 / 56.0);
    let clear = clear_mot(&data, &MotParams::default()).unwrap();
    close(
        "MOTA",
        clear.mota,
        1.0 - s.false_negative_rate - s.false_positive_rate - 1.0 / 56.0,
    );
    // Two sequences combine by summing: 4 of 8 tracks correct, rates unchanged.
    let both = BedloadScores::combine(&[s, s]);
    assert_eq!((both.truth_tracks, both.correct_tracks), (8, 4));
    close("combined FN rate", both.false_negative_rate, 2.0 / 56.0);
}

fn labels(id: u64, states: &[MotionState]) -> Vec<StateLabel> {
    states
        .iter()
        .enumerate()
        .map(|(frame, &state)| StateLabel {
            frame: frame as u64,
            id,
            state,
        })
        .collect()
}

/// True A in frames 0–5, followed by x; true B in frames 0–2, followed by y in 0–1; an
/// unmatched estimate f. States (R rest, L roll, S salt, ? unknown):
///
/// | frame | A | x | B | y |
/// |---|---|---|---|---|
/// | 0 | ? | R | ? | R |
/// | 1 | R | R | R | R |
/// | 2 | R | L | R | – |
/// | 3 | L | L |   |   |
/// | 4 | S | S |   |   |
/// | 5 | L | ? |   |   |
///
/// Samples: matched points with a known true state: A at 1–5 and B at 1 → 6; A0 and B0 are
/// left out (unknown truth); B2 is missed. Rest: A1, B1 right, A2 estimated roll → TP 2,
/// FN 1, FP 0: P 1, R 2/3, F = 2·(2/3)/(5/3) = 0.8. Roll: A3 right, A5 estimated unknown (FN),
/// A2 wrongly estimated roll (FP) → P 1/2, R 1/2, F 1/2. Salt: A4 → P = R = F = 1.
#[test]
fn motion_state_scores_per_state() {
    use MotionState::{Resting as R, Rolling as L, Saltating as S, Unknown as U};
    let mut t = truth(1, 0, 0..6);
    t.extend(truth(2, 1, 0..3));
    let mut e = estimate(10, 0, 0..6);
    e.extend(estimate(20, 1, 0..2));
    e.extend(estimate(30, 7, [3]));
    let (_, events) = events_of(&t, &e);
    let mut truth_states = labels(1, &[U, R, R, L, S, L]);
    truth_states.extend(labels(2, &[U, R, R]));
    let mut estimate_states = labels(10, &[R, R, L, L, S, U]);
    estimate_states.extend(labels(20, &[R, R]));
    estimate_states.push(StateLabel {
        frame: 3,
        id: 30,
        state: S,
    });
    let m = motion_state_scores(&events, &truth_states, &estimate_states).unwrap();
    assert_eq!((m.evaluated, m.unknown_truth), (6, 2));
    // Rows true rest/roll/salt, columns estimated rest/roll/salt/unknown.
    assert_eq!(m.confusion, [[2, 1, 0, 0], [0, 1, 0, 1], [0, 0, 1, 0]]);
    let counts = |s: &sillage_eval::papers::StateScores| {
        (s.true_positives, s.false_positives, s.false_negatives)
    };
    assert_eq!(counts(&m.resting), (2, 0, 1));
    assert_eq!(counts(&m.rolling), (1, 1, 1));
    assert_eq!(counts(&m.saltating), (1, 0, 0));
    assert_eq!(m.resting.precision, Some(1.0));
    close("rest R", m.resting.recall.unwrap(), 2.0 / 3.0);
    close("rest F", m.resting.f_score.unwrap(), 0.8);
    assert_eq!(
        (m.rolling.precision, m.rolling.recall, m.rolling.f_score),
        (Some(0.5), Some(0.5), Some(0.5))
    );
    assert_eq!(m.saltating.f_score, Some(1.0));

    // Without any saltating sample or estimate, its scores are undefined, not 0 or 1.
    let m = motion_state_scores(&events, &truth_states[..3], &estimate_states[..3]).unwrap();
    assert_eq!((m.saltating.precision, m.saltating.f_score), (None, None));

    // A label given twice is refused, naming the object and the frame.
    let mut twice = truth_states.clone();
    twice.push(truth_states[1]);
    let err = motion_state_scores(&events, &twice, &estimate_states).unwrap_err();
    assert!(
        err.to_string()
            .contains("truth id 1 has two motion states in frame 1")
    );
}

/// One true track followed by one estimate over 12 frames (R rest, L roll, S salt,
/// ? unknown):
///
/// | frame | 0 | 1 | 2 | 3 | 4 | 5 | 6 | 7 | 8 | 9 | 10 | 11 |
/// |---|---|---|---|---|---|---|---|---|---|---|---|---|
/// | truth | ? | R | R | R | R | L | L | L | S | S | S | S |
/// | estimate | R | R | L | L | S | L | R | ? | S | ? | L | S |
///
/// Frame 0 has no known true state; the other 11 fill the matrix (rows true, columns
/// estimated rest/roll/salt/unknown): rest [1, 2, 1, 0], roll [1, 1, 0, 1], salt
/// [0, 1, 2, 1]. TP/FP/FN are the diagonal, the rest of the column, the rest of the row:
/// rest 1/1/3 (P 1/2, R 1/4), roll 1/3/2 (P 1/4, R 1/3), salt 2/1/2 (P 2/3, R 1/2).
#[test]
fn motion_state_confusion_matrix() {
    use MotionState::{Resting as R, Rolling as L, Saltating as S, Unknown as U};
    let (data, events) = events_of(&truth(1, 0, 0..12), &estimate(9, 0, 0..12));
    let truth_states = labels(1, &[U, R, R, R, R, L, L, L, S, S, S, S]);
    let estimate_states = labels(9, &[R, R, L, L, S, L, R, U, S, U, L, S]);
    let m = motion_state_scores(&events, &truth_states, &estimate_states).unwrap();
    let matrix = [[1, 2, 1, 0], [1, 1, 0, 1], [0, 1, 2, 1]];
    assert_eq!(m.confusion, matrix);
    assert_eq!((m.evaluated, m.unknown_truth), (11, 1));
    let counts = |s: &sillage_eval::papers::StateScores| {
        (s.true_positives, s.false_positives, s.false_negatives)
    };
    assert_eq!(counts(&m.resting), (1, 1, 3));
    assert_eq!(counts(&m.rolling), (1, 3, 2));
    assert_eq!(counts(&m.saltating), (2, 1, 2));
    close("rest P", m.resting.precision.unwrap(), 1.0 / 2.0);
    close("rest R", m.resting.recall.unwrap(), 1.0 / 4.0);
    close("roll P", m.rolling.precision.unwrap(), 1.0 / 4.0);
    close("roll R", m.rolling.recall.unwrap(), 1.0 / 3.0);
    close("salt P", m.saltating.precision.unwrap(), 2.0 / 3.0);
    close("salt R", m.saltating.recall.unwrap(), 1.0 / 2.0);

    // Precision and recall agree with the matrix: diagonal over its column, over its row.
    let agree = |m: &sillage_eval::papers::MotionStateScores| {
        for (c, (_, s)) in m.by_state().into_iter().enumerate() {
            let diagonal = m.confusion[c][c] as f64;
            let column: u64 = m.confusion.iter().map(|row| row[c]).sum();
            let row: u64 = m.confusion[c].iter().sum();
            close("precision", s.precision.unwrap(), diagonal / column as f64);
            close("recall", s.recall.unwrap(), diagonal / row as f64);
        }
    };
    agree(&m);

    // Combining sums the matrices (and scores from the sum): with a perfect sequence of
    // one of each state.
    let (_, perfect_events) = events_of(&truth(1, 0, 0..4), &estimate(9, 0, 0..4));
    let perfect = motion_state_scores(
        &perfect_events,
        &labels(1, &[U, R, L, S]),
        &labels(9, &[U, R, L, S]),
    )
    .unwrap();
    assert_eq!(
        perfect.confusion,
        [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]
    );
    let both = MotionStateScores::combine(&[m, perfect, m]);
    assert_eq!(both.confusion, [[3, 4, 2, 0], [2, 3, 0, 2], [0, 2, 5, 2]]);
    assert_eq!((both.evaluated, both.unknown_truth), (25, 3));
    assert_eq!(counts(&both.rolling), (3, 6, 4));
    agree(&both);

    // The text report prints the matrix of each sequence, then COMBINED's.
    let metrics =
        PaperMetrics::new(&data, &events, Some((&truth_states, &estimate_states))).unwrap();
    let text = PapersReport::new(vec![("a".into(), metrics)]).to_string();
    let expected = "\
Motion-state confusion (rows: true state, columns: estimated state; matched points)
sequence  true  rest  roll  salt  unknown
a         rest     1     2     1        0
          roll     1     1     0        1
          salt     0     1     2        1
COMBINED  rest     1     2     1        0
          roll     1     1     0        1
          salt     0     1     2        1
";
    assert!(text.contains(expected), "{text}");
    let (states, vace) = (
        text.find("Motion states").unwrap(),
        text.find("VACE").unwrap(),
    );
    let confusion = text.find("Motion-state confusion").unwrap();
    assert!(states < confusion && confusion < vace, "{text}");
}

/// Truth 1, 2 and estimates 10, 20, 30 with these overlaps (similarities):
///
/// - frame 0: (1,10) 0.8, (1,20) 0.1, (2,20) 0.6 → mapping {1–10, 2–20} (1.4 > 0.1);
///   FDA = 1.4 / ((2 + 2)/2) = 0.7, MODP = 1.4 / 2 = 0.7;
/// - frame 1: truth 1, 2 and estimate 10: (1,10) 0.9, (2,10) 0.2 → {1–10};
///   FDA = 0.9 / 1.5 = 0.6, MODP = 0.9;
/// - frame 2: truth 1 alone → FDA 0; frame 3: estimate 30 alone → FDA 0.
///
/// SFDA = (0.7 + 0.6 + 0 + 0) / 4 = 0.325; N-MODP = (0.7 + 0.9) / 2 = 0.8.
///
/// Trajectories: 1 in frames {0,1,2}, 2 in {0,1}, 10 in {0,1}, 20 in {0}, 30 in {3}.
/// Per pair Σ overlap / |frames of either|: (1,10) 1.7 / 3; (1,20) 0.1 / 3; (2,20) 0.6 / 2 =
/// 0.3; (2,10) 0.2 / 2 = 0.1. Best mapping {1–10, 2–20}: STDA = 1.7/3 + 0.3 = 0.8667 (the
/// other, {1–20, 2–10}, gives 0.1333). ATA = STDA / ((2 + 3)/2); MOTP = (1.7 + 0.6) /
/// (2 + 1) frames where both of a mapped pair exist.
///
/// TrackEval's relaxed ATA counts the frames of a pair with overlap ≥ 0.5: (1,10) 2 of 3,
/// (2,20) 1 of 2, the others none; STDA 2/3 + 1/2 over (2 + 3)/2.
#[test]
fn vace_by_hand() {
    let frame = |frame, truth: &[u64], estimates: &[u64], similarity: &[f64]| FrameSimilarities {
        frame,
        truth_ids: truth.to_vec(),
        estimate_ids: estimates.to_vec(),
        similarity: similarity.to_vec(),
    };
    let data = MotData::from_similarities(&[
        frame(0, &[1, 2], &[10, 20], &[0.8, 0.1, 0.0, 0.6]),
        frame(1, &[1, 2], &[10], &[0.9, 0.2]),
        frame(2, &[1], &[], &[]),
        frame(3, &[], &[30], &[]),
    ])
    .unwrap();
    let v = vace(&data);
    assert_eq!((v.frames, v.mapped_frames), (4, 2));
    close("SFDA", v.sfda, 0.325);
    close("N-MODP", v.n_modp, 0.8);
    let stda = 1.7 / 3.0 + 0.3;
    close("STDA", v.stda, stda);
    close("ATA", v.ata, stda / 2.5);
    close("MOTP", v.motp, 2.3 / 3.0);
    close("relaxed STDA", v.stda_relaxed, 2.0 / 3.0 + 0.5);
    close("relaxed ATA", v.ata_relaxed, (2.0 / 3.0 + 0.5) / 2.5);
    assert_eq!(
        (v.truth_tracks, v.estimate_tracks, v.track_mapped_frames),
        (2, 3, 3)
    );
}

/// Reference objects A (frames 0–9), B (0–4), C (0–3); tracked objects x on A in 0–5; y on B
/// in 0–1 then on A in 6–8; z on B in 2–4. A is missed in frame 9, C always.
///
/// - M1: A's longest partner x, 6 of 10 frames → 0.6; B's z, 3 of 5 → 0.6; C 0 →
///   M1 = 1.2 / 3 = 0.4.
/// - M2: A has {x, y} → 1/2, B {y, z} → 1/2; C is never tracked, left out → M2 = 0.5.
/// - M3: x {A} → 1, y {A, B} → 1/2, z {B} → 1 → M3 = 2.5 / 3.
/// - M̄ = (0.4 + 0.5 + 2.5/3) / 3.
#[test]
fn etiseo_by_hand() {
    let mut t = truth(1, 0, 0..10);
    t.extend(truth(2, 1, 0..5));
    t.extend(truth(3, 2, 0..4));
    let mut e = estimate(10, 0, 0..6);
    e.extend(estimate(20, 1, 0..2));
    e.extend(estimate(20, 0, 6..9));
    e.extend(estimate(30, 1, 2..5));
    let (_, events) = events_of(&t, &e);
    let m = etiseo(&events);
    close("M1", m.tracking_time, 0.4);
    close("M2", m.id_persistence, 0.5);
    close("M3", m.id_confusion, 2.5 / 3.0);
    close("mean", m.mean, (0.4 + 0.5 + 2.5 / 3.0) / 3.0);
    assert_eq!(
        (
            m.reference_objects,
            m.tracked_references,
            m.associated_tracks
        ),
        (3, 2, 3)
    );

    // With a perfect one-object sequence: every object weighs the same. M1 = (1.2 + 1)/4,
    // M2 = (1 + 1)/3, M3 = (2.5 + 1)/4.
    let (_, perfect) = events_of(&truth(1, 0, 0..3), &estimate(5, 0, 0..3));
    let c = EtiseoMetrics::combine(&[m, etiseo(&perfect)]);
    close("combined M1", c.tracking_time, 2.2 / 4.0);
    close("combined M2", c.id_persistence, 2.0 / 3.0);
    close("combined M3", c.id_confusion, 3.5 / 4.0);
}

/// The report prints one table per paper with a row per sequence and COMBINED.
#[test]
fn report_tables() {
    let (data, events) = events_of(&truth(1, 0, 0..4), &estimate(9, 0, 0..4));
    let metrics = PaperMetrics::new(&data, &events, None).unwrap();
    let report = PapersReport::new(vec![("a".into(), metrics), ("b".into(), metrics)]);
    let text = report.to_string();
    for expected in ["MMPF+", "VACE", "ETISEO", "COMBINED"] {
        assert!(text.contains(expected), "{text}");
    }
    assert!(
        !text.contains("Motion states") && !text.contains("confusion"),
        "no states were given: {text}"
    );
    assert_eq!(report.combined.bedload.truth_tracks, 2);
}

/// The bead ground truth of the MMPF+ paper's code (10 frames, 397 beads, 3962 points),
/// matched as the paper does (disc IoU ≥ 0.43, radii 15 px black and 10 px transparent from
/// `sequence_param.txt`).
#[test]
fn real_bead_ground_truth() {
    let folder = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/bedload_beads_lafaye2018"
    );
    let beads = read_bead_csv(format!("{folder}/ground_truth/trackdatatruth.csv")).unwrap();
    let params = read_bead_sequence_params(format!("{folder}/sequence_param.txt")).unwrap();
    assert_eq!(beads.len(), 3962);
    // Counted with awk on the file: 3188 black, 774 transparent; states (first point of each
    // track unknown) 2305 resting, 1172 rolling, 88 saltating, 397 unknown.
    let black = beads
        .iter()
        .filter(|b| b.category == BeadCategory::Black)
        .count();
    assert_eq!(black, 3188);
    let disc = |b: &BeadPoint, shift_px: f64| Shape::Disc {
        centre_px: Point2::new(b.pos_px.x + shift_px, b.pos_px.y),
        radius_px: params.radius_px(b.category),
    };
    let truth: Vec<MotTruth> = beads
        .iter()
        .map(|b| MotTruth {
            frame: b.frame,
            id: b.id,
            shape: disc(b, 0.0),
            role: TruthRole::Scored,
        })
        .collect();
    let shifted = |shift_px: f64| -> Vec<MotEstimate> {
        beads
            .iter()
            .map(|b| MotEstimate {
                frame: b.frame,
                id: b.id + 1000,
                shape: disc(b, shift_px),
            })
            .collect()
    };
    let params_043 = MotParams {
        threshold: 0.43,
        ..MotParams::default()
    };
    let states: Vec<StateLabel> = beads
        .iter()
        .map(|b| StateLabel {
            frame: b.frame,
            id: b.id,
            state: b.motion_state,
        })
        .collect();
    let estimate_states: Vec<StateLabel> = states
        .iter()
        .map(|s| StateLabel {
            id: s.id + 1000,
            ..*s
        })
        .collect();

    // The truth against itself: everything perfect, every state right.
    let data = MotData::new(&truth, &shifted(0.0), Similarity::DiscIou, None).unwrap();
    let events = clear_events(&data, &params_043).unwrap();
    let p = PaperMetrics::new(&data, &events, Some((&states, &estimate_states))).unwrap();
    assert_eq!(
        (p.bedload.truth_tracks, p.bedload.correct_tracks),
        (397, 397)
    );
    let m = p.motion_states.unwrap();
    assert_eq!((m.evaluated, m.unknown_truth), (3565, 397));
    assert_eq!(
        (
            m.resting.true_positives,
            m.rolling.true_positives,
            m.saltating.true_positives
        ),
        (2305, 1172, 88)
    );
    assert_eq!(
        m.confusion,
        [[2305, 0, 0, 0], [0, 1172, 0, 0], [0, 0, 88, 0]]
    );
    assert_eq!((p.vace.sfda, p.vace.ata, p.etiseo.mean), (1.0, 1.0, 1.0));

    // Centres 7 px off: inside 0.637 r of a black bead (r = 15), outside for a transparent
    // one (r = 10): every black bead matches its own shifted estimate, no transparent one
    // does (a few transparent estimates land on a neighbour instead).
    let data = MotData::new(&truth, &shifted(7.0), Similarity::DiscIou, None).unwrap();
    let category: std::collections::HashMap<u64, BeadCategory> =
        beads.iter().map(|b| (b.id, b.category)).collect();
    let mut own = [0usize; 2];
    for frame in clear_events(&data, &params_043).unwrap() {
        for m in frame
            .matches
            .iter()
            .filter(|m| m.estimate_id == m.truth_id + 1000)
        {
            own[usize::from(category[&m.truth_id] == BeadCategory::Transparent)] += 1;
        }
    }
    assert_eq!(own, [3188, 0]);
    // Matching within 5 px (zero distance 10 px, threshold 0.5): 4 px off matches all,
    // 7 px off none.
    let within_5 = Similarity::Distance {
        zero_distance_px: 10.0,
    };
    for (shift, matched) in [(4.0, 3962), (7.0, 0)] {
        let data = MotData::new(&truth, &shifted(shift), within_5, None).unwrap();
        let clear = clear_mot(&data, &MotParams::default()).unwrap();
        assert_eq!(clear.true_positives, matched, "shift {shift}");
    }
}

fn spec() -> impl Strategy<Value = SceneSpec> {
    (1u64..30, 1u64..10, 1u64..20, any::<u64>()).prop_map(
        |(frames, objects_per_frame, lifetime, seed)| SceneSpec {
            frames,
            objects_per_frame,
            lifetime,
            miss_rate: 0.0,
            false_positives: 0,
            switch_every: 0,
            noise_px: 0.0,
            seed,
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A tracker that reports the truth exactly, under other ids, scores the ideal value of
    /// every paper: all tracks correct, no FN or FP, SFDA = ATA = N-MODP = MOTP = 1,
    /// M1 = M2 = M3 = 1, and every motion state right.
    #[test]
    fn a_perfect_tracker_scores_the_ideal(spec in spec()) {
        let (truth, _) = scene(&spec);
        let perfect: Vec<MotEstimate> = truth
            .iter()
            .map(|t| MotEstimate { frame: t.frame, id: t.id + 77, shape: t.shape })
            .collect();
        let state = |id: u64| [MotionState::Resting, MotionState::Rolling, MotionState::Saltating][id as usize % 3];
        let truth_states: Vec<StateLabel> =
            truth.iter().map(|t| StateLabel { frame: t.frame, id: t.id, state: state(t.id) }).collect();
        let estimate_states: Vec<StateLabel> =
            truth.iter().map(|t| StateLabel { frame: t.frame, id: t.id + 77, state: state(t.id) }).collect();
        let data = MotData::new(&truth, &perfect, Similarity::BoxIou, None).unwrap();
        let events = clear_events(&data, &MotParams::default()).unwrap();
        let p = PaperMetrics::new(&data, &events, Some((&truth_states, &estimate_states))).unwrap();
        prop_assert_eq!(p.bedload.correct_track_rate, 1.0);
        prop_assert_eq!((p.bedload.false_negative_rate, p.bedload.false_positive_rate), (0.0, 0.0));
        let v = p.vace;
        prop_assert_eq!((v.sfda, v.ata, v.n_modp, v.motp), (1.0, 1.0, 1.0, 1.0));
        prop_assert_eq!(v.ata_relaxed, 1.0);
        let e = p.etiseo;
        prop_assert_eq!((e.tracking_time, e.id_persistence, e.id_confusion, e.mean), (1.0, 1.0, 1.0, 1.0));
        let m = p.motion_states.unwrap();
        for (_, s) in m.by_state() {
            prop_assert!(s.false_positives == 0 && s.false_negatives == 0);
            prop_assert!(s.f_score.is_none_or(|f| f == 1.0));
        }
        prop_assert_eq!(m.evaluated, truth.len() as u64);
    }
}

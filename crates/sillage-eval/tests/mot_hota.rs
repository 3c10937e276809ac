//! HOTA on tiny hand-made sequences, each value derived by hand in the comments (TrackEval
//! `hota.py`: global alignment, per-frame matching, then per α).

use sillage_eval::mot::{FrameSimilarities, HotaMetrics, MotData, hota, hota_alphas};

fn frame(frame: u64, truth: &[u64], estimates: &[u64], similarity: &[f64]) -> FrameSimilarities {
    FrameSimilarities {
        frame,
        truth_ids: truth.to_vec(),
        estimate_ids: estimates.to_vec(),
        similarity: similarity.to_vec(),
    }
}

fn score(frames: &[FrameSimilarities]) -> HotaMetrics {
    hota(&MotData::from_similarities(frames).unwrap())
}

#[track_caller]
fn close(name: &str, actual: f64, expected: f64) {
    assert!(
        (actual - expected).abs() < 1e-12,
        "{name}: {actual} vs {expected}"
    );
}

/// The thresholds as NumPy computes them; the similarities used below sit between two of
/// them: 0.62 passes α ≤ 0.60 (12 values), 0.77 passes α ≤ 0.75 (15 values).
#[test]
fn alphas_are_trackevals() {
    let alphas = hota_alphas();
    assert_eq!(alphas.len(), 19);
    assert_eq!(alphas[0], 0.05);
    assert_eq!(alphas[18], 0.9500000000000001); // np.arange(0.05, 0.99, 0.05)[-1]
    assert_eq!(alphas.iter().filter(|&&a| a <= 0.62).count(), 12);
    assert_eq!(alphas.iter().filter(|&&a| a <= 0.77).count(), 15);
}

/// Truth A and estimate x in frames 0 and 1, similarity 1.0 then 0.62.
///
/// Alignment: each frame's pair is alone, so its share is 1 (0.62 / (0.62 + 0.62 − 0.62));
/// co-occurrence 2, A and x in 2 frames each: alignment 2 / (2 + 2 − 2) = 1. Both frames
/// match.
/// - α ≤ 0.60 (12 α): TP 2, FN 0, FP 0 → DetA 1; the pair matches twice: AssA =
///   2 · 2 / (2 + 2 − 2) / 2 = 1 → HOTA 1; LocA (1 + 0.62) / 2 = 0.81; DetRe = AssRe = 1.
/// - α ≥ 0.65 (7 α): frame 1 drops: TP 1, FN 1, FP 1 → DetA 1/3, DetRe = DetPr = 1/2;
///   AssA = 1 · 1 / (2 + 2 − 1) / 1 = 1/3 → HOTA 1/3; AssRe = 1 · (1/2) / 1 = 1/2;
///   LocA 1; OWTA √(1/2 · 1/3).
///
/// Means over the 19 α: HOTA = DetA = AssA = (12 + 7/3) / 19 = 43/57; LocA = (12 · 0.81 +
/// 7) / 19 = 0.88; DetRe = (12 + 3.5) / 19; OWTA = (12 + 7 √(1/6)) / 19; HOTA(0) 1,
/// LocA(0) 0.81.
#[test]
fn localisation_threshold_drops_a_match() {
    let h = score(&[
        frame(0, &[1], &[10], &[1.0]),
        frame(1, &[1], &[10], &[0.62]),
    ]);
    close("HOTA", h.hota, 43.0 / 57.0);
    close("DetA", h.det_a, 43.0 / 57.0);
    close("AssA", h.ass_a, 43.0 / 57.0);
    close("LocA", h.loc_a, 0.88);
    close("DetRe", h.det_re, 15.5 / 19.0);
    close("DetPr", h.det_pr, 15.5 / 19.0);
    close("AssRe", h.ass_re, 15.5 / 19.0);
    close("AssPr", h.ass_pr, 15.5 / 19.0);
    close("OWTA", h.owta, (12.0 + 7.0 * (1.0f64 / 6.0).sqrt()) / 19.0);
    close("HOTA(0)", h.hota_0, 1.0);
    close("LocA(0)", h.loc_a_0, 0.81);
    close("HOTALocA(0)", h.hota_loc_a_0, 0.81);
    assert_eq!(h.per_alpha.true_positives[11], 2);
    assert_eq!(h.per_alpha.true_positives[12], 1);
    assert_eq!(h.per_alpha.false_positives[18], 1);
}

/// Truth A in frames 0–3; the tracker follows it perfectly as x in frames 0–1 and as y in
/// frames 2–3 (one identity switch).
///
/// Every α: TP 4, FN = FP = 0 → DetA 1, LocA 1. Pairs (A, x) and (A, y) match twice each,
/// A is in 4 frames, x and y in 2: AssA = [2 · 2 / (4 + 2 − 2)] · 2 / 4 = 1/2 → HOTA √½;
/// AssRe = [2 · 2/4] · 2 / 4 = 1/2; AssPr = [2 · 2/2] · 2 / 4 = 1; OWTA √(1 · ½).
#[test]
fn an_identity_switch_halves_association() {
    let h = score(&[
        frame(0, &[1], &[10], &[1.0]),
        frame(1, &[1], &[10], &[1.0]),
        frame(2, &[1], &[20], &[1.0]),
        frame(3, &[1], &[20], &[1.0]),
    ]);
    close("HOTA", h.hota, 0.5f64.sqrt());
    close("DetA", h.det_a, 1.0);
    close("AssA", h.ass_a, 0.5);
    close("AssRe", h.ass_re, 0.5);
    close("AssPr", h.ass_pr, 1.0);
    close("LocA", h.loc_a, 1.0);
    close("OWTA", h.owta, 0.5f64.sqrt());
}

/// Frames 0–1: A with x at similarity 1. Frame 2: A and B, x and y with A–x = B–y = 0.77
/// and A–y = B–x = 0.87. By similarity alone frame 2 would pair A–y and B–x (1.74 > 1.54);
/// HOTA's score is alignment × similarity.
///
/// Alignment. Frame 2: row and column sums 1.64, so A–x gets 0.77 / (3.28 − 0.77) =
/// 0.77/2.51 and A–y gets 0.87/2.41. A–x: co-occurrence 2 + 0.77/2.51 = 2.306773, A and x
/// in 3 frames: 2.306773 / (6 − 2.306773) = 0.624595. A–y (A 3 frames, y 1):
/// 0.360996 / (4 − 0.360996) = 0.099202, B–x the same. B–y: 0.306773 / (2 − 0.306773) =
/// 0.181174. Scores: A–x + B–y = 0.480938 + 0.139504 = 0.620442 against
/// A–y + B–x = 2 · 0.086306 = 0.172612: frame 2 pairs A–x and B–y.
///
/// - α ≤ 0.75 (15 α): TP 4, no FN/FP → DetA 1; A–x matches 3 times, B–y once:
///   AssA = [3 · 3/(3 + 3 − 3) + 1 · 1/(1 + 1 − 1)] / 4 = 1; LocA (2 + 2 · 0.77) / 4 = 0.885.
/// - α ≥ 0.80 (4 α): frame 2 drops: TP 2, FN 2, FP 2 → DetA 1/3, DetRe = DetPr = 1/2;
///   AssA = 2 · 2/(3 + 3 − 2) / 2 = 1/2 → HOTA √(1/6); AssRe = AssPr = 2 · (2/3) / 2 = 2/3;
///   OWTA √(½ · ½) = ½; LocA 1.
///
/// Means: HOTA (15 + 4 √(1/6)) / 19; DetA (15 + 4/3) / 19; AssA = DetRe = OWTA = 17/19;
/// AssRe (15 + 8/3) / 19; LocA (15 · 0.885 + 4) / 19.
#[test]
fn global_alignment_keeps_identities_over_raw_similarity() {
    let h = score(&[
        frame(0, &[1], &[10], &[1.0]),
        frame(1, &[1], &[10], &[1.0]),
        frame(2, &[1, 2], &[10, 20], &[0.77, 0.87, 0.87, 0.77]),
    ]);
    close("HOTA", h.hota, (15.0 + 4.0 * (1.0f64 / 6.0).sqrt()) / 19.0);
    close("DetA", h.det_a, (15.0 + 4.0 / 3.0) / 19.0);
    close("AssA", h.ass_a, 17.0 / 19.0);
    close("DetRe", h.det_re, 17.0 / 19.0);
    close("OWTA", h.owta, 17.0 / 19.0);
    close("AssRe", h.ass_re, (15.0 + 8.0 / 3.0) / 19.0);
    close("AssPr", h.ass_pr, (15.0 + 8.0 / 3.0) / 19.0);
    close("LocA", h.loc_a, (15.0 * 0.885 + 4.0) / 19.0);
    close("LocA(0)", h.loc_a_0, 0.885);
}

/// Sequences combine by summing TP/FN/FP and weighting AssA and LocA by TP, not by
/// averaging HOTA. With the first two sequences above:
/// - α ≤ 0.60: TP 2 + 4 = 6, no FN/FP; AssA (1 · 2 + ½ · 4) / 6 = 2/3 → HOTA √(2/3);
///   LocA (0.81 · 2 + 1 · 4) / 6.
/// - α ≥ 0.65: TP 1 + 4 = 5, FN 1, FP 1 → DetA 5/7; AssA (⅓ · 1 + ½ · 4) / 5 = 7/15
///   → HOTA √(5/7 · 7/15) = √(1/3); LocA 1.
#[test]
fn sequences_combine_weighted_by_true_positives() {
    let one = score(&[
        frame(0, &[1], &[10], &[1.0]),
        frame(1, &[1], &[10], &[0.62]),
    ]);
    let two = score(&[
        frame(0, &[1], &[10], &[1.0]),
        frame(1, &[1], &[10], &[1.0]),
        frame(2, &[1], &[20], &[1.0]),
        frame(3, &[1], &[20], &[1.0]),
    ]);
    let c = HotaMetrics::combine(&[one, two]);
    let hota = (12.0 * (2.0f64 / 3.0).sqrt() + 7.0 * (1.0f64 / 3.0).sqrt()) / 19.0;
    close("HOTA", c.hota, hota);
    close(
        "AssA",
        c.ass_a,
        (12.0 * 2.0 / 3.0 + 7.0 * 7.0 / 15.0) / 19.0,
    );
    close("LocA", c.loc_a, (12.0 * 5.62 / 6.0 + 7.0) / 19.0);
    assert!((c.hota - (one.hota + two.hota) / 2.0).abs() > 1e-3);
    // One sequence combined is itself.
    let same = HotaMetrics::combine(&[two]);
    close("HOTA", same.hota, two.hota);
    close("LocA", same.loc_a, two.loc_a);
}

/// No estimates: every true object is a false negative; HOTA 0, LocA 1 (TrackEval's
/// convention for no true positives). No truth: every estimate is a false positive.
#[test]
fn empty_sides() {
    let h = score(&[frame(0, &[1, 2], &[], &[]), frame(3, &[1], &[], &[])]);
    assert_eq!(h.per_alpha.false_negatives, [3; 19]);
    assert_eq!(
        (h.hota, h.det_re, h.ass_a, h.loc_a, h.loc_a_0),
        (0.0, 0.0, 0.0, 1.0, 1.0)
    );
    let h = score(&[frame(0, &[], &[5], &[])]);
    assert_eq!(h.per_alpha.false_positives, [1; 19]);
    assert_eq!((h.hota, h.det_pr, h.loc_a), (0.0, 0.0, 1.0));
    let h = score(&[]);
    assert_eq!((h.hota, h.loc_a), (0.0, 1.0));
}

//! Table 1 of the MMPF+ paper on a synthetic bedload sequence with ground truth: 400 beads
//! (a packed bed under rolling and saltating beads), transparent beads missed at random and in
//! 5-frame bursts, false positives, position noise; the five trackers on the same detections.
//! And the motion-state smoother on a 1,000-frame sequence, learnt on one half, scored on the
//! other.

use sillage::bedload::{BeadFrame, bedload_table, track_beads};
use sillage::core::TrackPoint;
use sillage::eval::papers::{BeadTrackScores, score_bead_tracks};
use sillage::synth::{BedloadDetectionParams, BedloadSample, BedloadSceneParams, generate_bedload};
use sillage::track::bedload::{
    BedloadTrackerKind, BedloadTrackerParams, LabelledPoint, SaltationRule, fit_emission,
};

mod support;
use support::in_frames;

fn sequence() -> (Vec<BedloadSample>, BedloadSceneParams) {
    let scene = BedloadSceneParams {
        n_frames: 60,
        seed: 3,
        ..BedloadSceneParams::default()
    };
    let samples = generate_bedload(scene.clone(), BedloadDetectionParams::default()).unwrap();
    (samples, scene)
}

fn truth(samples: &[BedloadSample]) -> Vec<TrackPoint> {
    samples
        .iter()
        .flat_map(|s| s.truth.track_points())
        .collect()
}

/// The detections and candidates of every frame.
fn frames(samples: &[BedloadSample]) -> Vec<BeadFrame> {
    samples
        .iter()
        .map(|s| BeadFrame {
            frame: s.truth.index,
            detections: s.observation.detections.clone(),
            candidates: s.observation.candidates.clone(),
        })
        .collect()
}

fn report(kind: BedloadTrackerKind, s: &BeadTrackScores) {
    eprintln!("{:>9}: {s}", kind.name());
}

#[test]
fn table1_on_a_synthetic_sequence() {
    let (samples, scene) = sequence();
    let radii = [scene.black_radius_px, scene.transparent_radius_px];
    let truth = truth(&samples);
    let params = BedloadTrackerParams {
        radius_px: radii.to_vec(),
        ..BedloadTrackerParams::default()
    };
    let scores =
        bedload_table(&params, &BedloadTrackerKind::ALL, &frames(&samples), &truth).unwrap();
    for (kind, s) in &scores {
        report(*kind, s);
    }
    let get = |kind| &scores.iter().find(|(k, _)| *k == kind).unwrap().1;
    let (mmpf_plus, det) = (
        get(BedloadTrackerKind::MmpfPlus),
        get(BedloadTrackerKind::Det),
    );
    // The particle filters bridge the misses DET cannot: fewer misses, fewer identity
    // switches, more correct tracks (the paper's Table 1 ordering).
    assert!(
        mmpf_plus.table1.false_negative_rate < 0.5 * det.table1.false_negative_rate,
        "FN {} vs {}",
        mmpf_plus.table1.false_negative_rate,
        det.table1.false_negative_rate
    );
    assert!(mmpf_plus.table1.id_switches < det.table1.id_switches);
    assert!(mmpf_plus.table1.correct_tracks > det.table1.correct_tracks);
    assert!(mmpf_plus.mot.identity.idf1 > det.mot.identity.idf1);
}

/// Issue "Bedload motion states you can trust", its synthetic bar: on a 1,000-frame sequence
/// (seed 5, which chose nothing), the smoother's evidence learnt on frames 0-499 and scored
/// on 500-999: one frame's evidence, the window (`half_window` 2) with Eq. (4)'s saltating,
/// and the default (saltating over the steadiest stretch, its threshold learnt too).
#[test]
fn smoothed_states_over_the_window_on_an_unseen_synthetic_half() {
    let scene = BedloadSceneParams {
        n_frames: 1000,
        seed: 5,
        ..BedloadSceneParams::default()
    };
    let samples = generate_bedload(scene.clone(), BedloadDetectionParams::default()).unwrap();
    let radii = vec![scene.black_radius_px, scene.transparent_radius_px];
    let truth = truth(&samples);
    let frames = frames(&samples);
    let f_scores = |half_window: u32, saltation: SaltationRule| -> [f64; 3] {
        let mut params = BedloadTrackerParams {
            radius_px: radii.clone(),
            ..BedloadTrackerParams::default()
        };
        params.smoother.half_window = half_window;
        params.smoother.saltation = saltation;
        let plain = track_beads(&params, &frames).unwrap();
        let labelled = |points: &[TrackPoint]| -> Vec<LabelledPoint> {
            points.iter().map(LabelledPoint::of).collect()
        };
        let (emission, _) = fit_emission(
            &labelled(&in_frames(&plain, [0, 499])),
            &labelled(&truth),
            [0, 499],
            &radii,
            &params.calibration,
            &params.smoother,
            30,
        )
        .unwrap();
        params.smoother.emission = emission;
        let smoothed = track_beads(&params, &frames).unwrap();
        let scores = score_bead_tracks(
            &in_frames(&truth, [500, 999]),
            &in_frames(&smoothed, [500, 999]),
            &radii,
        )
        .unwrap();
        let f = scores
            .states
            .by_state()
            .map(|(_, c)| c.f_score.unwrap_or(0.0));
        eprintln!("half window {half_window}, saltation {saltation:?}: {f:.3?}");
        f
    };
    let one_frame = f_scores(0, SaltationRule::Smoothed);
    let frame = f_scores(2, SaltationRule::Frame);
    let default = f_scores(2, SaltationRule::SteadiestSpeed);
    // Measured (2026-11-28): one frame's evidence [0.933, 0.808, 0.604]; over ±2 frames with
    // Eq. (4)'s saltating [0.969, 0.922, 0.855]; with the steadiest stretch's (the default)
    // [0.969, 0.923, 0.928]. Every class passes the 0.90 on this half.
    assert!(default[0] >= 0.95, "resting {one_frame:?} -> {default:?}");
    assert!(default[1] >= 0.90, "rolling {one_frame:?} -> {default:?}");
    assert!(
        default[1] >= one_frame[1] + 0.05,
        "{one_frame:?} -> {default:?}"
    );
    assert!(default[2] >= 0.90, "saltating {frame:?} -> {default:?}");
    assert!(default[2] >= frame[2] + 0.03, "{frame:?} -> {default:?}");
}

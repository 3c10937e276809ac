//! Table 1 of the MMPF+ paper on a synthetic bedload sequence with ground truth: 400 beads
//! (a packed bed under rolling and saltating beads), transparent beads missed at random and in
//! 5-frame bursts, false positives, position noise; the five trackers on the same detections.

use sillage::bedload::{BeadFrame, bedload_table};
use sillage::core::TrackPoint;
use sillage::eval::papers::BeadTrackScores;
use sillage::synth::{BedloadDetectionParams, BedloadSample, BedloadSceneParams, generate_bedload};
use sillage::track::bedload::{BedloadTrackerKind, BedloadTrackerParams};

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

//! Integration tests of the synthetic bead detector: the truth does not depend on it, and
//! its misses, bursts, false positives, scores, candidates and position noise match their
//! parameters.

use std::collections::{HashMap, HashSet};

use sillage_core::{BLACK_BEAD_CLASS, TRANSPARENT_BEAD_CLASS, TrackId};
use sillage_synth::{
    BedloadDetectionParams, BedloadSample, BedloadSceneParams, BedloadSequence, MissCause,
    generate_bedload,
};

fn frames(n_frames: usize, seed: u64) -> BedloadSceneParams {
    BedloadSceneParams {
        n_frames,
        seed,
        ..Default::default()
    }
}

#[test]
fn the_detector_does_not_change_the_truth_nor_false_positives_the_true_detections() {
    let quiet = BedloadDetectionParams {
        false_positive_mean: 0.0,
        ..Default::default()
    };
    let noisy = BedloadDetectionParams {
        false_positive_mean: 5.0,
        ..Default::default()
    };
    let other = BedloadDetectionParams {
        position_sigma_px: 2.0,
        transparent_miss_probability: 0.2,
        ..Default::default()
    };
    let a = generate_bedload(frames(40, 1), quiet).unwrap();
    let b = generate_bedload(frames(40, 1), noisy).unwrap();
    let c = generate_bedload(frames(40, 1), other).unwrap();
    let mut extra = 0;
    for ((x, y), z) in a.iter().zip(&b).zip(&c) {
        assert_eq!(x.truth, y.truth);
        assert_eq!(x.truth, z.truth);
        let true_ones = |sample: &BedloadSample| {
            let obs = &sample.observation;
            let mut found: Vec<_> = obs
                .detections
                .iter()
                .zip(&obs.detection_sources)
                .filter_map(|(d, s)| s.map(|id| (id, d.pos_px.x.to_bits(), d.pos_px.y.to_bits())))
                .collect();
            found.sort_unstable();
            found
        };
        assert_eq!(true_ones(x), true_ones(y));
        assert_eq!(x.observation.missed, y.observation.missed);
        extra += y.observation.detections.len() - x.observation.detections.len();
    }
    assert!(
        extra > 100,
        "{extra} false positives in 40 frames at a mean of 5"
    );
}

#[test]
fn misses_bursts_false_positives_and_noise_match_their_parameters() {
    let detection = BedloadDetectionParams::default();
    let n_frames = 2500;
    let samples: Vec<_> = BedloadSequence::new(frames(n_frames, 9), detection.clone())
        .unwrap()
        .collect();
    let (mut free_frames, mut independent, mut burst_starts) = (0usize, 0usize, 0usize);
    let (mut false_positives, mut weak, mut missed_transparent) = (0usize, 0usize, 0usize);
    let (mut sum, mut sum2, mut n_noise) = ([0.0; 2], [0.0; 2], 0usize);
    // (track, frame) → cause, to follow the bursts.
    let mut misses: HashMap<(TrackId, u64), MissCause> = HashMap::new();
    for sample in &samples {
        let (truth, obs) = (&sample.truth, &sample.observation);
        let by_id: HashMap<_, _> = truth.beads.iter().map(|b| (b.track_id, b)).collect();
        for miss in &obs.missed {
            assert_ne!(
                miss.class, BLACK_BEAD_CLASS,
                "black beads are never missed by default"
            );
            misses.insert((miss.track_id, truth.index), miss.cause);
            missed_transparent += 1;
        }
        for bead in truth
            .beads
            .iter()
            .filter(|b| b.class == TRANSPARENT_BEAD_CLASS)
        {
            match misses.get(&(bead.track_id, truth.index)) {
                Some(MissCause::Burst { frame_in_burst: 0 }) => burst_starts += 1,
                Some(MissCause::Burst { .. }) => continue,
                Some(MissCause::Independent) => independent += 1,
                None => {}
            }
            free_frames += 1;
        }
        assert_eq!(obs.detections.len(), obs.detection_sources.len());
        assert_eq!(obs.candidates.len(), obs.candidate_sources.len());
        for (d, source) in obs.detections.iter().zip(&obs.detection_sources) {
            if d.class == BLACK_BEAD_CLASS {
                assert_eq!(d.strength, 1.0);
            } else {
                assert!((0.25..0.6).contains(&d.strength), "{}", d.strength);
            }
            let Some(id) = source else {
                assert_eq!(d.class, TRANSPARENT_BEAD_CLASS);
                false_positives += 1;
                continue;
            };
            let bead = by_id[id];
            assert_eq!(bead.class, d.class);
            let p = bead.pos_px;
            if p.x > 5.0 && p.x < 1274.0 && p.y > 5.0 && p.y < 314.0 {
                for (axis, e) in [d.pos_px.x - p.x, d.pos_px.y - p.y].into_iter().enumerate() {
                    sum[axis] += e;
                    sum2[axis] += e * e;
                }
                n_noise += 1;
            }
        }
        // Candidates: every transparent detection, plus weak ones from missed beads.
        let transparent: Vec<_> = obs
            .detections
            .iter()
            .zip(&obs.detection_sources)
            .filter(|(d, _)| d.class == TRANSPARENT_BEAD_CLASS)
            .collect();
        let strong: Vec<_> = obs
            .candidates
            .iter()
            .zip(&obs.candidate_sources)
            .filter(|(c, _)| c.strength >= 0.25)
            .collect();
        assert_eq!(transparent, strong);
        for (c, source) in obs.candidates.iter().zip(&obs.candidate_sources) {
            assert_eq!(c.class, TRANSPARENT_BEAD_CLASS);
            if c.strength < 0.25 {
                assert!(c.strength >= 0.20);
                let id = source.expect("weak candidates come from missed beads");
                assert!(obs.missed.iter().any(|m| m.track_id == id));
                weak += 1;
            }
        }
    }
    let rate = |count: usize, n: usize| count as f64 / n as f64;
    // An independent miss is drawn only where no burst starts.
    let independent_rate = rate(independent, free_frames - burst_starts);
    assert!(
        (independent_rate - 0.03).abs() < 0.002,
        "{independent_rate}"
    );
    let burst_rate = rate(burst_starts, free_frames);
    assert!((burst_rate - 0.01).abs() < 0.0015, "{burst_rate}");
    let fp_mean = rate(false_positives, n_frames);
    assert!((fp_mean - 1.0).abs() < 0.1, "{fp_mean}");
    let weak_share = rate(weak, missed_transparent);
    assert!((weak_share - 0.8).abs() < 0.03, "{weak_share}");
    for axis in 0..2 {
        let mean = sum[axis] / n_noise as f64;
        let sigma = (sum2[axis] / n_noise as f64 - mean * mean).sqrt();
        assert!(mean.abs() < 0.01, "axis {axis}: mean {mean}");
        assert!((sigma / 0.5 - 1.0).abs() < 0.03, "axis {axis}: σ {sigma}");
    }
    // Each burst lasts exactly `burst_length` frames unless the sequence or the bead ends.
    let present: HashSet<(TrackId, u64)> = samples
        .iter()
        .flat_map(|s| {
            s.truth
                .beads
                .iter()
                .map(move |b| (b.track_id, s.truth.index))
        })
        .collect();
    let (mut whole, length) = (0, detection.burst_length);
    for (&(id, frame), cause) in &misses {
        if *cause != (MissCause::Burst { frame_in_burst: 0 }) {
            continue;
        }
        let cut = (1..=u64::from(length)).any(|j| !present.contains(&(id, frame + j)));
        for j in 1..length {
            if present.contains(&(id, frame + u64::from(j))) {
                let expected = MissCause::Burst { frame_in_burst: j };
                assert_eq!(misses.get(&(id, frame + u64::from(j))), Some(&expected));
            }
        }
        let after = misses.get(&(id, frame + u64::from(length)));
        assert!(!matches!(after, Some(MissCause::Burst { frame_in_burst }) if *frame_in_burst > 0));
        whole += usize::from(!cut);
    }
    assert!(whole > 1_000, "{whole} whole bursts");
}

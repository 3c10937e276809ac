//! The bedload trackers on a hand-made scene with known trajectories: a bed of resting black
//! beads, transparent beads rolling and saltating over it, one of them missed for 5 frames
//! with only weak detector-confidence candidates left where it is.

use std::collections::{BTreeMap, BTreeSet};

use sillage_core::{Detection, FrameObservations, MotionState, Point2, TrackPoint, Tracker};
use sillage_track::bedload::{BedloadTracker, BedloadTrackerKind, BedloadTrackerParams};

const FRAMES: u64 = 40;
/// The frames in which the rolling bead 0 is not detected.
const MISSED: std::ops::Range<u64> = 12..17;

/// True position of transparent bead `bead` at `frame` (0: rolling at 4 px/frame, 1: rolling
/// at 6 px/frame, both touching the bed; 2: saltating in 50 px high, 20-frame hops at
/// 12 px/frame).
fn transparent(bead: usize, frame: u64) -> Point2 {
    let t = frame as f64;
    match bead {
        0 => Point2::new(900.0 - 4.0 * t, 278.0),
        1 => Point2::new(1200.0 - 6.0 * t, 278.0),
        _ => {
            let phase = (frame % 20) as f64;
            Point2::new(1250.0 - 12.0 * t, 278.0 - 0.5 * phase * (20.0 - phase))
        }
    }
}

/// Detections and candidates of one frame, with a deterministic ±0.3 px jitter.
fn frame_input(frame: u64) -> (Vec<Detection>, Vec<Detection>) {
    let jitter = |k: u64| ((frame * 7919 + k * 104_729) % 13) as f64 / 20.0 - 0.3;
    let mut detections: Vec<Detection> = (0..40)
        .map(|i| Detection::of_class(Point2::new(30.0 * i as f64 + 15.0, 300.0), 1.0, 0))
        .collect();
    let mut candidates = Vec::new();
    for bead in 0..3 {
        let p = transparent(bead, frame);
        let p = Point2::new(p.x + jitter(bead as u64), p.y - jitter(bead as u64 + 5));
        if bead == 0 && MISSED.contains(&frame) {
            candidates.push(Detection::of_class(p, 0.22, 1));
        } else {
            let d = Detection::of_class(p, 0.5, 1);
            detections.push(d);
            candidates.push(d);
        }
    }
    (detections, candidates)
}

fn run(params: &BedloadTrackerParams) -> Vec<TrackPoint> {
    let mut tracker = BedloadTracker::new(params).unwrap();
    let mut points = Vec::new();
    for frame in 0..FRAMES {
        let (detections, candidates) = frame_input(frame);
        let observations = FrameObservations {
            candidates: &candidates,
            ..FrameObservations::from_detections(frame, &detections)
        };
        tracker.step(&observations, &mut points).unwrap();
    }
    tracker.finish(&mut points).unwrap();
    points
}

fn params(kind: BedloadTrackerKind) -> BedloadTrackerParams {
    BedloadTrackerParams {
        tracker: kind,
        seed: 7,
        ..BedloadTrackerParams::default()
    }
}

/// The ids of the points within 3 px of transparent bead `bead`, frame by frame.
fn ids_following(points: &[TrackPoint], bead: usize) -> BTreeMap<u64, BTreeSet<u64>> {
    let mut ids: BTreeMap<u64, BTreeSet<u64>> = BTreeMap::new();
    for p in points.iter().filter(|p| p.class == 1) {
        if (p.pos_px - transparent(bead, p.frame)).norm() < 3.0 {
            ids.entry(p.frame).or_default().insert(p.track_id);
        }
    }
    ids
}

#[test]
fn mmpf_plus_keeps_identity_through_five_missed_frames_where_det_breaks_it() {
    let mmpf = run(&params(BedloadTrackerKind::MmpfPlus));
    let followed = ids_following(&mmpf, 0);
    let all: BTreeSet<u64> = followed.values().flatten().copied().collect();
    assert_eq!(
        all.len(),
        1,
        "one identity for the missed bead: {followed:?}"
    );
    assert_eq!(
        followed.len() as u64,
        FRAMES,
        "followed in every frame, misses included"
    );

    let det = run(&params(BedloadTrackerKind::Det));
    let followed = ids_following(&det, 0);
    let all: BTreeSet<u64> = followed.values().flatten().copied().collect();
    assert_eq!(
        all.len(),
        2,
        "DET ends the track at the miss and starts another"
    );
    assert!(MISSED.clone().all(|f| !followed.contains_key(&f)));
}

#[test]
fn every_tracker_follows_the_beads_it_sees() {
    for kind in BedloadTrackerKind::ALL {
        let points = run(&params(kind));
        // The saltating bead: one identity over its detected frames (all of them).
        let followed = ids_following(&points, 2);
        let ids: BTreeSet<u64> = followed.values().flatten().copied().collect();
        assert_eq!(ids.len(), 1, "{kind:?}: {followed:?}");
        // PF's single constant-velocity model overshoots at the rebounds, where its
        // estimate (the particles' mean) stays several px off the detection for a few
        // frames: the case the rebound sub-state of Eq. (3) is for.
        let slack = if kind == BedloadTrackerKind::Pf { 6 } else { 1 };
        assert!(
            followed.len() as u64 >= FRAMES - slack,
            "{kind:?}: {followed:?}"
        );
        // The 40 bed beads: 40 tracks, resting, over the whole sequence.
        let black: Vec<_> = points.iter().filter(|p| p.class == 0).collect();
        assert_eq!(black.len() as u64, 40 * FRAMES, "{kind:?}");
        let black_ids: BTreeSet<u64> = black.iter().map(|p| p.track_id).collect();
        assert_eq!(black_ids.len(), 40, "{kind:?}");
        let resting = black
            .iter()
            .filter(|p| p.motion_state == MotionState::Resting)
            .count();
        assert_eq!(
            resting as u64,
            40 * (FRAMES - 1),
            "{kind:?}: all but the birth frame"
        );
    }
}

#[test]
fn motion_states_and_velocities_follow_the_motion() {
    let points = run(&params(BedloadTrackerKind::MmpfPlus));
    let rolling: Vec<_> = points
        .iter()
        .filter(|p| p.class == 1 && (p.pos_px - transparent(1, p.frame)).norm() < 3.0)
        .filter(|p| p.frame >= 2)
        .collect();
    assert!(rolling.len() >= 35);
    for p in &rolling {
        let v = p.vel_px_per_frame.unwrap();
        assert!((v.x + 6.0).abs() < 1.5 && v.y.abs() < 1.5, "{p:?}");
        // 6 px/frame is between u_rest and u_salt and the bead touches the bed: rolling.
        assert_eq!(p.motion_state, MotionState::Rolling, "{p:?}");
        assert!(p.spread_px.is_some_and(|s| s > 0.0 && s < 3.0), "{p:?}");
    }
}

#[test]
fn same_output_for_one_thread_and_many() {
    let params = params(BedloadTrackerKind::MmpfPlus);
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let one = pool(1).install(|| run(&params));
    let four = pool(4).install(|| run(&params));
    assert_eq!(one, four);
    let other_seed = run(&BedloadTrackerParams { seed: 8, ..params });
    assert_ne!(one, other_seed, "the seed reaches the particles");
}

#[test]
fn bad_input_is_refused_with_the_frame() {
    let mut tracker = BedloadTracker::new(&BedloadTrackerParams::default()).unwrap();
    let mut sink = Vec::new();
    let bad = [Detection::of_class(Point2::new(1.0, 1.0), 1.0, 2)];
    let e = tracker
        .step(&FrameObservations::from_detections(3, &bad), &mut sink)
        .unwrap_err()
        .to_string();
    assert!(e.contains("frame 3") && e.contains("class 2"), "{e}");
    let nan = [Detection::of_class(Point2::new(f64::NAN, 1.0), 1.0, 0)];
    let e = tracker
        .step(&FrameObservations::from_detections(4, &nan), &mut sink)
        .unwrap_err()
        .to_string();
    assert!(e.contains("frame 4") && e.contains("not finite"), "{e}");
    tracker
        .step(&FrameObservations::from_detections(5, &[]), &mut sink)
        .unwrap();
    let e = tracker
        .step(&FrameObservations::from_detections(5, &[]), &mut sink)
        .unwrap_err()
        .to_string();
    assert!(e.contains("increasing order"), "{e}");
}

#[test]
fn a_lost_tracker_leaves_no_trail_of_predictions_unless_asked() {
    // A lone transparent bead rolling at 4 px/frame, seen in frames 0..10 only.
    let run_with = |at_once: bool| {
        let params = BedloadTrackerParams {
            emit_predictions_at_once: at_once,
            ..BedloadTrackerParams::default()
        };
        let mut tracker = BedloadTracker::new(&params).unwrap();
        let mut points = Vec::new();
        for frame in 0..30u64 {
            let p = Point2::new(600.0 - 4.0 * frame as f64, 200.0);
            let detections: Vec<_> = (frame < 10)
                .then(|| Detection::of_class(p, 0.5, 1))
                .into_iter()
                .collect();
            tracker
                .step(
                    &FrameObservations::from_detections(frame, &detections),
                    &mut points,
                )
                .unwrap();
        }
        tracker.finish(&mut points).unwrap();
        points.iter().map(|p| p.frame).max().unwrap()
    };
    assert_eq!(
        run_with(false),
        9,
        "held predictions dropped with the tracker"
    );
    // Emitted at once: the saltating survival limit (5 frames) of predictions — a bead
    // touching no other is measured saltating by Eq. (4) (nbN ≤ nbN_salt = 0).
    assert_eq!(run_with(true), 14);
}

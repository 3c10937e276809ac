//! One behavioural suite run against every implementation of the `Tracker` role: the PTV
//! tracker and the five bedload trackers of the MMPF+ paper's Table 1 (the pedestrian
//! trackers run through the facade's pipeline, `conformance_pipeline.rs`).
//!
//! Every tracker must: give the same points for 1 and 4 threads; give the same points run
//! twice; emit a point only once its frame has been seen (streaming) and everything by
//! `finish`; survive no frame at all, empty frames, a frame of thousands of detections and
//! far-away coordinates without panicking; give each (track, frame) one point, frames
//! increasing along a track; and refuse, without panicking, a frame that does not come after
//! the previous one.

use sillage::core::{Detection, FrameIndex, FrameObservations, Point2, TrackPoint, Tracker};
use sillage::track::bedload::{BedloadTracker, BedloadTrackerKind, BedloadTrackerParams};
use sillage::track::ptv::{PtvParams, PtvTracker};

/// A tracker under test, made fresh for each check.
type Maker = Box<dyn Fn() -> Box<dyn Tracker> + Sync>;

/// Every implementation, by name.
fn trackers() -> Vec<(String, Maker)> {
    let mut all: Vec<(String, Maker)> = vec![(
        "ptv".into(),
        Box::new(|| Box::new(PtvTracker::new(PtvParams::default()).unwrap())),
    )];
    for kind in BedloadTrackerKind::ALL {
        let make = move || -> Box<dyn Tracker> {
            let params = BedloadTrackerParams {
                tracker: kind,
                ..BedloadTrackerParams::default()
            };
            Box::new(BedloadTracker::new(&params).unwrap())
        };
        all.push((format!("bedload {kind:?}"), Box::new(make)));
    }
    all
}

/// 40 objects on a 60-px grid drifting 2 px a frame with a small wobble, for `frames`
/// frames; every seventh frame loses one object (a missed detection).
fn drifting_objects(frames: u64) -> Vec<(FrameIndex, Vec<Detection>)> {
    (0..frames)
        .map(|t| {
            let detections = (0..40u64)
                .filter(|&k| (k + t) % 7 != 0 || k % 5 != 0)
                .map(|k| {
                    let wobble = ((k * 31 + t * 17) % 11) as f64 * 0.05;
                    let x = 50.0 + (k % 8) as f64 * 60.0 + 2.0 * t as f64 + wobble;
                    let y = 50.0 + (k / 8) as f64 * 60.0 + 0.5 * t as f64 - wobble;
                    Detection::new(Point2::new(x, y), 1.0)
                })
                .collect();
            (t, detections)
        })
        .collect()
}

/// Runs `tracker` over `frames`, checking that each step emits only frames already seen.
fn run(tracker: &mut dyn Tracker, frames: &[(FrameIndex, Vec<Detection>)]) -> Vec<TrackPoint> {
    let mut points = Vec::new();
    for (frame, detections) in frames {
        let before = points.len();
        tracker
            .step(
                &FrameObservations::from_detections(*frame, detections),
                &mut points,
            )
            .unwrap();
        assert!(
            points[before..].iter().all(|p| p.frame <= *frame),
            "a point of a frame not yet seen was emitted at frame {frame}"
        );
    }
    tracker.finish(&mut points).unwrap();
    points
}

fn run_on_threads(
    make: &Maker,
    threads: usize,
    frames: &[(FrameIndex, Vec<Detection>)],
) -> Vec<TrackPoint> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| run(make().as_mut(), frames))
}

#[test]
fn every_tracker_gives_the_same_points_on_1_and_4_threads_and_when_run_twice() {
    let frames = drifting_objects(30);
    for (name, make) in trackers() {
        let one = run_on_threads(&make, 1, &frames);
        let four = run_on_threads(&make, 4, &frames);
        assert!(!one.is_empty(), "{name}: no point");
        assert_eq!(one, four, "{name}: thread count changed the points");
        assert_eq!(
            one,
            run_on_threads(&make, 4, &frames),
            "{name}: not repeatable"
        );
    }
}

#[test]
fn every_tracker_gives_one_point_per_track_and_frame_in_frame_order() {
    let frames = drifting_objects(30);
    for (name, make) in trackers() {
        let points = run(make().as_mut(), &frames);
        let mut last_frame = std::collections::HashMap::new();
        for p in &points {
            if let Some(previous) = last_frame.insert(p.track_id, p.frame) {
                assert!(
                    p.frame > previous,
                    "{name}: track {} has frame {} after frame {previous}",
                    p.track_id,
                    p.frame
                );
            }
        }
        let tracks = last_frame.len();
        assert!(
            (30..=120).contains(&tracks),
            "{name}: {tracks} tracks for 40 objects"
        );
    }
}

#[test]
fn every_tracker_survives_no_frame_empty_frames_and_gaps() {
    let mut frames = drifting_objects(20);
    for (_, detections) in &mut frames[5..9] {
        detections.clear();
    }
    let empty: Vec<(FrameIndex, Vec<Detection>)> = (0..10).map(|t| (t, Vec::new())).collect();
    for (name, make) in trackers() {
        assert!(
            run(make().as_mut(), &[]).is_empty(),
            "{name}: points from nothing"
        );
        assert!(
            run(make().as_mut(), &empty).is_empty(),
            "{name}: points from empty frames"
        );
        let points = run(make().as_mut(), &frames);
        assert!(
            points.iter().any(|p| p.frame >= 9),
            "{name}: nothing tracked after the empty frames"
        );
    }
}

#[test]
fn every_tracker_survives_a_crowded_frame_and_far_coordinates() {
    let crowd: Vec<Detection> = (0..3000u64)
        .map(|k| {
            let x = (k * 7919 % 2048) as f64 + 0.25;
            let y = (k * 104_729 % 2048) as f64 + 0.5;
            Detection::new(Point2::new(x, y), 1.0)
        })
        .collect();
    let far = vec![
        Detection::new(Point2::new(1.0e9, -1.0e9), 1.0),
        Detection::new(Point2::new(0.0, 0.0), 1.0),
    ];
    let frames = vec![(0, crowd.clone()), (1, crowd), (2, far.clone()), (3, far)];
    for (name, make) in trackers() {
        let mut tracker = make();
        let mut points = Vec::new();
        for (frame, detections) in &frames {
            // Refusing an input is allowed; panicking is not.
            let observations = FrameObservations::from_detections(*frame, detections);
            if tracker.step(&observations, &mut points).is_err() {
                break;
            }
        }
        let _ = tracker.finish(&mut points);
        assert!(
            points.iter().all(|p| p.frame <= 3),
            "{name}: frames invented"
        );
    }
}

#[test]
fn every_tracker_refuses_a_frame_that_does_not_come_after_the_last() {
    let frames = drifting_objects(4);
    for (name, make) in trackers() {
        let mut tracker = make();
        let mut points = Vec::new();
        for (frame, detections) in &frames {
            let observations = FrameObservations::from_detections(*frame, detections);
            tracker.step(&observations, &mut points).unwrap();
        }
        let (frame, detections) = &frames[2];
        let err = tracker
            .step(
                &FrameObservations::from_detections(*frame, detections),
                &mut points,
            )
            .expect_err(&format!("{name}: frame 2 accepted after frame 3"));
        assert!(err.to_string().contains('2'), "{name}: {err}");
    }
}

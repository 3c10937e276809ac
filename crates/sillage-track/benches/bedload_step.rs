//! One `BedloadTracker::step` (association, motion-state measurement, confidence density and
//! the filters; detection excluded) on a bedload scene of 400 and 4,000 beads: a packed bed of
//! resting black beads (¾) under transparent beads moving downstream at 2–12 px/frame (¼), 5 %
//! of those missed per frame with a weak candidate left where they are, and 1 false positive
//! per 400 beads.
//!
//! The tracker is warmed up on 10 frames; each sample clones it, steps the clone through the
//! 11th frame untimed (a clone's buffers start empty, a running tracker's are allocated and
//! in use) and times its step of the 12th. Groups: MMPF+ at N = 100 and 500 particles, and the five trackers of Table 1
//! at 400 beads, N = 100.

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::RngExt;
use sillage_core::{Detection, FrameObservations, Point2, TrackPoint, Tracker, rng_stream};
use sillage_track::bedload::{
    BedloadTracker, BedloadTrackerKind, BedloadTrackerParams, SaltationRule,
};

const WARM_FRAMES: u64 = 10;

/// Detections and candidates of `frames` frames of a scene of `beads` beads.
fn scene(beads: usize, frames: u64) -> Vec<(Vec<Detection>, Vec<Detection>)> {
    let mut rng = rng_stream(5, beads as u64);
    let width = 1280.0 * beads as f64 / 400.0;
    let black = beads * 3 / 4;
    let per_row = (width / 30.0) as usize;
    let bed: Vec<Point2> = (0..black)
        .map(|i| {
            let (row, col) = ((i / per_row) as f64, (i % per_row) as f64);
            Point2::new(15.0 + 30.0 * col + 15.0 * (row % 2.0), 305.0 - 26.0 * row)
        })
        .collect();
    let top = 305.0 - 26.0 * (black / per_row) as f64 - 30.0;
    let mut moving: Vec<(Point2, f64)> = (0..beads - black)
        .map(|_| {
            let p = Point2::new(
                rng.random::<f64>() * width,
                top - rng.random::<f64>() * 60.0,
            );
            (p, 2.0 + 10.0 * rng.random::<f64>())
        })
        .collect();
    let mut out = Vec::new();
    for _ in 0..frames {
        let mut detections: Vec<_> = bed
            .iter()
            .map(|&p| Detection::of_class(p, 1.0, 0))
            .collect();
        let mut candidates = Vec::new();
        for (p, speed) in &mut moving {
            p.x -= *speed;
            if p.x < 0.0 {
                p.x += width;
            }
            let seen = rng.random::<f64>() >= 0.05;
            let d = Detection::of_class(*p, if seen { 0.5 } else { 0.22 }, 1);
            if seen {
                detections.push(d);
            }
            candidates.push(d);
        }
        for _ in 0..beads / 400 {
            let fp = Point2::new(rng.random::<f64>() * width, rng.random::<f64>() * 320.0);
            detections.push(Detection::of_class(fp, 0.3, 1));
        }
        out.push((detections, candidates));
    }
    out
}

/// A tracker warmed up on the first frames of `frames`, and the next frame's input.
fn warmed(
    params: &BedloadTrackerParams,
    frames: &[(Vec<Detection>, Vec<Detection>)],
) -> BedloadTracker {
    let mut tracker = BedloadTracker::new(params).expect("valid params");
    let mut sink: Vec<TrackPoint> = Vec::new();
    for (f, (detections, candidates)) in frames[..WARM_FRAMES as usize].iter().enumerate() {
        let observations = FrameObservations {
            candidates,
            ..FrameObservations::from_detections(f as u64, detections)
        };
        tracker.step(&observations, &mut sink).expect("step");
    }
    tracker
}

fn bench_step(c: &mut Criterion, group: &str, cases: &[(String, BedloadTrackerParams, usize)]) {
    let mut group = c.benchmark_group(group);
    group.sample_size(20);
    for (name, params, beads) in cases {
        let frames = scene(*beads, WARM_FRAMES + 2);
        let tracker = warmed(params, &frames);
        let observations = |frame: u64| {
            let (detections, candidates) = &frames[frame as usize];
            FrameObservations {
                candidates,
                ..FrameObservations::from_detections(frame, detections)
            }
        };
        let (settling, timed) = (observations(WARM_FRAMES), observations(WARM_FRAMES + 1));
        group.bench_with_input(BenchmarkId::new(name.as_str(), beads), beads, |b, _| {
            b.iter_batched(
                || {
                    let mut tracker = tracker.clone();
                    let mut sink = Vec::<TrackPoint>::with_capacity(2 * beads);
                    tracker.step(&settling, &mut sink).expect("step");
                    sink.clear();
                    (tracker, sink)
                },
                |(mut tracker, mut sink)| {
                    tracker.step(&timed, &mut sink).expect("step");
                    // Returned, so that criterion drops the clone after the timing (a run does
                    // not free its tracker every frame).
                    (tracker, sink)
                },
                BatchSize::LargeInput,
            );
        });
    }
    group.finish();
}

fn scaling(c: &mut Criterion) {
    let mut cases = Vec::new();
    for particles in [100, 500] {
        for beads in [400, 4_000] {
            let mut params = BedloadTrackerParams::default();
            params.filter.particles = particles;
            cases.push((format!("mmpf_plus_n{particles}"), params, beads));
        }
    }
    bench_step(c, "bedload_step", &cases);
}

fn trackers(c: &mut Criterion) {
    let cases: Vec<_> = BedloadTrackerKind::ALL
        .iter()
        .map(|&kind| {
            let params = BedloadTrackerParams {
                tracker: kind,
                ..BedloadTrackerParams::default()
            };
            (kind.name().to_string(), params, 400)
        })
        .chain(std::iter::once({
            // The states frame by frame (the paper), to show the smoother's cost.
            let mut params = BedloadTrackerParams::default();
            params.smoother.lag = 0;
            ("mmpf_plus_lag0".to_string(), params, 400)
        }))
        .chain(std::iter::once({
            // Saltating by Eq. (4) frame by frame, to show the steadiest stretch's cost.
            let mut params = BedloadTrackerParams::default();
            params.smoother.saltation = SaltationRule::Frame;
            ("mmpf_plus_frame_salt".to_string(), params, 400)
        }))
        .collect();
    bench_step(c, "bedload_trackers", &cases);
}

criterion_group!(benches, scaling, trackers);
criterion_main!(benches);

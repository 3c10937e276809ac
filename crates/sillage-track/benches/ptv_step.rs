//! One `PtvTracker::step` (linking only, detection excluded) on a smooth cellular flow, for
//! 1k, 5k and 25k particles at the density of 25,000 particles in a 2048² frame.
//!
//! The tracker is warmed up on 8 frames (motion model and threshold settled); each sample
//! times the step of the 9th frame on a clone of it. Two configurations: TracTrac's
//! (`default`) and with displacement voting within 10 px (`voting`).

use std::f64::consts::PI;
use std::hint::black_box;

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::RngExt;
use sillage_core::{Detection, FrameObservations, Point2, TrackPoint, Tracker, Vec2, rng_stream};
use sillage_track::ptv::{PtvParams, PtvTracker};

const WARM_FRAMES: usize = 8;

/// Cellular (Taylor–Green) flow of 256 px cells, 3 px/frame at most.
fn velocity(p: Point2) -> Vec2 {
    let (kx, ky) = (PI * p.x / 256.0, PI * p.y / 256.0);
    Vec2::new(3.0 * kx.sin() * ky.cos(), -3.0 * kx.cos() * ky.sin())
}

/// `frames` frames of `n` particles advected by the flow (midpoint rule).
fn sequence(n: usize, frames: usize) -> Vec<Vec<Detection>> {
    let side = 2048.0 * (n as f64 / 25_000.0).sqrt();
    let mut rng = rng_stream(11, n as u64);
    let mut pts: Vec<Point2> = (0..n)
        .map(|_| Point2::new(rng.random::<f64>() * side, rng.random::<f64>() * side))
        .collect();
    let mut out = Vec::with_capacity(frames);
    for _ in 0..frames {
        out.push(pts.iter().map(|&p| Detection::new(p, 1.0)).collect());
        for p in &mut pts {
            let mid = *p + velocity(*p) * 0.5;
            *p = *p + velocity(mid);
        }
    }
    out
}

fn ptv_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("ptv_step");
    group.sample_size(20);
    let voting = PtvParams {
        vote_search_px: Some(10.0),
        ..Default::default()
    };
    for (name, params) in [("default", PtvParams::default()), ("voting", voting)] {
        for n in [1_000, 5_000, 25_000] {
            let frames = sequence(n, WARM_FRAMES + 1);
            let mut warmed = PtvTracker::new(params.clone()).expect("valid params");
            let mut sink: Vec<TrackPoint> = Vec::new();
            for (f, d) in frames[..WARM_FRAMES].iter().enumerate() {
                let obs = FrameObservations::from_detections(f as u64, d);
                warmed.step(&obs, &mut sink).expect("step");
            }
            let last = FrameObservations::from_detections(WARM_FRAMES as u64, &frames[WARM_FRAMES]);
            group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter_batched(
                    || (warmed.clone(), Vec::<TrackPoint>::with_capacity(n)),
                    |(mut tracker, mut out)| {
                        tracker.step(black_box(&last), &mut out).expect("step");
                        out
                    },
                    BatchSize::LargeInput,
                )
            });
        }
    }
    group.finish();
}

criterion_group!(benches, ptv_step);
criterion_main!(benches);

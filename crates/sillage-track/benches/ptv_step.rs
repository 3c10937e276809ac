//! One `PtvTracker::step` (linking only, detection excluded) on a smooth cellular flow, for
//! 1k, 5k and 25k particles at the density of 25,000 particles in a 2048² frame.
//!
//! The tracker is warmed up on 8 frames (motion model and threshold settled), then steps
//! through the next 32 frames in steady state, reusing its buffers as a real run does; a
//! fresh clone of the warmed tracker (not timed) starts over when the frames run out.
//! Detections come in raster order, as a detector emits them. Two configurations:
//! TracTrac's (`default`) and with displacement voting within 10 px (`voting`), both without
//! the warm-up (`warm_up_frames = 0`): its replay of the first frames is paid once per run,
//! not per step.

use std::f64::consts::PI;
use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::RngExt;
use sillage_core::{Detection, DiscardSink, FrameObservations, Point2, Tracker, Vec2, rng_stream};
use sillage_track::ptv::{PtvParams, PtvTracker, VoteSearch};

const WARM_FRAMES: usize = 8;

/// Frames stepped in steady state after the warm-up.
const TIMED_FRAMES: usize = 32;

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
        let mut frame: Vec<Detection> = pts.iter().map(|&p| Detection::new(p, 1.0)).collect();
        frame.sort_by(|a, b| {
            let row = |d: &Detection| d.pos_px.y.floor();
            row(a)
                .total_cmp(&row(b))
                .then(a.pos_px.x.total_cmp(&b.pos_px.x))
        });
        out.push(frame);
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
    let tractrac = PtvParams {
        warm_up_frames: 0,
        ..Default::default()
    };
    let voting = PtvParams {
        vote_search_px: VoteSearch::Px(10.0),
        ..tractrac.clone()
    };
    for (name, params) in [("default", tractrac), ("voting", voting)] {
        for n in [1_000, 5_000, 25_000] {
            let frames = sequence(n, WARM_FRAMES + TIMED_FRAMES);
            let mut warmed = PtvTracker::new(params.clone()).expect("valid params");
            for (f, d) in frames[..WARM_FRAMES].iter().enumerate() {
                let obs = FrameObservations::from_detections(f as u64, d);
                warmed.step(&obs, &mut DiscardSink).expect("step");
            }
            group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter_custom(|iters| {
                    let mut elapsed = Duration::ZERO;
                    let mut tracker = warmed.clone();
                    let mut next = WARM_FRAMES;
                    for _ in 0..iters {
                        if next == frames.len() {
                            tracker = warmed.clone();
                            next = WARM_FRAMES;
                        }
                        let obs = FrameObservations::from_detections(next as u64, &frames[next]);
                        let start = Instant::now();
                        tracker
                            .step(black_box(&obs), &mut DiscardSink)
                            .expect("step");
                        elapsed += start.elapsed();
                        next += 1;
                    }
                    elapsed
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, ptv_step);
criterion_main!(benches);

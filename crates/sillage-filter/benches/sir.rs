//! One SIR step (predict, Gaussian log-likelihood of a position measurement, normalise,
//! multinomial resampling) of every target, through `step_all` (rayon over targets).
//!
//! - `single`: one constant-velocity model (4 normal draws per particle);
//! - `switching`: constant position and constant velocity switched per particle by a 2×2
//!   transition table;
//! - `bedload`: the four motions of Eq. (3) of the MMPF+ paper with the Eq. (12) table.
//!
//! Sizes: 100, 400 and 4,000 targets × N = 100 and 500 particles. Filters are warmed up for a
//! few steps, then each sample times further steps on the same filters (steady state).

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use sillage_core::Point2;
use sillage_filter::{
    BedloadModel, BedloadParams, FilterParams, FilterSpec, InitialSpread, KinematicModel,
    KinematicParams, MotionModel, Noise2, Particle, ParticleFilter, Switching, SwitchingParams,
    step_all,
};

const WARM_STEPS: usize = 3;
const SIZES: [(usize, usize); 6] = [
    (100, 100),
    (100, 500),
    (400, 100),
    (400, 500),
    (4_000, 100),
    (4_000, 500),
];

/// Target `k`'s fixed measured position on a grid 40 px apart.
fn observation(k: usize) -> Point2 {
    Point2::new(40.0 * (k % 64) as f64, 40.0 * (k / 64) as f64)
}

fn filters(
    targets: usize,
    particles: usize,
    spread: impl Fn(Point2) -> InitialSpread,
) -> Vec<ParticleFilter> {
    let params = FilterParams {
        particles,
        ..Default::default()
    };
    let spec = FilterSpec::new(&params, 7).expect("valid params");
    (0..targets)
        .map(|k| spec.spawn(k as u64, &spread(observation(k))))
        .collect()
}

/// Gaussian position likelihood, 3 px² per axis (Eq. (8) with §4.3's variance).
fn likelihood(k: usize) -> impl FnMut(Particle) -> f64 {
    let z = observation(k);
    move |p: Particle| {
        let d = p.pos_px - z;
        -(d.x * d.x + d.y * d.y) / 6.0
    }
}

fn bench_model(
    c: &mut Criterion,
    name: &str,
    model: &impl MotionModel,
    spread: impl Fn(Point2) -> InitialSpread + Copy,
    sizes: &[(usize, usize)],
) {
    let mut group = c.benchmark_group(format!("sir_step/{name}"));
    group.sample_size(20);
    for &(targets, particles) in sizes {
        let mut bank = filters(targets, particles, spread);
        for _ in 0..WARM_STEPS {
            step_all(&mut bank, model, likelihood);
        }
        group.throughput(Throughput::Elements((targets * particles) as u64));
        group.bench_function(BenchmarkId::new(format!("{targets}x"), particles), |b| {
            b.iter(|| black_box(step_all(&mut bank, model, likelihood)))
        });
    }
    group.finish();
}

fn sir(c: &mut Criterion) {
    let noise = Noise2::diagonal(1.0, 1.0);
    let kinematic_spread = move |pos_px| InitialSpread {
        pos_px,
        pos_noise: noise.factor("init").expect("valid"),
        vel_px_per_frame: sillage_core::Vec2::ZERO,
        vel_noise: noise.factor("init").expect("valid"),
        mode: 0,
    };
    let cv = KinematicParams::ConstantVelocity {
        pos_noise: noise,
        vel_noise: noise.scaled(0.25),
    };
    let single = KinematicModel::new("model", &cv).expect("valid model");
    bench_model(c, "single", &single, kinematic_spread, &SIZES);

    let switching = Switching::new(&SwitchingParams {
        models: vec![KinematicParams::ConstantPosition { pos_noise: noise }, cv],
        transition: vec![vec![0.9, 0.1], vec![0.1, 0.9]],
    })
    .expect("valid switching");
    bench_model(c, "switching", &switching, kinematic_spread, &SIZES);

    let bedload = BedloadModel::new(BedloadParams::default()).expect("valid defaults");
    let bedload_spread = |pos_px| bedload.initial_spread(pos_px);
    bench_model(c, "bedload", &bedload, bedload_spread, &SIZES[..4]);
}

criterion_group!(benches, sir);
criterion_main!(benches);

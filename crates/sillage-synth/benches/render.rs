//! Rendering speed of the vortex frames: 2048² frames with up to 25,000 particles.

use criterion::{Criterion, criterion_group, criterion_main};
use sillage_core::Point2;
use sillage_synth::{Noise, NoiseKind, VortexFlow, VortexParams, render_spots};

fn render(c: &mut Criterion) {
    let mut group = c.benchmark_group("render_spots_2048");
    group.sample_size(10);
    for n_particles in [1_000, 25_000] {
        let params = VortexParams {
            width: 2048,
            height: 2048,
            n_particles,
            ..Default::default()
        };
        let flow = VortexFlow::new(&params).expect("valid parameters");
        let spots: Vec<(Point2, f64, f64)> =
            flow.positions().iter().map(|&p| (p, 0.5, 2.0)).collect();
        let noise = Noise::new(NoiseKind::Uniform, 0.125);
        group.bench_function(format!("{n_particles}_particles"), |b| {
            b.iter(|| render_spots(2048, 2048, &spots, noise, 7).expect("valid spots"))
        });
    }
    group.finish();
}

criterion_group!(benches, render);
criterion_main!(benches);

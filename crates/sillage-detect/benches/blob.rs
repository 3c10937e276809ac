//! Blob detection on a 2048² frame with ~25,000 Gaussian spots (σ = 1.2 px) and noise, seeded:
//! the defaults (scale and polarity measured on the first call, then the matched-scale second
//! look), a given scale (no second look), and the measurement itself (once per run). Then
//! the same seeding at σ = 2 px, where particle images overlap, with the defaults (which
//! split overlapping particles, `detector.deblend`, and re-fit the crowded ones,
//! `detector.refit_crowded`), without the re-fits, and without either.
//! Run with `cargo bench -p sillage-detect --bench blob`.

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;

use common::{Rng, Spot, render};
use criterion::{Criterion, criterion_group, criterion_main};
use sillage_core::{Detector, GrayImage};
use sillage_detect::{
    BlobDetector, BlobFilter, BlobParams, PolarityChoice, Scale, measure_particle_images,
};

/// The 2048² frame of the 25,000 seeded spots, images of std `sigma_px`.
fn frame(sigma_px: f64) -> GrayImage {
    let side = 2048;
    let mut rng = Rng(2024);
    let spots: Vec<Spot> = (0..25_000)
        .map(|_| Spot {
            x: rng.uniform() * side as f64,
            y: rng.uniform() * side as f64,
            amplitude: 0.3 + 0.5 * rng.uniform(),
        })
        .collect();
    render(side, side, 0.1, &spots, sigma_px, 0.02, &mut rng)
}

fn bench_blob(c: &mut Criterion) {
    let frame = frame(1.2);
    let mut group = c.benchmark_group("blob_2048x2048_25k");
    for filter in [BlobFilter::Dog, BlobFilter::Log] {
        let mut detector = BlobDetector::new(BlobParams {
            filter,
            ..BlobParams::default()
        })
        .unwrap();
        let mut out = Vec::new();
        // The first call measures the particle images (benched on its own below).
        detector.detect(&frame, &mut out).unwrap();
        group.bench_function(format!("{filter:?}"), |b| {
            b.iter(|| detector.detect(black_box(&frame), &mut out).unwrap())
        });
    }
    let mut given = BlobDetector::new(BlobParams {
        scale_px: Scale::Px(1.2),
        polarity: PolarityChoice::Bright,
        ..BlobParams::default()
    })
    .unwrap();
    let mut out = Vec::new();
    group.bench_function("Dog_given_scale", |b| {
        b.iter(|| given.detect(black_box(&frame), &mut out).unwrap())
    });
    group.bench_function("measure_particle_images", |b| {
        b.iter(|| measure_particle_images(black_box(&frame)).unwrap())
    });
    group.finish();
}

fn bench_deblend(c: &mut Criterion) {
    let frame = frame(2.0);
    let mut group = c.benchmark_group("blob_2048x2048_25k_sigma2");
    group.sample_size(10);
    let settings = [
        ("no_deblend", false, false),
        ("no_refit", true, false),
        ("defaults", true, true),
    ];
    for (name, deblend, refit_crowded) in settings {
        let mut detector = BlobDetector::new(BlobParams {
            deblend,
            refit_crowded,
            ..BlobParams::default()
        })
        .unwrap();
        let mut out = Vec::new();
        detector.detect(&frame, &mut out).unwrap();
        group.bench_function(name, |b| {
            b.iter(|| detector.detect(black_box(&frame), &mut out).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench_blob, bench_deblend);
criterion_main!(benches);

//! Gaussian blur, DoG and LoG on square frames (fixed seed). Run with
//! `cargo bench -p sillage-image --bench gaussian`.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use sillage_core::GrayImage;
use sillage_image::{DogFilter, GaussianFilter, LogFilter, Polarity};

/// A seeded pseudo-random frame with values in [0, 1).
fn frame(side: usize) -> GrayImage {
    let mut state = 0x5EED_u64;
    let data = (0..side * side)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        })
        .collect();
    GrayImage::from_vec(side, side, data).unwrap()
}

fn bench_filters(c: &mut Criterion) {
    for side in [1024, 2048] {
        let src = frame(side);
        let mut dst = GrayImage::default();
        let mut group = c.benchmark_group(format!("{side}x{side}"));
        for sigma in [1.0, 2.0, 4.0] {
            let mut blur = GaussianFilter::new(sigma).unwrap();
            group.bench_function(BenchmarkId::new("gaussian", sigma), |b| {
                b.iter(|| blur.apply(black_box(&src), &mut dst))
            });
        }
        let mut dog = DogFilter::new(2.0).unwrap();
        group.bench_function("dog_delta2", |b| {
            b.iter(|| dog.apply(black_box(&src), Polarity::Bright, &mut dst))
        });
        let mut log = LogFilter::new(2.0).unwrap();
        group.bench_function("log_delta2", |b| {
            b.iter(|| log.apply(black_box(&src), Polarity::Bright, &mut dst))
        });
        group.finish();
    }
}

criterion_group!(benches, bench_filters);
criterion_main!(benches);

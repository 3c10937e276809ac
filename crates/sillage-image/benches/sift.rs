//! SIFT on a 768×576 frame: `detect_and_describe` (OpenCV's `detectAndCompute`) and 10,000
//! `describe_at` queries (the particles of SIFT-PF), at random positions and clustered as
//! particles are. Run with
//! `cargo bench -p sillage-image --bench sift`; the frame is PETS09-S2L1 frame 1 from
//! `../shared/data` (beside the repository), or a seeded textured frame where it is absent.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use sillage_core::{GrayImage, Image};
use sillage_image::decode_levels;
use sillage_image::sift::{SiftDetector, SiftParams};

const PETS_FRAME: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/pets09_s2l1/img1/000001.jpg"
);

/// PETS09-S2L1 frame 1 as grey, or a textured 768×576 stand-in.
fn frame() -> GrayImage {
    if let Ok(picture) = image::open(PETS_FRAME) {
        let luma = picture.to_luma8();
        let (width, height) = (luma.width() as usize, luma.height() as usize);
        let mut grey = GrayImage::default();
        decode_levels(
            &Image::from_vec(width, height, luma.into_raw()).unwrap(),
            &mut grey,
        );
        return grey;
    }
    eprintln!("{PETS_FRAME} not found: using a synthetic frame");
    let (width, height) = (768, 576);
    let data = (0..width * height)
        .map(|i| {
            let (x, y) = ((i % width) as f32, (i / width) as f32);
            0.5 + 0.25 * (x * 0.11).sin() * (y * 0.07).cos() + 0.2 * ((x * y) * 0.0013).sin()
        })
        .collect();
    GrayImage::from_vec(width, height, data).unwrap()
}

fn bench_sift(c: &mut Criterion) {
    let frame = frame();
    let mut sift = SiftDetector::new(&SiftParams::default()).unwrap();
    let mut group = c.benchmark_group("sift_768x576");
    group.sample_size(10);
    group.bench_function("detect_and_describe", |b| {
        b.iter(|| sift.detect_and_describe(black_box(&frame)).unwrap().len())
    });
    sift.analyse(&frame).unwrap();
    let (width, height) = frame.dimensions();
    let queries: Vec<(f32, f32, f32, f32)> = (0..10_000)
        .map(|i| {
            let t = i as f32;
            let x = (t * 7.31) % width as f32;
            let y = (t * 3.17) % height as f32;
            (
                x,
                y,
                1.6 + (t * 0.37) % 4.0,
                (t * 0.61) % std::f32::consts::TAU,
            )
        })
        .collect();
    // SIFT-PF's pattern: 100 features of 100 particles each, within ±4 px of the feature.
    let clustered: Vec<(f32, f32, f32, f32)> = queries
        .iter()
        .enumerate()
        .map(|(i, _)| {
            let (x, y, s, o) = queries[i / 100 * 100];
            let t = i as f32;
            (x + (t * 1.37) % 8.0 - 4.0, y + (t * 2.11) % 8.0 - 4.0, s, o)
        })
        .collect();
    for (name, positions) in [
        ("describe_at_10k", &queries),
        ("describe_at_10k_clustered", &clustered),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                positions
                    .iter()
                    .filter_map(|&(x, y, s, o)| sift.describe_at(x, y, s, o))
                    .count()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_sift);
criterion_main!(benches);

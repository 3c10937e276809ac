//! Bead detection (MMPF+ §3.3) on one real 1280×320 flume frame of the shared sequence, with
//! its base mask and ring template, and the image primitives it is made of. Run with
//! `cargo bench -p sillage-detect --bench bead`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use sillage_core::{GrayImage, Image};
use sillage_detect::{BeadDetections, BeadDetector, BeadParams};
use sillage_image::{
    BoxMean, Morphology, PeakFinder, Reconstruction, RingCorrelator, RingTemplate,
    StructuringElement, box_mean_3x3, encode_levels,
};
use sillage_io::read_image;

const DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/bedload_beads_lafaye2018"
);

fn bench_bead(c: &mut Criterion) {
    let frame = read_image(format!(
        "{DATA}/images/BaumerBim10MegaAmont0507Image72040.tif"
    ))
    .unwrap();
    let mask = read_image(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/bedload_beads_lafaye2018/sequence_base_mask.tif"
    ))
    .unwrap();
    let mut group = c.benchmark_group("bead_1280x320");
    let mut detector = BeadDetector::new(BeadParams::default())
        .unwrap()
        .with_base_mask(&mask);
    let mut beads = BeadDetections::default();
    group.bench_function("detect", |b| {
        b.iter(|| {
            detector
                .detect_beads(black_box(&frame), &mut beads)
                .unwrap()
        })
    });

    // The stages, on the images the detector feeds them (each input computed once, so that
    // any subset of the benchmarks can be run with a filter).
    let (mut a, mut t) = (GrayImage::default(), GrayImage::default());
    let mut morphology = Morphology::new();
    let disk8 = StructuringElement::disk(8).unwrap();
    let disk22 = StructuringElement::disk(22).unwrap();
    group.bench_function("dilate_disk8", |b| {
        b.iter(|| morphology.dilate(black_box(&frame), &disk8, &mut a))
    });
    group.bench_function("close_disk22", |b| {
        b.iter(|| morphology.close(black_box(&frame), &disk22, &mut a))
    });
    let mut closed = GrayImage::default();
    morphology.close(&frame, &disk22, &mut closed);
    let top_hat = GrayImage::from_vec(
        frame.width(),
        frame.height(),
        closed
            .as_slice()
            .iter()
            .zip(frame.as_slice())
            .map(|(c, f)| c - f)
            .collect(),
    )
    .unwrap();
    let mut reconstruction = Reconstruction::new();
    group.bench_function("h_concave", |b| {
        b.iter(|| reconstruction.h_concave(black_box(&top_hat), 44.0 / 255.0, &mut a))
    });
    let mut concave = GrayImage::default();
    reconstruction
        .h_concave(&top_hat, 44.0 / 255.0, &mut concave)
        .unwrap();
    let mut correlator = RingCorrelator::new(RingTemplate::annulus(6.0, 10.0).unwrap());
    group.bench_function("ring_ncc", |b| {
        b.iter(|| correlator.apply(black_box(&concave), &mut t))
    });
    let mut correlation = GrayImage::default();
    correlator.apply(&concave, &mut correlation);
    group.bench_function("mean3x3_twice", |b| {
        b.iter(|| {
            box_mean_3x3(black_box(&correlation), &mut a);
            box_mean_3x3(&a, &mut t);
        })
    });
    let mut smoothing = BoxMean::new();
    group.bench_function("mean3x3_twice_fused", |b| {
        b.iter(|| smoothing.apply(black_box(&correlation), 2, &mut t))
    });
    // The levels path of 8-bit frames (what the detector runs on the real frames).
    let (mut levels, mut out) = (Image::default(), Image::default());
    assert!(encode_levels(&frame, &mut levels));
    group.bench_function("dilate_disk8_levels", |b| {
        b.iter(|| morphology.dilate_levels(black_box(&levels), &disk8, &mut out))
    });
    group.bench_function("close_disk22_levels", |b| {
        b.iter(|| morphology.close_levels(black_box(&levels), &disk22, &mut out))
    });
    let top_hat_levels = Image::from_vec(
        frame.width(),
        frame.height(),
        top_hat
            .as_slice()
            .iter()
            .map(|&v| (v * 255.0).round() as u8)
            .collect(),
    )
    .unwrap();
    group.bench_function("h_concave_levels", |b| {
        b.iter(|| reconstruction.h_concave_levels(black_box(&top_hat_levels), 44, &mut out))
    });
    let mut concave_levels = Image::default();
    reconstruction.h_concave_levels(&top_hat_levels, 44, &mut concave_levels);
    group.bench_function("ring_ncc_levels", |b| {
        b.iter(|| correlator.apply_levels(black_box(&concave_levels), &mut t))
    });
    box_mean_3x3(&correlation, &mut a);
    box_mean_3x3(&a, &mut t);
    let (mut finder, mut peaks) = (PeakFinder::new(), Vec::new());
    group.bench_function("maxima", |b| {
        b.iter(|| finder.find(black_box(&t), 1, 0.2, &mut peaks))
    });
    group.finish();
}

criterion_group!(benches, bench_bead);
criterion_main!(benches);

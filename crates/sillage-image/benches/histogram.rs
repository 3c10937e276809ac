//! HSV box histograms of the pedestrian IMM-PF observation model on a realistic case: a
//! 768×576 frame, one person's 120×200 px region of interest, 200 particle boxes of 30×80 px,
//! 110 bins (fixed seed). Run with `cargo bench -p sillage-image --bench histogram`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use sillage_core::RgbImage;
use sillage_image::{BinImage, BoxPx, HsvBinning};

/// SplitMix64.
fn next(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A street-like frame: a smooth background, flat-coloured "people" (rectangles) and ±8
/// levels of noise, so neighbouring pixels often share a bin as in real images.
fn frame(width: usize, height: usize) -> RgbImage {
    let mut state = 0x5EED_u64;
    let people: Vec<(usize, usize, [u8; 3])> = (0..20)
        .map(|_| {
            let x = (next(&mut state) % (width as u64 - 40)) as usize;
            let y = (next(&mut state) % (height as u64 - 100)) as usize;
            let c = [0; 3].map(|_: u8| (next(&mut state) % 256) as u8);
            (x, y, c)
        })
        .collect();
    let mut pixels = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let mut p = [
                (60 + x * 120 / width) as u8,
                (80 + y * 100 / height) as u8,
                110,
            ];
            for &(px, py, c) in &people {
                if (px..px + 40).contains(&x) && (py..py + 100).contains(&y) {
                    p = c;
                }
            }
            let noise = next(&mut state);
            for (k, v) in p.iter_mut().enumerate() {
                let n = ((noise >> (8 * k)) % 17) as i32 - 8;
                *v = (i32::from(*v) + n).clamp(0, 255) as u8;
            }
            pixels.push(p);
        }
    }
    RgbImage::from_vec(width, height, pixels).unwrap()
}

fn bench_histograms(c: &mut Criterion) {
    let rgb = frame(768, 576);
    let binning = HsvBinning::default();
    let mut bins = BinImage::new();
    bins.fill_hsv(&rgb, &binning).unwrap();
    let mut state = 7u64;
    let mut unit = || (next(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
    // 200 boxes inside one person's 120×200 px region of interest at (300, 200).
    let boxes: Vec<BoxPx> = (0..200)
        .map(|_| {
            let (x, y) = (300.0 + unit() * 90.0, 200.0 + unit() * 120.0);
            BoxPx {
                x_min: x,
                y_min: y,
                x_max: x + 30.0,
                y_max: y + 80.0,
            }
        })
        .collect();
    let mut histogram = vec![0.0f32; binning.bins()];
    let mut group = c.benchmark_group("hsv_histogram");
    group.bench_function("fill_hsv_768x576", |b| {
        b.iter(|| bins.fill_hsv(black_box(&rgb), &binning).unwrap())
    });
    for stride in [1, 2] {
        group.bench_function(format!("direct_200_boxes_stride{stride}"), |b| {
            b.iter(|| {
                for region in &boxes {
                    bins.box_histogram(black_box(region), stride, &mut histogram)
                        .unwrap();
                }
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_histograms);
criterion_main!(benches);

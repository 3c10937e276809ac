//! Gaussian, DoG, LoG and median filters against direct references, and thread invariance.

mod common;

use common::random_image;
use sillage_core::GrayImage;
use sillage_image::{
    DogFilter, GaussianFilter, GaussianKernel, LogFilter, MedianSize, Polarity, median_filter,
};

/// Reflect-101 by brute force: bounce until inside.
pub fn reflect(mut i: isize, n: usize) -> usize {
    let n = n as isize;
    if n == 1 {
        return 0;
    }
    loop {
        if i < 0 {
            i = -i;
        } else if i >= n {
            i = 2 * (n - 1) - i;
        } else {
            return i as usize;
        }
    }
}

/// Direct 2-D convolution in f64 with the separable kernel `w(i)·w(j)`, reflect-101 border.
pub fn reference_blur(src: &GrayImage, sigma: f64) -> Vec<f64> {
    let k = GaussianKernel::new(sigma).unwrap();
    let r = k.radius() as isize;
    let (w, h) = src.dimensions();
    let mut out = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut acc = 0.0f64;
            for j in -r..=r {
                for i in -r..=r {
                    let v = src.get(reflect(x as isize + i, w), reflect(y as isize + j, h));
                    acc += f64::from(k.weight(i)) * f64::from(k.weight(j)) * f64::from(v);
                }
            }
            out[y * w + x] = acc;
        }
    }
    out
}

/// Largest absolute difference between an image and a reference.
pub fn max_abs_diff(image: &GrayImage, reference: &[f64]) -> f64 {
    image
        .as_slice()
        .iter()
        .zip(reference)
        .map(|(&a, &b)| (f64::from(a) - b).abs())
        .fold(0.0, f64::max)
}

const SIZES: [(usize, usize); 6] = [(1, 1), (7, 3), (2048, 3), (37, 41), (5, 300), (64, 1)];

#[test]
fn gaussian_matches_direct_convolution() {
    for (seed, &(w, h)) in SIZES.iter().enumerate() {
        let src = random_image(w, h, seed as u64);
        for sigma in [0.5, 1.0, 2.0, 3.7] {
            let mut dst = GrayImage::default();
            GaussianFilter::new(sigma).unwrap().apply(&src, &mut dst);
            assert_eq!(dst.dimensions(), (w, h));
            let err = max_abs_diff(&dst, &reference_blur(&src, sigma));
            assert!(err < 1e-5, "{w}×{h} σ={sigma}: max error {err}");
        }
    }
}

#[test]
fn dog_is_the_difference_of_two_blurs_of_the_input() {
    for (seed, &(w, h)) in SIZES.iter().enumerate() {
        let src = random_image(w, h, 100 + seed as u64);
        for delta in [1.0, 2.0, 2.5] {
            let narrow = reference_blur(&src, 0.8 * delta);
            let wide = reference_blur(&src, 1.2 * delta);
            let mut dog = DogFilter::new(delta).unwrap();
            for (polarity, sign) in [(Polarity::Bright, 1.0), (Polarity::Dark, -1.0)] {
                let mut dst = GrayImage::default();
                dog.apply(&src, polarity, &mut dst);
                let reference: Vec<f64> = narrow
                    .iter()
                    .zip(&wide)
                    .map(|(a, b)| sign * (a - b))
                    .collect();
                let err = max_abs_diff(&dst, &reference);
                assert!(
                    err < 1e-5,
                    "{w}×{h} δ={delta} {polarity:?}: max error {err}"
                );
            }
        }
    }
}

#[test]
fn log_is_the_negated_laplacian_of_the_blur() {
    for (seed, &(w, h)) in SIZES.iter().enumerate() {
        let src = random_image(w, h, 200 + seed as u64);
        let blur = reference_blur(&src, 1.5);
        let at = |x: isize, y: isize| blur[reflect(y, h) * w + reflect(x, w)];
        let reference: Vec<f64> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as isize, (i / w) as isize);
                4.0 * at(x, y) - at(x - 1, y) - at(x + 1, y) - at(x, y - 1) - at(x, y + 1)
            })
            .collect();
        let mut log = LogFilter::new(1.5).unwrap();
        let mut dst = GrayImage::default();
        log.apply(&src, Polarity::Bright, &mut dst);
        let err = max_abs_diff(&dst, &reference);
        assert!(err < 1e-5, "{w}×{h}: max error {err}");
        log.apply(&src, Polarity::Dark, &mut dst);
        let negated: Vec<f64> = reference.iter().map(|v| -v).collect();
        assert!(max_abs_diff(&dst, &negated) < 1e-5);
    }
}

#[test]
fn blob_filters_respond_positively_to_their_polarity() {
    let mut spot = GrayImage::new(21, 21);
    spot.set(10, 10, 1.0);
    let mut dst = GrayImage::default();
    DogFilter::new(2.0)
        .unwrap()
        .apply(&spot, Polarity::Bright, &mut dst);
    assert!(dst.get(10, 10) > 0.0);
    LogFilter::new(2.0)
        .unwrap()
        .apply(&spot, Polarity::Dark, &mut dst);
    assert!(dst.get(10, 10) < 0.0);
}

#[test]
fn median_matches_sorting_reference() {
    for (seed, &(w, h)) in SIZES.iter().chain(&[(2, 2), (13, 9)]).enumerate() {
        // Quantised values so that ties occur.
        let mut src = random_image(w, h, 300 + seed as u64);
        for v in src.as_mut_slice() {
            *v = (*v * 8.0).floor() / 8.0;
        }
        for size in [MedianSize::Three, MedianSize::Five] {
            let r = size.radius() as isize;
            let mut dst = GrayImage::default();
            median_filter(&src, size, &mut dst);
            for y in 0..h {
                for x in 0..w {
                    let mut window = Vec::new();
                    for dy in -r..=r {
                        for dx in -r..=r {
                            let cx = (x as isize + dx).clamp(0, w as isize - 1) as usize;
                            let cy = (y as isize + dy).clamp(0, h as isize - 1) as usize;
                            window.push(src.get(cx, cy));
                        }
                    }
                    window.sort_by(f32::total_cmp);
                    assert_eq!(dst.get(x, y), window[window.len() / 2], "{w}×{h} {size:?}");
                }
            }
        }
    }
}

/// Runs `f` on a rayon pool of `threads` threads.
fn with_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

#[test]
fn filters_are_bit_identical_whatever_the_thread_count() {
    let src = random_image(517, 700, 7);
    let run = || {
        let mut blur = GrayImage::default();
        let mut dog = GrayImage::default();
        let mut log = GrayImage::default();
        let mut median = GrayImage::default();
        GaussianFilter::new(2.0).unwrap().apply(&src, &mut blur);
        DogFilter::new(2.0)
            .unwrap()
            .apply(&src, Polarity::Bright, &mut dog);
        LogFilter::new(2.0)
            .unwrap()
            .apply(&src, Polarity::Dark, &mut log);
        median_filter(&src, MedianSize::Five, &mut median);
        let stats = sillage_image::mean_std(&dog).unwrap();
        (
            blur,
            dog,
            log,
            median,
            stats.mean.to_bits(),
            stats.std.to_bits(),
        )
    };
    let one = with_threads(1, run);
    for threads in [2, 3] {
        assert!(
            with_threads(threads, run) == one,
            "{threads} threads differ from 1"
        );
    }
}

#[test]
fn filter_reuse_across_sizes_is_correct() {
    let mut filter = GaussianFilter::new(1.0).unwrap();
    let mut dst = GrayImage::default();
    for (w, h) in [(300, 300), (10, 4), (301, 129)] {
        let src = random_image(w, h, (w * h) as u64);
        filter.apply(&src, &mut dst);
        assert!(max_abs_diff(&dst, &reference_blur(&src, 1.0)) < 1e-5);
    }
}

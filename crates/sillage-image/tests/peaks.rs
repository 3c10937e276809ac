//! Local maxima against brute force, and sub-pixel fits on sampled spots.

mod common;

use common::random_image;
use proptest::prelude::*;
use sillage_core::GrayImage;
use sillage_image::{Peak, PeakFinder, SubpixelFit, refine_peak};

/// The definition, literally: the first maximum of its window in raster order, above threshold.
fn brute_force(image: &GrayImage, n: usize, threshold: f32) -> Vec<Peak> {
    let (w, h) = image.dimensions();
    let mut peaks = Vec::new();
    for y in n..h.saturating_sub(n) {
        for x in n..w.saturating_sub(n) {
            let v = image.get(x, y);
            if v <= threshold {
                continue;
            }
            let mut first_max = (y - n, x - n);
            for yy in y - n..=y + n {
                for xx in x - n..=x + n {
                    if image.get(xx, yy) > image.get(first_max.1, first_max.0) {
                        first_max = (yy, xx);
                    }
                }
            }
            if first_max == (y, x) {
                peaks.push(Peak { y, x });
            }
        }
    }
    peaks
}

proptest! {
    #[test]
    fn peaks_match_brute_force(
        w in 1usize..70, h in 1usize..80, n in 1usize..4, levels in 2u32..6,
        threshold in -0.1f32..0.9, seed in any::<u64>(),
    ) {
        let mut image = random_image(w, h, seed);
        // Few grey levels, so that plateaus and ties are common.
        for v in image.as_mut_slice() {
            *v = (*v * levels as f32).floor() / levels as f32;
        }
        let mut found = Vec::new();
        PeakFinder::new().find(&image, n, threshold, &mut found);
        prop_assert_eq!(found, brute_force(&image, n, threshold));
    }
}

#[test]
fn a_plateau_gives_exactly_one_peak() {
    let mut image = GrayImage::new(8, 8);
    for (x, y) in [(3, 3), (4, 3), (3, 4), (4, 4)] {
        image.set(x, y, 1.0);
    }
    let mut found = Vec::new();
    PeakFinder::new().find(&image, 1, 0.5, &mut found);
    assert_eq!(found, vec![Peak { y: 3, x: 3 }]);
}

/// A point-sampled Gaussian spot of σ = `sigma` centred at `(cx, cy)`, on `background`.
fn spot(cx: f64, cy: f64, sigma: f64, background: f64) -> GrayImage {
    let (w, h) = (15, 15);
    let data = (0..w * h)
        .map(|i| {
            let (dx, dy) = ((i % w) as f64 - cx, (i / w) as f64 - cy);
            (background + (-(dx * dx + dy * dy) / (2.0 * sigma * sigma)).exp()) as f32
        })
        .collect();
    GrayImage::from_vec(w, h, data).unwrap()
}

#[test]
fn gaussian_fit_recovers_sampled_spots() {
    for sigma in [0.8, 1.2, 2.0] {
        for k in 0..10 {
            let (ox, oy) = (-0.45 + 0.1 * k as f64, 0.4 - 0.09 * k as f64);
            let image = spot(7.0 + ox, 7.0 + oy, sigma, 0.0);
            let p = refine_peak(&image, 7, 7, SubpixelFit::Gaussian).unwrap();
            assert!(
                (p.x - 7.0 - ox).abs() < 0.01,
                "σ={sigma} x: {} vs {}",
                p.x,
                7.0 + ox
            );
            assert!(
                (p.y - 7.0 - oy).abs() < 0.01,
                "σ={sigma} y: {} vs {}",
                p.y,
                7.0 + oy
            );
        }
    }
}

#[test]
fn quadratic_fit_is_biased_but_on_the_right_side() {
    let image = spot(7.3, 6.8, 1.2, 0.0);
    let p = refine_peak(&image, 7, 7, SubpixelFit::Quadratic).unwrap();
    assert!(p.x > 7.0 && p.x < 7.5 && (p.x - 7.3).abs() < 0.1, "{p:?}");
    assert!(p.y < 7.0 && p.y > 6.5 && (p.y - 6.8).abs() < 0.1, "{p:?}");
}

#[test]
fn gaussian_fit_handles_non_positive_neighbourhoods() {
    // A spot on a negative pedestal (as in a DoG trough): ln needs the local shift.
    let image = spot(7.2, 7.0, 1.0, -0.3);
    let p = refine_peak(&image, 7, 7, SubpixelFit::Gaussian).unwrap();
    assert!(p.is_finite() && p.x > 7.0 && p.x < 7.5, "{p:?}");
    assert!(refine_peak(&image, 0, 7, SubpixelFit::Gaussian).is_none());
    assert!(refine_peak(&image, 7, 14, SubpixelFit::Gaussian).is_none());
}

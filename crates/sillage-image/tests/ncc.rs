//! Ring-template NCC against the direct formula, and what is (not) a ring.

mod common;

use common::random_image;
use sillage_core::GrayImage;
use sillage_image::{RingCorrelator, RingTemplate};

/// BeadTracking's template: −0.593137 on the ring, 1 elsewhere (21×21).
fn beadtracking_template() -> GrayImage {
    let side = 21;
    let data = (0..side * side)
        .map(|i| {
            let (x, y) = ((i % side) as i64 - 10, (i / side) as i64 - 10);
            let d2 = x * x + y * y;
            if d2 > 37 && d2 <= 101 { -0.593137 } else { 1.0 }
        })
        .collect();
    GrayImage::from_vec(side, side, data).unwrap()
}

/// Direct NCC in f64 with the template centred on each pixel, zeros outside the image.
fn reference(src: &GrayImage, template: &GrayImage) -> Vec<f64> {
    let (w, h) = src.dimensions();
    let side = template.width();
    let r = (side / 2) as isize;
    let t: Vec<f64> = template.as_slice().iter().map(|&v| f64::from(v)).collect();
    let t_mean = t.iter().sum::<f64>() / t.len() as f64;
    let mut out = vec![0.0; w * h];
    for y in 0..h as isize {
        for x in 0..w as isize {
            let f: Vec<f64> = (0..side * side)
                .map(|i| {
                    let (xx, yy) = (x + (i % side) as isize - r, y + (i / side) as isize - r);
                    if xx >= 0 && yy >= 0 && xx < w as isize && yy < h as isize {
                        f64::from(src.get(xx as usize, yy as usize))
                    } else {
                        0.0
                    }
                })
                .collect();
            let f_mean = f.iter().sum::<f64>() / f.len() as f64;
            let (mut num, mut tt, mut ff) = (0.0, 0.0, 0.0);
            for (a, b) in t.iter().zip(&f) {
                num += (a - t_mean) * (b - f_mean);
                tt += (a - t_mean).powi(2);
                ff += (b - f_mean).powi(2);
            }
            out[y as usize * w + x as usize] = if ff > 1e-12 * f.len() as f64 {
                num / (tt * ff).sqrt()
            } else {
                0.0
            };
        }
    }
    out
}

#[test]
fn matches_the_direct_formula_inside_and_at_the_borders() {
    let template = beadtracking_template();
    let ring = RingTemplate::from_image(&template).unwrap();
    assert_eq!((ring.radius(), ring.ring_pixels()), (10, 204));
    let mut correlator = RingCorrelator::new(ring);
    for (seed, (w, h)) in [(60, 45), (7, 30), (33, 5)].into_iter().enumerate() {
        let mut src = random_image(w, h, seed as u64);
        // A flat patch: its windows are flat inside, and 0 there.
        for y in 0..h.min(25) {
            for x in 0..w.min(25) {
                src.set(x, y, 0.25);
            }
        }
        let mut ncc = GrayImage::default();
        correlator.apply(&src, &mut ncc);
        let expected = reference(&src, &template);
        for (i, (&got, &want)) in ncc.as_slice().iter().zip(&expected).enumerate() {
            assert!(
                (f64::from(got) - want).abs() < 1e-5,
                "{w}×{h} pixel {i}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn a_dark_ring_correlates_best_at_its_centre() {
    let (w, h) = (64, 48);
    let data = (0..w * h)
        .map(|i| {
            let d = ((i % w) as f64 - 30.0).hypot((i / w) as f64 - 20.0);
            if d > 6.0 && d <= 10.0 { 0.3 } else { 0.8 }
        })
        .collect();
    let src = GrayImage::from_vec(w, h, data).unwrap();
    let mut ncc = GrayImage::default();
    RingCorrelator::new(RingTemplate::annulus(6.0, 10.0).unwrap()).apply(&src, &mut ncc);
    let best = (0..w * h).max_by(|&a, &b| ncc.as_slice()[a].total_cmp(&ncc.as_slice()[b]));
    assert_eq!(best, Some(20 * w + 30));
    assert!(ncc.get(30, 20) > 0.9999, "{}", ncc.get(30, 20));
}

#[test]
fn templates_that_are_not_rings_are_rejected_with_the_reason() {
    let image = |side: usize, f: &dyn Fn(i64, i64) -> f32| {
        let c = (side / 2) as i64;
        let data = (0..side * side)
            .map(|i| f((i % side) as i64 - c, (i / side) as i64 - c))
            .collect();
        GrayImage::from_vec(side, side, data).unwrap()
    };
    let ring = |x: i64, y: i64| {
        if (25..=64).contains(&(x * x + y * y)) {
            0.0
        } else {
            1.0
        }
    };
    RingTemplate::from_image(&image(17, &ring)).unwrap();
    let cases: [(GrayImage, &str); 7] = [
        (GrayImage::new(16, 16), "odd side"),
        (GrayImage::new(9, 11), "odd side"),
        (image(17, &|_, _| 0.5), "all its pixels"),
        (
            image(17, &|x, y| if x * x + y * y <= 16 { 0.0 } else { 1.0 }),
            "centre",
        ),
        (
            image(17, &|x, y| ring(x, y) + if x == 0 { 0.5 } else { 0.0 }),
            "third value",
        ),
        (
            image(17, &|x, y| if x > 2 { ring(x, y) } else { 1.0 }),
            "symmetric",
        ),
        (
            image(17, &|x, y| {
                if x * x + y * y == 36 || x * x + y * y == 64 {
                    0.0
                } else {
                    1.0
                }
            }),
            "hole",
        ),
    ];
    for (template, reason) in cases {
        let err = RingTemplate::from_image(&template).unwrap_err().to_string();
        assert!(
            err.contains("not a ring") && err.contains(reason),
            "{reason}: {err}"
        );
    }
    assert!(RingTemplate::annulus(0.0, 10.0).is_err());
    assert!(RingTemplate::annulus(9.5, 10.0).is_err());
}

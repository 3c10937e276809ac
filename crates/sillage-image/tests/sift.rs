//! SIFT on synthetic scenes with known truth: rotation invariance, a Gaussian blob's position and
//! scale, the contrast and edge tests, descriptors at arbitrary positions, determinism, errors.

use std::f32::consts::{FRAC_PI_2, TAU};

use sillage_core::GrayImage;
use sillage_image::PixelBox;
use sillage_image::sift::{SiftDescriptor, SiftDetector, SiftKeypoint, SiftParams};

/// A seeded xorshift stream in `[0, 1)`.
fn uniform(state: &mut u64) -> f32 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 40) as f32 / (1u64 << 24) as f32
}

/// Grey 0.5 plus Gaussian blobs `(x, y, σx, σy, amplitude)`.
fn blobs(width: usize, height: usize, blobs: &[(f32, f32, f32, f32, f32)]) -> GrayImage {
    let data = (0..width * height)
        .map(|i| {
            let (x, y) = ((i % width) as f32, (i / width) as f32);
            0.5 + blobs
                .iter()
                .map(|&(bx, by, sx, sy, a)| {
                    let (dx, dy) = ((x - bx) / sx, (y - by) / sy);
                    a * (-0.5 * (dx * dx + dy * dy)).exp()
                })
                .sum::<f32>()
        })
        .collect();
    GrayImage::from_vec(width, height, data).unwrap()
}

/// 129×129 px (a side of 2⁷ + 1, so that a quarter turn maps every octave's grid onto
/// itself) of 150 random round blobs kept 24 px from the sides, bright and dark.
fn textured() -> GrayImage {
    let mut state = 0x51F7_u64;
    let spots: Vec<_> = (0..150)
        .map(|_| {
            let x = 24.0 + 80.0 * uniform(&mut state);
            let y = 24.0 + 80.0 * uniform(&mut state);
            let s = 1.5 + 3.0 * uniform(&mut state);
            let a = 0.4 * (uniform(&mut state) - 0.5);
            (x, y, s, s, a)
        })
        .collect();
    blobs(129, 129, &spots)
}

/// The image turned a quarter clockwise on screen: `(x, y) → (height − 1 − y, x)`.
fn quarter_turn(image: &GrayImage) -> GrayImage {
    let (width, height) = image.dimensions();
    let data = (0..width * height)
        .map(|i| {
            let (xr, yr) = (i % height, i / height);
            image.get(yr, height - 1 - xr)
        })
        .collect();
    GrayImage::from_vec(height, width, data).unwrap()
}

fn detect(params: &SiftParams, frame: &GrayImage) -> Vec<(SiftKeypoint, SiftDescriptor)> {
    SiftDetector::new(params)
        .unwrap()
        .detect_and_describe(frame)
        .unwrap()
}

fn angle_gap(a: f32, b: f32) -> f32 {
    let d = (a - b).rem_euclid(TAU);
    d.min(TAU - d)
}

#[test]
fn a_quarter_turn_maps_keypoints_and_descriptors_onto_themselves() {
    let frame = textured();
    let turned = quarter_turn(&frame);
    let params = SiftParams::default();
    let (original, rotated) = (detect(&params, &frame), detect(&params, &turned));
    assert!(original.len() >= 30, "{} keypoints", original.len());
    assert_eq!(original.len(), rotated.len());
    let height = frame.height() as f32;
    let mut unrelated = Vec::new();
    for (kp, descriptor) in &original {
        let (x, y) = (height - 1.0 - kp.y, kp.x);
        let (twin, twin_descriptor) = rotated
            .iter()
            .min_by(|a, b| {
                let d = |k: &SiftKeypoint| {
                    (k.x - x).hypot(k.y - y) + angle_gap(k.orientation, kp.orientation + FRAC_PI_2)
                };
                d(&a.0).total_cmp(&d(&b.0))
            })
            .unwrap();
        assert!((twin.x - x).hypot(twin.y - y) < 0.5, "{kp:?} vs {twin:?}");
        assert!(
            (twin.sigma / kp.sigma - 1.0).abs() < 0.01,
            "{kp:?} vs {twin:?}"
        );
        assert!(angle_gap(twin.orientation, kp.orientation + FRAC_PI_2) < 0.02);
        assert!(descriptor.distance(twin_descriptor) < 0.05, "{kp:?}");
        unrelated.extend(
            rotated
                .iter()
                .filter(|(k, _)| (k.x - x).hypot(k.y - y) > 4.0)
                .map(|(_, d)| descriptor.distance(d)),
        );
    }
    unrelated.sort_by(f32::total_cmp);
    assert!(
        unrelated[unrelated.len() / 20] > 0.3,
        "5 % quantile {}",
        unrelated[unrelated.len() / 20]
    );
}

#[test]
fn a_gaussian_blob_gives_a_keypoint_at_its_centre_and_scale() {
    // A blob of std σ_b is blurred by √(σ² − 0.5²) at nominal level σ (the input counts as
    // blurred by 0.5 px), so at its centre G_σ ∗ I = A·b/(σ² + b), with b = σ_b² − 0.25. The
    // DoG of layer σ is D(σ) = G_kσ ∗ I − G_σ ∗ I, extremal over σ where
    // (k²σ² + b) = k(σ² + b), i.e. σ = √b / √k: the keypoint scale is
    // √(σ_b² − ¼) · 2^(−1/(2s)), 0.89 σ_b at s = 3 (not σ_b as for the normalised Laplacian).
    for (sigma_b, x0, y0) in [
        (2.5f32, 40.3f32, 37.8f32),
        (4.0, 44.6, 41.2),
        (6.0, 47.5, 46.0),
    ] {
        let frame = blobs(96, 88, &[(x0, y0, sigma_b, sigma_b, 0.4)]);
        let found = detect(&SiftParams::default(), &frame);
        let (kp, _) = found
            .iter()
            .min_by(|a, b| {
                let d = |k: &SiftKeypoint| (k.x - x0).hypot(k.y - y0);
                d(&a.0).total_cmp(&d(&b.0))
            })
            .unwrap();
        let expected = (sigma_b * sigma_b - 0.25).sqrt() * 2f32.powf(-1.0 / 6.0);
        assert!((kp.x - x0).hypot(kp.y - y0) < 0.2, "σ_b {sigma_b}: {kp:?}");
        assert!(
            (kp.sigma / expected - 1.0).abs() < 0.05,
            "σ_b {sigma_b}: {kp:?}, expected {expected}"
        );
    }
}

#[test]
fn contrast_and_edge_tests_reject_what_they_should() {
    let flat = GrayImage::from_vec(64, 64, vec![0.5; 64 * 64]).unwrap();
    assert!(detect(&SiftParams::default(), &flat).is_empty());
    let step = GrayImage::from_vec(
        64,
        64,
        (0..64 * 64)
            .map(|i| if (i % 64) as f32 > 30.3 { 0.8 } else { 0.2 })
            .collect(),
    )
    .unwrap();
    assert!(detect(&SiftParams::default(), &step).is_empty());
    assert!(detect(&SiftParams::permissive(), &step).is_empty());

    let near = |found: &[(SiftKeypoint, SiftDescriptor)], x: f32, y: f32| {
        found.iter().any(|(k, _)| (k.x - x).hypot(k.y - y) < 1.0)
    };
    // Centres off the half-pixel: a blob centred exactly between two samples of an octave
    // makes the refinement oscillate between them and fail (OpenCV alike).
    // A faint blob: |D| ≈ 0.004 < 0.04 / 3, but above 0.005 / 3.
    let faint = blobs(64, 64, &[(31.3, 30.2, 2.5, 2.5, 0.02)]);
    assert!(!near(&detect(&SiftParams::default(), &faint), 31.3, 30.2));
    assert!(near(&detect(&SiftParams::permissive(), &faint), 31.3, 30.2));
    // An elongated ridge: curvature ratio ≈ (σy/σx)² = 36, above (r+1)²/r for r = 10.
    let ridge = blobs(64, 64, &[(31.3, 30.2, 2.0, 12.0, 0.4)]);
    let lax = SiftParams {
        edge_threshold: 100.0,
        ..SiftParams::default()
    };
    assert!(!near(&detect(&SiftParams::default(), &ridge), 31.3, 30.2));
    assert!(near(&detect(&lax, &ridge), 31.3, 30.2));
}

#[test]
fn permissive_thresholds_give_more_keypoints() {
    let mut frame = textured();
    let mut state = 7u64;
    frame
        .as_mut_slice()
        .iter_mut()
        .for_each(|v| *v += 0.01 * uniform(&mut state));
    let default = detect(&SiftParams::default(), &frame).len();
    let permissive = detect(&SiftParams::permissive(), &frame).len();
    assert!(permissive > default, "{permissive} vs {default}");
}

#[test]
fn descriptors_at_keypoints_equal_the_keypoints_descriptors() {
    let frame = textured();
    let mut sift = SiftDetector::new(&SiftParams::default()).unwrap();
    let found = sift.detect_and_describe(&frame).unwrap();
    assert!(!found.is_empty());
    for (kp, descriptor) in &found {
        assert_eq!(sift.describe(kp).as_ref(), Some(descriptor));
        let at = sift.describe_at(kp.x, kp.y, kp.sigma, kp.orientation);
        assert_eq!(at.as_ref(), Some(descriptor), "{kp:?}");
        let norm: f32 = descriptor.0.iter().map(|v| v * v).sum::<f32>().sqrt();
        assert!((norm - 1.0).abs() < 1e-4);
        assert!(descriptor.0.iter().all(|&v| v >= 0.0));
    }
    // Partly outside the image is fine; entirely outside is None.
    assert!(sift.describe_at(-3.0, 20.0, 2.0, 0.3).is_some());
    assert!(sift.describe_at(-300.0, 20.0, 2.0, 0.3).is_none());
    assert!(sift.describe_at(20.0, 20.0, f32::NAN, 0.3).is_none());
    assert!(sift.orientation_at(-300.0, 20.0, 2.0).is_none());
}

#[test]
fn orientation_at_a_keypoint_is_its_dominant_orientation() {
    let frame = textured();
    let mut sift = SiftDetector::new(&SiftParams::default()).unwrap();
    let found = sift.detect_and_describe(&frame).unwrap();
    // A keypoint alone at its position (one orientation peak): orientation_at gives it back
    // (up to rounding the position to the grid, which the keypoint's histogram also does).
    let single: Vec<_> = found
        .iter()
        .filter(|(k, _)| {
            found
                .iter()
                .filter(|(o, _)| o.x == k.x && o.y == k.y)
                .count()
                == 1
        })
        .collect();
    assert!(!single.is_empty());
    for (kp, _) in single {
        let at = sift.orientation_at(kp.x, kp.y, kp.sigma).unwrap();
        assert!(angle_gap(at, kp.orientation) < 1e-4, "{kp:?}: {at}");
    }
}

#[test]
fn a_region_finds_the_whole_frame_keypoints_inside_it() {
    let frame = textured();
    let mut sift = SiftDetector::new(&SiftParams::default()).unwrap();
    sift.analyse(&frame).unwrap();
    let mut all = Vec::new();
    sift.keypoints(None, &mut all);
    let region = PixelBox {
        x0: 30,
        y0: 40,
        x1: 90,
        y1: 100,
    };
    let inside: Vec<_> = all
        .iter()
        .filter(|k| k.x >= 29.5 && k.x < 89.5 && k.y >= 39.5 && k.y < 99.5)
        .copied()
        .collect();
    let mut found = vec![all[0]];
    sift.keypoints(Some(region), &mut found);
    assert!(inside.len() >= 10 && inside.len() < all.len());
    assert_eq!(found[0], all[0], "appends");
    assert_eq!(found[1..], inside[..]);
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let frame = textured();
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| detect(&SiftParams::permissive(), &frame))
    };
    let one = run(1);
    assert!(!one.is_empty());
    assert_eq!(one, run(4));
}

#[test]
fn bad_input_gives_clear_errors() {
    let mut sift = SiftDetector::new(&SiftParams::default()).unwrap();
    assert!(
        sift.describe_at(10.0, 10.0, 2.0, 0.0).is_none(),
        "before any frame"
    );
    let empty = sift.analyse(&GrayImage::default()).unwrap_err().to_string();
    assert!(empty.contains("too small"), "{empty}");
    let thin = GrayImage::from_vec(10, 50, vec![0.5; 500]).unwrap();
    let message = sift.analyse(&thin).unwrap_err().to_string();
    assert!(
        message.contains("10×50") && message.contains("11 px"),
        "{message}"
    );
    let bad = SiftParams {
        octave_layers: 0,
        ..SiftParams::default()
    };
    let message = SiftDetector::new(&bad).unwrap_err().to_string();
    assert!(message.contains("octave_layers"), "{message}");
    // The smallest frame accepted works.
    let small = blobs(11, 11, &[(5.0, 5.0, 1.5, 1.5, 0.3)]);
    sift.detect_and_describe(&small).unwrap();
}

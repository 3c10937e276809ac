//! Acceptance: sub-pixel localisation of isolated particles against the Cramér–Rao bound.
//!
//! For a Gaussian spot `A·exp(−r²/2σ²)` in white noise of standard deviation σₙ, the Fisher
//! information on the x position is `Σ (∂g/∂x)²/σₙ² ≈ (A²/σₙ²) ∫∫ (x²/σ⁴) e^{−r²/σ²} dx dy
//! = (A²/σₙ²)·π/2`, so no unbiased estimator does better than `σₙ/A·√(2/π)` px per axis,
//! whatever σ. Uniform noise U(0, m) has σₙ = m/√12.

use sillage::core::{Detection, Detector, Point2};
use sillage::detect::{BlobDetector, BlobParams, Scale};
use sillage::synth::{Noise, NoiseKind, render_spots};

const PEAK: f64 = 0.5;

/// Spots on a 24-px grid with seeded sub-pixel offsets, so none interact.
fn isolated_spots(width: usize, height: usize, seed: u64) -> Vec<Point2> {
    use rand::RngExt;
    let mut rng = sillage::core::rng_stream(seed, 0);
    let mut spots = Vec::new();
    for gy in 1..height / 24 {
        for gx in 1..width / 24 {
            spots.push(Point2::new(
                gx as f64 * 24.0 + rng.random_range(-0.5..0.5),
                gy as f64 * 24.0 + rng.random_range(-0.5..0.5),
            ));
        }
    }
    spots
}

/// Per-axis RMS and mean Euclidean localisation errors over several noisy frames, and the
/// share of spots found within 1 px.
fn localisation_errors(noise: Noise, sigma_px: f64, params: BlobParams) -> (f64, f64, f64, f64) {
    let (width, height) = (512, 512);
    let mut detector = BlobDetector::new(params).unwrap();
    let (mut sx, mut sy, mut se, mut n, mut total) = (0.0, 0.0, 0.0, 0usize, 0usize);
    let mut detections: Vec<Detection> = Vec::new();
    for seed in 0..6 {
        let truth = isolated_spots(width, height, seed);
        let spots: Vec<_> = truth.iter().map(|&p| (p, PEAK, sigma_px)).collect();
        let image = render_spots(width, height, &spots, noise, 100 + seed).unwrap();
        detector.detect(&image, &mut detections).unwrap();
        for p in &truth {
            total += 1;
            let Some(nearest) = detections
                .iter()
                .map(|d| d.pos_px)
                .filter(|d| d.distance(*p) < 1.0)
                .min_by(|a, b| a.distance(*p).total_cmp(&b.distance(*p)))
            else {
                continue;
            };
            sx += (nearest.x - p.x).powi(2);
            sy += (nearest.y - p.y).powi(2);
            se += nearest.distance(*p);
            n += 1;
        }
    }
    let found = n as f64 / total as f64;
    let n = n as f64;
    ((sx / n).sqrt(), (sy / n).sqrt(), se / n, found)
}

/// The default detector: scale and polarity measured from the frame.
fn default_params() -> BlobParams {
    BlobParams::default()
}

#[test]
fn gaussian_noise_rms_error_is_within_1_5_cramer_rao_at_every_particle_size() {
    for sigma_px in [0.7, 1.0, 1.5, 2.0, 2.5, 3.0] {
        for snr in [5.0, 10.0, 20.0] {
            let sigma_noise = PEAK / snr;
            let bound = sigma_noise / PEAK * (2.0 / std::f64::consts::PI).sqrt();
            let (rx, ry, _, found) = localisation_errors(
                Noise::new(NoiseKind::Gaussian, sigma_noise),
                sigma_px,
                default_params(),
            );
            eprintln!(
                "σ {sigma_px} px, SNR {snr}: found {:.1} %, RMS x {rx:.4} y {ry:.4} px, Cramér–Rao {bound:.4} px, ratio {:.2}",
                100.0 * found,
                rx.max(ry) / bound
            );
            // The default's scale is below the particles' (to resolve neighbours), so at peak
            // SNR 5 it misses some faint spots (measured 2026-11-28: 83 % at σ 0.7, 99.6-99.8 %
            // at σ 1-3; RMS 1.14-1.32× the bound everywhere); at SNR ≥ 10 it must find them
            // all.
            if snr >= 10.0 {
                assert!(
                    found > 0.99,
                    "σ {sigma_px}, SNR {snr}: only {found} of the spots found"
                );
            }
            assert!(
                rx < 1.5 * bound && ry < 1.5 * bound,
                "σ {sigma_px}, SNR {snr}: {rx} {ry} vs bound {bound}"
            );
        }
    }
}

#[test]
fn a_matched_scale_finds_every_isolated_spot_at_snr_5_and_more() {
    let params = BlobParams {
        scale_px: Scale::Px(1.2),
        ..BlobParams::default()
    };
    for snr in [5.0, 10.0, 20.0] {
        let sigma_noise = PEAK / snr;
        let bound = sigma_noise / PEAK * (2.0 / std::f64::consts::PI).sqrt();
        let (rx, ry, _, found) =
            localisation_errors(Noise::new(NoiseKind::Gaussian, sigma_noise), 1.2, params);
        assert!(found > 0.99, "SNR {snr}: only {found} of the spots found");
        assert!(
            rx < 1.5 * bound && ry < 1.5 * bound,
            "SNR {snr}: {rx} {ry} vs bound {bound}"
        );
    }
}

#[test]
fn uniform_noise_at_the_papers_snr_10_beats_tractrac() {
    // TracTrac's paper reports a mean position error of 0.057 px at SNR 10 (uniform noise of
    // magnitude A/SNR).
    let magnitude = PEAK / 10.0;
    let bound = magnitude / 12f64.sqrt() / PEAK * (2.0 / std::f64::consts::PI).sqrt();
    let (rx, ry, mean, found) = localisation_errors(
        Noise::new(NoiseKind::Uniform, magnitude),
        1.2,
        default_params(),
    );
    assert!(found > 0.999, "only {found} of the spots found");
    eprintln!(
        "uniform SNR 10: RMS x {rx:.4} y {ry:.4}, mean {mean:.4} px, Cramér–Rao {bound:.4} px"
    );
    assert!(mean < 0.057, "mean error {mean}");
    assert!(
        rx < 1.5 * bound && ry < 1.5 * bound,
        "{rx} {ry} vs bound {bound}"
    );
}

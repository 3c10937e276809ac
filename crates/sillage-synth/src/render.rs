//! Renders Gaussian spots plus noise into a [`GrayImage`], in parallel row bands with
//! results identical whatever the number of threads.

use rand::RngExt;
use rand_distr::StandardNormal;
use rayon::prelude::*;
use sillage_core::{Error, GrayImage, Point2, Result, rng_stream};

use crate::noise::{Noise, NoiseKind};

/// Rows per band: the unit of parallel work and of noise streams (fixed, so that the image
/// does not depend on the number of threads).
pub(crate) const BAND_ROWS: usize = 16;

/// A spot is drawn in a window of ± this many standard deviations (the rest is < 3.4e-4 of
/// its peak).
const WINDOW_SIGMAS: f64 = 4.0;

/// Renders `width × height` pixels: the noise of `noise` (one seeded stream per band of
/// rows, derived from `seed`), plus each spot `(centre, amplitude, sigma_px)` as an
/// isotropic Gaussian `amplitude · exp(−|p − centre|² / 2σ²)` sampled at pixel centres.
///
/// Overlapping spots add and nothing is clamped: values can exceed 1 where spots overlap and
/// go below 0 with Gaussian noise (the model stays linear; writers clamp when quantising).
/// Spots are cut at the image border (no wrap). Same inputs, same image, on any thread
/// count. Errors name the first spot with a non-finite value or a `sigma_px` ≤ 0.
pub fn render_spots(
    width: usize,
    height: usize,
    spots: &[(Point2, f64, f64)],
    noise: Noise,
    seed: u64,
) -> Result<GrayImage> {
    noise.validate()?;
    for (index, &(centre, amplitude, sigma)) in spots.iter().enumerate() {
        if !(centre.is_finite() && amplitude.is_finite() && sigma.is_finite() && sigma > 0.0) {
            return Err(Error::input(format!(
                "spot {index} at ({}, {}) with amplitude {amplitude} and sigma {sigma} px: \
                 positions and amplitudes must be finite and sigma a finite number > 0",
                centre.x, centre.y
            )));
        }
    }
    let mut image = GrayImage::new(width, height);
    render_into(&mut image, spots, noise, seed);
    Ok(image)
}

/// The renderer proper, on inputs already checked (see [`render_spots`]).
pub(crate) fn render_into(
    image: &mut GrayImage,
    spots: &[(Point2, f64, f64)],
    noise: Noise,
    seed: u64,
) {
    let (width, height) = image.dimensions();
    if width == 0 || height == 0 {
        return;
    }
    let windows: Vec<Option<Window>> = spots
        .iter()
        .map(|&spot| Window::of(spot, width, height))
        .collect();
    let bands = spots_per_band(height, &windows);
    image
        .as_mut_slice()
        .par_chunks_mut(BAND_ROWS * width)
        .zip(bands.par_iter())
        .enumerate()
        .for_each(|(band, (pixels, band_spots))| {
            fill_noise(pixels, noise, seed, band as u64);
            let rows = band * BAND_ROWS..band * BAND_ROWS + pixels.len() / width;
            let mut profile = Vec::new();
            for &index in band_spots {
                // Listed spots have a window.
                if let Some(window) = &windows[index] {
                    add_spot(pixels, width, &rows, spots[index], window, &mut profile);
                }
            }
        });
}

/// For each band of rows, the indices (ascending) of the spots whose window reaches it.
fn spots_per_band(height: usize, windows: &[Option<Window>]) -> Vec<Vec<usize>> {
    let mut bands = vec![Vec::new(); height.div_ceil(BAND_ROWS)];
    for (index, window) in windows.iter().enumerate() {
        let Some(window) = window else {
            continue;
        };
        for band in bands[window.rows.0 / BAND_ROWS..=window.rows.1 / BAND_ROWS].iter_mut() {
            band.push(index);
        }
    }
    bands
}

/// Fills one band with noise drawn from its own stream `(seed, band)`.
pub(crate) fn fill_noise(pixels: &mut [f32], noise: Noise, seed: u64, band: u64) {
    if noise.magnitude == 0.0 {
        pixels.fill(0.0);
        return;
    }
    let mut rng = rng_stream(seed, band);
    let magnitude = noise.magnitude as f32;
    match noise.kind {
        NoiseKind::Uniform => pixels
            .iter_mut()
            .for_each(|p| *p = rng.random::<f32>() * magnitude),
        NoiseKind::Gaussian => pixels
            .iter_mut()
            .for_each(|p| *p = rng.sample::<f32, _>(StandardNormal) * magnitude),
    }
}

/// The pixel window (inclusive column and row ranges) a spot is drawn in, clipped to the
/// image; `None` when it misses the image.
struct Window {
    cols: (usize, usize),
    rows: (usize, usize),
}

impl Window {
    fn of((centre, _, sigma): (Point2, f64, f64), width: usize, height: usize) -> Option<Self> {
        let reach = WINDOW_SIGMAS * sigma;
        let cols = clipped_range(centre.x - reach, centre.x + reach, width)?;
        let rows = clipped_range(centre.y - reach, centre.y + reach, height)?;
        Some(Self { cols, rows })
    }
}

/// Integer pixel indices in `[low, high] ∩ [0, len − 1]`, or `None` when empty.
fn clipped_range(low: f64, high: f64, len: usize) -> Option<(usize, usize)> {
    let last = (len - 1) as f64;
    let first = low.ceil().max(0.0);
    let end = high.floor().min(last);
    (first <= end).then_some((first as usize, end as usize))
}

/// Adds one spot, drawn in `window`, to the pixels of a band holding image rows `rows`;
/// `profile` is a reused buffer for the separable column profile.
fn add_spot(
    pixels: &mut [f32],
    width: usize,
    rows: &std::ops::Range<usize>,
    (centre, amplitude, sigma): (Point2, f64, f64),
    window: &Window,
    profile: &mut Vec<f64>,
) {
    let inv_two_var = 0.5 / (sigma * sigma);
    profile.clear();
    profile.extend(
        (window.cols.0..=window.cols.1)
            .map(|x| (-(x as f64 - centre.x).powi(2) * inv_two_var).exp()),
    );
    for y in window.rows.0.max(rows.start)..=window.rows.1.min(rows.end - 1) {
        let weight = amplitude * (-(y as f64 - centre.y).powi(2) * inv_two_var).exp();
        let start = (y - rows.start) * width;
        let row = &mut pixels[start + window.cols.0..=start + window.cols.1];
        for (pixel, &gx) in row.iter_mut().zip(profile.iter()) {
            *pixel += (weight * gx) as f32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_noise_free_spot_has_its_amplitude_at_its_centre() {
        let image =
            render_spots(9, 9, &[(Point2::new(4.0, 4.0), 0.5, 1.0)], Noise::none(), 0).unwrap();
        assert_eq!(image.get(4, 4), 0.5);
        let side = 0.5 * (-0.5f64).exp();
        assert!((f64::from(image.get(5, 4)) - side).abs() < 1e-7);
        assert_eq!(image.get(4, 5), image.get(5, 4));
    }

    #[test]
    fn spots_are_cut_at_the_border_and_far_spots_ignored() {
        let spots = [
            (Point2::new(0.0, 0.0), 1.0, 2.0),
            (Point2::new(-100.0, 3.0), 1.0, 2.0),
            (Point2::new(3.0, 1e9), 1.0, 2.0),
        ];
        let image = render_spots(4, 40, &spots, Noise::none(), 0).unwrap();
        assert_eq!(image.get(0, 0), 1.0);
        assert_eq!(image.get(0, 39), 0.0);
    }

    #[test]
    fn bad_spots_and_noise_are_rejected() {
        let nan = [(Point2::new(f64::NAN, 0.0), 1.0, 1.0)];
        let err = render_spots(4, 4, &nan, Noise::none(), 0).unwrap_err();
        assert!(err.to_string().contains("spot 0"), "{err}");
        assert!(
            render_spots(4, 4, &[(Point2::new(1.0, 1.0), 1.0, 0.0)], Noise::none(), 0).is_err()
        );
        let noise = Noise::new(NoiseKind::Gaussian, -1.0);
        assert!(render_spots(4, 4, &[], noise, 0).is_err());
    }

    #[test]
    fn empty_images_are_fine() {
        let image = render_spots(0, 5, &[(Point2::new(0.0, 0.0), 1.0, 1.0)], Noise::none(), 0);
        assert!(image.unwrap().is_empty());
    }
}

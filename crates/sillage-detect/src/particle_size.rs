//! The size and polarity of the particle images, measured from a frame: blobs found as maxima of
//! the scale-normalised Laplacian of Gaussian over position and scale (Lindeberg's automatic
//! scale selection), both signs at once.
//!
//! For a Gaussian particle image of std σ, `−s²∇²(G_s ∗ I)` at its centre is
//! `2A·s²σ²/(s² + σ²)²`, largest at `s = σ` whatever the amplitude `A`: the scale of each
//! blob's maximum is its σ. Noise maxima are kept out by a per-scale threshold (median + 6
//! robust standard deviations of that scale's response); the polarity whose blobs stand out
//! more (90th percentile of their significance) wins, and the measured σ is the median over its
//! stronger half. The source density counts only the blobs that stand out at least a tenth as
//! much as that percentile ([`PARTICLE_SHARE`]): the particle images, not the texture.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sillage_core::{Error, GrayImage, Result};
use sillage_image::{LogFilter, Polarity, median_mad};

/// Smallest scale searched, px.
const MIN_SCALE_PX: f64 = 0.5;
/// Scales per octave (factor 2 in σ).
const SCALES_PER_OCTAVE: usize = 4;
/// Number of scales: 0.5 to 8 px. Maxima on the first and last scale are not kept (their
/// true scale may lie outside), so particle images of σ ≈ 0.6 to 6.7 px are measured.
const N_SCALES: usize = 4 * SCALES_PER_OCTAVE + 1;
/// A blob must stand this many robust standard deviations above its scale's median response.
const SIGNIFICANCE: f64 = 6.0;
/// Fewer blobs than this are "no particles".
const MIN_BLOBS: usize = 1;
/// The noise of a scale's response is taken as at least this share of its largest magnitude,
/// so that noise-free frames (robust deviation 0) still have a threshold.
const NOISE_FLOOR: f32 = 1e-3;
/// Largest side of the central crop measured (bounds the cost on very large frames).
const MAX_SIDE_PX: usize = 1024;
/// Fewest pixels a rayon task scales or scans for the largest response.
const PIXELS_PER_TASK: usize = 1 << 16;
/// Fewest rows a rayon task scans for extrema.
const ROWS_PER_TASK: usize = 32;

/// What [`measure_particle_images`] found.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ParticleImages {
    /// Median std σ of the particle images, px (a Gaussian of this σ matches them).
    pub sigma_px: f64,
    /// Whether the particles are brighter or darker than their background.
    pub polarity: Polarity,
    /// Blobs of that polarity the measurement used.
    pub blobs: usize,
    /// Blobs of the other polarity (for the record: a clear choice has far fewer).
    pub blobs_other_polarity: usize,
    /// Blobs of that polarity standing out at least [`PARTICLE_SHARE`] as much as the 90th
    /// percentile's: those counted as particle images in the source density.
    #[serde(default)]
    pub particle_blobs: usize,
    /// Median std σ of the stronger half of the particle images, px: `sigma_px` without the
    /// weak blobs, which on textured frames are many and small.
    #[serde(default)]
    pub particle_sigma_px: f64,
    /// The source density `N_s`: the particle images (`particle_blobs`) per pixel of the
    /// measured region times the area `π(2σ)²` of a particle image (its e⁻² disc, σ
    /// `particle_sigma_px`). Particle images overlap, and PTV can no
    /// longer separate them, as it nears 1 (see [`DENSE_SOURCE_DENSITY`]). Blobs that merge
    /// are counted once, so it reads low on saturated frames, never above about π.
    #[serde(default)]
    pub source_density: f64,
}

impl ParticleImages {
    /// A warning for run summaries when the source density reaches
    /// [`DENSE_SOURCE_DENSITY`]; `None` below it.
    pub fn density_warning(&self) -> Option<String> {
        (self.source_density >= DENSE_SOURCE_DENSITY).then(|| {
            format!(
                "the particle images cover the frame (source density {:.2}: {} particle images \
                 of σ {:.2} px on the first frame); PTV cannot separate particles this dense, and \
                 most trajectories will be false. Record with fewer particles or smaller images, \
                 or measure the flow by cross-correlation (PIV)",
                self.source_density, self.particle_blobs, self.particle_sigma_px
            )
        })
    }
}

/// Source density (as measured, [`ParticleImages::source_density`]) from which
/// [`ParticleImages::density_warning`] warns.
///
/// Chosen on the tune halves of both `sillage bench ptv-accuracy` families (36 cases,
/// 2026-11-30): the cases PTV still solves there measure at most 0.40 (defaults ≥ 54 % true
/// recoveries), those beyond it (≤ 9 % true for the defaults, ≤ 0.1 % for the best of the
/// grid) at least 0.60; 0.5 lies between. On the report halves (36 cases, never used to
/// choose) it warns on all five cases whose defaults recover ≤ 8 % (measured 0.60–0.75, false
/// recoveries 21–98 %) and on none of the other 31 (the densest of those measures 0.48 and
/// recovers 53 %). Merged images count once, so the measure reads low where images overlap:
/// 0.60 was a true `N_s` of 0.9–1.0, 0.75 one of 5.6. (Figures of every blob counted; with
/// [`PARTICLE_SHARE`] since 2026-12-01: 0.59–0.68 warned, at most 0.47 not, on the report
/// halves.)
pub const DENSE_SOURCE_DENSITY: f64 = 0.5;

/// Share of the 90th percentile's significance from which a blob counts as a particle image
/// in the source density; weaker blobs are taken as texture, compression blocks or noise.
///
/// Chosen on the tune halves of both `sillage bench ptv-accuracy` families (36 cases,
/// 2026-12-01), as the largest share that keeps the cases PTV cannot solve as far above
/// [`DENSE_SOURCE_DENSITY`] as counting every blob did: at 0.05 and 0.1 they measure at least
/// 0.60 and 0.59 (0.60 with every blob), at 0.2 0.54, at 0.3 0.45, below it; the densest
/// solvable case stays at 0.40. On the report halves (never used to choose) the five cases the
/// defaults cannot solve (≤ 8 % true recoveries) measure 0.59–0.68 and the other 31 at most
/// 0.47, as before: the same warnings (8 of the main family's 12 report cases share their
/// first frame with a tune case; the two unsolvable ones with a frame of their own read 0.60
/// and 0.62). On trackpy's tutorial movie (dark spheres on a textured,
/// compressed background, about 524 per frame for trackpy), 1,342 of the first frame's 3,824
/// dark blobs count, of σ 2.07 px: 0.27, where every blob gave a false warning at 0.51.
pub const PARTICLE_SHARE: f64 = 0.1;

/// One maximum over position and scale.
#[derive(Debug, Clone, Copy)]
struct Blob {
    sigma_px: f64,
    significance: f64,
}

/// Measures the particle images of `image` (its central `MAX_SIDE_PX`² at most). Errors with
/// "no particles found" on a frame without at least `MIN_BLOBS` blobs of σ ≈ 0.6–6.7 px
/// standing clear of the noise: empty, flat, pure noise or one huge blob.
pub fn measure_particle_images(image: &GrayImage) -> Result<ParticleImages> {
    let crop = central_crop(image);
    let image = crop.as_ref().unwrap_or(image);
    let (width, height) = image.dimensions();
    if width < 3 || height < 3 {
        return Err(no_particles(format!(
            "the frame is {width}×{height} px, too small to measure particles in"
        )));
    }
    let mut bright = Vec::new();
    let mut dark = Vec::new();
    let mut layers: [GrayImage; 3] = Default::default();
    let mut noise = [(0.0f32, 0.0f32); 3];
    let mut samples = Vec::new();
    let pixel_noise = pixel_noise_sigma(image, &mut samples);
    for k in 0..N_SCALES {
        let slot = k % 3;
        let scale = scale_of(k as f64);
        LogFilter::new(scale)?.apply(image, Polarity::Bright, &mut layers[slot]);
        let normalisation = (scale * scale) as f32;
        layers[slot]
            .as_mut_slice()
            .par_chunks_mut(PIXELS_PER_TASK)
            .for_each(|chunk| chunk.iter_mut().for_each(|v| *v *= normalisation));
        // The largest magnitude is the same whatever the order of the comparisons.
        let floor = NOISE_FLOOR
            * layers[slot]
                .as_slice()
                .par_chunks(PIXELS_PER_TASK)
                .map(|chunk| chunk.iter().fold(0.0f32, |m, v| m.max(v.abs())))
                .reduce(|| 0.0, f32::max);
        let white = pixel_noise * white_noise_gain(scale)?;
        noise[slot] = match median_mad(&layers[slot], &mut samples) {
            Some(s) => (s.median as f32, (s.sigma as f32).min(white).max(floor)),
            None => (0.0, 0.0),
        };
        if k >= 2 {
            let (below, centre, above) = ((k - 2) % 3, (k - 1) % 3, slot);
            collect_maxima(
                &layers,
                [below, centre, above],
                noise[centre],
                k - 1,
                &mut bright,
                &mut dark,
            );
        }
    }
    let (polarity, chosen, other) = if contrast(&mut bright) >= contrast(&mut dark) {
        (Polarity::Bright, bright, dark.len())
    } else {
        (Polarity::Dark, dark, bright.len())
    };
    if chosen.len() < MIN_BLOBS {
        return Err(no_particles(format!(
            "{} bright and {other} dark blob(s) of σ 0.6–6.7 px stand {SIGNIFICANCE} robust \
             standard deviations above the noise: the frame looks empty, flat, pure noise or \
             one large object",
            chosen.len()
        )));
    }
    // `chosen` is sorted by decreasing significance: the particle images are its prefix down to
    // a share of the 90th percentile's.
    let typical = chosen[chosen.len() / 10].significance;
    let particle_blobs = chosen.partition_point(|b| b.significance >= PARTICLE_SHARE * typical);
    let particle_sigma_px = stronger_half_median_sigma(&chosen[..particle_blobs]);
    let disc_px2 = std::f64::consts::PI * (2.0 * particle_sigma_px).powi(2);
    Ok(ParticleImages {
        sigma_px: stronger_half_median_sigma(&chosen),
        polarity,
        blobs: chosen.len(),
        blobs_other_polarity: other,
        particle_blobs,
        particle_sigma_px,
        source_density: particle_blobs as f64 * disc_px2 / (width * height) as f64,
    })
}

/// The median σ of the stronger half of `blobs` (sorted by decreasing significance, not
/// empty): weak maxima are the likeliest to be noise or overlaps.
fn stronger_half_median_sigma(blobs: &[Blob]) -> f64 {
    let mut sigmas: Vec<f64> = blobs[..blobs.len().div_ceil(2)]
        .iter()
        .map(|b| b.sigma_px)
        .collect();
    sigmas.sort_by(f64::total_cmp);
    sigmas[sigmas.len() / 2]
}

/// Robust std of the pixel noise (Immerkær's estimator, with a median instead of a mean): the
/// mask `[1 −2 1; −2 4 −2; 1 −2 1]` cancels smooth structure, so on white noise of std σₙ its
/// output has std 6σₙ, and particles barely reach it. Infinity when the frame is too small.
fn pixel_noise_sigma(image: &GrayImage, samples: &mut Vec<f32>) -> f32 {
    let (width, height) = image.dimensions();
    if width < 3 || height < 3 {
        return f32::INFINITY;
    }
    let mut response = GrayImage::new(width - 2, height - 2);
    for y in 1..height - 1 {
        let (up, row, down) = (image.row(y - 1), image.row(y), image.row(y + 1));
        let out = response.row_mut(y - 1);
        for (i, value) in out.iter_mut().enumerate() {
            let x = i + 1;
            let ring = up[x - 1] + up[x + 1] + down[x - 1] + down[x + 1];
            let cross = up[x] + down[x] + row[x - 1] + row[x + 1];
            *value = ring - 2.0 * cross + 4.0 * row[x];
        }
    }
    median_mad(&response, samples).map_or(f32::INFINITY, |s| s.sigma as f32 / 6.0)
}

/// The std of the normalised LoG response at `scale` to unit white noise, measured on a
/// seeded noise image (the discrete filter, not a continuous approximation).
fn white_noise_gain(scale: f64) -> Result<f32> {
    const SIDE: usize = 128;
    let mut noise = uniform_noise(SIDE, SIDE, 0x9e37_79b9_7f4a_7c15);
    // Uniform in [-√3, √3): unit variance.
    noise
        .as_mut_slice()
        .iter_mut()
        .for_each(|v| *v = (*v - 0.5) * 2.0 * 3f32.sqrt());
    let mut response = GrayImage::default();
    LogFilter::new(scale)?.apply(&noise, Polarity::Bright, &mut response);
    let n = response.as_slice().len() as f64;
    let variance = response
        .as_slice()
        .iter()
        .map(|&v| f64::from(v).powi(2))
        .sum::<f64>()
        / n;
    Ok((variance.sqrt() * scale * scale) as f32)
}

/// A `width × height` image of uniform values in `[0, 1)` from a fixed linear congruential
/// sequence started at `seed` (deterministic, no dependency).
fn uniform_noise(width: usize, height: usize, seed: u64) -> GrayImage {
    let mut state = seed;
    let mut image = GrayImage::new(width, height);
    for v in image.as_mut_slice() {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        *v = (state >> 40) as f32 / (1u64 << 24) as f32;
    }
    image
}

/// How clearly blobs of one polarity stand out: the significance of their 90th percentile
/// (0 without blobs). A percentile, not a sum, so that many weak blobs of the other sign
/// (the dark gaps between bright particles, the ghosts a moving particle leaves in a
/// background estimate) do not outvote the particles themselves. Sorts `blobs` by
/// decreasing significance.
fn contrast(blobs: &mut [Blob]) -> f64 {
    blobs.sort_by(|a, b| b.significance.total_cmp(&a.significance));
    blobs.get(blobs.len() / 10).map_or(0.0, |b| b.significance)
}

/// The error of a frame without measurable particles.
fn no_particles(why: String) -> Error {
    Error::input(format!(
        "no particles found to measure their size and polarity: {why}; check the frame, or \
         set detector.scale_px and detector.polarity by hand"
    ))
}

/// Scale number `k` (fractional between scales) in px.
fn scale_of(k: f64) -> f64 {
    MIN_SCALE_PX * 2f64.powf(k / SCALES_PER_OCTAVE as f64)
}

/// The central `MAX_SIDE_PX` × `MAX_SIDE_PX` of `image`, when it is larger.
fn central_crop(image: &GrayImage) -> Option<GrayImage> {
    let (width, height) = image.dimensions();
    if width <= MAX_SIDE_PX && height <= MAX_SIDE_PX {
        return None;
    }
    let (w, h) = (width.min(MAX_SIDE_PX), height.min(MAX_SIDE_PX));
    let (x0, y0) = ((width - w) / 2, (height - h) / 2);
    let mut data = Vec::with_capacity(w * h);
    for y in y0..y0 + h {
        data.extend_from_slice(&image.row(y)[x0..x0 + w]);
    }
    GrayImage::from_vec(w, h, data).ok()
}

/// Adds the maxima of scale `k` (layer `ids[1]`, its neighbours `ids[0]` below and `ids[2]`
/// above) to `bright` (positive response) and `dark` (negative): extrema of their 3×3×3
/// neighbourhood beyond the scale's noise threshold.
fn collect_maxima(
    layers: &[GrayImage; 3],
    ids: [usize; 3],
    (median, sigma): (f32, f32),
    k: usize,
    bright: &mut Vec<Blob>,
    dark: &mut Vec<Blob>,
) {
    if sigma <= 0.0 {
        return;
    }
    let centre = &layers[ids[1]];
    let height = centre.height();
    let threshold = SIGNIFICANCE as f32 * sigma;
    // Rows in parallel, their blobs gathered in row order: the same lists as one pass.
    let rows: Vec<(Vec<Blob>, Vec<Blob>)> = (1..height - 1)
        .into_par_iter()
        .with_min_len(ROWS_PER_TASK)
        .map(|y| row_extrema(layers, ids, (median, threshold, sigma), k, y))
        .collect();
    for (row_bright, row_dark) in rows {
        bright.extend(row_bright);
        dark.extend(row_dark);
    }
}

/// [`collect_maxima`]'s extrema in row `y` of the centre layer (1 ≤ y < height − 1) whose
/// distance from the median exceeds `threshold`: (bright, dark).
fn row_extrema(
    layers: &[GrayImage; 3],
    ids: [usize; 3],
    (median, threshold, sigma): (f32, f32, f32),
    k: usize,
    y: usize,
) -> (Vec<Blob>, Vec<Blob>) {
    let (mut bright, mut dark) = (Vec::new(), Vec::new());
    let width = layers[ids[1]].width();
    let row = layers[ids[1]].row(y);
    for (x, &here) in row.iter().enumerate().take(width - 1).skip(1) {
        let v = here - median;
        if v.abs() <= threshold {
            continue;
        }
        let sign = v.signum();
        let value = sign * here;
        let is_extremum = ids.iter().all(|&id| {
            let layer = &layers[id];
            (y - 1..=y + 1).all(|yy| {
                let r = layer.row(yy);
                (x - 1..=x + 1).all(|xx| {
                    let other = sign * r[xx];
                    other < value || (other == value && (id, yy, xx) == (ids[1], y, x))
                })
            })
        });
        if !is_extremum {
            continue;
        }
        let at = |id: usize| f64::from(sign * layers[id].get(x, y));
        let offset = sillage_image::parabola_offset(at(ids[0]), at(ids[1]), at(ids[2]));
        let blob = Blob {
            sigma_px: scale_of(k as f64 + offset),
            significance: f64::from(v.abs() / sigma),
        };
        if sign > 0.0 {
            bright.push(blob);
        } else {
            dark.push(blob);
        }
    }
    (bright, dark)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spots(sigma: f64, amplitude: f32) -> GrayImage {
        let (w, h) = (160, 160);
        let mut image = GrayImage::new(w, h);
        for gy in 1..8 {
            for gx in 1..8 {
                let (cx, cy) = (gx as f64 * 20.0 + 0.3, gy as f64 * 20.0 - 0.2);
                for y in 0..h {
                    for x in 0..w {
                        let r2 = (x as f64 - cx).powi(2) + (y as f64 - cy).powi(2);
                        let v = image.get(x, y)
                            + amplitude * (-r2 / (2.0 * sigma * sigma)).exp() as f32;
                        image.set(x, y, v);
                    }
                }
            }
        }
        image
    }

    #[test]
    fn measures_sigma_and_polarity_of_clean_spots() {
        for sigma in [0.8, 1.5, 3.0] {
            for (amplitude, polarity) in [(0.5, Polarity::Bright), (-0.5, Polarity::Dark)] {
                let m = measure_particle_images(&spots(sigma, amplitude)).unwrap();
                assert_eq!(m.polarity, polarity, "σ {sigma}");
                assert!((m.sigma_px / sigma - 1.0).abs() < 0.15, "σ {sigma}: {m:?}");
            }
        }
    }

    /// `count` spots of std `sigma` at positions from a fixed sequence on a `side`² frame,
    /// with a little noise.
    fn random_spots(count: usize, sigma: f64, side: usize) -> GrayImage {
        let mut image = uniform_noise(side, side, 11);
        image.as_mut_slice().iter_mut().for_each(|v| *v *= 0.02);
        add_random_spots(&mut image, count, sigma, 0.5, 5);
        image
    }

    /// Adds `count` spots of std `sigma` and peak `amplitude` to `image` (square), at
    /// positions from the fixed sequence `seed`.
    fn add_random_spots(
        image: &mut GrayImage,
        count: usize,
        sigma: f64,
        amplitude: f64,
        seed: u64,
    ) {
        let side = image.width();
        let positions = uniform_noise(2 * count, 1, seed);
        let reach = (4.0 * sigma).ceil() as isize;
        for k in 0..count {
            let cx = f64::from(positions.get(2 * k, 0)) * side as f64;
            let cy = f64::from(positions.get(2 * k + 1, 0)) * side as f64;
            for dy in -reach..=reach {
                for dx in -reach..=reach {
                    let (x, y) = (cx as isize + dx, cy as isize + dy);
                    if x < 0 || y < 0 || x >= side as isize || y >= side as isize {
                        continue;
                    }
                    let (x, y) = (x as usize, y as usize);
                    let r2 = (x as f64 - cx).powi(2) + (y as f64 - cy).powi(2);
                    let v =
                        image.get(x, y) + (amplitude * (-r2 / (2.0 * sigma * sigma)).exp()) as f32;
                    image.set(x, y, v);
                }
            }
        }
    }

    #[test]
    fn faint_texture_does_not_count_as_particle_images() {
        // 60 particles of σ 2 px (N_s = 60 · π(2σ)² / 160² ≈ 0.118) on a background of 300
        // bright and 300 dark specks of σ 1 px, a tenth of their contrast: blobs, but not
        // particle images.
        let mut image = random_spots(60, 2.0, 160);
        add_random_spots(&mut image, 300, 1.0, 0.05, 9);
        add_random_spots(&mut image, 300, 1.0, -0.05, 13);
        let m = measure_particle_images(&image).unwrap();
        let true_density = 60.0 * std::f64::consts::PI * 16.0 / (160.0 * 160.0);
        assert!((m.source_density / true_density - 1.0).abs() < 0.2, "{m:?}");
        assert!((55..=60).contains(&m.particle_blobs), "{m:?}");
        assert!((m.particle_sigma_px / 2.0 - 1.0).abs() < 0.15, "{m:?}");
        // Every blob, at the σ̂ they give, would read the density nearly twice as high.
        let every_blob =
            m.blobs as f64 * std::f64::consts::PI * (2.0 * m.sigma_px).powi(2) / (160.0 * 160.0);
        assert!(every_blob > 1.5 * m.source_density, "{every_blob}: {m:?}");
    }

    #[test]
    fn the_source_density_separates_sparse_particles_from_a_saturated_frame() {
        // 0.002 particles per pixel of σ 1.5 px: N_s = 0.002 · 4π · 1.5² ≈ 0.057.
        let sparse = measure_particle_images(&random_spots(51, 1.5, 160)).unwrap();
        assert!(
            (0.03..0.09).contains(&sparse.source_density),
            "sparse: {sparse:?}"
        );
        assert_eq!(sparse.density_warning(), None);
        // 0.05 particles per pixel of σ 2.5 px: N_s ≈ 3.9, images everywhere.
        let saturated = measure_particle_images(&random_spots(1280, 2.5, 160)).unwrap();
        assert!(
            saturated.source_density >= DENSE_SOURCE_DENSITY,
            "saturated: {saturated:?}"
        );
        let warning = saturated.density_warning().unwrap();
        assert!(warning.contains("source density"), "{warning}");
    }

    #[test]
    fn the_measurement_does_not_depend_on_the_number_of_threads() {
        let mut image = spots(1.5, 0.5);
        let noise = uniform_noise(160, 160, 7);
        for (v, n) in image.as_mut_slice().iter_mut().zip(noise.as_slice()) {
            *v += 0.05 * n;
        }
        let measure_with = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| measure_particle_images(&image).unwrap())
        };
        assert_eq!(measure_with(1), measure_with(3));
    }

    #[test]
    fn frames_without_particles_say_so() {
        let mut huge = GrayImage::new(256, 256);
        for y in 0..256 {
            for x in 0..256 {
                let r2 = (x as f64 - 128.0).powi(2) + (y as f64 - 128.0).powi(2);
                huge.set(x, y, (-r2 / (2.0 * 40.0 * 40.0)).exp() as f32);
            }
        }
        let mut flat = GrayImage::new(64, 64);
        flat.as_mut_slice().fill(0.7);
        for (what, image) in [
            ("empty", GrayImage::new(0, 0)),
            ("flat", flat),
            ("pure noise", uniform_noise(512, 512, 12345)),
            ("one huge blob", huge),
        ] {
            let err = measure_particle_images(&image).unwrap_err().to_string();
            assert!(err.contains("no particles found"), "{what}: {err}");
        }
    }
}

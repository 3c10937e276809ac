//! Pixels of a walkers frame: a seeded, smoothly textured static background; walkers painted
//! far to near with area-sampled edges (so sub-pixel motion is smooth); the visible share of
//! each walker from the same samples; sensor noise; 8-bit colour and its Rec. 601 grey.

use rand::RngExt;
use rayon::prelude::*;
use sillage_core::{GrayImage, Point2, RgbImage, luma_601, rng_stream};

use super::appearance::{Appearance, Stride, inside_silhouette};
use crate::noise::Noise;
use crate::render::{BAND_ROWS, fill_noise};

/// Samples per pixel side: a pixel takes the mean colour of 4 × 4 points of the scene.
const SUBSAMPLES: usize = 4;

/// Smooth colour blobs of the background.
const BACKGROUND_BLOBS: usize = 12;
/// Faint rectangles of the background (walls, windows, benches): some structure.
const BACKGROUND_RECTANGLES: usize = 5;
/// Largest change a background blob makes to a channel.
const BLOB_AMPLITUDE: f64 = 0.05;
/// Largest change a background rectangle makes to a channel.
const RECTANGLE_AMPLITUDE: f64 = 0.04;
/// Background grey levels stay in this range: well apart from the walkers' dark clothes and
/// light stripes.
const BACKGROUND_RANGE: (f32, f32) = (0.38, 0.66);

/// A walker as drawn in one frame: its look, its box and its stride pose.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Placed<'a> {
    /// Clothes and face.
    pub look: &'a Appearance,
    /// Top-left corner of the box, px.
    pub top_left: Point2,
    /// Box width, px.
    pub width_px: f64,
    /// Box height, px.
    pub height_px: f64,
    /// Leg pose.
    pub stride: Stride,
}

impl Placed<'_> {
    /// Body coordinates of image point `(x, y)`.
    fn body(&self, x: f64, y: f64) -> (f64, f64) {
        (
            (x - self.top_left.x) / self.width_px,
            (y - self.top_left.y) / self.height_px,
        )
    }

    /// Whether image point `(x, y)` is on the walker.
    fn covers(&self, x: f64, y: f64) -> bool {
        let (u, v) = self.body(x, y);
        inside_silhouette(u, v, self.stride)
    }
}

/// The static background of a sequence, as linear colour in `[0, 1]`.
#[derive(Debug, Clone)]
pub(crate) struct Background {
    pixels: Vec<[f32; 3]>,
}

impl Background {
    /// A `width × height` background from `seed`: a tinted mid grey, a ground darker or
    /// lighter than the upper part below a seeded horizon, soft Gaussian colour blobs and
    /// faint rectangles, within [`BACKGROUND_RANGE`].
    pub fn new(width: usize, height: usize, seed: u64) -> Self {
        let mut rng = rng_stream(seed, BACKGROUND_STREAM);
        let base: [f64; 3] = std::array::from_fn(|_| 0.52 + rng.random_range(-0.04..0.04));
        let horizon = height as f64 * rng.random_range(0.3..0.45);
        let ground: [f64; 3] = std::array::from_fn(|_| rng.random_range(-0.05..0.05));
        let side = width.min(height) as f64;
        let blobs: Vec<(Point2, f64, [f64; 3])> = (0..BACKGROUND_BLOBS)
            .map(|_| {
                let centre = Point2::new(
                    rng.random_range(0.0..width as f64),
                    rng.random_range(0.0..height as f64),
                );
                let radius = side * rng.random_range(0.08..0.25);
                let amplitude =
                    std::array::from_fn(|_| rng.random_range(-BLOB_AMPLITUDE..BLOB_AMPLITUDE));
                (centre, radius, amplitude)
            })
            .collect();
        let rectangles: Vec<([f64; 4], [f64; 3])> = (0..BACKGROUND_RECTANGLES)
            .map(|_| {
                let (w, h) = (
                    rng.random_range(0.05..0.3) * width as f64,
                    rng.random_range(0.05..0.2) * height as f64,
                );
                let x0 = rng.random_range(0.0..width as f64 - w);
                let y0 = rng.random_range(0.0..horizon.max(h + 1.0) - h);
                let amplitude = std::array::from_fn(|_| {
                    rng.random_range(-RECTANGLE_AMPLITUDE..RECTANGLE_AMPLITUDE)
                });
                ([x0, y0, x0 + w, y0 + h], amplitude)
            })
            .collect();
        let mut pixels = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                let (xf, yf) = (x as f64, y as f64);
                let mut colour = base;
                // A soft horizon, 3 px wide.
                let below = ((yf - horizon) / 3.0).clamp(-0.5, 0.5) + 0.5;
                for (c, g) in colour.iter_mut().zip(ground) {
                    *c += below * g;
                }
                for (centre, radius, amplitude) in &blobs {
                    let d2 = (xf - centre.x).powi(2) + (yf - centre.y).powi(2);
                    let weight = (-0.5 * d2 / (radius * radius)).exp();
                    for (c, a) in colour.iter_mut().zip(amplitude) {
                        *c += weight * a;
                    }
                }
                for (rect, amplitude) in &rectangles {
                    if (rect[0]..rect[2]).contains(&xf) && (rect[1]..rect[3]).contains(&yf) {
                        for (c, a) in colour.iter_mut().zip(amplitude) {
                            *c += a;
                        }
                    }
                }
                pixels
                    .push(colour.map(|c| (c as f32).clamp(BACKGROUND_RANGE.0, BACKGROUND_RANGE.1)));
            }
        }
        Self { pixels }
    }

    /// The background's pixels, row-major.
    pub fn pixels(&self) -> &[[f32; 3]] {
        &self.pixels
    }
}

/// Stream of the background's random draws.
const BACKGROUND_STREAM: u64 = 1 << 60;

/// Paints `walker` over `canvas` (`width` px wide, row-major): each pixel under its box takes
/// the mean colour of its [`SUBSAMPLES`]² scene points, the walker's where it covers them and
/// the canvas's elsewhere (painter's algorithm: paint far to near).
pub(crate) fn paint_walker(canvas: &mut [[f32; 3]], width: usize, walker: &Placed) {
    let height = canvas.len() / width;
    let step = 1.0 / SUBSAMPLES as f64;
    let pixel_range = |start: f64, extent: f64, limit: usize| {
        let first = (start + 0.5).floor().max(0.0) as usize;
        let end = ((start + extent + 0.5).ceil().max(0.0) as usize).min(limit);
        first..end
    };
    let rows = pixel_range(walker.top_left.y, walker.height_px, height);
    let cols = pixel_range(walker.top_left.x, walker.width_px, width);
    let full = (SUBSAMPLES * SUBSAMPLES) as f32;
    for py in rows {
        for px in cols.clone() {
            let (mut sum, mut hits) = ([0.0f32; 3], 0usize);
            for b in 0..SUBSAMPLES {
                let y = py as f64 - 0.5 + (b as f64 + 0.5) * step;
                for a in 0..SUBSAMPLES {
                    let x = px as f64 - 0.5 + (a as f64 + 0.5) * step;
                    let (u, v) = walker.body(x, y);
                    if let Some(colour) = walker.look.colour_at(u, v, walker.stride) {
                        sum.iter_mut().zip(colour).for_each(|(s, c)| *s += c);
                        hits += 1;
                    }
                }
            }
            if hits > 0 {
                let pixel = &mut canvas[py * width + px];
                let cover = hits as f32 / full;
                for (p, s) in pixel.iter_mut().zip(sum) {
                    *p = *p * (1.0 - cover) + s / full;
                }
            }
        }
    }
}

/// Share of what is `in the frame` and `visible` among `walker`'s silhouette points, sampled
/// [`SUBSAMPLES`] per px over its box: `(points in the frame, points visible)` over the
/// total, a point being visible when it is in the `width × height` frame and no walker of
/// `nearer` covers it.
pub(crate) fn visible_shares(
    walker: &Placed,
    nearer: &[Placed],
    width: usize,
    height: usize,
) -> (f64, f64) {
    let n_u = (walker.width_px * SUBSAMPLES as f64).ceil().max(1.0) as usize;
    let n_v = (walker.height_px * SUBSAMPLES as f64).ceil().max(1.0) as usize;
    let (x_end, y_end) = (width as f64 - 0.5, height as f64 - 0.5);
    let (mut total, mut in_frame, mut visible) = (0usize, 0usize, 0usize);
    for j in 0..n_v {
        let v = (j as f64 + 0.5) / n_v as f64;
        let y = walker.top_left.y + v * walker.height_px;
        for i in 0..n_u {
            let u = (i as f64 + 0.5) / n_u as f64;
            if !inside_silhouette(u, v, walker.stride) {
                continue;
            }
            total += 1;
            let x = walker.top_left.x + u * walker.width_px;
            if !((-0.5..x_end).contains(&x) && (-0.5..y_end).contains(&y)) {
                continue;
            }
            in_frame += 1;
            if !nearer.iter().any(|other| other.covers(x, y)) {
                visible += 1;
            }
        }
    }
    let share = |count: usize| count as f64 / total.max(1) as f64;
    (share(in_frame), share(visible))
}

/// Adds noise drawn from `seed` (one stream per band of [`BAND_ROWS`] rows, so the frame does
/// not depend on the number of threads) to `canvas` and quantises it into `colour` (8 bits,
/// rounded, clamped) and `grey` (the Rec. 601 luma of the 8-bit colour, as a decoder reading
/// the colour PNG computes it). `noise_buffer` is scratch space, reused across frames.
pub(crate) fn finish_frame(
    canvas: &[[f32; 3]],
    noise: Noise,
    seed: u64,
    noise_buffer: &mut Vec<f32>,
    colour: &mut RgbImage,
    grey: &mut GrayImage,
) {
    let width = colour.width();
    noise_buffer.resize(3 * canvas.len(), 0.0);
    noise_buffer
        .par_chunks_mut(3 * BAND_ROWS * width.max(1))
        .enumerate()
        .for_each(|(band, values)| fill_noise(values, noise, seed, band as u64));
    let to_byte = |v: f32| (v * 255.0).round().clamp(0.0, 255.0) as u8;
    for (((out, g), pixel), n) in colour
        .as_mut_slice()
        .iter_mut()
        .zip(grey.as_mut_slice())
        .zip(canvas)
        .zip(noise_buffer.chunks_exact(3))
    {
        *out = [
            to_byte(pixel[0] + n[0]),
            to_byte(pixel[1] + n[1]),
            to_byte(pixel[2] + n[2]),
        ];
        *g = luma_601(*out);
    }
}

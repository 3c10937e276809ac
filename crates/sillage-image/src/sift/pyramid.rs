//! The SIFT scale space of one frame (Lowe 2004 §3, OpenCV's `buildGaussianPyramid` and
//! `buildDoGPyramid`): per octave, `s + 3` Gaussian levels blurred incrementally, the `s + 2`
//! differences of adjacent levels, and the gradient magnitude and orientation of the `s` levels
//! that keypoints use (levels `1..=s`), computed once per frame so that orientation histograms
//! and descriptors at any position only read them.
//!
//! Geometry: octave `o` (0-based) samples the input every `2^(o + first)` px, `first = −1` when
//! the input is doubled and 0 otherwise, and octave px `(u, v)` is input px
//! `(u, v) · 2^(o + first)` (origin at the centre of the top-left pixel in both). Level `i` of an
//! octave has blur `σ₀ · 2^(i/s)` octave px. The doubling interpolates pixel-aligned (even
//! pixels copy the input, odd ones average their two or four neighbours) so that this relation
//! is exact; OpenCV's `INTER_LINEAR` doubling is shifted by a quarter input pixel instead, which
//! its keypoint coordinates ignore.

use std::f32::consts::{FRAC_PI_2, PI, TAU};

use rayon::prelude::*;
use sillage_core::{Error, GrayImage, Result};

use super::params::SiftParams;
use crate::gaussian::GaussianFilter;
use sillage_core::multiversion;

/// Pixels left out at each side of an octave when searching extrema (OpenCV's `SIFT_IMG_BORDER`).
pub(crate) const BORDER: usize = 5;

/// Smallest side of an input frame: one extremum must fit inside the border.
pub const MIN_SIFT_SIDE: usize = 2 * BORDER + 1;

/// Blur assumed in the input frame, px (Lowe 2004 §3.3; OpenCV's `SIFT_INIT_SIGMA`).
const INPUT_BLUR: f64 = 0.5;

/// Rows per parallel job of the per-pixel passes (DoG, gradients): fixed, so nothing depends on
/// the thread count (no pass reduces across pixels anyway).
const ROWS_PER_JOB: usize = 16;

/// The images of one octave.
#[derive(Debug, Clone, Default)]
pub(crate) struct Octave {
    /// Gaussian levels `0..s+3`.
    pub gauss: Vec<GrayImage>,
    /// `dog[i] = gauss[i + 1] − gauss[i]`, `i` in `0..s+2`.
    pub dog: Vec<GrayImage>,
    /// Gradient magnitude of Gaussian levels `1..=s` (`magnitude[i - 1]` for level `i`), 0 on
    /// the one-pixel frame where central differences are undefined.
    pub magnitude: Vec<GrayImage>,
    /// Gradient direction of the same levels, radians in `[0, 2π)`, measured from +x towards
    /// +y (y down, so clockwise on screen).
    pub orientation: Vec<GrayImage>,
}

impl Octave {
    /// Width and height of the octave's images.
    pub fn dimensions(&self) -> (usize, usize) {
        self.gauss[0].dimensions()
    }
}

/// Gaussian, DoG and gradient pyramids of one frame, with the blurs that build them; the
/// images are reused from frame to frame (no allocation once a frame size has been seen).
#[derive(Debug, Clone)]
pub(crate) struct ScaleSpace {
    params: SiftParams,
    /// Blur from the (doubled) input to level 0 of the first octave.
    base_blur: GaussianFilter,
    /// `level_blurs[i - 1]` takes level `i − 1` to level `i` of any octave.
    level_blurs: Vec<GaussianFilter>,
    doubled: GrayImage,
    octaves: Vec<Octave>,
    octave_count: usize,
}

impl ScaleSpace {
    /// The blurs of a valid parameter set: level `i` has blur `σ₀·k^i` with `k = 2^(1/s)`, so
    /// going from level `i − 1` takes `sqrt((σ₀k^i)² − (σ₀k^(i−1))²)` (OpenCV's `sig[i]`).
    pub fn new(params: &SiftParams) -> Result<Self> {
        params.validate()?;
        let s = params.octave_layers;
        let input_blur = if params.upsample {
            2.0 * INPUT_BLUR
        } else {
            INPUT_BLUR
        };
        let base_sigma = (params.sigma * params.sigma - input_blur * input_blur)
            .max(0.01)
            .sqrt();
        let k = 2f64.powf(1.0 / s as f64);
        let level_blurs = (1..s + 3)
            .map(|i| {
                let previous = params.sigma * k.powi(i as i32 - 1);
                GaussianFilter::new(previous * (k * k - 1.0).sqrt())
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            params: *params,
            base_blur: GaussianFilter::new(base_sigma)?,
            level_blurs,
            doubled: GrayImage::default(),
            octaves: Vec::new(),
            octave_count: 0,
        })
    }

    /// Layers per octave `s`.
    pub fn layers(&self) -> usize {
        self.params.octave_layers
    }

    /// σ₀, octave px.
    pub fn sigma(&self) -> f64 {
        self.params.sigma
    }

    /// The octaves built by the last [`build`](Self::build).
    pub fn octaves(&self) -> &[Octave] {
        &self.octaves[..self.octave_count]
    }

    /// Index of the first octave: −1 when the input is doubled, 0 otherwise (OpenCV's
    /// `firstOctave`).
    pub fn first_octave(&self) -> i32 {
        -i32::from(self.params.upsample)
    }

    /// Input px per px of octave `octave` (0-based), `2^(octave + first)`.
    pub fn octave_step(&self, octave: usize) -> f32 {
        2f32.powi(octave as i32 + self.first_octave())
    }

    /// Builds every image of `frame` (grey in `[0, 1]`, both sides ≥ [`MIN_SIFT_SIDE`]).
    pub fn build(&mut self, frame: &GrayImage) -> Result<()> {
        self.octave_count = 0;
        let (width, height) = frame.dimensions();
        if width < MIN_SIFT_SIDE || height < MIN_SIFT_SIDE {
            return Err(Error::input(format!(
                "a {width}×{height} frame is too small for SIFT: both sides must be at least \
                 {MIN_SIFT_SIDE} px"
            )));
        }
        self.octave_count = self.octave_count_for(width.min(height));
        if self.octaves.len() < self.octave_count {
            self.octaves.resize_with(self.octave_count, Octave::default);
        }
        let s = self.layers();
        for octave in &mut self.octaves[..self.octave_count] {
            octave.gauss.resize_with(s + 3, GrayImage::default);
            octave.dog.resize_with(s + 2, GrayImage::default);
            octave.magnitude.resize_with(s, GrayImage::default);
            octave.orientation.resize_with(s, GrayImage::default);
        }

        if self.params.upsample {
            double_size(frame, &mut self.doubled);
            self.base_blur
                .apply(&self.doubled, &mut self.octaves[0].gauss[0]);
        } else {
            self.base_blur.apply(frame, &mut self.octaves[0].gauss[0]);
        }
        for o in 0..self.octave_count {
            let (done, rest) = self.octaves.split_at_mut(o);
            let octave = &mut rest[0];
            if let Some(previous) = done.last() {
                halve_size(&previous.gauss[s], &mut octave.gauss[0]);
            }
            for (i, blur) in self.level_blurs.iter_mut().enumerate() {
                let (lower, upper) = octave.gauss.split_at_mut(i + 1);
                blur.apply(&lower[i], &mut upper[0]);
            }
            for (i, dog) in octave.dog.iter_mut().enumerate() {
                difference(&octave.gauss[i + 1], &octave.gauss[i], dog);
            }
            for i in 0..s {
                gradients(
                    &octave.gauss[i + 1],
                    &mut octave.magnitude[i],
                    &mut octave.orientation[i],
                );
            }
        }
        Ok(())
    }

    /// OpenCV's octave count, `round(log2(min side)) − 2 − first`, at least 1, capped by
    /// `max_octaves` and by the halvings the frame allows.
    fn octave_count_for(&self, min_side: usize) -> usize {
        let opencv = ((min_side as f64).log2().round() as i64 - 2 - i64::from(self.first_octave()))
            .max(1) as usize;
        let mut count = opencv.min(self.params.max_octaves.unwrap_or(usize::MAX));
        let first_side = min_side << usize::from(self.params.upsample);
        while count > 1 && first_side >> (count - 1) == 0 {
            count -= 1;
        }
        count
    }
}

/// Doubles `src` into `dst`, pixel-aligned: `dst(2u, 2v) = src(u, v)`, odd pixels the mean of
/// their neighbours along each odd axis (the last ones replicate the border).
fn double_size(src: &GrayImage, dst: &mut GrayImage) {
    let (width, height) = src.dimensions();
    dst.reshape(2 * width, 2 * height);
    let row_pair = |y: usize| {
        let top = src.row(y / 2);
        let bottom = src.row((y / 2 + y % 2).min(height - 1));
        (top, bottom)
    };
    dst.as_mut_slice()
        .par_chunks_mut(2 * width)
        .enumerate()
        .for_each(|(y, out)| {
            let (top, bottom) = row_pair(y);
            for (u, pair) in out.chunks_exact_mut(2).enumerate() {
                let next = (u + 1).min(width - 1);
                let left = 0.5 * (top[u] + bottom[u]);
                let right = 0.5 * (top[next] + bottom[next]);
                pair[0] = left;
                pair[1] = 0.5 * (left + right);
            }
        });
}

/// Every second pixel of `src` (`dst(u, v) = src(2u, 2v)`), the first level of the next octave.
fn halve_size(src: &GrayImage, dst: &mut GrayImage) {
    let (width, height) = (src.width() / 2, src.height() / 2);
    dst.reshape(width, height);
    for (v, out) in dst
        .as_mut_slice()
        .chunks_exact_mut(width.max(1))
        .enumerate()
    {
        let row = src.row(2 * v);
        for (u, value) in out.iter_mut().enumerate() {
            *value = row[2 * u];
        }
    }
}

/// `dst = a − b`, pixel by pixel.
fn difference(a: &GrayImage, b: &GrayImage, dst: &mut GrayImage) {
    let (width, height) = a.dimensions();
    dst.reshape(width, height);
    dst.as_mut_slice()
        .par_chunks_mut(ROWS_PER_JOB * width)
        .zip(a.as_slice().par_chunks(ROWS_PER_JOB * width))
        .zip(b.as_slice().par_chunks(ROWS_PER_JOB * width))
        .for_each(|((out, a), b)| {
            for ((d, &a), &b) in out.iter_mut().zip(a).zip(b) {
                *d = a - b;
            }
        });
}

/// Central-difference gradient of `level` (OpenCV's `dx = I(x+1) − I(x−1)`, no ½), as magnitude
/// and direction images; the outer one-pixel frame gets magnitude 0.
fn gradients(level: &GrayImage, magnitude: &mut GrayImage, orientation: &mut GrayImage) {
    let (width, height) = level.dimensions();
    magnitude.reshape(width, height);
    orientation.reshape(width, height);
    magnitude
        .as_mut_slice()
        .par_chunks_mut(width)
        .zip(orientation.as_mut_slice().par_chunks_mut(width))
        .enumerate()
        .with_min_len(ROWS_PER_JOB)
        .for_each(|(y, (mag, ori))| {
            if y == 0 || y + 1 >= height || width < 3 {
                mag.fill(0.0);
                ori.fill(0.0);
                return;
            }
            let rows = (level.row(y - 1), level.row(y), level.row(y + 1));
            gradient_row_widest(rows, mag, ori);
        });
}

multiversion! {
    /// [`gradient_row`] on the widest SIMD the CPU offers (same bits on every path).
    fn gradient_row_widest(rows: (&[f32], &[f32], &[f32]), mag: &mut [f32], ori: &mut [f32]) => gradient_row
}

/// One row of [`gradients`]: `rows` are the level's rows above, at and below it.
#[inline(always)]
fn gradient_row(rows: (&[f32], &[f32], &[f32]), mag: &mut [f32], ori: &mut [f32]) {
    let (up, row, down) = rows;
    let width = row.len();
    for edge in [0, width - 1] {
        mag[edge] = 0.0;
        ori[edge] = 0.0;
    }
    let inner = 1..width - 1;
    for (((m, o), (&left, &right)), (&above, &below)) in mag[inner.clone()]
        .iter_mut()
        .zip(&mut ori[inner.clone()])
        .zip(row.iter().zip(&row[2..]))
        .zip(up[inner.clone()].iter().zip(&down[inner]))
    {
        let (dx, dy) = (right - left, below - above);
        *m = (dx * dx + dy * dy).sqrt();
        *o = direction(dx, dy);
    }
}

/// `atan2(dy, dx)` in `[0, 2π)` by an odd degree-9 polynomial of `min/max` on `[0, 1]`
/// (least-squares fit, largest error 1.2·10⁻⁵ rad, 0.0007°; OpenCV's `fastAtan2` errs by up to
/// ~0.01°); branch-free, so the gradient loop vectorises. `(0, 0)` gives 0.
#[inline(always)]
pub(crate) fn direction(dx: f32, dy: f32) -> f32 {
    const C: [f32; 5] = [
        0.999_866_37,
        -0.330_305_46,
        0.180_162_19,
        -0.085_160_81,
        0.020_847_35,
    ];
    let (ax, ay) = (dx.abs(), dy.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    let z = lo / (hi + f32::MIN_POSITIVE);
    let t = z * z;
    let mut angle = z * (C[0] + t * (C[1] + t * (C[2] + t * (C[3] + t * C[4]))));
    if ay > ax {
        angle = FRAC_PI_2 - angle;
    }
    if dx < 0.0 {
        angle = PI - angle;
    }
    if dy < 0.0 {
        angle = TAU - angle;
    }
    if angle >= TAU { 0.0 } else { angle }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_direction_matches_atan2() {
        let mut worst = 0f32;
        for i in 0..3600 {
            let a = i as f32 * TAU / 3600.0 + 0.0003;
            for r in [1e-3f32, 0.5, 2.0] {
                let (dx, dy) = (r * a.cos(), r * a.sin());
                let exact = dy.atan2(dx).rem_euclid(TAU);
                let mut error = (direction(dx, dy) - exact).abs();
                error = error.min(TAU - error);
                worst = worst.max(error);
            }
        }
        assert!(worst < 2e-5, "{worst}");
        assert_eq!(direction(0.0, 0.0), 0.0);
        assert!((direction(0.0, 1.0) - FRAC_PI_2).abs() < 1e-6);
        assert!((direction(-1.0, 0.0) - PI).abs() < 1e-6);
    }

    #[test]
    fn doubling_is_pixel_aligned_and_halving_inverts_it() {
        let src = GrayImage::from_vec(3, 2, vec![0.0, 1.0, 2.0, 4.0, 5.0, 6.0]).unwrap();
        let mut big = GrayImage::default();
        double_size(&src, &mut big);
        assert_eq!(big.dimensions(), (6, 4));
        assert_eq!(big.row(0), &[0.0, 0.5, 1.0, 1.5, 2.0, 2.0]);
        assert_eq!(big.row(1), &[2.0, 2.5, 3.0, 3.5, 4.0, 4.0]);
        assert_eq!(big.row(3), big.row(2));
        let mut small = GrayImage::default();
        halve_size(&big, &mut small);
        assert_eq!(small, src);
    }
}

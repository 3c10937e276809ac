//! SIFT keypoints and descriptors (Lowe 2004, "Distinctive image features from scale-invariant
//! keypoints", IJCV 60(2)), following OpenCV's `SIFT` step by step, for the SIFT-PF tracker
//! (Souded et al. 2011), whose particles each need a descriptor at an arbitrary position.
//!
//! [`SiftDetector::analyse`] builds the scale space of a frame once (`pyramid`: Gaussian
//! octaves, DoG, gradient magnitude and direction of the levels keypoints use); then
//! [`keypoints`](SiftDetector::keypoints) finds and refines DoG extrema (`extrema`) and
//! gives each orientation peak a keypoint (`orientation`), and
//! [`describe_at`](SiftDetector::describe_at) computes a descriptor ([`descriptor`]) at any
//! position, scale and orientation from the stored gradients, cheaply enough for thousands of
//! particles per frame.
//!
//! Differences from OpenCV (measured in `docs/siftpf.md`): Gaussian kernels are cut at 3σ
//! rather than 4σ; the doubled input is pixel-aligned (OpenCV's is shifted by ¼ input px);
//! the descriptor window sits at the exact position rather than the rounded one; descriptors
//! stay `f32` (unit length) rather than bytes; direction is a polynomial `atan2` within
//! 1.2·10⁻⁵ rad.
//!
//! ```
//! use sillage_core::GrayImage;
//! use sillage_image::sift::{SiftDetector, SiftParams};
//!
//! // A dark disc of radius 6 px on a bright background, centred at (31.5, 28.0).
//! let (w, h) = (64, 56);
//! let data = (0..w * h)
//!     .map(|i| {
//!         let (x, y) = ((i % w) as f32 - 31.5, (i / w) as f32 - 28.0);
//!         if x * x + y * y < 36.0 { 0.2 } else { 0.8 }
//!     })
//!     .collect();
//! let frame = GrayImage::from_vec(w, h, data)?;
//! let mut sift = SiftDetector::new(&SiftParams::default())?;
//! let features = sift.detect_and_describe(&frame)?;
//! let (disc, _) = features
//!     .iter()
//!     .min_by(|a, b| {
//!         let d = |k: &sillage_image::sift::SiftKeypoint| (k.x - 31.5).hypot(k.y - 28.0);
//!         d(&a.0).total_cmp(&d(&b.0))
//!     })
//!     .unwrap();
//! assert!((disc.x - 31.5).abs() < 0.5 && (disc.y - 28.0).abs() < 0.5);
//! # Ok::<(), sillage_core::Error>(())
//! ```

pub mod descriptor;
mod extrema;
mod orientation;
pub mod params;
mod pyramid;

use rayon::prelude::*;
use sillage_core::{GrayImage, Result};

use crate::components::PixelBox;
use extrema::{Extremum, ExtremumTest, MAX_REFINE_STEPS};
use orientation::{Peaks, orientation_histogram};
use pyramid::{BORDER, Octave, ScaleSpace};

pub use descriptor::{DESCRIPTOR_LEN, SiftDescriptor};
pub use params::{MAX_OCTAVE_LAYERS, MAX_SIFT_SIGMA, SiftParams};
pub use pyramid::MIN_SIFT_SIDE;

/// A SIFT keypoint, in input-image coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SiftKeypoint {
    /// Column, input px (origin at the centre of the top-left pixel).
    pub x: f32,
    /// Row, input px.
    pub y: f32,
    /// Scale σ, input px: the blur `σ₀ · 2^(layer/s)` of the keypoint's level times the
    /// octave's step (OpenCV's `KeyPoint::size` is 2σ).
    pub sigma: f32,
    /// Orientation, radians in `[0, 2π)`, from +x towards +y (y down): OpenCV's `angle`.
    pub orientation: f32,
    /// `|D(x̂)|`, the DoG at the refined extremum (grey levels in `[0, 1]`): OpenCV's
    /// `response`.
    pub contrast: f32,
    /// `tr(H)²/det(H)` of the DoG's 2×2 spatial Hessian, ≥ 4; small is corner-like (robust),
    /// large edge-like (Lowe 2004 §4.1).
    pub edge_ratio: f32,
    /// Octave, −1 for the doubled input (OpenCV's numbering): the position was found on a grid
    /// of `2^octave` input px.
    pub octave: i32,
    /// Refined layer within the octave, in `(½, s + ½)`.
    pub layer: f32,
}

/// The SIFT detector and descriptor of one frame at a time; owns its scale space, reused from
/// frame to frame of the same size.
#[derive(Debug, Clone)]
pub struct SiftDetector {
    params: SiftParams,
    space: ScaleSpace,
    test: ExtremumTest,
}

impl SiftDetector {
    /// A detector with validated `params`.
    pub fn new(params: &SiftParams) -> Result<Self> {
        Ok(Self {
            params: *params,
            space: ScaleSpace::new(params)?,
            test: ExtremumTest::new(
                params.octave_layers,
                params.contrast_threshold,
                params.edge_threshold,
            ),
        })
    }

    /// The parameters in use.
    pub fn params(&self) -> &SiftParams {
        &self.params
    }

    /// Builds the Gaussian and DoG pyramids and the gradient images of `frame` (grey in
    /// `[0, 1]`, both sides at least [`MIN_SIFT_SIDE`] px) and keeps them for the queries
    /// below. On error, the previous frame's scale space is gone and queries find nothing.
    pub fn analyse(&mut self, frame: &GrayImage) -> Result<()> {
        self.space.build(frame)
    }

    /// Appends to `out` the keypoints of the analysed frame whose position lies in `region`
    /// (pixel `(u, v)` covering `[u − ½, u + ½) × [v − ½, v + ½)`; `None`: the whole frame),
    /// ordered by octave, layer, row, column, orientation, exact duplicates removed (as
    /// OpenCV). Only the region, widened by the few samples a refinement may move, is searched.
    pub fn keypoints(&self, region: Option<PixelBox>, out: &mut Vec<SiftKeypoint>) {
        let start = out.len();
        for (o, octave) in self.space.octaves().iter().enumerate() {
            let (width, height) = octave.dimensions();
            if width <= 2 * BORDER || height <= 2 * BORDER {
                continue;
            }
            let step = self.space.octave_step(o);
            let (cols, rows) = match region {
                None => (BORDER..width - BORDER, BORDER..height - BORDER),
                Some(b) => (
                    search_range(b.x0, b.x1, step, width),
                    search_range(b.y0, b.y1, step, height),
                ),
            };
            for layer in 1..=self.space.layers() {
                out.par_extend(rows.clone().into_par_iter().flat_map_iter(|row| {
                    self.test
                        .candidates(octave, layer, row, cols.clone())
                        .filter_map(move |col| self.test.refine(octave, layer, col, row))
                        .flat_map(move |extremum| self.oriented(o, octave, extremum))
                        .filter(move |kp| region.is_none_or(|b| contains(&b, kp.x, kp.y)))
                }));
            }
        }
        let found = &mut out[start..];
        found.sort_by(|a, b| {
            (a.octave.cmp(&b.octave))
                .then(a.layer.round().total_cmp(&b.layer.round()))
                .then(a.y.total_cmp(&b.y))
                .then(a.x.total_cmp(&b.x))
                .then(a.orientation.total_cmp(&b.orientation))
                .then(a.layer.total_cmp(&b.layer))
        });
        let mut kept = start;
        for i in start..out.len() {
            if kept == start || out[i] != out[kept - 1] {
                out[kept] = out[i];
                kept += 1;
            }
        }
        out.truncate(kept);
    }

    /// One keypoint per orientation peak of a refined extremum of octave `o`.
    fn oriented(
        &self,
        o: usize,
        octave: &Octave,
        extremum: Extremum,
    ) -> impl Iterator<Item = SiftKeypoint> + use<> {
        let step = self.space.octave_step(o);
        let layer = extremum.layer as f32 + extremum.offset[2];
        let scale = self.level_scale(layer);
        let hist = orientation_histogram(
            &octave.magnitude[extremum.layer - 1],
            &octave.orientation[extremum.layer - 1],
            extremum.col as i64,
            extremum.row as i64,
            scale,
        );
        let keypoint = SiftKeypoint {
            x: (extremum.col as f32 + extremum.offset[0]) * step,
            y: (extremum.row as f32 + extremum.offset[1]) * step,
            sigma: scale * step,
            orientation: 0.0,
            contrast: extremum.contrast,
            edge_ratio: extremum.edge_ratio,
            octave: o as i32 + self.space.first_octave(),
            layer,
        };
        Peaks::of(&hist).map(move |orientation| SiftKeypoint {
            orientation,
            ..keypoint
        })
    }

    /// Blur of (fractional) layer `layer`, octave px: `σ₀ · 2^(layer/s)`.
    fn level_scale(&self, layer: f32) -> f32 {
        (self.space.sigma() * 2f64.powf(f64::from(layer) / self.space.layers() as f64)) as f32
    }

    /// The level whose blur is nearest `sigma` input px, in log scale, among layers `1..=s` of
    /// every octave: `(octave index, layer)`; `None` before any frame or for a non-positive
    /// or non-finite `sigma`.
    fn nearest_level(&self, sigma: f32) -> Option<(usize, usize)> {
        let octaves = self.space.octaves().len();
        if octaves == 0 || !(sigma.is_finite() && sigma > 0.0) {
            return None;
        }
        let s = self.space.layers();
        let base = self.space.sigma() * f64::from(self.space.octave_step(0));
        let level = (s as f64 * (f64::from(sigma) / base).log2()).round();
        let level = level.clamp(1.0, (octaves * s) as f64) as usize;
        let o = (level - 1) / s;
        Some((o, level - o * s))
    }

    /// The descriptor at `(x, y)` input px, scale `sigma` input px and `orientation` radians,
    /// from the gradients of the level nearest `sigma` (see [`SiftDetector::describe`]);
    /// `None` when the window lies entirely outside the image (partly outside is fine: the
    /// samples outside are left out, as OpenCV does), or for non-finite arguments.
    pub fn describe_at(
        &self,
        x: f32,
        y: f32,
        sigma: f32,
        orientation: f32,
    ) -> Option<SiftDescriptor> {
        let (o, layer) = self.nearest_level(sigma)?;
        self.describe_on_level(o, layer, x, y, sigma, orientation)
    }

    /// The descriptor of a keypoint of this detector, on its own level (OpenCV's
    /// `calcDescriptors`); equal to `describe_at(kp.x, kp.y, kp.sigma, kp.orientation)`, whose
    /// nearest level is the keypoint's. `None` as for [`describe_at`](Self::describe_at) or
    /// when the keypoint's octave or layer is not in this scale space.
    pub fn describe(&self, kp: &SiftKeypoint) -> Option<SiftDescriptor> {
        let o = usize::try_from(kp.octave - self.space.first_octave()).ok()?;
        let layer = kp.layer.round();
        if o >= self.space.octaves().len() || !(1.0..=self.space.layers() as f32).contains(&layer) {
            return None;
        }
        self.describe_on_level(o, layer as usize, kp.x, kp.y, kp.sigma, kp.orientation)
    }

    fn describe_on_level(
        &self,
        o: usize,
        layer: usize,
        x: f32,
        y: f32,
        sigma: f32,
        orientation: f32,
    ) -> Option<SiftDescriptor> {
        if !(x.is_finite() && y.is_finite() && orientation.is_finite()) {
            return None;
        }
        let octave = &self.space.octaves()[o];
        let step = self.space.octave_step(o);
        descriptor::describe(
            &octave.magnitude[layer - 1],
            &octave.orientation[layer - 1],
            x / step,
            y / step,
            sigma / step,
            orientation,
        )
    }

    /// Describes every keypoint, in order, in parallel; keypoints whose window misses the
    /// image (none of this detector's) are dropped.
    pub fn describe_all(&self, keypoints: &[SiftKeypoint]) -> Vec<(SiftKeypoint, SiftDescriptor)> {
        keypoints
            .par_iter()
            .filter_map(|kp| self.describe(kp).map(|d| (*kp, d)))
            .collect()
    }

    /// The dominant gradient orientation at `(x, y)` input px and scale `sigma` input px: the
    /// highest peak of the 36-bin histogram of [`keypoints`](Self::keypoints), on the level
    /// nearest `sigma`, around the position rounded to that level's grid; `None` without
    /// gradient there (or before any frame, or for non-finite arguments).
    pub fn orientation_at(&self, x: f32, y: f32, sigma: f32) -> Option<f32> {
        let (o, layer) = self.nearest_level(sigma)?;
        if !(x.is_finite() && y.is_finite()) {
            return None;
        }
        let octave = &self.space.octaves()[o];
        let step = self.space.octave_step(o);
        let hist = orientation_histogram(
            &octave.magnitude[layer - 1],
            &octave.orientation[layer - 1],
            (x / step).round() as i64,
            (y / step).round() as i64,
            sigma / step,
        );
        Peaks::of(&hist).dominant()
    }

    /// [`analyse`](Self::analyse), then every keypoint of the frame with its descriptor
    /// (OpenCV's `detectAndCompute`).
    pub fn detect_and_describe(
        &mut self,
        frame: &GrayImage,
    ) -> Result<Vec<(SiftKeypoint, SiftDescriptor)>> {
        self.analyse(frame)?;
        let mut keypoints = Vec::new();
        self.keypoints(None, &mut keypoints);
        Ok(self.describe_all(&keypoints))
    }
}

/// Whether `(x, y)` input px lies in the pixels of `region`.
fn contains(region: &PixelBox, x: f32, y: f32) -> bool {
    let inside = |v: f32, lo: usize, hi: usize| v >= lo as f32 - 0.5 && v < hi as f32 - 0.5;
    inside(x, region.x0, region.x1) && inside(y, region.y0, region.y1)
}

/// Samples of an octave (`step` input px each, `len` of them) to search for extrema that may
/// end in input pixels `lo..hi`: those pixels plus [`MAX_REFINE_STEPS`] samples each side, a
/// refinement moving at most a sample per step in practice, within the border.
fn search_range(lo: usize, hi: usize, step: f32, len: usize) -> std::ops::Range<usize> {
    let margin = MAX_REFINE_STEPS as f32;
    let first = ((lo as f32 - 0.5) / step - margin)
        .floor()
        .max(BORDER as f32) as usize;
    let last = ((hi as f32 - 0.5) / step + margin).ceil().max(0.0) as usize;
    first..last.min(len - BORDER).max(first)
}

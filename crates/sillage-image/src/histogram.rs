//! Colour and motion histograms of boxes, compared by the Bhattacharyya coefficient: the
//! observation model of the pedestrian IMM particle filter (§4.3 of its paper), after Pérez,
//! Vermaak & Blake 2004, "Data fusion for visual tracking with particles" (HSV histograms
//! with `Nh × Ns` hue–saturation bins for coloured pixels and `Nv` value-only bins for the
//! others; histograms of the absolute difference between consecutive frames).
//!
//! A frame is binned once into a [`BinImage`] (one bin index per pixel, [`BinImage::fill_hsv`]
//! or [`BinImage::fill_difference`]); then every particle's box costs one pass over its pixels
//! ([`BinImage::box_histogram`], optionally sampling every `stride`-th row and column).
//!
//! An integral histogram (per-bin cumulative counts over one person's region of interest, 4
//! lookups per bin and box) was measured against this direct accumulation and lost: filling
//! it for a 120×200 px ROI costs more than 200 boxes of 30×80 px read directly (see
//! `BENCHMARKS.md`, "HSV box histograms"), so it is not kept.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sillage_core::{Error, GrayImage, Image, Result, RgbImage};

/// Most bins a [`BinImage`] can hold (its bin indexes are `u8`).
pub const MAX_BINS: usize = 256;

/// Tolerance of the saturation and value thresholds, so that a pixel exactly at a threshold
/// (a saturation of exactly 0.1, say) counts as above it whatever the rounding of `f64`.
const THRESHOLD_TOLERANCE: f64 = 1e-9;

/// How an HSV pixel is binned (Pérez, Vermaak & Blake 2004): a pixel with saturation
/// `≥ min_saturation` and value `≥ min_value` goes to one of `hue_bins × saturation_bins`
/// joint bins (bin `h · saturation_bins + s`), any other pixel to one of `value_bins` bins
/// after them (bin `hue_bins · saturation_bins + v`).
///
/// Hue, saturation and value are in `[0, 1]` (hue is the angle / 360°), each quantised into
/// equal bins; the top value falls in the last bin.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HsvBinning {
    /// `Nh`, hue bins of coloured pixels; default 10 (Pérez et al. 2004).
    pub hue_bins: usize,
    /// `Ns`, saturation bins of coloured pixels; default 10 (Pérez et al. 2004).
    pub saturation_bins: usize,
    /// `Nv`, value bins of the pixels too dark or too grey for a hue; default 10 (Pérez et
    /// al. 2004).
    pub value_bins: usize,
    /// Saturation in `[0, 1]` from which a pixel's hue counts; default 0.1 (Pérez et al.
    /// 2004).
    pub min_saturation: f64,
    /// Value in `[0, 1]` from which a pixel's hue counts; default 0.2 (Pérez et al.
    /// 2004).
    pub min_value: f64,
}

impl Default for HsvBinning {
    fn default() -> Self {
        Self {
            hue_bins: 10,
            saturation_bins: 10,
            value_bins: 10,
            min_saturation: 0.1,
            min_value: 0.2,
        }
    }
}

impl HsvBinning {
    /// Number of bins, `Nh · Ns + Nv` (110 by default); saturates instead of overflowing, so
    /// [`validate`](Self::validate) can refuse absurd values.
    pub fn bins(&self) -> usize {
        self.hue_bins
            .saturating_mul(self.saturation_bins)
            .saturating_add(self.value_bins)
    }

    /// Errors unless every bin count is at least 1, the total is at most [`MAX_BINS`], and
    /// both thresholds are in `[0, 1]`; the error names the key.
    pub fn validate(&self) -> Result<()> {
        for (key, value) in [
            ("hue_bins", self.hue_bins),
            ("saturation_bins", self.saturation_bins),
            ("value_bins", self.value_bins),
        ] {
            if value == 0 {
                return Err(Error::parameter(key, value, "must be at least 1"));
            }
        }
        if self.bins() > MAX_BINS {
            return Err(Error::parameter(
                "hue_bins",
                self.hue_bins,
                format!(
                    "hue_bins × saturation_bins + value_bins = {} but at most {MAX_BINS} bins are \
                     supported; use fewer bins",
                    self.bins()
                ),
            ));
        }
        for (key, value) in [
            ("min_saturation", self.min_saturation),
            ("min_value", self.min_value),
        ] {
            if !(0.0..=1.0).contains(&value) {
                return Err(Error::parameter(key, value, "must be in [0, 1]"));
            }
        }
        Ok(())
    }
}

/// The integer tables of one [`HsvBinning`], so that binning a pixel is exact integer
/// arithmetic on its 8-bit channels.
struct HsvTables {
    hue_bins: u32,
    saturation_bins: u32,
    value_bins: u32,
    /// Smallest `max(r, g, b)` whose value reaches `min_value`.
    min_max: u32,
    /// For each `max(r, g, b)`, the smallest `max − min` whose saturation reaches
    /// `min_saturation`.
    min_delta: [u32; 256],
}

impl HsvTables {
    fn new(binning: &HsvBinning) -> Self {
        let smallest = |threshold: f64, scale: u32| {
            ((threshold - THRESHOLD_TOLERANCE) * f64::from(scale))
                .ceil()
                .max(0.0) as u32
        };
        let mut min_delta = [0; 256];
        for (max, slot) in (0u32..).zip(min_delta.iter_mut()) {
            *slot = smallest(binning.min_saturation, max);
        }
        Self {
            hue_bins: binning.hue_bins as u32,
            saturation_bins: binning.saturation_bins as u32,
            value_bins: binning.value_bins as u32,
            min_max: smallest(binning.min_value, 255),
            min_delta,
        }
    }

    /// The bin of one 8-bit RGB pixel. Hue is `num / (6 · delta)` of a turn, with the usual
    /// sectors (red, then green at 1/3, blue at 2/3); a grey coloured pixel (possible only
    /// with `min_saturation = 0`) has hue 0.
    #[inline]
    fn bin(&self, [r, g, b]: [u8; 3]) -> u8 {
        let (r, g, b) = (u32::from(r), u32::from(g), u32::from(b));
        let max = r.max(g).max(b);
        let delta = max - r.min(g).min(b);
        if max >= self.min_max && delta >= self.min_delta[max as usize] {
            let hue = if delta == 0 {
                0
            } else {
                let num = if max == r {
                    if g >= b { g - b } else { 6 * delta - (b - g) }
                } else if max == g {
                    2 * delta + b - r
                } else {
                    4 * delta + r - g
                };
                (num * self.hue_bins / (6 * delta)).min(self.hue_bins - 1)
            };
            // A black pixel (possible only with `min_value = 0`) has saturation 0.
            let saturation = (delta * self.saturation_bins)
                .checked_div(max)
                .map_or(0, |s| s.min(self.saturation_bins - 1));
            (hue * self.saturation_bins + saturation) as u8
        } else {
            let value = (max * self.value_bins / 255).min(self.value_bins - 1);
            (self.hue_bins * self.saturation_bins + value) as u8
        }
    }
}

/// An axis-aligned box in pixel coordinates (origin at the centre of the top-left pixel):
/// pixel `(x, y)` is inside when `x_min ≤ x < x_max` and `y_min ≤ y < y_max`, so boxes that
/// touch share no pixel.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct BoxPx {
    /// Left edge, px.
    pub x_min: f64,
    /// Top edge, px.
    pub y_min: f64,
    /// Right edge (exclusive), px.
    pub x_max: f64,
    /// Bottom edge (exclusive), px.
    pub y_max: f64,
}

impl BoxPx {
    /// The box centred on `(x, y)` with the given width and height, px.
    pub fn centred(x: f64, y: f64, width: f64, height: f64) -> Self {
        Self {
            x_min: x - 0.5 * width,
            y_min: y - 0.5 * height,
            x_max: x + 0.5 * width,
            y_max: y + 0.5 * height,
        }
    }

    /// The columns `c0..c1` and rows `r0..r1` of its pixels inside a `width × height` image;
    /// `None` when there are none (including NaN corners).
    pub fn pixel_range(
        &self,
        width: usize,
        height: usize,
    ) -> Option<(std::ops::Range<usize>, std::ops::Range<usize>)> {
        let bound = |v: f64, n: usize| v.ceil().clamp(0.0, n as f64) as usize;
        if !(self.x_min < self.x_max && self.y_min < self.y_max) {
            return None;
        }
        let columns = bound(self.x_min, width)..bound(self.x_max, width);
        let rows = bound(self.y_min, height)..bound(self.y_max, height);
        (!columns.is_empty() && !rows.is_empty()).then_some((columns, rows))
    }
}

/// One bin index per pixel, with the number of bins: a frame binned once, from which the
/// histogram of any box is accumulated. Its buffer is reused from frame to frame.
#[derive(Debug, Clone, Default)]
pub struct BinImage {
    bins: usize,
    image: Image<u8>,
}

impl BinImage {
    /// An empty bin image, to be filled by [`fill_hsv`](Self::fill_hsv) or
    /// [`fill_difference`](Self::fill_difference).
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of bins; every index is below it.
    pub fn bins(&self) -> usize {
        self.bins
    }

    /// The bin index of each pixel.
    pub fn image(&self) -> &Image<u8> {
        &self.image
    }

    /// Bins the colour frame `rgb` by hue, saturation and value (Pérez et al. 2004).
    /// Errors when `binning` is invalid.
    pub fn fill_hsv(&mut self, rgb: &RgbImage, binning: &HsvBinning) -> Result<()> {
        binning.validate()?;
        let tables = HsvTables::new(binning);
        let (width, height) = rgb.dimensions();
        self.bins = binning.bins();
        self.image.reshape(width, height);
        let width = width.max(1);
        self.image
            .as_mut_slice()
            .par_chunks_mut(width)
            .zip(rgb.as_slice().par_chunks(width))
            .for_each(|(out, pixels)| {
                for (o, &p) in out.iter_mut().zip(pixels) {
                    *o = tables.bin(p);
                }
            });
        Ok(())
    }

    /// Bins the absolute difference `|current − previous|` of two grey frames linearly into
    /// `bins` bins over `[0, full_scale)`, differences `≥ full_scale` in the last bin (the
    /// motion cue of Pérez et al. 2004). Errors when the sizes differ, `bins` is not in
    /// `1..=MAX_BINS` or `full_scale` is not positive and finite.
    pub fn fill_difference(
        &mut self,
        previous: &GrayImage,
        current: &GrayImage,
        bins: usize,
        full_scale: f32,
    ) -> Result<()> {
        if !(1..=MAX_BINS).contains(&bins) {
            return Err(Error::parameter(
                "bins",
                bins,
                format!("must be in 1..={MAX_BINS}"),
            ));
        }
        if !(full_scale.is_finite() && full_scale > 0.0) {
            return Err(Error::parameter(
                "full_scale",
                full_scale,
                "must be a positive grey-level difference (1 is the sensor's full scale)",
            ));
        }
        if previous.dimensions() != current.dimensions() {
            return Err(Error::input(format!(
                "the current frame is {}×{} px but the previous one is {}×{} px; frame \
                 differences need frames of one size",
                current.width(),
                current.height(),
                previous.width(),
                previous.height()
            )));
        }
        let (width, height) = current.dimensions();
        self.bins = bins;
        self.image.reshape(width, height);
        let scale = bins as f32 / full_scale;
        let last = (bins - 1) as f32;
        let width = width.max(1);
        self.image
            .as_mut_slice()
            .par_chunks_mut(width)
            .zip(previous.as_slice().par_chunks(width))
            .zip(current.as_slice().par_chunks(width))
            .for_each(|((out, before), after)| {
                for ((o, &p), &c) in out.iter_mut().zip(before).zip(after) {
                    // A NaN difference lands in bin 0 (`as` saturates and maps NaN to 0).
                    *o = ((c - p).abs() * scale).min(last) as u8;
                }
            });
        Ok(())
    }

    /// The normalised histogram of the pixels of `region` (clipped to the image), sampling
    /// every `stride`-th row and column from its top-left pixel, written into `histogram`
    /// (one entry per bin, summing to 1). Returns the number of pixels counted; 0 means the
    /// box misses the image and `histogram` is all zeros. Errors when `histogram` does not
    /// have [`bins`](Self::bins) entries or `stride` is 0.
    pub fn box_histogram(
        &self,
        region: &BoxPx,
        stride: usize,
        histogram: &mut [f32],
    ) -> Result<usize> {
        self.check_histogram(histogram)?;
        if stride == 0 {
            return Err(Error::parameter("stride", stride, "must be at least 1"));
        }
        let Some((columns, rows)) = region.pixel_range(self.image.width(), self.image.height())
        else {
            histogram.fill(0.0);
            return Ok(0);
        };
        // Four sets of counters, so runs of pixels in one bin (common in real frames) do not
        // chain every increment on the previous one; a `u8` index into 256 counters needs no
        // bounds check.
        let mut lanes = [[0u32; MAX_BINS]; 4];
        for y in rows.step_by(stride) {
            let row = &self.image.row(y)[columns.clone()];
            let mut i = 0;
            while i + 3 * stride < row.len() {
                lanes[0][usize::from(row[i])] += 1;
                lanes[1][usize::from(row[i + stride])] += 1;
                lanes[2][usize::from(row[i + 2 * stride])] += 1;
                lanes[3][usize::from(row[i + 3 * stride])] += 1;
                i += 4 * stride;
            }
            for &bin in row[i.min(row.len())..].iter().step_by(stride) {
                lanes[0][usize::from(bin)] += 1;
            }
        }
        let mut counts = [0u32; MAX_BINS];
        for (b, count) in counts[..self.bins].iter_mut().enumerate() {
            *count = lanes[0][b] + lanes[1][b] + lanes[2][b] + lanes[3][b];
        }
        Ok(normalise(&counts[..self.bins], histogram))
    }

    fn check_histogram(&self, histogram: &[f32]) -> Result<()> {
        if histogram.len() == self.bins {
            Ok(())
        } else {
            Err(Error::input(format!(
                "a histogram of {} entries was given for a bin image of {} bins; size it with \
                 BinImage::bins",
                histogram.len(),
                self.bins
            )))
        }
    }
}

/// Writes `counts / Σ counts` into `histogram` (zeros when the sum is 0); returns the sum.
fn normalise(counts: &[u32], histogram: &mut [f32]) -> usize {
    let total: u64 = counts.iter().map(|&c| u64::from(c)).sum();
    let scale = if total == 0 { 0.0 } else { 1.0 / total as f64 };
    for (h, &c) in histogram.iter_mut().zip(counts) {
        *h = (f64::from(c) * scale) as f32;
    }
    total as usize
}

/// The Bhattacharyya coefficient `Σ sqrt(aᵢ bᵢ)` of two normalised histograms: 1 when they
/// are equal, 0 when they share no bin. Only the common length
/// is compared.
pub fn bhattacharyya_coefficient(a: &[f32], b: &[f32]) -> f64 {
    debug_assert_eq!(a.len(), b.len(), "histograms of different bin counts");
    a.iter()
        .zip(b)
        .map(|(&p, &q)| (f64::from(p) * f64::from(q)).sqrt())
        .sum()
}

/// The Bhattacharyya distance `sqrt(1 − coefficient)`, clamped at 0 when rounding lifts the
/// coefficient of two equal histograms above 1.
pub fn bhattacharyya_distance(a: &[f32], b: &[f32]) -> f64 {
    (1.0 - bhattacharyya_coefficient(a, b)).max(0.0).sqrt()
}

//! The observation model of the IMM-PF paper (§4.3, after Pérez, Vermaak & Blake 2004): HSV
//! colour histograms of the top and bottom halves of a person's box and a histogram of the
//! absolute difference between consecutive frames, each compared with the reference taken
//! when the tracker was created by the Bhattacharyya distance:
//! `ln p(Z | X) = −λ_c (d²_top + d²_bottom) − λ_m d²_motion − λ_f (1 − f)`,
//! `d² = 1 − Σᵢ √(hᵢ h_ref,ᵢ)`, where the last term, ours, weighs the share `f` of the box the
//! background subtraction marks as foreground (0 in the paper's model, `λ_f = 0`).

use serde::{Deserialize, Serialize};
use sillage_core::{Error, GrayImage, Image, Result, RgbImage};
use sillage_image::{BinImage, BoxPx, HsvBinning, bhattacharyya_coefficient};

use super::foreground::ForegroundShare;
use super::person_box::PersonBox;

/// Parameters of the colour and motion likelihood.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AppearanceParams {
    /// The HSV binning; default Pérez et al.'s 10×10 hue-saturation bins + 10 value bins.
    pub binning: HsvBinning,
    /// λ_c, the weight of the squared colour distances; default 20 (Pérez et al. 2004).
    pub colour_weight: f64,
    /// λ_m, the weight of the squared motion-histogram distance; 0 ignores motion; default
    /// 3 (chosen on PETS 2009 among 0, 3 and 10, docs/immpf.md: a walker's frame difference
    /// changes with its stride, so a heavy motion term pulls boxes off walkers).
    pub motion_weight: f64,
    /// λ_f, the weight of the share of the box that is not foreground (not in the paper);
    /// default 10. Without it, boxes slide along people of uniform colour, a box above a
    /// person's head matching the reference nearly as well as one on the person (measured on
    /// PETS 2009: see docs/immpf.md); 0 gives the paper's model.
    pub foreground_weight: f64,
    /// Bins of the frame-difference histogram; default 8.
    pub motion_bins: usize,
    /// Frame differences at or above this (grey levels in [0, 1]) fall in the last motion
    /// bin; default 0.25.
    pub motion_full_scale: f32,
    /// Every `stride`-th row and column of a box is counted; default 2 (a quarter of the
    /// pixels: the histograms of 30×70 px boxes change little, the cost falls 4×).
    pub stride: usize,
}

impl Default for AppearanceParams {
    fn default() -> Self {
        Self {
            binning: HsvBinning::default(),
            colour_weight: 20.0,
            motion_weight: 3.0,
            foreground_weight: 10.0,
            motion_bins: 8,
            motion_full_scale: 0.25,
            stride: 2,
        }
    }
}

impl AppearanceParams {
    /// Checks every value; errors name the key.
    pub fn validate(&self) -> Result<()> {
        self.binning.validate()?;
        for (key, value) in [
            ("colour_weight", self.colour_weight),
            ("motion_weight", self.motion_weight),
            ("foreground_weight", self.foreground_weight),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::parameter(
                    key,
                    value,
                    "must be a finite weight ≥ 0 (Pérez et al. use 20)",
                ));
            }
        }
        if !(2..=256).contains(&self.motion_bins) {
            return Err(Error::parameter(
                "motion_bins",
                self.motion_bins,
                "must be in 2..=256",
            ));
        }
        if !(self.motion_full_scale > 0.0 && self.motion_full_scale <= 1.0) {
            return Err(Error::parameter(
                "motion_full_scale",
                self.motion_full_scale,
                "must be a grey-level difference in (0, 1]",
            ));
        }
        if !(1..=16).contains(&self.stride) {
            return Err(Error::parameter(
                "stride",
                self.stride,
                "must be in 1..=16 pixels",
            ));
        }
        Ok(())
    }
}

/// The per-pixel bins of one frame: colour, motion from the previous frame's grey levels,
/// and the foreground mask's summed areas. Its buffers are reused when it is updated again.
#[derive(Debug, Clone, Default)]
pub struct FrameCues {
    colour: BinImage,
    motion: BinImage,
    foreground: ForegroundShare,
    has_motion: bool,
    has_foreground: bool,
}

impl FrameCues {
    /// Bins `colour` and the difference of `grey` with `previous`, the previous frame's grey
    /// levels (none at the first frame: the motion term is then left out), and sums the
    /// `foreground` mask (none: the foreground term is left out). Frames must keep one size.
    pub fn update(
        &mut self,
        params: &AppearanceParams,
        colour: &RgbImage,
        grey: &GrayImage,
        previous: Option<&GrayImage>,
        foreground: Option<&Image<bool>>,
    ) -> Result<()> {
        self.colour.fill_hsv(colour, &params.binning)?;
        self.has_foreground = foreground.is_some();
        if let Some(mask) = foreground {
            self.foreground.fill(mask);
        }
        self.has_motion = previous.is_some();
        if let Some(previous) = previous {
            self.motion.fill_difference(
                previous,
                grey,
                params.motion_bins,
                params.motion_full_scale,
            )?;
        }
        Ok(())
    }

    /// The share of `b`'s pixels that the foreground mask marks; `None` without a mask or
    /// when `b` holds no pixel.
    pub(crate) fn foreground_share(&self, b: &PersonBox) -> Option<f64> {
        if self.has_foreground {
            self.foreground.share(b)
        } else {
            None
        }
    }
}

/// The reference histograms of one person, taken at its tracker's birth.
#[derive(Debug, Clone, PartialEq)]
pub struct Appearance {
    top: Vec<f32>,
    bottom: Vec<f32>,
    /// Absent when the tracker was born on the first frame (no difference yet).
    motion: Option<Vec<f32>>,
}

/// Scratch histograms, one set per thread.
#[derive(Debug, Clone, Default)]
pub struct HistogramScratch {
    colour: Vec<f32>,
    motion: Vec<f32>,
}

/// `ln p(Z | X)` below which a box is worthless: a box entirely outside the image.
const OUTSIDE_LOG_LIKELIHOOD: f64 = -1e3;

impl Appearance {
    /// The reference of the person in `person` (None when the box holds no pixel).
    pub fn capture(
        params: &AppearanceParams,
        cues: &FrameCues,
        person: &PersonBox,
    ) -> Option<Self> {
        let histogram = |bins: &BinImage, b: PersonBox| {
            let mut h = vec![0.0; bins.bins()];
            (box_histogram(bins, &b, params.stride, &mut h) > 0).then_some(h)
        };
        Some(Self {
            top: histogram(&cues.colour, person.half(true))?,
            bottom: histogram(&cues.colour, person.half(false))?,
            motion: if cues.has_motion {
                histogram(&cues.motion, *person)
            } else {
                None
            },
        })
    }

    /// `ln p(Z | X)` of a person in `person` (§4.3).
    /// The share of the box's pixels whose frame difference leaves the first motion bin (is
    /// at least `motion_full_scale / motion_bins`): how much of the box moves; `None` without
    /// a previous frame.
    pub fn moving_share(&self) -> Option<f64> {
        self.motion.as_ref().map(|h| 1.0 - f64::from(h[0]))
    }

    /// `ln p(Z | X)` of a person in `person` (§4.3).
    pub fn log_likelihood(
        &self,
        params: &AppearanceParams,
        cues: &FrameCues,
        person: &PersonBox,
        scratch: &mut HistogramScratch,
    ) -> f64 {
        let distance = |bins: &BinImage, b: PersonBox, reference: &[f32], h: &mut Vec<f32>| {
            h.resize(bins.bins(), 0.0);
            if box_histogram(bins, &b, params.stride, h) == 0 {
                return None;
            }
            Some((1.0 - bhattacharyya_coefficient(h, reference)).max(0.0))
        };
        let (Some(top), Some(bottom)) = (
            distance(
                &cues.colour,
                person.half(true),
                &self.top,
                &mut scratch.colour,
            ),
            distance(
                &cues.colour,
                person.half(false),
                &self.bottom,
                &mut scratch.colour,
            ),
        ) else {
            return OUTSIDE_LOG_LIKELIHOOD;
        };
        let mut log = -params.colour_weight * (top + bottom);
        if let (Some(reference), true) =
            (&self.motion, cues.has_motion && params.motion_weight > 0.0)
        {
            match distance(&cues.motion, *person, reference, &mut scratch.motion) {
                Some(d) => log -= params.motion_weight * d,
                None => return OUTSIDE_LOG_LIKELIHOOD,
            }
        }
        if cues.has_foreground && params.foreground_weight > 0.0 {
            let share = cues.foreground.share(person).unwrap_or(0.0);
            log -= params.foreground_weight * (1.0 - share);
        }
        log
    }
}

/// The normalised histogram of the bins inside `b` (clipped to the image) into `out`; the
/// number of pixels counted (0: nothing inside).
fn box_histogram(bins: &BinImage, b: &PersonBox, stride: usize, out: &mut [f32]) -> usize {
    let region = BoxPx {
        x_min: b.left_px,
        y_min: b.top_px,
        x_max: b.right_px(),
        y_max: b.bottom_px(),
    };
    // `out` has one entry per bin and the stride is validated: no error is possible.
    bins.box_histogram(&region, stride, out).unwrap_or(0)
}

//! The observation model of the IMM-PF paper (§4.3, after Pérez, Vermaak & Blake 2004): HSV
//! colour histograms of the top and bottom halves of a person's box and a histogram of the
//! absolute difference between consecutive frames, each compared with the reference taken
//! when the tracker was created by the Bhattacharyya distance:
//! `ln p(Z | X) = −λ_c (d²_top + d²_bottom) − λ_m d²_motion − λ_f (1 − f)`,
//! `d² = 1 − Σᵢ √(hᵢ h_ref,ᵢ)`, where the last term, ours, weighs the share `f` of the box the
//! background subtraction marks as foreground (0 in the paper's model, `λ_f = 0`). The
//! references follow the person slowly ([`Appearance::adapt`], also ours).

use serde::{Deserialize, Serialize};
use sillage_core::{Error, GrayImage, Image, Result, RgbImage};
use sillage_image::{BinImage, BoxPx, HsvBinning, bhattacharyya_coefficient};

use super::foreground::ForegroundShare;
use sillage_core::BoundingBox;

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
    /// α of the reference update `h_ref ← (1 − α) h_ref + α h(estimate)` (Nummiaro,
    /// Koller-Meier & Van Gool, "An adaptive color-based particle filter", 2003; not in the
    /// IMM-PF paper), made after each frame whose estimated box scores at least
    /// `adapt_min_log_likelihood`; default 0.05. 0 keeps the reference taken at birth (the
    /// paper). On PETS 2009 S2.L1 the colour distance of a followed person to its birth
    /// reference grows over 100 frames until the tracker dies (docs/immpf.md).
    pub adapt_rate: f64,
    /// The colour log-likelihood `−λ_c (d²_top + d²_bottom)` the estimated box must reach
    /// for the reference to be updated; default −3 (`d²_top + d²_bottom ≤ 0.15` with
    /// λ_c = 20), so that a box sliding off its person does not teach the reference.
    pub adapt_min_log_likelihood: f64,
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
            adapt_rate: 0.05,
            adapt_min_log_likelihood: -3.0,
        }
    }
}

impl AppearanceParams {
    /// Checks every value; errors name the key.
    pub fn validate(&self) -> Result<()> {
        self.binning.validate()?;
        for (key, value) in [
            ("appearance.colour_weight", self.colour_weight),
            ("appearance.motion_weight", self.motion_weight),
            ("appearance.foreground_weight", self.foreground_weight),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::parameter(
                    key,
                    value,
                    "must be a finite weight ≥ 0 (Pérez et al. use 20)",
                ));
            }
        }
        if !(0.0..=1.0).contains(&self.adapt_rate) {
            return Err(Error::parameter(
                "appearance.adapt_rate",
                self.adapt_rate,
                "must be in [0, 1] (0 keeps the reference of the birth)",
            ));
        }
        if !(self.adapt_min_log_likelihood.is_finite() && self.adapt_min_log_likelihood <= 0.0) {
            return Err(Error::parameter(
                "appearance.adapt_min_log_likelihood",
                self.adapt_min_log_likelihood,
                "must be a finite log-likelihood ≤ 0",
            ));
        }
        if !(2..=256).contains(&self.motion_bins) {
            return Err(Error::parameter(
                "appearance.motion_bins",
                self.motion_bins,
                "must be in 2..=256",
            ));
        }
        if !(self.motion_full_scale > 0.0 && self.motion_full_scale <= 1.0) {
            return Err(Error::parameter(
                "appearance.motion_full_scale",
                self.motion_full_scale,
                "must be a grey-level difference in (0, 1]",
            ));
        }
        if !(1..=16).contains(&self.stride) {
            return Err(Error::parameter(
                "appearance.stride",
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
    pub(crate) fn foreground_share(&self, b: &BoundingBox) -> Option<f64> {
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
    /// The top half's colour histogram.
    top: Vec<f32>,
    /// The bottom half's colour histogram, then the motion histogram.
    bottom_or_motion: Vec<f32>,
}

/// `ln p(Z | X)` below which a box is worthless: a box entirely outside the image.
const OUTSIDE_LOG_LIKELIHOOD: f64 = -1e3;

impl Appearance {
    /// The reference of the person in `person` (None when the box holds no pixel).
    pub fn capture(
        params: &AppearanceParams,
        cues: &FrameCues,
        person: &BoundingBox,
    ) -> Option<Self> {
        let histogram = |bins: &BinImage, b: BoundingBox| {
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

    /// The share of the box's pixels whose frame difference leaves the first motion bin (is
    /// at least `motion_full_scale / motion_bins`): how much of the box moves; `None` without
    /// a previous frame.
    pub fn moving_share(&self) -> Option<f64> {
        self.motion.as_ref().map(|h| 1.0 - f64::from(h[0]))
    }

    /// `(d²_top + d²_bottom) / 2` between two appearances, in `[0, 1]`: the mean squared
    /// Bhattacharyya distance of their halves' colour histograms (§4.3's d², the motion
    /// histograms left out).
    pub fn colour_distance(&self, other: &Appearance) -> f64 {
        let d2 = |a: &[f32], b: &[f32]| (1.0 - bhattacharyya_coefficient(a, b)).max(0.0);
        (d2(&self.top, &other.top) + d2(&self.bottom, &other.bottom)) / 2.0
    }

    /// `−λ_c (d²_top + d²_bottom)` of `person`, the colour part of the likelihood; `None`
    /// when a half of the box holds no pixel. The histograms of the top and bottom halves
    /// are left in `scratch`.
    fn colour_log_likelihood(
        &self,
        params: &AppearanceParams,
        cues: &FrameCues,
        person: &BoundingBox,
        scratch: &mut HistogramScratch,
    ) -> Option<f64> {
        let (top, bottom) = (&mut scratch.top, &mut scratch.bottom_or_motion);
        let stride = params.stride;
        let d_top = squared_distance(&cues.colour, person.half(true), &self.top, stride, top)?;
        let d_bottom = squared_distance(
            &cues.colour,
            person.half(false),
            &self.bottom,
            stride,
            bottom,
        )?;
        Some(-params.colour_weight * (d_top + d_bottom))
    }

    /// Blends the histograms of `person` (the tracker's estimate) into the reference, at
    /// `adapt_rate`, when its colour likelihood reaches `adapt_min_log_likelihood`: the
    /// reference follows slow changes of light and pose (Nummiaro et al. 2003) while a box
    /// that has slid off its person leaves it as it is. Returns whether it was updated.
    pub fn adapt(
        &mut self,
        params: &AppearanceParams,
        cues: &FrameCues,
        person: &BoundingBox,
        scratch: &mut HistogramScratch,
    ) -> bool {
        let rate = params.adapt_rate as f32;
        if rate <= 0.0
            || !self
                .colour_log_likelihood(params, cues, person, scratch)
                .is_some_and(|log| log >= params.adapt_min_log_likelihood)
        {
            return false;
        }
        let blend = |reference: &mut [f32], h: &[f32]| {
            for (r, &v) in reference.iter_mut().zip(h) {
                *r = (1.0 - rate) * *r + rate * v;
            }
        };
        // The halves' histograms were just computed for the gate.
        blend(&mut self.top, &scratch.top);
        blend(&mut self.bottom, &scratch.bottom_or_motion);
        if let (Some(motion), true) = (&mut self.motion, cues.has_motion) {
            let h = &mut scratch.bottom_or_motion;
            h.resize(cues.motion.bins(), 0.0);
            if box_histogram(&cues.motion, person, params.stride, h) > 0 {
                blend(motion, h);
            }
        }
        true
    }

    /// `ln p(Z | X)` of a person in `person` (§4.3).
    pub fn log_likelihood(
        &self,
        params: &AppearanceParams,
        cues: &FrameCues,
        person: &BoundingBox,
        scratch: &mut HistogramScratch,
    ) -> f64 {
        let Some(mut log) = self.colour_log_likelihood(params, cues, person, scratch) else {
            return OUTSIDE_LOG_LIKELIHOOD;
        };
        if let (Some(reference), true) =
            (&self.motion, cues.has_motion && params.motion_weight > 0.0)
        {
            let h = &mut scratch.bottom_or_motion;
            match squared_distance(&cues.motion, *person, reference, params.stride, h) {
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

/// `d² = 1 − Σᵢ √(hᵢ h_ref,ᵢ)` between the histogram of `b` (computed into `h`) and
/// `reference`; `None` when `b` holds no pixel.
fn squared_distance(
    bins: &BinImage,
    b: BoundingBox,
    reference: &[f32],
    stride: usize,
    h: &mut Vec<f32>,
) -> Option<f64> {
    h.resize(bins.bins(), 0.0);
    (box_histogram(bins, &b, stride, h) > 0)
        .then(|| (1.0 - bhattacharyya_coefficient(h, reference)).max(0.0))
}

/// The normalised histogram of the bins inside `b` (clipped to the image) into `out`; the
/// number of pixels counted (0: nothing inside).
fn box_histogram(bins: &BinImage, b: &BoundingBox, stride: usize, out: &mut [f32]) -> usize {
    let region = BoxPx {
        x_min: b.left_px,
        y_min: b.top_px,
        x_max: b.right_px(),
        y_max: b.bottom_px(),
    };
    // `out` has one entry per bin and the stride is validated: no error is possible.
    bins.box_histogram(&region, stride, out).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_core::Point2;

    /// Cues of a 40×60 grey frame with a 16×40 person (rows 10-49) whose rows are of
    /// `colour(row)`.
    fn cues_with(params: &AppearanceParams, colour: impl Fn(usize) -> [u8; 3]) -> FrameCues {
        let (w, h) = (40, 60);
        let mut rgb = RgbImage::from_vec(w, h, vec![[120, 120, 120]; w * h]).unwrap();
        for y in 10..50 {
            for x in 12..28 {
                rgb.set(x, y, colour(y));
            }
        }
        let grey = GrayImage::from_vec(w, h, vec![0.5; w * h]).unwrap();
        let mut cues = FrameCues::default();
        cues.update(params, &rgb, &grey, None, None).unwrap();
        cues
    }

    #[test]
    fn the_reference_follows_a_slow_change_and_ignores_a_poor_match() {
        let params = AppearanceParams {
            adapt_rate: 0.5,
            adapt_min_log_likelihood: -15.0,
            ..AppearanceParams::default()
        };
        let person = BoundingBox::standing_on(Point2::new(20.0, 50.0), 16.0, 40.0);
        let (red, blue) = ([200, 30, 30], [30, 30, 160]);
        let born = cues_with(&params, |y| if y < 30 { red } else { blue });
        let mut appearance = Appearance::capture(&params, &born, &person).unwrap();
        let mut scratch = HistogramScratch::default();
        // A third of the shirt turns yellow (a scarf, a turn): the colour likelihood drops,
        // then recovers as the reference learns it.
        let later = cues_with(&params, |y| match y {
            ..17 => [220, 200, 40],
            17..30 => red,
            _ => blue,
        });
        let colour = |appearance: &Appearance, scratch: &mut HistogramScratch| {
            appearance
                .colour_log_likelihood(&params, &later, &person, scratch)
                .unwrap()
        };
        let before = colour(&appearance, &mut scratch);
        assert!(before < -0.5, "a change to learn: {before}");
        assert!(appearance.adapt(&params, &later, &person, &mut scratch));
        let after = colour(&appearance, &mut scratch);
        assert!(after > before + 0.2, "{before} → {after}");
        // A box on someone else (other colours) is below the gate: nothing is learnt.
        let stranger = cues_with(
            &params,
            |y| if y < 30 { [30, 160, 40] } else { [90, 60, 20] },
        );
        let kept = appearance.clone();
        assert!(!appearance.adapt(&params, &stranger, &person, &mut scratch));
        assert_eq!(appearance, kept);
        // α = 0 is the paper's fixed reference.
        let fixed = AppearanceParams {
            adapt_rate: 0.0,
            ..params
        };
        assert!(!appearance.adapt(&fixed, &later, &person, &mut scratch));
        assert_eq!(appearance, kept);
    }
}

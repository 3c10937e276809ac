//! Frame pre-processing before blob detection (TracTrac §3.1.1 and its `imProc`): an optional
//! median filter, then an optional background subtraction, with an optional mask.

use serde::{Deserialize, Serialize};
use sillage_core::{Error, GrayImage, Result};
use sillage_image::{BackgroundModel, MedianSize, apply_mask, median_filter};

/// Background subtraction settings (TracTrac's `BG = 1`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BackgroundParams {
    /// Adaptation speed β, grey levels per frame, in `(0, 1]`. Default 0.01, the code's
    /// `BGspeed` (the paper's text says 0.001).
    pub speed: f32,
    /// Frames averaged into the initial background, in `1..=100_000`. Default 100, the code's
    /// `min(100, n)` (the paper's Eq. (2) says `1/(2β)` frames, 50 at β = 0.01).
    pub init_frames: usize,
}

impl Default for BackgroundParams {
    fn default() -> Self {
        Self {
            speed: 0.01,
            init_frames: 100,
        }
    }
}

/// Pre-processing settings; the default does nothing (TracTrac's `noise = 0`, `BG = 0`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PreprocessParams {
    /// Median filter window (`3` or `5`), or none.
    pub median: Option<MedianSize>,
    /// Background subtraction, or none.
    pub background: Option<BackgroundParams>,
}

impl PreprocessParams {
    /// Errors naming the key when a value is out of range.
    pub fn validate(&self) -> Result<()> {
        if let Some(bg) = &self.background {
            if !(bg.speed.is_finite() && bg.speed > 0.0 && bg.speed <= 1.0) {
                return Err(Error::parameter(
                    "background.speed",
                    bg.speed,
                    "must be a number in (0, 1] (grey levels per frame)",
                ));
            }
            if !(1..=100_000).contains(&bg.init_frames) {
                return Err(Error::parameter(
                    "background.init_frames",
                    bg.init_frames,
                    "must be an integer in 1..=100000",
                ));
            }
        }
        Ok(())
    }
}

/// Turns raw frames into the images detectors see: `F = median(I)·mask − B`.
///
/// Background initialisation: call [`Preprocessor::prime`] with the first frames of the
/// sequence (up to `init_frames` of them are averaged, Eq. (2)) before processing, as
/// TracTrac does. Without priming, the background is the running mean of the frames processed
/// so far until `init_frames` have been seen, so the first frames have a weak foreground
/// (frame 0's is `I·mask − I`); after that, each frame moves it by at most β (Eq. (1)).
/// `F` is always computed against the background of the previous frames.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Preprocessor {
    params: PreprocessParams,
    background: Option<BackgroundModel>,
    primed: bool,
    denoised: GrayImage,
}

impl Preprocessor {
    /// A pre-processor with validated `params`.
    pub fn new(params: PreprocessParams) -> Result<Self> {
        params.validate()?;
        let background = match params.background {
            Some(bg) => Some(BackgroundModel::new(bg.speed)?),
            None => None,
        };
        Ok(Self {
            params,
            background,
            primed: false,
            denoised: GrayImage::default(),
        })
    }

    /// The settings.
    pub fn params(&self) -> &PreprocessParams {
        &self.params
    }

    /// The current background, when background subtraction is on and a frame has been seen.
    pub fn background(&self) -> Option<&GrayImage> {
        self.background
            .as_ref()
            .filter(|m| m.frames_averaged() > 0)
            .map(BackgroundModel::background)
    }

    /// Initialises the background from the mean of the first `init_frames` of `frames`
    /// (median-filtered as in [`Preprocessor::process`]) and returns how many were used; later
    /// frames then only update it. Does nothing (returns 0) without background subtraction.
    pub fn prime<'a>(&mut self, frames: impl IntoIterator<Item = &'a GrayImage>) -> Result<usize> {
        let (Some(model), Some(bg)) = (&mut self.background, self.params.background) else {
            return Ok(0);
        };
        let mut used = 0;
        for frame in frames.into_iter().take(bg.init_frames) {
            let denoised = denoise(self.params.median, frame, &mut self.denoised);
            model.accumulate(denoised)?;
            used += 1;
        }
        self.primed = used > 0;
        Ok(used)
    }

    /// Pre-processes `frame` into `out` (reshaped), multiplying by `mask` when given, and
    /// advances the background. Errors when `mask` or `frame` differ in size from earlier
    /// frames.
    pub fn process(
        &mut self,
        frame: &GrayImage,
        mask: Option<&GrayImage>,
        out: &mut GrayImage,
    ) -> Result<()> {
        let denoised = denoise(self.params.median, frame, &mut self.denoised);
        let (Some(model), Some(bg)) = (&mut self.background, self.params.background) else {
            copy_into(denoised, out);
            return match mask {
                Some(mask) => apply_mask(out, mask),
                None => Ok(()),
            };
        };
        let initialising = !self.primed && model.frames_averaged() < bg.init_frames;
        if initialising {
            model.accumulate(denoised)?;
            model.foreground(denoised, mask, out)
        } else {
            model.foreground(denoised, mask, out)?;
            model.update(denoised)
        }
    }
}

/// `frame` median-filtered into `buffer` when `median` is set, else `frame` itself.
fn denoise<'a>(
    median: Option<MedianSize>,
    frame: &'a GrayImage,
    buffer: &'a mut GrayImage,
) -> &'a GrayImage {
    match median {
        Some(size) => {
            median_filter(frame, size, buffer);
            buffer
        }
        None => frame,
    }
}

/// Copies `src` into `dst`, reusing the allocation of `dst`.
fn copy_into(src: &GrayImage, dst: &mut GrayImage) {
    dst.reshape(src.width(), src.height());
    dst.as_mut_slice().copy_from_slice(src.as_slice());
}

//! TracTrac's background model: an initial mean of the first frames, then a slew-rate-limited
//! update (TracTrac paper Eqs. (1)–(2), as its code implements them).

use rayon::prelude::*;
use sillage_core::{Error, GrayImage, Result};

use crate::mask::check_same_size;

/// Pixels per parallel job of the per-pixel loops.
const CHUNK: usize = 1 << 14;

/// Background image `B` and its adaptation speed β.
///
/// `B` starts as the running mean of the frames given to [`BackgroundModel::accumulate`]
/// (Eq. (2)), then follows each frame `I` with [`BackgroundModel::update`]: with
/// `r₂ = B − I`, `B ← clip(B + r, 0, 1)` where `r = −β` if `r₂ > β`, `+β` if `r₂ < −β` and
/// `−r₂` otherwise. That is Eq. (1), `B += β·sign(I − B)`, with a dead band so that `B` lands
/// exactly on `I` instead of oscillating around it.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct BackgroundModel {
    background: GrayImage,
    speed: f32,
    frames_averaged: usize,
}

impl BackgroundModel {
    /// An empty model of adaptation speed `speed` = β, in `(0, 1]` (TracTrac's `BGspeed`).
    pub fn new(speed: f32) -> Result<Self> {
        if !(speed.is_finite() && speed > 0.0 && speed <= 1.0) {
            return Err(Error::parameter(
                "speed",
                speed,
                "background speed must be a number in (0, 1] (grey levels per frame)",
            ));
        }
        Ok(Self {
            background: GrayImage::default(),
            speed,
            frames_averaged: 0,
        })
    }

    /// The current background `B`.
    pub fn background(&self) -> &GrayImage {
        &self.background
    }

    /// Number of frames averaged into the initial background so far.
    pub fn frames_averaged(&self) -> usize {
        self.frames_averaged
    }

    /// Adds `frame` to the initial mean (Eq. (2)): after `k` calls `B` is the mean of the `k`
    /// frames. Errors when `frame` differs in size from the earlier ones.
    pub fn accumulate(&mut self, frame: &GrayImage) -> Result<()> {
        if self.frames_averaged == 0 {
            self.background.clone_from(frame);
        } else {
            check_same_size(&self.background, frame, "frame")?;
            let weight = 1.0 / (self.frames_averaged + 1) as f32;
            self.per_pixel(frame, |b, i| b + (i - b) * weight);
        }
        self.frames_averaged += 1;
        Ok(())
    }

    /// One slew-limited step of `B` toward `frame` (Eq. (1) with the code's dead band). A model
    /// that has seen no frame yet starts from `frame` itself.
    pub fn update(&mut self, frame: &GrayImage) -> Result<()> {
        if self.frames_averaged == 0 {
            return self.accumulate(frame);
        }
        check_same_size(&self.background, frame, "frame")?;
        let beta = self.speed;
        self.per_pixel(frame, |b, i| {
            (b + (i - b).clamp(-beta, beta)).clamp(0.0, 1.0)
        });
        Ok(())
    }

    /// Foreground `F = I·mask − B` into `out` (reshaped); errors on a size mismatch or when
    /// the model has seen no frame.
    pub fn foreground(
        &self,
        frame: &GrayImage,
        mask: Option<&GrayImage>,
        out: &mut GrayImage,
    ) -> Result<()> {
        if self.frames_averaged == 0 {
            return Err(Error::input(
                "the background model has seen no frame yet; give it one with accumulate()",
            ));
        }
        check_same_size(&self.background, frame, "frame")?;
        if let Some(mask) = mask {
            check_same_size(&self.background, mask, "mask")?;
        }
        out.reshape(frame.width(), frame.height());
        let (b, i) = (self.background.as_slice(), frame.as_slice());
        out.as_mut_slice()
            .par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, out)| {
                let range = c * CHUNK..c * CHUNK + out.len();
                let (b, i) = (&b[range.clone()], &i[range.clone()]);
                match mask {
                    Some(m) => {
                        let m = &m.as_slice()[range];
                        for (((o, &b), &i), &m) in out.iter_mut().zip(b).zip(i).zip(m) {
                            *o = i * m - b;
                        }
                    }
                    None => {
                        for ((o, &b), &i) in out.iter_mut().zip(b).zip(i) {
                            *o = i - b;
                        }
                    }
                }
            });
        Ok(())
    }

    /// `B[p] = f(B[p], I[p])` for every pixel, in parallel.
    fn per_pixel(&mut self, frame: &GrayImage, f: impl Fn(f32, f32) -> f32 + Sync) {
        let frame = frame.as_slice();
        self.background
            .as_mut_slice()
            .par_chunks_mut(CHUNK)
            .zip(frame.par_chunks(CHUNK))
            .for_each(|(b, i)| {
                for (b, &i) in b.iter_mut().zip(i) {
                    *b = f(*b, i);
                }
            });
    }
}

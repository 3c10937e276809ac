//! Per-pixel adaptive Gaussian mixture background (Stauffer & Grimson 1999), with the
//! recursive updates of Zivkovic (2004) and an optional shadow test on the brightness ratio.
//!
//! Each pixel holds `K` Gaussians (weight `w`, mean `μ`, variance `σ²`) over its grey level,
//! ordered by `w / σ`. A new value matches the first Gaussian within `λσ`; the weights move as
//! `w ← w + α (o − w)` (`o` = 1 for the matched one, 0 for the others), the matched Gaussian as
//! `μ ← μ + (α/w)(x − μ)`, `σ² ← σ² + (α/w)((x − μ)² − σ²)`; without a match the least
//! probable Gaussian is replaced by one at `x`. The background is the first Gaussians whose
//! weights add up to the background ratio; a value matching one of them is background. During
//! the first `1/α` frames `α` is `1/(t + 1)`, so that the model starts as a running mean.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sillage_core::{Error, GrayImage, Image, Result};

/// Label of a background pixel in a [`MixtureBackground`] mask.
pub const BACKGROUND: u8 = 0;
/// Label of a shadow pixel: darker than a background Gaussian by a ratio in the shadow range.
pub const SHADOW: u8 = 127;
/// Label of a foreground (moving) pixel.
pub const FOREGROUND: u8 = 255;

/// Most Gaussians a pixel may hold.
pub const MAX_GAUSSIANS: usize = 8;

/// Parameters of the mixture background; grey levels in `[0, 1]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MixtureParams {
    /// Gaussians per pixel, K (Stauffer & Grimson use 3 to 5).
    pub gaussians: usize,
    /// Frames the model remembers: the learning rate is α = 1 / history.
    pub history: usize,
    /// Frames of the start-up phase, in which the learning rate is the running mean's
    /// α = 1/(t + 1) (never below 1/history), so that the people of the first frame, learnt
    /// as background, leave no ghost once they walk on; α = 1/history afterwards. Default
    /// 200, the history: the usual running-mean start. That start also learns people who
    /// stop into the background several times faster than 1/history for as long as it
    /// lasts: on PETS 2009 S2.L1 (150 frames) two people who stand for 60 frames were half
    /// absent from the foreground, and the pedestrian tracker uses 20 (docs/immpf.md).
    pub bootstrap_frames: usize,
    /// A value matches a Gaussian within this many standard deviations (λ; 2.5 in the paper).
    pub match_sigmas: f32,
    /// Share of the weight that the background Gaussians hold (T; Stauffer & Grimson leave
    /// it to the scene, OpenCV's MOG2 uses 0.9): lower keeps people who stop in the
    /// foreground longer. 0.6 found the most PETS 2009 people of 0.6, 0.7 and 0.9.
    pub background_ratio: f32,
    /// Standard deviation of a new Gaussian, grey levels (15/255 as MOG2).
    pub initial_sigma: f32,
    /// Lower bound of a Gaussian's standard deviation, grey levels (4/255 as MOG2): sensor
    /// noise never goes below it, and it keeps a static scene from matching nothing.
    pub min_sigma: f32,
    /// Pixels darker than a background Gaussian by a ratio in this range are shadows, not
    /// foreground (Prati et al. 2003 on the brightness ratio); `None` (the default): no
    /// shadow test. On grey frames the ratio alone also takes dark clothes for shadows: on
    /// PETS 2009, `[0.5, 0.9]` found 2.9 points fewer people.
    pub shadow_ratio: Option<[f32; 2]>,
}

impl Default for MixtureParams {
    fn default() -> Self {
        Self {
            gaussians: 3,
            history: 200,
            bootstrap_frames: 200,
            match_sigmas: 2.5,
            background_ratio: 0.6,
            initial_sigma: 15.0 / 255.0,
            min_sigma: 4.0 / 255.0,
            shadow_ratio: None,
        }
    }
}

impl MixtureParams {
    /// Checks every value; errors name the key and the accepted range.
    pub fn validate(&self) -> Result<()> {
        let check = |ok: bool, key: &str, value: String, range: &str| {
            if ok {
                Ok(())
            } else {
                Err(Error::parameter(key, value, range))
            }
        };
        check(
            (1..=MAX_GAUSSIANS).contains(&self.gaussians),
            "gaussians",
            self.gaussians.to_string(),
            "1 to 8 Gaussians per pixel",
        )?;
        check(
            self.history >= 1,
            "history",
            self.history.to_string(),
            "at least 1 frame",
        )?;
        check(
            self.match_sigmas.is_finite() && self.match_sigmas > 0.0,
            "match_sigmas",
            self.match_sigmas.to_string(),
            "a positive number of standard deviations (2.5 is usual)",
        )?;
        check(
            self.background_ratio > 0.0 && self.background_ratio <= 1.0,
            "background_ratio",
            self.background_ratio.to_string(),
            "a share of the weight in (0, 1]",
        )?;
        check(
            self.min_sigma.is_finite() && self.min_sigma > 0.0,
            "min_sigma",
            self.min_sigma.to_string(),
            "a positive grey-level spread (4/255 is usual)",
        )?;
        check(
            self.initial_sigma.is_finite() && self.initial_sigma >= self.min_sigma,
            "initial_sigma",
            self.initial_sigma.to_string(),
            "a grey-level spread at least min_sigma",
        )?;
        if let Some([low, high]) = self.shadow_ratio {
            check(
                low.is_finite() && high.is_finite() && 0.0 < low && low < high && high < 1.0,
                "shadow_ratio",
                format!("[{low}, {high}]"),
                "two brightness ratios 0 < low < high < 1, e.g. [0.5, 0.9]",
            )?;
        }
        Ok(())
    }
}

/// The mixture model of every pixel of a frame size, updated frame by frame.
#[derive(Debug, Clone)]
pub struct MixtureBackground {
    params: MixtureParams,
    width: usize,
    height: usize,
    /// Per pixel, `K` Gaussians in order: weight, mean, variance (pixel-major).
    gaussians: Vec<[f32; 3]>,
    /// Frames seen.
    frames: u64,
}

impl MixtureBackground {
    /// An empty model of `width × height` frames (every pixel foreground until it has been
    /// seen).
    pub fn new(params: &MixtureParams, width: usize, height: usize) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            params: params.clone(),
            width,
            height,
            gaussians: vec![[0.0; 3]; width * height * params.gaussians],
            frames: 0,
        })
    }

    /// Frames the model has seen.
    pub fn frames_seen(&self) -> u64 {
        self.frames
    }

    /// Learns `frame` and labels its pixels into `labels` ([`BACKGROUND`], [`SHADOW`],
    /// [`FOREGROUND`]); parallel over rows, the same result for any thread count.
    pub fn apply(&mut self, frame: &GrayImage, labels: &mut Image<u8>) -> Result<()> {
        if frame.dimensions() != (self.width, self.height) {
            return Err(Error::input(format!(
                "a {}×{} frame after {}×{} ones; every frame of a sequence must have the same \
                 size",
                frame.width(),
                frame.height(),
                self.width,
                self.height
            )));
        }
        labels.reshape(self.width, self.height);
        // α = 1/(t + 1) during the start-up (a running mean, never below 1/history), then
        // α = 1/history.
        let alpha = if self.frames < self.params.bootstrap_frames as u64 {
            1.0 / (self.frames + 1).min(self.params.history as u64) as f32
        } else {
            1.0 / self.params.history as f32
        };
        let first = self.frames == 0;
        let k = self.params.gaussians;
        let params = &self.params;
        let row_len = self.width;
        self.gaussians
            .par_chunks_mut(row_len * k)
            .zip(labels.as_mut_slice().par_chunks_mut(row_len))
            .zip(frame.as_slice().par_chunks(row_len))
            .for_each(|((model_row, label_row), pixel_row)| {
                for ((pixel, label), &value) in model_row
                    .chunks_exact_mut(k)
                    .zip(label_row.iter_mut())
                    .zip(pixel_row)
                {
                    *label = if first {
                        start_pixel(pixel, value, params);
                        FOREGROUND
                    } else {
                        update_pixel(pixel, value, alpha, params)
                    };
                }
            });
        self.frames += 1;
        Ok(())
    }
}

/// The first value of a pixel: one Gaussian of weight 1 at it.
fn start_pixel(pixel: &mut [[f32; 3]], value: f32, params: &MixtureParams) {
    pixel.fill([0.0, 0.0, params.initial_sigma * params.initial_sigma]);
    pixel[0] = [1.0, value, params.initial_sigma * params.initial_sigma];
}

/// Learns `value` into the Gaussians of one pixel (sorted by `w/σ`) and labels it.
fn update_pixel(pixel: &mut [[f32; 3]], value: f32, alpha: f32, params: &MixtureParams) -> u8 {
    let min_var = params.min_sigma * params.min_sigma;
    let lambda2 = params.match_sigmas * params.match_sigmas;
    // The label comes from the model before this value is learnt.
    let mut cumulative = 0.0;
    let mut matched = None;
    let mut background_count = pixel.len();
    for (i, &[w, mean, var]) in pixel.iter().enumerate() {
        if matched.is_none() && w > 0.0 && (value - mean) * (value - mean) <= lambda2 * var {
            matched = Some(i);
        }
        cumulative += w;
        if cumulative >= params.background_ratio && background_count == pixel.len() {
            background_count = i + 1;
        }
    }
    let label = match matched {
        Some(i) if i < background_count => BACKGROUND,
        _ if is_shadow(&pixel[..background_count], value, params) => SHADOW,
        _ => FOREGROUND,
    };
    for g in pixel.iter_mut() {
        g[0] *= 1.0 - alpha;
    }
    match matched {
        Some(i) => {
            let g = &mut pixel[i];
            g[0] += alpha;
            let rho = (alpha / g[0]).min(1.0);
            let d = value - g[1];
            g[1] += rho * d;
            g[2] = (g[2] + rho * (d * d - g[2])).max(min_var);
        }
        None => {
            let last = pixel.len() - 1;
            pixel[last] = [alpha, value, params.initial_sigma * params.initial_sigma];
        }
    }
    let total: f32 = pixel.iter().map(|g| g[0]).sum();
    for g in pixel.iter_mut() {
        g[0] /= total;
    }
    sort_by_fitness(pixel);
    label
}

/// Whether `value` is a shadow on one of the background Gaussians: darker by a brightness
/// ratio inside the shadow range.
fn is_shadow(background: &[[f32; 3]], value: f32, params: &MixtureParams) -> bool {
    let Some([low, high]) = params.shadow_ratio else {
        return false;
    };
    background.iter().any(|&[w, mean, _]| {
        w > 0.0 && mean > params.min_sigma && (low..high).contains(&(value / mean))
    })
}

/// Insertion sort by `w/σ`, largest first (stable: ties keep their order). Each Gaussian's
/// `w/σ` is taken once, not at every comparison.
fn sort_by_fitness(pixel: &mut [[f32; 3]]) {
    let mut fitness = [0f32; MAX_GAUSSIANS];
    for (f, g) in fitness.iter_mut().zip(pixel.iter()) {
        *f = g[0] / g[2].sqrt();
    }
    for i in 1..pixel.len() {
        let mut j = i;
        while j > 0 && fitness[j] > fitness[j - 1] {
            pixel.swap(j, j - 1);
            fitness.swap(j, j - 1);
            j -= 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(width: usize, height: usize, level: impl Fn(usize, usize) -> f32) -> GrayImage {
        let data = (0..width * height)
            .map(|i| level(i % width, i / width))
            .collect();
        GrayImage::from_vec(width, height, data).unwrap()
    }

    /// Deterministic noise in `[-amplitude, amplitude]`.
    fn noise(seed: u64, amplitude: f32) -> f32 {
        let h = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((h >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0) * amplitude
    }

    #[test]
    fn a_static_noisy_scene_becomes_background_and_a_square_is_foreground() {
        let (w, h) = (40, 30);
        let params = MixtureParams {
            shadow_ratio: Some([0.5, 0.9]),
            ..MixtureParams::default()
        };
        let mut model = MixtureBackground::new(&params, w, h).unwrap();
        let mut labels = Image::new(w, h);
        for t in 0..30u64 {
            let f = frame(w, h, |x, y| {
                0.5 + noise(t * 10_000 + (y * w + x) as u64, 0.01)
            });
            model.apply(&f, &mut labels).unwrap();
        }
        assert!(labels.as_slice().iter().all(|&l| l == BACKGROUND));
        // A bright square: foreground; a darker patch (ratio 0.7): shadow.
        let f = frame(w, h, |x, y| match (x, y) {
            (5..15, 5..15) => 0.95,
            (20..30, 5..15) => 0.35,
            _ => 0.5,
        });
        model.apply(&f, &mut labels).unwrap();
        assert_eq!(labels.get(10, 10), FOREGROUND);
        assert_eq!(labels.get(25, 10), SHADOW);
        assert_eq!(labels.get(2, 25), BACKGROUND);
        let foreground = labels
            .as_slice()
            .iter()
            .filter(|&&l| l == FOREGROUND)
            .count();
        assert_eq!(foreground, 100);
    }

    /// Frames of an object parked at frame `warm_frames` (grey 0.8 on a static 0.2 scene)
    /// until its pixels join the background; 400 if they never do.
    fn frames_to_absorb(params: &MixtureParams, warm_frames: usize) -> usize {
        let (w, h) = (4, 4);
        let mut model = MixtureBackground::new(params, w, h).unwrap();
        let mut labels = Image::new(w, h);
        for _ in 0..warm_frames {
            model.apply(&frame(w, h, |_, _| 0.2), &mut labels).unwrap();
        }
        let parked = frame(w, h, |_, _| 0.8);
        let mut frames = 0;
        loop {
            model.apply(&parked, &mut labels).unwrap();
            frames += 1;
            if labels.get(0, 0) == BACKGROUND || frames == 400 {
                return frames;
            }
        }
    }

    #[test]
    fn an_object_that_stays_is_learnt_into_the_background() {
        let params = MixtureParams {
            history: 20,
            background_ratio: 0.7,
            ..MixtureParams::default()
        };
        let frames = frames_to_absorb(&params, 30);
        // The new Gaussian joins the background once the old one's weight (1 − α)^n falls
        // below T: n = ln T / ln(1 − α) ≈ 7 frames at α = 1/20, T = 0.7.
        assert!((6..10).contains(&frames), "{frames}");
    }

    #[test]
    fn a_short_start_up_keeps_a_stopped_object_in_the_foreground_longer() {
        let absorbed_after = |bootstrap_frames: usize| {
            let params = MixtureParams {
                bootstrap_frames,
                ..MixtureParams::default()
            };
            frames_to_absorb(&params, 30)
        };
        // Running mean from frame 30: the old Gaussian's weight 30/(30 + n) falls below
        // T = 0.6 after n = 21 frames; at α = 1/200, (1 − α)^n after n = 102.
        let (long, short) = (absorbed_after(200), absorbed_after(10));
        assert!((18..25).contains(&long), "{long}");
        assert!((95..110).contains(&short), "{short}");
    }

    #[test]
    fn bad_parameters_and_sizes_are_refused() {
        let bad = [
            MixtureParams {
                gaussians: 0,
                ..MixtureParams::default()
            },
            MixtureParams {
                background_ratio: 1.5,
                ..MixtureParams::default()
            },
            MixtureParams {
                shadow_ratio: Some([0.9, 0.5]),
                ..MixtureParams::default()
            },
            MixtureParams {
                min_sigma: 0.0,
                ..MixtureParams::default()
            },
        ];
        for params in bad {
            assert!(MixtureBackground::new(&params, 4, 4).is_err(), "{params:?}");
        }
        let mut model = MixtureBackground::new(&MixtureParams::default(), 4, 4).unwrap();
        let mut labels = Image::new(4, 4);
        let error = model
            .apply(&GrayImage::new(5, 4), &mut labels)
            .unwrap_err()
            .to_string();
        assert!(error.contains("5×4") && error.contains("4×4"), "{error}");
    }
}

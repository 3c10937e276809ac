//! Backlit side views of the synthetic bedload scene that look like the frames of the MMPF+
//! paper's flume (Lafaye de Micheaux, Ducottet & Frey 2018, §2, §3.3.1, Fig. 2): a bright
//! backlight, opaque black beads, transparent beads seen as faint dark rims around a bright
//! centre, camera noise, 8-bit grey levels.
//!
//! The image is a backlit 2-D projection (the paper's flume is 6.5 mm wide, one bead thick):
//! 1. the backlight `B(x, y)`: a plane (level and gradients) times a static pattern;
//! 2. the transparent beads, back to front in a depth order drawn once per bead: each one
//!    replaces what lies behind it, inside its outline, by the backlight (times
//!    `transparent_opacity`: a ball lens images the backlight, not the bead behind it), then
//!    multiplies it by its transmission (a bright body, a dark rim). So a bead partly behind
//!    another loses the covered part of its rim: the paper's "faint dark rings of different
//!    shapes because of their neighbouring configurations". Each bead's rim has its own
//!    darkness, blur, radius and angular irregularity, drawn from its track id (the same in
//!    every frame, as a real bead's);
//! 3. the black beads, over everything (they are opaque: they hide a transparent bead from
//!    behind as well as from in front);
//! 4. white Gaussian noise (drawn among 2¹⁶ quantiles of N(0, 1), 16 random bits a pixel,
//!    which is 3 times faster than exact draws), clipping to `[0, 1]` and rounding to the
//!    sensor's grey levels.
//!
//! Every profile is a function of the distance to the bead centre with Gaussian-blurred
//! edges, sampled at pixel centres (so edges are anti-aliased). See [`BedloadRenderParams`]
//! for the profiles and the measurements on the real frames behind their defaults.
//!
//! Not rendered: the free surface and the flume base of the real frames, motion blur,
//! the refraction of neighbouring beads through transparent ones.
//!
//! ```
//! use sillage_core::GrayImage;
//! use sillage_synth::{BedloadRenderParams, BedloadRenderer, BedloadScene, BedloadSceneParams};
//!
//! let scene = BedloadScene::new(BedloadSceneParams { n_frames: 2, ..Default::default() })?;
//! let mut renderer = BedloadRenderer::new(BedloadRenderParams::default())?;
//! let mut image = GrayImage::new(1280, 320);
//! for frame in scene {
//!     renderer.render(&frame, &mut image);
//! }
//! // The backlight above the bed, black inside a bed bead (the bottom-left one).
//! assert!((image.get(640, 20) - 0.85).abs() < 0.05);
//! assert!(image.get(15, 304) < 0.02);
//! # Ok::<(), sillage_core::Error>(())
//! ```

use rand::RngExt;
use rand_distr::StandardNormal;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sillage_core::{BLACK_BEAD_CLASS, Error, GrayImage, Point2, Result, TrackId, rng_stream};

use super::BedloadFrame;
use super::params::check;

/// Stream of the static illumination pattern (seed only: the same in every frame).
const STREAM_PATTERN: u64 = 0xBED0_0101;
/// Stream of the per-frame noise (then one stream per frame index, one per band of rows).
const STREAM_NOISE: u64 = 0xBED0_0102;
/// Stream of the looks of the transparent beads (then one stream per track id).
const STREAM_LOOK: u64 = 0xBED0_0103;
/// Rows per band: the unit of parallel work and of noise streams (fixed, so that the image
/// does not depend on the number of threads).
const BAND_ROWS: usize = 16;
/// Outlines are tabulated against the squared distance to the centre in steps of this many
/// px² (0.004 px in distance at 15 px).
const LUT_STEP_PX2: f64 = 0.125;
/// Edges and rim flanks are drawn out to this many standard deviations.
const REACH_SIGMAS: f64 = 4.0;
/// Per-bead draws (blur factor, rim radius) are clipped to this many standard deviations.
const SPREAD_SIGMAS: f64 = 3.0;
/// Number of quantiles of N(0, 1) the noise is drawn from (16 random bits a pixel).
const NORMAL_QUANTILES: usize = 1 << 16;
/// Largest bead radius accepted, px.
const MAX_RADIUS_PX: f64 = 200.0;
/// Largest blur of an edge or rim flank accepted, px.
const MAX_SIGMA_PX: f64 = 20.0;

/// How the synthetic bedload frames look. Grey levels are in `[0, 1]` (8-bit / 255),
/// distances in px. The defaults imitate the ten real frames of the paper's authors
/// (`shared/data/bedload_beads_lafaye2018`, 2.056e-4 m/px), measured against their hand-made
/// ground truth: least-squares fits of the mean radial profiles of the black beads (265 in
/// frame 1) and of the transparent beads away from any other bead (42 in frame 1), their
/// centres refined to 1/8 px by fitting that profile; per-bead fits of 173 such transparent
/// profiles in the ten frames for the spreads; the bead-free pixels for the backlight and
/// the noise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BedloadRenderParams {
    /// Backlight grey level at the centre of the frame, in `[0.001, 1]` (default 0.85:
    /// 217/255, the mean bead-free pixel of the real frames).
    pub background_level: f64,
    /// Backlight change from the left edge to the right edge, in `[−1, 1]` (default 0.055:
    /// the bead-free pixels above the bed go from 208/255 on the left to 222/255 on the right).
    pub background_gradient_x: f64,
    /// Backlight change from the top edge to the bottom edge, in `[−1, 1]` (default 0: no
    /// trend down the real frames).
    pub background_gradient_y: f64,
    /// Standard deviation of the static pixel-to-pixel variation of the backlight (dust,
    /// sensor pattern), relative to it, in `[0, 0.5]`; drawn once from `seed`, the same in
    /// every frame (default 0.0086: the real bead-free pixels deviate by 2.25/255 from their
    /// local mean, of which 1.28/255 is the per-frame noise, and 1.85/217 is left).
    pub illumination_sigma: f64,
    /// Share of that variation's variance which is spatially correlated, in `[0, 1]` (default
    /// 0.3: the real bead-free pixels correlate by 0.17, 0.11 and 0.07 with their neighbours
    /// 1, 2 and 3 px away).
    pub illumination_correlated_fraction: f64,
    /// Correlation length of that share: the standard deviation of the Gaussian that blurs
    /// white noise into it, px, in `[0, 20]` (default 1.5).
    pub illumination_correlation_px: f64,
    /// Standard deviation of the white Gaussian noise drawn anew for every frame, in
    /// `[0, 0.5]` (default 0.005: the real frames' differences from one frame to the next
    /// have a standard deviation of 1.81/255, i.e. 1.28/255 per frame).
    pub noise_sigma: f64,
    /// Radius of the black beads where their edge crosses half the backlight, px, in
    /// `[0.5, 200]` (default 14.0: the fit gives 13.98; their 6 mm are 29.2 px across, which
    /// the scene rounds to a 15-px radius).
    pub black_radius_px: f64,
    /// Grey level inside the black beads before noise, in `[−0.1, 1)`; below 0 is the
    /// sensor's black offset, clipped to 0 like the real camera's (default −0.006: 94 % of
    /// the real beads' pixels within 10 px of their centre read 0).
    pub black_level: f64,
    /// Blur of the bead outlines (the optics' point-spread function), a Gaussian standard
    /// deviation in `[0, 20]` px; it also anti-aliases them (default 0.83, the fit of the
    /// black edges).
    pub edge_sigma_px: f64,
    /// Radius of the outline of the transparent beads, px, in `[0.5, 200]` (default 10.4,
    /// the fit; 4 mm are 19.5 px across).
    pub transparent_radius_px: f64,
    /// Transmission of a transparent bead's body (its bright centre), in `[0, 1]` (default
    /// 0.95, the fit: 204/214 at the centre of the real beads).
    pub centre_transmission: f64,
    /// Radius of the darkest point of a transparent bead's rim, px, in
    /// `(0, transparent_radius_px]` (default 8.7, the fit).
    pub ring_radius_px: f64,
    /// Transmission at the darkest point of the rim, in `[0, centre_transmission]` (default
    /// 0.59, the fit: 126/214 in the real beads' mean profile).
    pub ring_transmission: f64,
    /// Gaussian width of the rim towards the centre, px, in `(0, 20]` (default 1.65, the fit:
    /// the real rims darken slowly from 4 px out).
    pub ring_inner_sigma_px: f64,
    /// Gaussian width of the rim outwards, px, in `(0, 20]` (default 0.95, the fit).
    pub ring_outer_sigma_px: f64,
    /// Spread across beads of the rim's blur, in `[0, 1]`: each bead's rim widths are
    /// multiplied, and its darkening divided, by `exp(spread · N(0, 1))`, as beads away from
    /// the focal plane across the flume's width are blurred (default 0.13: the per-bead fits'
    /// outer widths go from 0.79 to 1.23 times their median, 5th to 95th percentile, and the
    /// fainter rims are the wider ones).
    pub ring_blur_spread: f64,
    /// Standard deviation across beads of the rim's darkening, on top of the blur's, in
    /// `[0, 0.5]` (default 0.03: the per-bead fits' darkening goes from 0.26 to 0.40).
    pub ring_transmission_spread: f64,
    /// Standard deviation across beads of the rim's radius, px, in `[0, 5]` (default 0.2: the
    /// per-bead fits go from 8.5 to 9.2 px).
    pub ring_radius_spread_px: f64,
    /// Relative change of the rim's darkening around the bead (first angular harmonic), in
    /// `[0, 1]`: darker by this fraction on one side, lighter on the other (default 0.28, the
    /// median over 25 transparent beads of frame 1 away from any other bead).
    pub ring_asymmetry: f64,
    /// Relative change of the rim's darkening at twice the angular frequency, about an axis
    /// drawn per bead, in `[0, 1]` (default 0.08: the real rims' second harmonic, 0.11, less
    /// the 0.07 that noise alone gives on the rendered rims).
    pub ring_ellipticity: f64,
    /// Direction of the darkest side of the rims, degrees from +x towards +y (down), in
    /// `[−360, 360]` (default −100: the darkest eighth of the real rims is one of the top two
    /// for 111 of 173 beads).
    pub ring_dark_side_deg: f64,
    /// Standard deviation across beads of that direction, degrees, in `[0, 360]` (default 40).
    pub ring_dark_side_spread_deg: f64,
    /// How much of what lies behind a transparent bead, inside its outline, it hides, in
    /// `[0, 1]`: 1 shows the backlight through it (a ball lens), 0 stacks the transmissions
    /// of overlapping beads (both rims show across each other). Default 1: with it, the rims
    /// of the real frames' ground truth rendered are as hard to detect as the real ones.
    pub transparent_opacity: f64,
    /// Grey levels of the sensor: values are rounded to multiples of `1/levels`, 0 or
    /// `1..=65535` (default 255, an 8-bit camera as the paper's; 65535 for 16 bits; 0 leaves
    /// them unrounded).
    pub levels: u32,
    /// Seed of the illumination pattern, the noise and the beads' looks (default 0). The noise
    /// of a frame depends on the seed and the frame index only, the look of a bead on the
    /// seed and its track id only.
    pub seed: u64,
}

impl Default for BedloadRenderParams {
    fn default() -> Self {
        Self {
            background_level: 0.85,
            background_gradient_x: 0.055,
            background_gradient_y: 0.0,
            illumination_sigma: 0.0086,
            illumination_correlated_fraction: 0.3,
            illumination_correlation_px: 1.5,
            noise_sigma: 0.005,
            black_radius_px: 14.0,
            black_level: -0.006,
            edge_sigma_px: 0.83,
            transparent_radius_px: 10.4,
            centre_transmission: 0.95,
            ring_radius_px: 8.7,
            ring_transmission: 0.59,
            ring_inner_sigma_px: 1.65,
            ring_outer_sigma_px: 0.95,
            ring_blur_spread: 0.13,
            ring_transmission_spread: 0.03,
            ring_radius_spread_px: 0.2,
            ring_asymmetry: 0.28,
            ring_ellipticity: 0.08,
            ring_dark_side_deg: -100.0,
            ring_dark_side_spread_deg: 40.0,
            transparent_opacity: 1.0,
            levels: 255,
            seed: 0,
        }
    }
}

impl BedloadRenderParams {
    /// Checks every value; the error names the key and its allowed range.
    pub fn validate(&self) -> Result<()> {
        check("background_level", self.background_level, 1e-3, 1.0)?;
        check(
            "background_gradient_x",
            self.background_gradient_x,
            -1.0,
            1.0,
        )?;
        check(
            "background_gradient_y",
            self.background_gradient_y,
            -1.0,
            1.0,
        )?;
        let lowest = self.background_level
            - 0.5 * (self.background_gradient_x.abs() + self.background_gradient_y.abs());
        if lowest <= 0.0 {
            return Err(Error::parameter(
                "background_gradient_x",
                self.background_gradient_x,
                format!(
                    "with `background_gradient_y` = {} and `background_level` = {} the \
                     backlight falls to {lowest:.3} in a corner; it must stay above 0 (lower \
                     the gradients or raise the level)",
                    self.background_gradient_y, self.background_level
                ),
            ));
        }
        check("illumination_sigma", self.illumination_sigma, 0.0, 0.5)?;
        check(
            "illumination_correlated_fraction",
            self.illumination_correlated_fraction,
            0.0,
            1.0,
        )?;
        check(
            "illumination_correlation_px",
            self.illumination_correlation_px,
            0.0,
            MAX_SIGMA_PX,
        )?;
        check("noise_sigma", self.noise_sigma, 0.0, 0.5)?;
        check("black_radius_px", self.black_radius_px, 0.5, MAX_RADIUS_PX)?;
        if !(self.black_level.is_finite() && (-0.1..1.0).contains(&self.black_level)) {
            return Err(Error::parameter(
                "black_level",
                self.black_level,
                "must be a finite number in [−0.1, 1)",
            ));
        }
        check("edge_sigma_px", self.edge_sigma_px, 0.0, MAX_SIGMA_PX)?;
        check(
            "transparent_radius_px",
            self.transparent_radius_px,
            0.5,
            MAX_RADIUS_PX,
        )?;
        check("centre_transmission", self.centre_transmission, 0.0, 1.0)?;
        positive_up_to(
            "ring_radius_px",
            self.ring_radius_px,
            self.transparent_radius_px,
        )?;
        check(
            "ring_transmission",
            self.ring_transmission,
            0.0,
            self.centre_transmission,
        )?;
        positive_up_to(
            "ring_inner_sigma_px",
            self.ring_inner_sigma_px,
            MAX_SIGMA_PX,
        )?;
        positive_up_to(
            "ring_outer_sigma_px",
            self.ring_outer_sigma_px,
            MAX_SIGMA_PX,
        )?;
        check("ring_blur_spread", self.ring_blur_spread, 0.0, 1.0)?;
        check(
            "ring_transmission_spread",
            self.ring_transmission_spread,
            0.0,
            0.5,
        )?;
        check(
            "ring_radius_spread_px",
            self.ring_radius_spread_px,
            0.0,
            5.0,
        )?;
        check("ring_asymmetry", self.ring_asymmetry, 0.0, 1.0)?;
        check("ring_ellipticity", self.ring_ellipticity, 0.0, 1.0)?;
        check("ring_dark_side_deg", self.ring_dark_side_deg, -360.0, 360.0)?;
        check(
            "ring_dark_side_spread_deg",
            self.ring_dark_side_spread_deg,
            0.0,
            360.0,
        )?;
        check("transparent_opacity", self.transparent_opacity, 0.0, 1.0)?;
        if self.levels > 65_535 {
            return Err(Error::parameter(
                "levels",
                self.levels,
                "must be 0 (no rounding) or in 1..=65535 (255 for 8 bits, 65535 for 16)",
            ));
        }
        Ok(())
    }
}

/// `value` must be finite and in `(0, high]`.
fn positive_up_to(key: &str, value: f64, high: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 && value <= high {
        Ok(())
    } else {
        let message = format!("must be a finite number in (0, {high}]");
        Err(Error::parameter(key, value, message))
    }
}

/// A radial profile tabulated against the squared distance to the centre (no square root
/// per pixel), linearly interpolated.
#[derive(Debug, Clone)]
struct Profile {
    /// Values at `d² = k · LUT_STEP_PX2`, `k = 0..len`; those within 1e-6 of 0 or 1 are
    /// exactly 0 or 1.
    values: Vec<f32>,
    /// Squared distance up to which the profile is exactly 1, px².
    full_px2: f64,
}

impl Profile {
    /// `f(d)` tabulated out to `reach_px` (and a step beyond).
    fn tabulate(reach_px: f64, f: impl Fn(f64) -> f64) -> Self {
        let len = (reach_px * reach_px / LUT_STEP_PX2).ceil() as usize + 2;
        let values: Vec<f32> = (0..len)
            .map(|k| {
                let v = f((k as f64 * LUT_STEP_PX2).sqrt());
                if (v - 1.0).abs() < 1e-6 {
                    1.0
                } else if v.abs() < 1e-6 {
                    0.0
                } else {
                    v as f32
                }
            })
            .collect();
        let ones = values.iter().take_while(|&&v| v == 1.0).count();
        Self {
            values,
            full_px2: ones.saturating_sub(1) as f64 * LUT_STEP_PX2,
        }
    }

    /// The profile at squared distance `d2`, which must be within the tabulated reach.
    #[inline]
    fn at(&self, d2: f64) -> f32 {
        let t = d2 / LUT_STEP_PX2;
        let k = t as usize;
        let frac = (t - k as f64) as f32;
        let (a, b) = (self.values[k], self.values[k + 1]);
        a + (b - a) * frac
    }
}

/// The look of one transparent bead, the same in every frame: it is drawn from the seed and
/// the bead's track id only.
#[derive(Debug, Clone, Copy)]
struct Look {
    /// Index of the bead in the frame being rendered.
    index: usize,
    /// Painter's order: beads with a larger key are in front.
    depth_key: u64,
    /// `centre_transmission` minus this bead's rim transmission.
    ring_depth: f32,
    /// Radius of its rim's darkest point, px.
    ring_radius: f32,
    /// `1 / 2σ²` of its rim towards the centre, px⁻².
    ring_inner_scale: f32,
    /// `1 / 2σ²` of its rim outwards, px⁻².
    ring_outer_scale: f32,
    /// Unit vector towards the darkest side of its rim.
    dark_side: (f32, f32),
    /// Unit vector along the axis of its rim's second harmonic.
    axis: (f32, f32),
}

/// Renders [`BedloadFrame`]s: parameters validated and outlines tabulated once, the static
/// illumination pattern drawn once per frame size, buffers reused. Deterministic: the same
/// frame, bit for bit, whatever the number of threads.
#[derive(Debug, Clone)]
pub struct BedloadRenderer {
    params: BedloadRenderParams,
    /// Outline of a transparent bead: 1 inside, 0 outside, blurred edge.
    transparent_cover: Profile,
    /// `(reach², reach)` beyond which a transparent bead leaves a pixel alone, px.
    transparent_reach: (f64, f64),
    /// Outline of a black bead.
    black_cover: Profile,
    /// The same reach for black beads.
    black_reach: (f64, f64),
    /// Seed of the per-bead looks, from `seed`.
    look_seed: u64,
    /// Seed of the per-frame noise, from `seed`.
    noise_seed: u64,
    /// The backlight of the last frame size (plane times static pattern).
    light: GrayImage,
    /// The transparent beads of the frame being rendered, back to front.
    looks: Vec<Look>,
    /// `NORMAL_QUANTILES` quantiles of N(0, 1), scaled to unit variance: the noise.
    normal_quantiles: Vec<f32>,
    /// `k / levels` for `k = 0..=levels` (empty when `levels` = 0).
    levels: Vec<f32>,
}

impl BedloadRenderer {
    /// A renderer for `params`; fails on invalid parameters, naming the key.
    pub fn new(params: BedloadRenderParams) -> Result<Self> {
        params.validate()?;
        let p = &params;
        let widest_rim = p.ring_outer_sigma_px * (SPREAD_SIGMAS * p.ring_blur_spread).exp();
        let transparent_reach = (p.transparent_radius_px + REACH_SIGMAS * p.edge_sigma_px)
            .max(p.transparent_radius_px + REACH_SIGMAS * widest_rim)
            + 1.0;
        let transparent_cover = Profile::tabulate(transparent_reach, |d| {
            step(p.transparent_radius_px - d, p.edge_sigma_px)
        });
        let black_reach = p.black_radius_px + REACH_SIGMAS * p.edge_sigma_px + 1.0;
        let black_cover = Profile::tabulate(black_reach, |d| {
            step(p.black_radius_px - d, p.edge_sigma_px)
        });
        let levels = match p.levels {
            0 => Vec::new(),
            n => (0..=n).map(|k| k as f32 / n as f32).collect(),
        };
        Ok(Self {
            look_seed: rng_stream(p.seed, STREAM_LOOK).random(),
            noise_seed: rng_stream(p.seed, STREAM_NOISE).random(),
            params,
            transparent_cover,
            transparent_reach: (transparent_reach.powi(2), transparent_reach),
            black_cover,
            black_reach: (black_reach.powi(2), black_reach),
            light: GrayImage::default(),
            looks: Vec::new(),
            normal_quantiles: normal_quantiles(),
            levels,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &BedloadRenderParams {
        &self.params
    }

    /// Renders the beads of `frame` into `out`, whose size is the frame's (`out` is
    /// overwritten; an empty `out` gets nothing). The noise depends on the seed and
    /// `frame.index` only, the look of each transparent bead on the seed and its track id.
    pub fn render(&mut self, frame: &BedloadFrame, out: &mut GrayImage) {
        let (width, height) = out.dimensions();
        if width == 0 || height == 0 {
            return;
        }
        if self.light.dimensions() != (width, height) {
            self.light = backlight(width, height, &self.params);
        }
        let mut looks = std::mem::take(&mut self.looks);
        looks.clear();
        looks.extend(
            frame
                .beads
                .iter()
                .enumerate()
                .filter(|(_, bead)| bead.class != BLACK_BEAD_CLASS)
                .map(|(index, bead)| self.look(index, bead.track_id)),
        );
        looks.sort_by_key(|look| (look.depth_key, look.index));
        let frame_seed: u64 = rng_stream(self.noise_seed, frame.index).random();
        let this = &*self;
        out.as_mut_slice()
            .par_chunks_mut(BAND_ROWS * width)
            .zip(this.light.as_slice().par_chunks(BAND_ROWS * width))
            .enumerate()
            .for_each(|(band, (pixels, light))| {
                let band = Band {
                    width,
                    y0: band * BAND_ROWS,
                    light,
                };
                this.render_band(frame, &looks, &band, pixels, frame_seed);
            });
        self.looks = looks;
    }

    /// The look of the transparent bead `track_id`, at `index` in the frame.
    fn look(&self, index: usize, track_id: TrackId) -> Look {
        let p = &self.params;
        let mut rng = rng_stream(self.look_seed, track_id);
        let depth_key: u64 = rng.random();
        let mut normal = || -> f64 {
            let z: f64 = rng.sample(StandardNormal);
            z.clamp(-SPREAD_SIGMAS, SPREAD_SIGMAS)
        };
        let (blur, darkening, radius, turn) = (normal(), normal(), normal(), normal());
        let axis = std::f64::consts::PI * rng.random::<f64>();
        // Out of focus, a rim is wider and fainter, about as dark in all.
        let blur = (p.ring_blur_spread * blur).exp();
        let depth = ((p.centre_transmission - p.ring_transmission) / blur
            + p.ring_transmission_spread * darkening)
            .clamp(0.0, p.centre_transmission);
        let ring_radius = (p.ring_radius_px + p.ring_radius_spread_px * radius)
            .clamp(0.5 * p.ring_radius_px, p.transparent_radius_px);
        let scale = |sigma: f64| (0.5 / (sigma * blur).powi(2)) as f32;
        let angle = (p.ring_dark_side_deg + p.ring_dark_side_spread_deg * turn).to_radians();
        Look {
            index,
            depth_key,
            ring_depth: depth as f32,
            ring_radius: ring_radius as f32,
            ring_inner_scale: scale(p.ring_inner_sigma_px),
            ring_outer_scale: scale(p.ring_outer_sigma_px),
            dark_side: (angle.cos() as f32, angle.sin() as f32),
            axis: (axis.cos() as f32, axis.sin() as f32),
        }
    }

    /// One band of rows: backlight, transparent beads back to front, black beads, noise.
    fn render_band(
        &self,
        frame: &BedloadFrame,
        looks: &[Look],
        band: &Band<'_>,
        pixels: &mut [f32],
        frame_seed: u64,
    ) {
        let p = &self.params;
        pixels.copy_from_slice(band.light);
        let opacity = p.transparent_opacity as f32;
        let body_loss = (1.0 - p.centre_transmission) as f32;
        let (asymmetry, ellipticity) = (p.ring_asymmetry as f32, p.ring_ellipticity as f32);
        for look in looks {
            let centre = frame.beads[look.index].pos_px;
            let ((ux, uy), (ax, ay)) = (look.dark_side, look.axis);
            let draw = |x: usize, y: usize, d2: f64, v: &mut f32, light: f32| {
                let cover = self.transparent_cover.at(d2);
                let d = d2.sqrt() as f32;
                let off = d - look.ring_radius;
                let scale = if off < 0.0 {
                    look.ring_inner_scale
                } else {
                    look.ring_outer_scale
                };
                // cos θ from the dark side, cos 2θ from the axis.
                let (dx, dy) = ((x as f64 - centre.x) as f32, (y as f64 - centre.y) as f32);
                let (cos1, cos2) = if d > 1e-6 {
                    let along = (dx * ax + dy * ay) / d;
                    ((dx * ux + dy * uy) / d, 2.0 * along * along - 1.0)
                } else {
                    (0.0, 0.0)
                };
                let rim = look.ring_depth
                    * (-off * off * scale).exp()
                    * (1.0 + asymmetry * cos1 + ellipticity * cos2);
                let transmission = (1.0 - body_loss * cover - rim).clamp(0.0, 1.0);
                let hidden = opacity * cover;
                *v = transmission * (hidden * light + (1.0 - hidden) * *v);
            };
            each_pixel(centre, self.transparent_reach, band, pixels, draw);
        }
        for bead in frame.beads.iter().filter(|b| b.class == BLACK_BEAD_CLASS) {
            self.draw_black(bead.pos_px, band, pixels);
        }
        // Noise: quantiles of N(0, 1) picked by 16 random bits each.
        let sigma = p.noise_sigma as f32;
        if sigma > 0.0 {
            let mut rng = rng_stream(frame_seed, (band.y0 / BAND_ROWS) as u64);
            for chunk in pixels.chunks_mut(4) {
                let mut bits: u64 = rng.random();
                for v in chunk {
                    *v += sigma * self.normal_quantiles[(bits & 0xFFFF) as usize];
                    bits >>= 16;
                }
            }
        }
        for v in pixels.iter_mut() {
            *v = v.clamp(0.0, 1.0);
        }
        if !self.levels.is_empty() {
            // Round half up (values are ≥ 0): a truncating conversion, then the exact level.
            let levels = p.levels as f32;
            for v in pixels.iter_mut() {
                *v = self.levels[(*v * levels + 0.5) as usize];
            }
        }
    }

    /// Lays the black bead at `centre` over the band: its level inside the fully covered
    /// disk, blended with what lies beneath on its edge.
    fn draw_black(&self, centre: Point2, band: &Band<'_>, pixels: &mut [f32]) {
        let black_level = self.params.black_level as f32;
        let reach2 = self.black_reach.0;
        let full_px2 = self.black_cover.full_px2;
        let rows = pixels.len() / band.width;
        for (y, dy2, c0, c1) in disk_spans(centre, self.black_reach, band, rows) {
            let row = &mut pixels[(y - band.y0) * band.width..(y - band.y0 + 1) * band.width];
            // The fully covered span, [c1 + 1, c1] (empty) when there is none.
            let inner = (full_px2 - dy2).max(0.0).sqrt();
            let (i0, i1) = match clipped(centre.x - inner, centre.x + inner, c0, c1 + 1) {
                Some(span) if dy2 <= full_px2 => span,
                _ => (c1 + 1, c1),
            };
            if i0 <= i1 {
                row[i0..=i1].fill(black_level);
            }
            for x in (c0..i0).chain(i1 + 1..=c1) {
                let d2 = dy2 + (x as f64 - centre.x).powi(2);
                if d2 < reach2 {
                    let v = &mut row[x];
                    *v += (black_level - *v) * self.black_cover.at(d2);
                }
            }
        }
    }
}

/// A band of rows being rendered: the frame width, its first row and its backlight.
struct Band<'a> {
    width: usize,
    y0: usize,
    light: &'a [f32],
}

/// The rows of the disk of squared radius `reach.0` (`reach.1` its root) around `centre` that
/// fall in the `rows` rows of `band`: `(y, dy², first column, last column)`, columns clipped to
/// the frame.
fn disk_spans(
    centre: Point2,
    (reach2, reach): (f64, f64),
    band: &Band<'_>,
    rows: usize,
) -> impl Iterator<Item = (usize, f64, usize, usize)> {
    let width = band.width;
    let row_span = clipped(centre.y - reach, centre.y + reach, band.y0, band.y0 + rows);
    row_span
        .into_iter()
        .flat_map(|(r0, r1)| r0..=r1)
        .filter_map(move |y| {
            let dy2 = (y as f64 - centre.y).powi(2);
            let half = (reach2 - dy2).max(0.0).sqrt();
            let (c0, c1) = clipped(centre.x - half, centre.x + half, 0, width)?;
            Some((y, dy2, c0, c1))
        })
}

/// Calls `f(x, y, d², pixel, backlight)` on the pixels of `band` (`pixels`) whose squared
/// distance to `centre` is below `reach.0` (`reach.1` its square root), row span by row span.
fn each_pixel(
    centre: Point2,
    (reach2, reach): (f64, f64),
    band: &Band<'_>,
    pixels: &mut [f32],
    mut f: impl FnMut(usize, usize, f64, &mut f32, f32),
) {
    let rows = pixels.len() / band.width;
    for (y, dy2, c0, c1) in disk_spans(centre, (reach2, reach), band, rows) {
        let start = (y - band.y0) * band.width;
        let span = start + c0..=start + c1;
        for ((x, v), &light) in (c0..).zip(&mut pixels[span.clone()]).zip(&band.light[span]) {
            let d2 = dy2 + (x as f64 - centre.x).powi(2);
            if d2 < reach2 {
                f(x, y, d2, v, light);
            }
        }
    }
}

/// Integer indices in `[low, high] ∩ [start, end − 1]`, or `None` when empty (or NaN).
fn clipped(low: f64, high: f64, start: usize, end: usize) -> Option<(usize, usize)> {
    let first = low.ceil().max(start as f64);
    let last = high.floor().min(end as f64 - 1.0);
    (first <= last).then_some((first as usize, last as usize))
}

/// The backlight of a `width × height` frame: a plane through `background_level` at the
/// centre of the frame with the gradients, times the static pattern.
fn backlight(width: usize, height: usize, params: &BedloadRenderParams) -> GrayImage {
    let p = params;
    let mut light = illumination_pattern(width, height, p);
    for (y, row) in light.as_mut_slice().chunks_mut(width).enumerate() {
        let fy = y as f64 / (height.max(2) - 1) as f64 - 0.5;
        for (x, v) in row.iter_mut().enumerate() {
            let fx = x as f64 / (width.max(2) - 1) as f64 - 0.5;
            let level =
                p.background_level + p.background_gradient_x * fx + p.background_gradient_y * fy;
            *v *= level as f32;
        }
    }
    light
}

/// The static relative illumination of a `width × height` frame, from the seed only:
/// `1 + illumination_sigma · (√(1 − f) · w + √f · s)`, `w` white Gaussian noise, `s` white
/// Gaussian noise blurred by a Gaussian of `illumination_correlation_px` and scaled back to
/// unit variance, `f` = `illumination_correlated_fraction`.
fn illumination_pattern(width: usize, height: usize, params: &BedloadRenderParams) -> GrayImage {
    let mut pattern = GrayImage::new(width, height);
    if params.illumination_sigma == 0.0 {
        pattern.as_mut_slice().fill(1.0);
        return pattern;
    }
    let mut stream = rng_stream(params.seed, STREAM_PATTERN);
    let (white_seed, smooth_seed): (u64, u64) = (stream.random(), stream.random());
    let fraction = params.illumination_correlated_fraction;
    let white = gaussian_field(width, height, white_seed);
    let mut smooth = gaussian_field(width, height, smooth_seed);
    blur_to_unit_variance(&mut smooth, params.illumination_correlation_px);
    let a = (params.illumination_sigma * (1.0 - fraction).sqrt()) as f32;
    let b = (params.illumination_sigma * fraction.sqrt()) as f32;
    for ((p, &w), &s) in pattern
        .as_mut_slice()
        .iter_mut()
        .zip(white.as_slice())
        .zip(smooth.as_slice())
    {
        *p = 1.0 + a * w + b * s;
    }
    pattern
}

/// White standard Gaussian noise, one stream per band of rows from `seed`.
fn gaussian_field(width: usize, height: usize, seed: u64) -> GrayImage {
    let mut field = GrayImage::new(width, height);
    field
        .as_mut_slice()
        .par_chunks_mut(BAND_ROWS * width)
        .enumerate()
        .for_each(|(band, pixels)| {
            let mut rng = rng_stream(seed, band as u64);
            for v in pixels.iter_mut() {
                *v = rng.sample(StandardNormal);
            }
        });
    field
}

/// Blurs unit-variance white noise by a Gaussian of `sigma_px` (separable, edges clamped)
/// and scales it back to unit variance; `sigma_px` = 0 leaves it alone.
fn blur_to_unit_variance(field: &mut GrayImage, sigma_px: f64) {
    if sigma_px == 0.0 {
        return;
    }
    let radius = (3.0 * sigma_px).ceil() as isize;
    let kernel: Vec<f32> = (-radius..=radius)
        .map(|k| (-0.5 * (k as f64 / sigma_px).powi(2)).exp() as f32)
        .collect();
    // White noise of unit variance blurred by the 2-D kernel k(x)k(y) has the variance
    // Σk(x)²k(y)² = (Σk²)².
    let norm: f32 = kernel.iter().map(|k| k * k).sum();
    let (width, height) = field.dimensions();
    let clamp = |i: isize, len: usize| i.clamp(0, len as isize - 1) as usize;
    let mut rows = GrayImage::new(width, height);
    rows.as_mut_slice()
        .par_chunks_mut(width)
        .zip(field.as_slice().par_chunks(width))
        .for_each(|(out, src)| {
            for (x, o) in out.iter_mut().enumerate() {
                *o = (-radius..=radius)
                    .zip(&kernel)
                    .map(|(k, w)| w * src[clamp(x as isize + k, width)])
                    .sum();
            }
        });
    field
        .as_mut_slice()
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(y, out)| {
            out.fill(0.0);
            for (k, w) in (-radius..=radius).zip(&kernel) {
                let src = rows.row(clamp(y as isize + k, height));
                for (o, &v) in out.iter_mut().zip(src) {
                    *o += w * v;
                }
            }
            for o in out.iter_mut() {
                *o /= norm;
            }
        });
}

/// The quantiles `Φ⁻¹((i + ½)/n)`, `i < n = NORMAL_QUANTILES`, scaled to unit variance (their
/// tails end at ±4.3: a draw is within 1e-4 of a true N(0, 1) one in distribution).
fn normal_quantiles() -> Vec<f32> {
    let n = NORMAL_QUANTILES;
    let quantiles: Vec<f64> = (0..n)
        .map(|i| inverse_normal_cdf((i as f64 + 0.5) / n as f64))
        .collect();
    let variance = quantiles.iter().map(|q| q * q).sum::<f64>() / n as f64;
    let scale = variance.sqrt().recip();
    quantiles.iter().map(|q| (q * scale) as f32).collect()
}

/// `Φ⁻¹(p)` for `p` in (0, 1), within 1.2e-9 relative (P. J. Acklam's rational
/// approximation).
fn inverse_normal_cdf(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    const P_LOW: f64 = 0.024_25;
    if p < P_LOW {
        tail((-2.0 * p.ln()).sqrt())
    } else if p <= 1.0 - P_LOW {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    }
}

/// A unit step at 0 blurred by a Gaussian of standard deviation `sigma` (`Φ(t/σ)`); a hard
/// step (½ on it) for `sigma` = 0.
fn step(t: f64, sigma: f64) -> f64 {
    if sigma == 0.0 {
        return if t > 0.0 {
            1.0
        } else if t < 0.0 {
            0.0
        } else {
            0.5
        };
    }
    0.5 * (1.0 + erf(t / (sigma * std::f64::consts::SQRT_2)))
}

/// The error function, within 1.5e-7 (Abramowitz & Stegun 7.1.26).
fn erf(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x.abs());
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let y = 1.0 - poly * (-x * x).exp();
    if x < 0.0 { -y } else { y }
}

/// Renders `frame` with `params` into `out` (its size is the frame's) with a one-off
/// [`BedloadRenderer`]; keep a renderer to render a sequence (it draws the static pattern
/// once). Fails on invalid parameters, naming the key.
pub fn render_bedload_frame(
    frame: &BedloadFrame,
    params: &BedloadRenderParams,
    out: &mut GrayImage,
) -> Result<()> {
    BedloadRenderer::new(params.clone())?.render(frame, out);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TrueBead;
    use sillage_core::{MotionState, TRANSPARENT_BEAD_CLASS};

    fn bead(track_id: TrackId, class: u32, x: f64, y: f64) -> TrueBead {
        TrueBead {
            track_id,
            class,
            pos_px: Point2::new(x, y),
            vel_px_per_frame: None,
            motion_state: MotionState::Resting,
            in_bed: false,
        }
    }

    /// Noise-free, unrounded, flat backlight, regular rims: profiles can be read exactly.
    fn clean() -> BedloadRenderParams {
        BedloadRenderParams {
            background_gradient_x: 0.0,
            illumination_sigma: 0.0,
            noise_sigma: 0.0,
            black_level: 0.0,
            ring_blur_spread: 0.0,
            ring_transmission_spread: 0.0,
            ring_radius_spread_px: 0.0,
            ring_asymmetry: 0.0,
            ring_ellipticity: 0.0,
            levels: 0,
            ..BedloadRenderParams::default()
        }
    }

    fn render(params: &BedloadRenderParams, beads: Vec<TrueBead>, w: usize, h: usize) -> GrayImage {
        let frame = BedloadFrame { index: 0, beads };
        let mut image = GrayImage::new(w, h);
        render_bedload_frame(&frame, params, &mut image).unwrap();
        image
    }

    #[test]
    fn erf_and_the_tabulated_outline_match_direct_evaluation() {
        // erf(0.5), erf(1), erf(2) to 7 digits.
        for (x, reference) in [(0.5, 0.520_499_9), (1.0, 0.842_700_8), (2.0, 0.995_322_3)] {
            assert!((erf(x) - reference).abs() < 2e-7 && (erf(-x) + reference).abs() < 2e-7);
        }
        let f = |d: f64| step(14.0 - d, 0.83);
        let profile = Profile::tabulate(18.0, f);
        for i in 0..1800 {
            let d = i as f64 / 100.0;
            assert!(
                (f64::from(profile.at(d * d)) - f(d)).abs() < 2e-3,
                "d = {d}"
            );
        }
    }

    #[test]
    fn the_noise_quantiles_are_a_unit_gaussian() {
        for (p, reference) in [(0.5, 0.0), (0.975, 1.959_963_985), (0.001, -3.090_232_306)] {
            assert!((inverse_normal_cdf(p) - reference).abs() < 1e-8, "{p}");
        }
        let q = normal_quantiles();
        let n = q.len() as f64;
        let mean = q.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
        let var = q.iter().map(|&v| f64::from(v).powi(2)).sum::<f64>() / n;
        assert!(
            mean.abs() < 1e-6 && (var - 1.0).abs() < 1e-5,
            "{mean} {var}"
        );
        assert!(q.windows(2).all(|w| w[0] < w[1]) && q[0] == -q[q.len() - 1]);
    }

    #[test]
    fn black_bead_spans_match_a_per_pixel_evaluation() {
        let renderer = BedloadRenderer::new(BedloadRenderParams::default()).unwrap();
        let (width, height) = (50, 40);
        let light: Vec<f32> = (0..width * height)
            .map(|i| 0.5 + (i % 7) as f32 * 0.01)
            .collect();
        for centre in [
            Point2::new(20.3, 17.8),
            Point2::new(2.0, 39.5),
            Point2::new(-10.0, 5.0),
        ] {
            let band = Band {
                width,
                y0: 0,
                light: &light,
            };
            let mut fast = light.clone();
            renderer.draw_black(centre, &band, &mut fast);
            let level = renderer.params.black_level as f32;
            let (reach2, _) = renderer.black_reach;
            for (i, (&f, &l)) in fast.iter().zip(&light).enumerate() {
                let (x, y) = ((i % width) as f64, (i / width) as f64);
                let d2 = (x - centre.x).powi(2) + (y - centre.y).powi(2);
                let slow = if d2 < reach2 {
                    l + (level - l) * renderer.black_cover.at(d2)
                } else {
                    l
                };
                assert!((f - slow).abs() < 1e-6, "({x}, {y}): {f} vs {slow}");
            }
        }
    }

    #[test]
    fn a_black_bead_is_black_inside_and_the_backlight_outside() {
        let params = clean();
        let image = render(&params, vec![bead(0, BLACK_BEAD_CLASS, 30.0, 25.0)], 60, 50);
        assert_eq!(image.get(30, 25), 0.0);
        assert!(image.get(30, 25 + 10) < 0.001);
        // Half the backlight on the edge, the backlight 5 σ out.
        assert!(
            (image.get(44, 25) - 0.425).abs() < 0.01,
            "{}",
            image.get(44, 25)
        );
        assert!((image.get(48, 25) - 0.85).abs() < 1e-4);
        assert!((image.get(1, 1) - 0.85).abs() < 1e-6);
    }

    #[test]
    fn a_transparent_bead_has_a_bright_centre_and_a_dark_rim() {
        let params = clean();
        let image = render(
            &params,
            vec![bead(3, TRANSPARENT_BEAD_CLASS, 20.0, 20.0)],
            40,
            40,
        );
        let at = |dx: usize| f64::from(image.get(20 + dx, 20)) / 0.85;
        assert!((at(0) - 0.95).abs() < 1e-3, "{}", at(0));
        // The darkest pixel is the one nearest 8.7 px, about the rim transmission.
        let darkest = (0..15).min_by(|&a, &b| at(a).total_cmp(&at(b))).unwrap();
        assert_eq!(darkest, 9);
        assert!((at(9) - 0.59).abs() < 0.03, "{}", at(9));
        assert!((at(14) - 1.0).abs() < 2e-3, "{}", at(14));
    }

    #[test]
    fn black_beads_hide_transparent_ones_and_front_beads_hide_the_rims_behind() {
        let params = clean();
        let image = render(
            &params,
            vec![
                bead(0, BLACK_BEAD_CLASS, 20.0, 20.0),
                bead(1, TRANSPARENT_BEAD_CLASS, 20.0, 20.0),
            ],
            40,
            40,
        );
        assert_eq!(image.get(20 + 8, 20), 0.0);

        // Two overlapping transparent beads: inside the front one's body, no rim of the
        // other; with transmissions stacked (opacity 0), both rims show.
        let pair = |opacity: f64| {
            let params = BedloadRenderParams {
                transparent_opacity: opacity,
                ..clean()
            };
            let beads = vec![
                bead(1, TRANSPARENT_BEAD_CLASS, 20.0, 20.0),
                bead(2, TRANSPARENT_BEAD_CLASS, 33.0, 20.0),
            ];
            render(&params, beads, 60, 40)
        };
        let (hidden, stacked) = (pair(1.0), pair(0.0));
        let single = render(
            &params,
            vec![bead(1, TRANSPARENT_BEAD_CLASS, 20.0, 20.0)],
            60,
            40,
        );
        let front = if hidden.get(29, 20) < 0.7 { 20.0 } else { 33.0 };
        // The rim of the front bead, on the line between the centres, inside the other.
        let x = if front == 20.0 { 29 } else { 24 };
        assert!(hidden.get(x, 20) < 0.6, "front rim {}", hidden.get(x, 20));
        // The rim of the bead behind at the same place is hidden: it is as bright as the
        // front bead's body alone.
        let behind_x = if front == 20.0 { 24 } else { 29 };
        assert!(
            hidden.get(behind_x, 20) > 0.75,
            "behind {}",
            hidden.get(behind_x, 20)
        );
        assert!(stacked.get(24, 20) < 0.6 && stacked.get(29, 20) < 0.6);
        assert!(single.get(29, 20) < 0.6 && single.get(24, 20) > 0.75);
    }

    #[test]
    fn looks_follow_the_track_id_not_the_frame() {
        let params = BedloadRenderParams::default();
        let renderer = BedloadRenderer::new(params).unwrap();
        let (a, b) = (renderer.look(0, 7), renderer.look(5, 7));
        assert_eq!(
            (a.depth_key, a.ring_depth, a.dark_side),
            (b.depth_key, b.ring_depth, b.dark_side)
        );
        assert_ne!(a.depth_key, renderer.look(0, 8).depth_key);
    }

    #[test]
    fn the_illumination_pattern_has_its_variance_and_correlation() {
        let params = BedloadRenderParams {
            illumination_sigma: 0.01,
            illumination_correlated_fraction: 0.5,
            ..BedloadRenderParams::default()
        };
        let pattern = illumination_pattern(400, 300, &params);
        let values = pattern.as_slice();
        let n = values.len() as f64;
        let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
        let var = values
            .iter()
            .map(|&v| (f64::from(v) - mean).powi(2))
            .sum::<f64>()
            / n;
        assert!(
            (mean - 1.0).abs() < 1e-4 && (var.sqrt() - 0.01).abs() < 5e-4,
            "{var}"
        );
        // Lag-1 correlation: half the variance blurred by σ = 1.5 px, exp(−1/9)/2 = 0.45.
        let mut cov = 0.0;
        for y in 0..300 {
            for x in 0..399 {
                cov += (f64::from(pattern.get(x, y)) - mean)
                    * (f64::from(pattern.get(x + 1, y)) - mean);
            }
        }
        let rho = cov / (300.0 * 399.0) / var;
        assert!((rho - 0.45).abs() < 0.03, "{rho}");
    }
}

//! What a walker looks like: an upright person-like silhouette (head, torso with arms, hips,
//! two legs in one of two stride poses) and seeded clothes — a dark dominant colour per walker
//! with light stripes, checks and a logo-like patch, so that SIFT finds corners on every one
//! (the features the SIFT-PF tracker follows) and colour histograms tell walkers apart.
//!
//! Body coordinates `(u, v)` run over the walker's box: `u` from its left edge (0) to its right
//! edge (1), `v` from the top of the head (0) to the soles (1).

use rand::RngExt;
use sillage_core::rng_stream;

/// Columns of the narrowest part of the solid body (the hips), as shares of the box width:
/// a walker hidden inside this band and [`SOLID_BODY_V`] of a nearer one is fully covered.
pub(crate) const SOLID_BODY_U: (f64, f64) = (0.07, 0.93);
/// Rows of the solid body, shoulders to knees, as shares of the box height.
pub(crate) const SOLID_BODY_V: (f64, f64) = (0.16, 0.80);

/// Head: an ellipse at the top centre, `(centre u, centre v, radius u, radius v)`.
const HEAD: (f64, f64, f64, f64) = (0.5, 0.085, 0.2, 0.085);
/// Top of the hair line's end: above it the head is hair, below it face.
const HAIR_BOTTOM_V: f64 = 0.06;
/// Bottom of the torso (arms included, the full box width).
const TORSO_BOTTOM_V: f64 = 0.56;
/// Height of the belt below the torso.
const BELT_HEIGHT_V: f64 = 0.025;
/// Half width of a lower leg, share of the box width.
const LEG_HALF_WIDTH_U: f64 = 0.15;
/// Distance of each leg's centre from the body's axis, legs apart and legs together.
const LEG_OFFSET_U: [f64; 2] = [0.23, 0.14];
/// Top of the shoes.
const SHOE_TOP_V: f64 = 0.96;
/// Frames a stride pose is held before the legs swing to the other one.
const STRIDE_FRAMES: usize = 4;

/// Luma of the dark dominant colours (clothes), in `[0, 1]`: far below the background's.
const DARK_LUMA: f32 = 0.2;
/// Share of the pure hue mixed into white for the light colours (stripes, logo).
const LIGHT_HUE_SHARE: f32 = 0.35;
/// Golden-ratio step of the dominant hue from one walker to the next: well apart for any
/// small number of walkers.
const HUE_STEP: f64 = 0.381_966;

/// Stream of the sequence-wide hue offset, and tag of the per-walker look streams.
const LOOK_STREAM_TAG: u64 = 1 << 61;

/// Skin tones a face is drawn in.
const SKIN: [[f32; 3]; 3] = [[0.93, 0.76, 0.62], [0.78, 0.57, 0.42], [0.52, 0.36, 0.26]];
/// Hair colours.
const HAIR: [[f32; 3]; 3] = [[0.08, 0.06, 0.05], [0.3, 0.18, 0.08], [0.6, 0.45, 0.2]];
/// Shoe colour.
const SHOE: [f32; 3] = [0.05, 0.05, 0.06];

/// Which of the two stride poses the legs are in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stride {
    /// Legs apart (feet outward).
    Apart,
    /// Legs together.
    Together,
}

impl Stride {
    /// The pose `frames_walked` frames after the walker's first frame.
    pub fn after(frames_walked: usize) -> Self {
        if (frames_walked / STRIDE_FRAMES).is_multiple_of(2) {
            Stride::Apart
        } else {
            Stride::Together
        }
    }
}

/// The part of the body under `(u, v)`, `None` outside the silhouette.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Part {
    Hair,
    Face,
    Torso,
    Belt,
    Hips,
    Leg,
    Shoe,
}

/// The body part at body coordinates `(u, v)` in pose `stride`, `None` outside the silhouette.
fn body_part(u: f64, v: f64, stride: Stride) -> Option<Part> {
    if !(0.0..1.0).contains(&u) || !(0.0..1.0).contains(&v) {
        return None;
    }
    if v < SOLID_BODY_V.0 {
        let (cu, cv, ru, rv) = HEAD;
        let inside = ((u - cu) / ru).powi(2) + ((v - cv) / rv).powi(2) < 1.0;
        return inside.then_some(if v < HAIR_BOTTOM_V {
            Part::Hair
        } else {
            Part::Face
        });
    }
    if v < TORSO_BOTTOM_V {
        return Some(Part::Torso);
    }
    if v < SOLID_BODY_V.1 {
        let inside = (SOLID_BODY_U.0..SOLID_BODY_U.1).contains(&u);
        return inside.then_some(if v < TORSO_BOTTOM_V + BELT_HEIGHT_V {
            Part::Belt
        } else {
            Part::Hips
        });
    }
    let offset = LEG_OFFSET_U[stride as usize];
    let on_leg = [0.5 - offset, 0.5 + offset]
        .iter()
        .any(|centre| (u - centre).abs() < LEG_HALF_WIDTH_U);
    on_leg.then_some(if v < SHOE_TOP_V {
        Part::Leg
    } else {
        Part::Shoe
    })
}

/// Whether body coordinates `(u, v)` are inside the silhouette in pose `stride`.
pub(crate) fn inside_silhouette(u: f64, v: f64, stride: Stride) -> bool {
    body_part(u, v, stride).is_some()
}

/// A texture over body coordinates measured in box heights (so that stripes are square
/// whatever the box's aspect).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Pattern {
    /// No texture.
    Plain,
    /// Horizontal stripes of the given period.
    HorizontalStripes(f64),
    /// Vertical stripes of the given period.
    VerticalStripes(f64),
    /// A checkerboard of squares of the given side.
    Checks(f64),
}

impl Pattern {
    /// Whether `(x, y)` (box heights) falls on the pattern's second colour.
    fn second(self, x: f64, y: f64) -> bool {
        let half = |t: f64, period: f64| (t / period).rem_euclid(1.0) >= 0.5;
        match self {
            Pattern::Plain => false,
            Pattern::HorizontalStripes(period) => half(y, period),
            Pattern::VerticalStripes(period) => half(x, period),
            Pattern::Checks(side) => {
                ((x / side).floor() as i64 + (y / side).floor() as i64).rem_euclid(2) == 1
            }
        }
    }
}

/// One walker's clothes and face: seeded colours and patterns.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Appearance {
    /// Box width over box height: turns `u` into box heights.
    aspect: f64,
    top: [f32; 3],
    bottom: [f32; 3],
    stripes: [f32; 3],
    logo: [f32; 3],
    skin: [f32; 3],
    hair: [f32; 3],
    torso: Pattern,
    hips: Pattern,
    /// Logo patch: centre `v` and half side in box heights.
    logo_v: f64,
    logo_half: f64,
}

impl Appearance {
    /// The look of walker `id` (from 1) of the sequence seeded `seed`, for boxes of
    /// `aspect` = width / height. The dominant hue steps by the golden ratio from walker to
    /// walker from a seeded offset; the rest comes from the walker's own stream.
    pub fn new(seed: u64, id: u64, aspect: f64) -> Self {
        let hue_offset: f64 = rng_stream(seed, LOOK_STREAM_TAG).random();
        let mut rng = rng_stream(seed, LOOK_STREAM_TAG | id);
        let hue = (hue_offset + HUE_STEP * id as f64).rem_euclid(1.0);
        let bottom_hue = (hue + rng.random_range(0.3..0.7)).rem_euclid(1.0);
        let light_hue = (hue + rng.random_range(0.2..0.8)).rem_euclid(1.0);
        let period = rng.random_range(0.07..0.11);
        let torso = match rng.random_range(0..3) {
            0 => Pattern::HorizontalStripes(period),
            1 => Pattern::VerticalStripes(period),
            _ => Pattern::Checks(0.5 * period),
        };
        let hips = match rng.random_range(0..3) {
            0 => Pattern::Plain,
            1 => Pattern::Checks(rng.random_range(0.05..0.08)),
            _ => Pattern::VerticalStripes(rng.random_range(0.06..0.1)),
        };
        Self {
            aspect,
            top: dark(hue),
            bottom: dark(bottom_hue),
            stripes: light(light_hue),
            logo: light((light_hue + 0.5).rem_euclid(1.0)),
            skin: SKIN[rng.random_range(0..SKIN.len())],
            hair: HAIR[rng.random_range(0..HAIR.len())],
            torso,
            hips,
            logo_v: rng.random_range(0.27..0.4),
            logo_half: rng.random_range(0.05..0.07),
        }
    }

    /// The colour at body coordinates `(u, v)` in pose `stride` (linear RGB in `[0, 1]`),
    /// `None` outside the silhouette.
    pub fn colour_at(&self, u: f64, v: f64, stride: Stride) -> Option<[f32; 3]> {
        let x = u * self.aspect;
        let colour = match body_part(u, v, stride)? {
            Part::Hair => self.hair,
            Part::Face => self.skin,
            Part::Torso => {
                let (dx, dy) = ((x - 0.5 * self.aspect).abs(), (v - self.logo_v).abs());
                if dx.max(dy) < self.logo_half {
                    // A light square with a dark diamond: eight corners.
                    if dx + dy < 0.75 * self.logo_half {
                        self.top
                    } else {
                        self.logo
                    }
                } else if self.torso.second(x, v) {
                    self.stripes
                } else {
                    self.top
                }
            }
            Part::Belt => self.stripes,
            Part::Hips => {
                if self.hips.second(x, v) {
                    self.stripes
                } else {
                    self.bottom
                }
            }
            Part::Leg => self.bottom,
            Part::Shoe => SHOE,
        };
        Some(colour)
    }
}

/// Pure hue `h` in `[0, 1)` at full saturation and value.
fn hue_rgb(h: f64) -> [f32; 3] {
    let sector = h * 6.0;
    let f = (sector - sector.floor()) as f32;
    match sector as u32 % 6 {
        0 => [1.0, f, 0.0],
        1 => [1.0 - f, 1.0, 0.0],
        2 => [0.0, 1.0, f],
        3 => [0.0, 1.0 - f, 1.0],
        4 => [f, 0.0, 1.0],
        _ => [1.0, 0.0, 1.0 - f],
    }
}

/// Rec. 601 luma of a linear colour in `[0, 1]`.
fn luma(c: [f32; 3]) -> f32 {
    sillage_core::LUMA_601
        .iter()
        .zip(c)
        .map(|(w, v)| w * v)
        .sum()
}

/// A dark, saturated colour of hue `h` with luma [`DARK_LUMA`].
fn dark(h: f64) -> [f32; 3] {
    // 80 % saturation, then scaled down to the target luma (every hue's luma exceeds it).
    let c = hue_rgb(h).map(|v| 0.2 + 0.8 * v);
    let scale = DARK_LUMA / luma(c);
    c.map(|v| v * scale)
}

/// A light tint of hue `h`: white with [`LIGHT_HUE_SHARE`] of the hue.
fn light(h: f64) -> [f32; 3] {
    hue_rgb(h).map(|v| 1.0 - LIGHT_HUE_SHARE + LIGHT_HUE_SHARE * v)
}

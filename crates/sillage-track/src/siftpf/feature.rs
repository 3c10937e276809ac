//! One tracked SIFT feature and its particle filter (§2.2 of Souded et al.): state
//! `(x, y, u, v, h, n)`, constant-velocity prediction (Eqs. (3)-(4)), particles weighted by
//! the Gaussian of their descriptor's distance to the feature's, times the motion confidence
//! `c` (Eq. (5)), SIR, the barycentre as the new position, the descriptor re-computed there
//! and the feature dropped when it varied too much.

use sillage_core::{Image, Point2, Vec2};
use sillage_filter::{FilterSpec, InitialSpread, KinematicModel, ParticleFilter, noise::Gauss2};
use sillage_image::{SiftDescriptor, SiftDetector, SiftKeypoint};

use super::params::FeatureFilterParams;

/// Log-likelihood of a particle whose descriptor window leaves the image: far below any
/// descriptor distance's.
const OUTSIDE_LOG_LIKELIHOOD: f64 = -1e3;
/// Variations a feature needs before its own σ and drop test replace the defaults.
const MIN_HISTORY: u32 = 3;
/// σ of the reliability's descriptor term: a variation of this distance halves it roughly.
const RELIABILITY_SIGMA: f64 = 0.3;

/// The running mean and mean square of a feature's descriptor variations (§2.2.3: "feature
/// variation learning").
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct VariationHistory {
    count: u32,
    mean: f64,
    mean_square: f64,
}

impl VariationHistory {
    fn push(&mut self, variation: f64) {
        self.count += 1;
        let n = f64::from(self.count);
        self.mean += (variation - self.mean) / n;
        self.mean_square += (variation * variation - self.mean_square) / n;
    }

    fn std(&self) -> f64 {
        (self.mean_square - self.mean * self.mean).max(0.0).sqrt()
    }
}

/// What became of a feature in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeatureFate {
    /// Followed: new position and descriptor.
    Kept,
    /// Its descriptor varied too much, or its window left the image (§2.2.3).
    Dropped,
}

/// The frame a feature's particles are weighed against.
#[derive(Clone, Copy)]
pub struct FeatureFrame<'a> {
    /// The frame's scale space, analysed.
    pub sift: &'a SiftDetector,
    /// The motion pixels of the frame.
    pub foreground: &'a Image<bool>,
}

impl FeatureFrame<'_> {
    /// True when the pixel nearest `p` is a motion pixel (false outside the frame).
    pub fn is_moving(&self, p: Point2) -> bool {
        let (x, y) = (p.x.round(), p.y.round());
        if x < 0.0 || y < 0.0 {
            return false;
        }
        let (w, h) = self.foreground.dimensions();
        let (x, y) = (x as usize, y as usize);
        x < w && y < h && self.foreground.as_slice()[y * w + x]
    }
}

/// Where a new feature starts (§2.1): its keypoint and descriptor, its first reliability
/// and its place in the object's box.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureSeed {
    /// The detected keypoint (position, scale, orientation).
    pub keypoint: SiftKeypoint,
    /// Its descriptor.
    pub descriptor: SiftDescriptor,
    /// The selection's robustness score, in `[0, 1]`.
    pub reliability: f64,
    /// Position inside the object's box as shares of its width and height.
    pub anchor: (f64, f64),
}

/// A SIFT feature followed by its own particle filter.
#[derive(Debug, Clone)]
pub struct TrackedFeature {
    filter: ParticleFilter,
    pos_px: Point2,
    vel_px_per_frame: Vec2,
    sigma_px: f32,
    orientation: f32,
    descriptor: SiftDescriptor,
    history: VariationHistory,
    reliability: f64,
    /// Position inside the object's box as shares of its width and height, from the last
    /// frame the object had a blob of its own (the pre-merge layout of §2.3).
    anchor: (f64, f64),
}

impl TrackedFeature {
    /// A feature starting from `seed`, moving at `vel_px_per_frame` (its object's), its
    /// particles drawn from the stream `feature_id` of the run's seed.
    pub fn new(
        spec: &FilterSpec,
        feature_id: u64,
        seed: FeatureSeed,
        vel_px_per_frame: Vec2,
        params: &FeatureFilterParams,
    ) -> Self {
        let FeatureSeed {
            keypoint,
            descriptor,
            reliability,
            anchor,
        } = seed;
        let pos_px = Point2::new(f64::from(keypoint.x), f64::from(keypoint.y));
        let spread = InitialSpread {
            pos_px,
            pos_noise: isotropic(params.position_noise_px / 2.0),
            vel_px_per_frame,
            vel_noise: isotropic(params.velocity_noise_px_per_frame),
            mode: 0,
        };
        Self {
            filter: spec.spawn(feature_id, &spread),
            pos_px,
            vel_px_per_frame,
            sigma_px: keypoint.sigma,
            orientation: keypoint.orientation,
            descriptor,
            history: VariationHistory::default(),
            reliability,
            anchor,
        }
    }

    /// Position, px.
    pub fn pos_px(&self) -> Point2 {
        self.pos_px
    }

    /// Velocity, px/frame.
    pub fn vel_px_per_frame(&self) -> Vec2 {
        self.vel_px_per_frame
    }

    /// The tracked descriptor `H_f`.
    pub fn descriptor(&self) -> &SiftDescriptor {
        &self.descriptor
    }

    /// `w_k` of Eq. (6), in `[0, 1]`: how reliable the feature is for linking its object.
    pub fn reliability(&self) -> f64 {
        self.reliability
    }

    /// Place in the object's box, as shares of its width and height.
    pub fn anchor(&self) -> (f64, f64) {
        self.anchor
    }

    /// Records the feature's place in its object's box (after a one-to-one link).
    pub fn set_anchor(&mut self, anchor: (f64, f64)) {
        self.anchor = anchor;
    }

    /// σ of Eq. (5): the root mean square of the feature's descriptor variations so far
    /// (the σ of a Gaussian of the distance centred on 0), floored; the initial value until
    /// it has three variations.
    fn likelihood_sigma(&self, params: &FeatureFilterParams) -> f64 {
        if self.history.count < MIN_HISTORY {
            params.initial_sigma
        } else {
            self.history.mean_square.sqrt().max(params.min_sigma)
        }
    }

    /// One frame of §2.2: predict (Eqs. (3)-(4)), weigh (Eq. (5)) with `c₀ =
    /// motion_confidence` off the motion pixels, resample (SIR), move to the barycentre,
    /// re-compute the descriptor there and test its variation.
    pub fn step(
        &mut self,
        model: &KinematicModel,
        frame: FeatureFrame<'_>,
        motion_confidence: f64,
        params: &FeatureFilterParams,
    ) -> FeatureFate {
        let sigma = self.likelihood_sigma(params);
        let inv_two_var = 1.0 / (2.0 * sigma * sigma);
        let log_c0 = motion_confidence.ln();
        let (scale, orientation) = (self.sigma_px, self.orientation);
        let reference = &self.descriptor;
        self.filter.predict(model);
        self.filter.weight(|p| {
            let log_c = if frame.is_moving(p.pos_px) {
                0.0
            } else {
                log_c0
            };
            match frame
                .sift
                .describe_at(p.pos_px.x as f32, p.pos_px.y as f32, scale, orientation)
            {
                Some(h) => {
                    let d = f64::from(h.distance(reference));
                    log_c - d * d * inv_two_var
                }
                None => OUTSIDE_LOG_LIKELIHOOD,
            }
        });
        self.filter.resample();
        let estimate = self.filter.estimate();
        let pos_px = Point2::new(estimate.mean.at(0), estimate.mean.at(1));
        let Some(descriptor) =
            frame
                .sift
                .describe_at(pos_px.x as f32, pos_px.y as f32, scale, orientation)
        else {
            return FeatureFate::Dropped;
        };
        let variation = f64::from(descriptor.distance(&self.descriptor));
        let too_large = variation > params.max_variation
            || (self.history.count >= MIN_HISTORY
                && variation > self.history.mean + params.variation_sigmas * self.history.std());
        if too_large {
            return FeatureFate::Dropped;
        }
        self.history.push(variation);
        self.pos_px = pos_px;
        self.vel_px_per_frame = Vec2::new(estimate.mean.at(2), estimate.mean.at(3));
        self.descriptor = descriptor;
        let c = if frame.is_moving(pos_px) {
            1.0
        } else {
            motion_confidence
        };
        let consistency = (-0.5 * (self.history.mean / RELIABILITY_SIGMA).powi(2)).exp();
        self.reliability = c * consistency;
        FeatureFate::Kept
    }
}

/// An isotropic Gaussian of standard deviation `sigma` (valid for any finite σ ≥ 0).
pub(crate) fn isotropic(sigma: f64) -> Gauss2 {
    sillage_filter::Noise2::diagonal(sigma * sigma, sigma * sigma)
        .factor("noise")
        .expect("a finite σ ≥ 0 is validated by SiftPfParams")
}

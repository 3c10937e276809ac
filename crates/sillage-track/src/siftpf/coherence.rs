//! The "world" coherency criteria of §2.4: an object's size and speed learned as Gaussians
//! while it is tracked, in metres through the ground-plane homography when one is given, in
//! pixels otherwise; a candidate for resuming it after an occlusion must fit them.

use sillage_core::{Homography, Point2};

use sillage_core::BoundingBox;

/// Samples a Gaussian needs before it judges a candidate.
const MIN_SAMPLES: u32 = 3;
/// The σ used is at least this share of the mean (a person seen only walking steadily
/// would otherwise reject the same person a little slower).
const MIN_RELATIVE_SIGMA: f64 = 0.15;

/// Welford's running mean and variance.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct RunningGaussian {
    count: u32,
    mean: f64,
    m2: f64,
}

impl RunningGaussian {
    fn push(&mut self, value: f64) {
        self.count += 1;
        let delta = value - self.mean;
        self.mean += delta / f64::from(self.count);
        self.m2 += delta * (value - self.mean);
    }

    /// The standard deviation, floored at a share of the mean.
    fn sigma(&self) -> f64 {
        let var = if self.count > 1 {
            self.m2 / f64::from(self.count - 1)
        } else {
            0.0
        };
        var.sqrt().max(MIN_RELATIVE_SIGMA * self.mean.abs())
    }

    /// True when `value` lies within `k` σ of the mean, or too few samples were seen.
    fn admits(&self, value: f64, k: f64) -> bool {
        self.count < MIN_SAMPLES || (value - self.mean).abs() <= k * self.sigma()
    }
}

/// Image to world: the foot point and apparent size of a box in metres through the
/// ground-plane homography, or in pixels without one.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WorldScale {
    homography: Option<Homography>,
}

impl WorldScale {
    /// Metres through `homography`, pixels without one.
    pub fn new(homography: Option<Homography>) -> Self {
        Self { homography }
    }

    /// Where the box stands: its foot point on the ground (m) or in the image (px).
    pub fn ground(&self, b: &BoundingBox) -> Point2 {
        let foot = b.foot();
        self.homography
            .as_ref()
            .and_then(|h| h.ground_from_image(foot))
            .unwrap_or(foot)
    }

    /// Width and height of the box, in metres at its foot point (px per metre across the
    /// view there) or in pixels.
    pub fn size(&self, b: &BoundingBox) -> (f64, f64) {
        match self
            .homography
            .as_ref()
            .and_then(|h| h.px_per_metre_across(b.foot()))
        {
            Some(px_per_m) if px_per_m > 0.0 => (b.width_px / px_per_m, b.height_px / px_per_m),
            _ => (b.width_px, b.height_px),
        }
    }
}

/// An object's learned width, height and speed (per frame), in world units.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Coherence {
    width: RunningGaussian,
    height: RunningGaussian,
    speed: RunningGaussian,
}

impl Coherence {
    /// Learns one frame: the box's size, and the distance its foot travelled since the
    /// previous frame it was seen in one-to-one (if any).
    pub fn learn(&mut self, size: (f64, f64), step: Option<f64>) {
        self.width.push(size.0);
        self.height.push(size.1);
        if let Some(step) = step {
            self.speed.push(step);
        }
    }

    /// True when a candidate of `size` that travelled `distance` in `frames` frames fits
    /// within `k` σ of the learned size and under the speed's mean + k σ.
    pub fn admits(&self, size: (f64, f64), distance: f64, frames: u32, k: f64) -> bool {
        let speed_ok = self.speed.count < MIN_SAMPLES
            || distance
                <= f64::from(frames.max(1)) * (self.speed.mean + k * self.speed.sigma())
                    + 0.5 * self.width.mean;
        self.width.admits(size.0, k) && self.height.admits(size.1, k) && speed_ok
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn learned_gaussians_gate_size_and_travel() {
        let mut c = Coherence::default();
        assert!(c.admits((100.0, 1.0), 1e6, 1, 3.0), "nothing learned yet");
        for i in 0..10 {
            c.learn((20.0 + f64::from(i % 2), 60.0), Some(2.0));
        }
        assert!(c.admits((21.0, 61.0), 2.0, 1, 3.0));
        assert!(!c.admits((40.0, 60.0), 2.0, 1, 3.0), "twice as wide");
        // 10 frames at 2 px/frame (σ floored at 0.3) plus half a width: 10 · 2.9 + 10.25.
        assert!(c.admits((20.0, 60.0), 39.0, 10, 3.0));
        assert!(!c.admits((20.0, 60.0), 40.0, 10, 3.0));
    }

    #[test]
    fn pixels_without_a_homography() {
        let b = BoundingBox {
            left_px: 10.0,
            top_px: 20.0,
            width_px: 24.0,
            height_px: 60.0,
        };
        let scale = WorldScale::new(None);
        assert_eq!(scale.size(&b), (24.0, 60.0));
        assert_eq!(scale.ground(&b), Point2::new(22.0, 80.0));
    }
}

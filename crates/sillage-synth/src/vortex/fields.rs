//! The flows particles can follow: the TracTrac paper's vortex (Eqs. 13-16) and a family of
//! classic flows for accuracy benchmarks (a Lamb–Oseen vortex pair, a stagnation point, a
//! shear layer, a cellular vortex array, random-Fourier-mode turbulence).

use std::f64::consts::{PI, TAU};

use rand::RngExt;
use serde::{Deserialize, Serialize};
use sillage_core::{FrameIndex, Vec2, rng_stream};

use super::flow::vortex_map;

/// Which flow moves the particles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FlowKind {
    /// The TracTrac paper's unsteady vortex with shear (Eqs. 13-16), its speed set by
    /// `delta` (the default).
    #[default]
    PaperVortex,
    /// Two counter-rotating Lamb–Oseen vortices, `u_θ = Γ/(2πr)·(1 − e^{−r²/r_c²})`, a sixth of
    /// the width apart from the centre, core radius a tenth of the width.
    LambOseenPair,
    /// A planar stagnation-point flow `u = U·x/L, v = −U·y/L` (L: half the width).
    Stagnation,
    /// A `tanh` shear layer `u = U·tanh(y/δ)` (δ: a tenth of the height) with a travelling
    /// sinusoidal cross-flow of 15 % of U confined to the layer.
    ShearLayer,
    /// A steady cellular array of vortices, stream function `ψ ∝ sin(kx)·sin(ky)` with cells
    /// an eighth of the width across.
    CellularArray,
    /// Divergence-free turbulence-like flow: the stream function is a sum of 24 random Fourier
    /// modes with wavelengths from an eighth to half the width, the velocity of each falling as
    /// k^(−5/6) (a k^(−5/3) energy spectrum), phases drifting slowly in time.
    FourierTurbulence,
}

impl FlowKind {
    /// Every kind, in a fixed order.
    pub const ALL: [FlowKind; 6] = [
        FlowKind::PaperVortex,
        FlowKind::LambOseenPair,
        FlowKind::Stagnation,
        FlowKind::ShearLayer,
        FlowKind::CellularArray,
        FlowKind::FourierTurbulence,
    ];

    /// The TOML / command-line name.
    pub fn name(self) -> &'static str {
        match self {
            FlowKind::PaperVortex => "paper_vortex",
            FlowKind::LambOseenPair => "lamb_oseen_pair",
            FlowKind::Stagnation => "stagnation",
            FlowKind::ShearLayer => "shear_layer",
            FlowKind::CellularArray => "cellular_array",
            FlowKind::FourierTurbulence => "fourier_turbulence",
        }
    }
}

/// Number of modes of [`FlowKind::FourierTurbulence`].
const FOURIER_MODES: usize = 24;
/// Stream tag of the Fourier modes' draws, apart from particle and noise streams.
const FOURIER_STREAM_TAG: u64 = 1 << 62;

/// One mode of the stream function `a · sin(k·x + φ + ω·n)`.
#[derive(Debug, Clone, Copy)]
struct Mode {
    wave: Vec2,
    amplitude: f64,
    phase: f64,
    drift: f64,
}

/// A flow of [`FlowKind`] set up for one image size and speed: the map from a position to the
/// next frame's.
#[derive(Debug, Clone)]
pub struct FlowField {
    kind: FlowKind,
    delta: f64,
    width: f64,
    height: f64,
    speed: f64,
    modes: Vec<Mode>,
}

impl FlowField {
    /// The field of `kind` on a `width × height` image: the paper's vortex runs at time step
    /// `delta`; the other kinds peak at `max_displacement_px` px per frame. `seed` draws the
    /// Fourier modes.
    pub fn new(
        kind: FlowKind,
        width: usize,
        height: usize,
        delta: f64,
        max_displacement_px: f64,
        seed: u64,
    ) -> Self {
        let mut field = Self {
            kind,
            delta,
            width: width as f64,
            height: height as f64,
            speed: 1.0,
            modes: Vec::new(),
        };
        if kind == FlowKind::FourierTurbulence {
            field.modes = fourier_modes(field.width, seed);
        }
        if kind != FlowKind::PaperVortex {
            let peak = field.peak_speed();
            field.speed = if peak > 0.0 {
                max_displacement_px / peak
            } else {
                0.0
            };
        }
        field
    }

    /// The position one frame after frame `n` of a particle at `c` (relative to the image
    /// centre). The paper's vortex is its own map; the others integrate their velocity over
    /// one frame with the midpoint rule.
    pub fn map(&self, c: Vec2, n: FrameIndex) -> Vec2 {
        if self.kind == FlowKind::PaperVortex {
            return vortex_map(c, n, self.delta);
        }
        let half = c + self.velocity(c, n as f64) * 0.5;
        c + self.velocity(half, n as f64 + 0.5)
    }

    /// The velocity (px per frame) at `c` (relative to the image centre) at time `t` (frames).
    fn velocity(&self, c: Vec2, t: f64) -> Vec2 {
        let (w, h) = (self.width, self.height);
        let v = match self.kind {
            FlowKind::PaperVortex => vortex_map(c, t as FrameIndex, self.delta) - c,
            FlowKind::LambOseenPair => {
                let core = w / 10.0;
                let offset = Vec2::new(w / 6.0, 0.0);
                lamb_oseen(c - offset, core) - lamb_oseen(c + offset, core)
            }
            FlowKind::Stagnation => Vec2::new(c.x, -c.y) / (w / 2.0),
            FlowKind::ShearLayer => {
                let thickness = h / 10.0;
                let layer = (-(c.y / thickness).powi(2)).exp();
                Vec2::new(
                    (c.y / thickness).tanh(),
                    0.15 * layer * (TAU * c.x / (w / 2.0) - 0.05 * t).sin(),
                )
            }
            FlowKind::CellularArray => {
                let k = PI / (w / 8.0);
                Vec2::new(
                    (k * c.x).sin() * (k * c.y).cos(),
                    -(k * c.x).cos() * (k * c.y).sin(),
                )
            }
            FlowKind::FourierTurbulence => self.modes.iter().fold(Vec2::ZERO, |sum, mode| {
                let arg = mode.wave.x * c.x + mode.wave.y * c.y + mode.phase + mode.drift * t;
                // u = ∂ψ/∂y, v = −∂ψ/∂x for ψ = a·sin(arg).
                sum + Vec2::new(mode.wave.y, -mode.wave.x) * (mode.amplitude * arg.cos())
            }),
        };
        v * self.speed
    }

    /// The largest speed of the unscaled field over a 65 × 65 grid of the image at t = 0.
    fn peak_speed(&self) -> f64 {
        const STEPS: usize = 64;
        let mut peak = 0.0f64;
        for i in 0..=STEPS {
            for j in 0..=STEPS {
                let c = Vec2::new(
                    (i as f64 / STEPS as f64 - 0.5) * self.width,
                    (j as f64 / STEPS as f64 - 0.5) * self.height,
                );
                peak = peak.max(self.velocity(c, 0.0).norm());
            }
        }
        peak
    }
}

/// Velocity of a unit-circulation Lamb–Oseen vortex of core radius `core` at `r` from its
/// centre (counter-clockwise in image axes).
fn lamb_oseen(r: Vec2, core: f64) -> Vec2 {
    let r2 = r.x * r.x + r.y * r.y;
    if r2 == 0.0 {
        return Vec2::ZERO;
    }
    let u_theta_over_r = (1.0 - (-r2 / (core * core)).exp()) / (TAU * r2);
    Vec2::new(-r.y, r.x) * u_theta_over_r
}

/// The random modes of [`FlowKind::FourierTurbulence`] for an image `width` px wide.
fn fourier_modes(width: f64, seed: u64) -> Vec<Mode> {
    let mut rng = rng_stream(seed, FOURIER_STREAM_TAG);
    (0..FOURIER_MODES)
        .map(|_| {
            let wavelength = width / rng.random_range(2.0..8.0);
            let k = TAU / wavelength;
            let angle = rng.random_range(0.0..TAU);
            Mode {
                wave: Vec2::new(k * angle.cos(), k * angle.sin()),
                // Velocity amplitude a·k ∝ k^(−5/6): a k^(−5/3) energy spectrum.
                amplitude: k.powf(-11.0 / 6.0),
                phase: rng.random_range(0.0..TAU),
                drift: rng.random_range(-0.05..0.05),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn divergence(field: &FlowField, c: Vec2) -> f64 {
        let h = 1e-3;
        let dx =
            field.velocity(c + Vec2::new(h, 0.0), 3.0) - field.velocity(c - Vec2::new(h, 0.0), 3.0);
        let dy =
            field.velocity(c + Vec2::new(0.0, h), 3.0) - field.velocity(c - Vec2::new(0.0, h), 3.0);
        (dx.x + dy.y) / (2.0 * h)
    }

    #[test]
    fn every_family_flow_peaks_at_the_requested_speed() {
        for kind in FlowKind::ALL.into_iter().skip(1) {
            let field = FlowField::new(kind, 512, 512, 0.01, 6.0, 3);
            let peak = field.peak_speed();
            assert!((peak - 6.0).abs() < 1e-9, "{kind:?}: {peak}");
        }
    }

    #[test]
    fn incompressible_flows_have_no_divergence() {
        for kind in [
            FlowKind::LambOseenPair,
            FlowKind::CellularArray,
            FlowKind::FourierTurbulence,
            FlowKind::Stagnation,
        ] {
            let field = FlowField::new(kind, 512, 512, 0.01, 6.0, 3);
            for c in [Vec2::new(13.0, -40.0), Vec2::new(-100.0, 77.0)] {
                assert!(divergence(&field, c).abs() < 1e-6, "{kind:?} at {c:?}");
            }
        }
    }

    #[test]
    fn the_paper_vortex_is_eqs_13_to_16() {
        let field = FlowField::new(FlowKind::PaperVortex, 512, 512, 0.01, 6.0, 3);
        let c = Vec2::new(50.0, 0.0);
        assert_eq!(field.map(c, 50), vortex_map(c, 50, 0.01));
    }
}

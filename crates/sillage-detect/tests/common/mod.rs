//! A seeded renderer of Gaussian spots, shared by the tests and the benchmark (which includes
//! this file with `#[path]`, so it does not depend on `sillage-synth`).

use sillage_core::GrayImage;

/// SplitMix64: a tiny seeded generator, enough for test scenes.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u = self.uniform().max(1e-300);
        let v = self.uniform();
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

/// One spot: centre (px) and peak amplitude above the background (negative for dark spots).
#[derive(Debug, Clone, Copy)]
pub struct Spot {
    pub x: f64,
    pub y: f64,
    pub amplitude: f64,
}

/// Renders point-sampled Gaussian spots of σ = `sigma` on a uniform `background`, plus
/// Gaussian noise of std `noise` (none when 0).
pub fn render(
    width: usize,
    height: usize,
    background: f64,
    spots: &[Spot],
    sigma: f64,
    noise: f64,
    rng: &mut Rng,
) -> GrayImage {
    let mut data = vec![background; width * height];
    let reach = (4.0 * sigma).ceil() as isize;
    for s in spots {
        let (cx, cy) = (s.x.round() as isize, s.y.round() as isize);
        for y in (cy - reach).max(0)..(cy + reach + 1).min(height as isize) {
            for x in (cx - reach).max(0)..(cx + reach + 1).min(width as isize) {
                let (dx, dy) = (x as f64 - s.x, y as f64 - s.y);
                data[y as usize * width + x as usize] +=
                    s.amplitude * (-(dx * dx + dy * dy) / (2.0 * sigma * sigma)).exp();
            }
        }
    }
    if noise > 0.0 {
        for v in &mut data {
            *v += noise * rng.normal();
        }
    }
    GrayImage::from_vec(width, height, data.into_iter().map(|v| v as f32).collect()).unwrap()
}

//! Standard normal draws for the process noises, two per 64-bit random word.
//!
//! The ziggurat method of Marsaglia & Tsang (2000, "The Ziggurat Method for Generating Random
//! Variables", 128 layers, R = 3.442619855899, V = 9.91256303526217e-3) with independent bits
//! for the layer and the abscissa (Doornik 2005): each 32-bit half gives 7 bits of layer and
//! 25 bits of signed abscissa (resolution 2⁻²⁴ of the layer's width), so one `u64` yields two
//! normals on the fast path (97 % of draws). The wedges and the tail are sampled exactly with
//! fresh double-precision uniforms. This halves the cost of a draw against `rand_distr`'s
//! one-normal-per-word ziggurat, and the noise draws dominate the prediction step.

use std::sync::LazyLock;

use rand::{Rng, RngExt};
use sillage_core::RngStream;

/// Number of layers.
const LAYERS: usize = 128;
/// Start of the tail, R.
const TAIL_START: f64 = 3.442619855899;
/// Area of each layer, V.
const LAYER_AREA: f64 = 9.91256303526217e-3;
/// 2⁻²⁴: one step of the 25-bit signed abscissa.
const ABSCISSA_STEP: f64 = 1.0 / (1u32 << 24) as f64;

/// The unnormalised density `exp(−x²/2)`.
fn density(x: f64) -> f64 {
    (-0.5 * x * x).exp()
}

/// Layer edges `x[0] > x[1] = R > … > x[128] = 0` (x[0] = V/f(R): the base layer's width with
/// its tail folded in), the fast-path ratios `x[i+1]/x[i]` and the densities `f(x[i])`.
struct Ziggurat {
    edge: [f64; LAYERS + 1],
    ratio: [f64; LAYERS],
    density: [f64; LAYERS + 1],
}

impl Ziggurat {
    fn new() -> Self {
        let mut edge = [0.0; LAYERS + 1];
        edge[0] = LAYER_AREA / density(TAIL_START);
        edge[1] = TAIL_START;
        // Each layer has area V: x[i]·(f(x[i+1]) − f(x[i])) = V.
        for i in 2..LAYERS {
            edge[i] = (-2.0 * (LAYER_AREA / edge[i - 1] + density(edge[i - 1])).ln()).sqrt();
        }
        let ratio = std::array::from_fn(|i| edge[i + 1] / edge[i]);
        let density = edge.map(density);
        Self {
            edge,
            ratio,
            density,
        }
    }
}

static ZIGGURAT: LazyLock<Ziggurat> = LazyLock::new(Ziggurat::new);

/// A source of standard normal (and uniform) draws over one target's random stream.
pub struct Normals<'r> {
    rng: &'r mut RngStream,
    tables: &'static Ziggurat,
}

impl<'r> Normals<'r> {
    /// Draws from `rng`.
    pub fn new(rng: &'r mut RngStream) -> Self {
        Self {
            rng,
            tables: &ZIGGURAT,
        }
    }

    /// Two independent N(0, 1) draws.
    #[inline]
    pub fn pair(&mut self) -> (f64, f64) {
        let bits = self.rng.next_u64();
        (
            self.normal_from_bits(bits as u32),
            self.normal_from_bits((bits >> 32) as u32),
        )
    }

    /// A uniform draw in `[0, 1)`.
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        self.rng.random()
    }

    /// One normal from 32 random bits: the fast path, or the exact slow path.
    #[inline(always)]
    fn normal_from_bits(&mut self, bits: u32) -> f64 {
        let layer = (bits as usize) & (LAYERS - 1);
        let u = f64::from(bits >> 7) * ABSCISSA_STEP - 1.0;
        if u.abs() < self.tables.ratio[layer] {
            return u * self.tables.edge[layer];
        }
        self.slow(layer, u)
    }

    /// The wedge test of layers 1..127 and the tail of layer 0 (Marsaglia 1964), restarting
    /// with fresh bits on rejection.
    #[cold]
    fn slow(&mut self, mut layer: usize, mut u: f64) -> f64 {
        let t = self.tables;
        loop {
            if u.abs() < t.ratio[layer] {
                return u * t.edge[layer];
            }
            if layer == 0 {
                loop {
                    // 1 − U is in (0, 1], so both logarithms are finite.
                    let a = -(1.0 - self.uniform()).ln() / TAIL_START;
                    let b = -(1.0 - self.uniform()).ln();
                    if 2.0 * b > a * a {
                        return (TAIL_START + a).copysign(u);
                    }
                }
            }
            let x = u * t.edge[layer];
            let y = t.density[layer] + self.uniform() * (t.density[layer + 1] - t.density[layer]);
            if y < density(x) {
                return x;
            }
            let bits = self.rng.next_u64() as u32;
            layer = (bits as usize) & (LAYERS - 1);
            u = f64::from(bits >> 7) * ABSCISSA_STEP - 1.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_layers_close_at_zero() {
        let t = &*ZIGGURAT;
        // The recurrence must end at the top of the density: x[127] small, f(x[127]) + V/x[127]
        // ≈ 1 (R and V are a consistent pair).
        let top = LAYER_AREA / t.edge[LAYERS - 1] + t.density[LAYERS - 1];
        assert!((top - 1.0).abs() < 1e-9, "{top}");
        assert_eq!(t.edge[LAYERS], 0.0);
        assert!(t.edge.windows(2).all(|w| w[0] > w[1]));
    }
}

//! Standard normal draws for the process noises, generated in blocks by vectorised loops.
//!
//! The Box–Muller transform (Box & Muller 1958): two uniforms `U₁` in `(0, 1]` and `U₂` in
//! `[0, 1)` give the independent pair `√(−2 ln U₁)·(cos 2πU₂, sin 2πU₂)`. Each uniform is one
//! 32-bit word from `LANES` xoshiro128++ generators stepped side by side, seeded from the
//! target's own stream the first time a [`Normals`] needs them; the radius is therefore
//! bounded by √(64 ln 2) ≈ 6.66 (a larger radius has probability 2⁻³² ≈ 2.3·10⁻¹⁰ per pair).
//!
//! A block of `BLOCK` pairs is drawn at once in one branch-free loop (no table, no
//! rejection), which the compiler vectorises: AVX-512 or AVX2 where the CPU has them, with the
//! same bits on every path. The logarithm, cosine and sine are single precision (errors below
//! 3·10⁻⁷, far below any noise they scale), which doubles the lanes per vector; the draws are
//! widened to `f64` where they are used. Measured against the one-at-a-time ziggurat this
//! replaced in BENCHMARKS.md ("Particle-filter engine", run 6).

use rand::RngExt;
use sillage_core::RngStream;

use crate::fast_math::{cos_sin_turn_f32, ln_unit_f32};
use crate::lanes::{LANES, LaneGenerators};

/// Pairs drawn per block (a multiple of [`LANES`]).
pub(crate) const BLOCK: usize = 32;
/// 2⁻³²: one step of a 32-bit word as a uniform.
const WORD_STEP: f32 = 1.0 / 4_294_967_296.0;

/// One block of pairs: the first and the second normal of each pair, in single precision
/// (so that the loop that draws them is single precision throughout: twice the lanes).
#[derive(Clone)]
pub(crate) struct Block {
    /// First draw of each pair.
    pub(crate) first: [f32; BLOCK],
    /// Second draw of each pair.
    pub(crate) second: [f32; BLOCK],
}

impl Block {
    /// A block of zeros, to be filled by [`Normals::fill_block`].
    pub(crate) const ZERO: Block = Block {
        first: [0.0; BLOCK],
        second: [0.0; BLOCK],
    };

    /// Pair `j` as `f64`.
    #[inline(always)]
    pub(crate) fn pair(&self, j: usize) -> (f64, f64) {
        (f64::from(self.first[j]), f64::from(self.second[j]))
    }
}

/// Fills `block` from `generators`: two words per pair, element-wise.
#[inline(always)]
fn box_muller(generators: &mut LaneGenerators, block: &mut Block) {
    for (first, second) in block
        .first
        .chunks_exact_mut(LANES)
        .zip(block.second.chunks_exact_mut(LANES))
    {
        let radial = generators.next();
        let angular = generators.next();
        for l in 0..LANES {
            let u = (radial[l] as f32 + 1.0) * WORD_STEP;
            let radius = (-2.0 * ln_unit_f32(u)).sqrt();
            let (cos, sin) = cos_sin_turn_f32(angular[l]);
            first[l] = radius * cos;
            second[l] = radius * sin;
        }
    }
}

sillage_core::multiversion! {
    /// [`box_muller`] on the widest SIMD the CPU offers.
    fn box_muller_widest(generators: &mut LaneGenerators, block: &mut Block) => box_muller
}

/// A source of standard normal (and uniform) draws over one target's random stream.
pub struct Normals<'r> {
    rng: &'r mut RngStream,
    generators: Option<LaneGenerators>,
    block: Block,
    next: usize,
}

impl<'r> Normals<'r> {
    /// Draws from `rng`.
    pub fn new(rng: &'r mut RngStream) -> Self {
        Self {
            rng,
            generators: None,
            block: Block::ZERO,
            next: BLOCK,
        }
    }

    /// Two independent N(0, 1) draws.
    #[inline]
    pub fn pair(&mut self) -> (f64, f64) {
        if self.next >= BLOCK {
            self.refill();
        }
        let pair = self.block.pair(self.next);
        self.next += 1;
        pair
    }

    /// A uniform draw in `[0, 1)`.
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        self.rng.random()
    }

    /// Fills `block` with [`BLOCK`] fresh pairs (for loops over many particles at once).
    pub(crate) fn fill_block(&mut self, block: &mut Block) {
        let generators = self
            .generators
            .get_or_insert_with(|| LaneGenerators::seeded(self.rng));
        box_muller_widest(generators, block);
    }

    /// Draws the next block of pairs for [`Normals::pair`].
    #[cold]
    fn refill(&mut self) {
        let mut block = Block::ZERO;
        self.fill_block(&mut block);
        self.block = block;
        self.next = 0;
    }
}

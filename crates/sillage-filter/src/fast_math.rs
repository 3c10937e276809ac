//! Branch-free `exp`, `ln` and `cos`/`sin` for the particle loops, written so that the compiler
//! can vectorise them (no call, no branch, no table lookup): the weights' normalisation takes
//! one exponential per particle (the C library's scalar calls were 11 % of a SIR step), the
//! normal draws a logarithm and a cosine–sine pair per two draws, the multinomial resampling
//! a logarithm per particle.
//!
//! Classic range reductions (Cody & Waite, as in Cephes and fdlibm) with polynomials long
//! enough for a relative error below 10⁻¹⁴ for the weights' `exp`; the draws' `ln`, `cos` and
//! `sin` are single precision (errors below 3·10⁻⁷, far below any noise or spacing they
//! shape), which doubles the lanes per vector and keeps division and square root cheap. The result is the same on every machine (plain IEEE additions and multiplications,
//! no fused operations), so the filters stay reproducible.

/// `ln 2` split in a high part with zeros in its low bits (so `k·LN2_HI` is exact for
/// |k| < 2¹¹) and the rest (fdlibm's constants).
const LN2_HI: f64 = 6.931_471_803_691_238e-1;
/// The rest of `ln 2` after [`LN2_HI`].
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
/// Below this, `exp` is under the smallest normal number and is returned as 0.
const EXP_FLOOR: f64 = -708.0;
/// 1.5·2⁵²: adding it rounds a number below 2⁵¹ in magnitude to an integer (ties to even),
/// which then sits in the low bits of the sum (SSE2 has no rounding or 64-bit conversion
/// instructions; this keeps the loops vectorisable).
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// `eˣ` for `x ≤ 0` (−∞ and anything below −708 give 0; NaN gives 0): `x = k·ln 2 + r`,
/// `|r| ≤ ln 2 / 2`, `eʳ` by its Taylor series to degree 13, then the exponent `k` put in
/// the bits. Relative error < 10⁻¹⁴ against `f64::exp`.
#[inline(always)]
pub(crate) fn exp_nonpositive(x: f64) -> f64 {
    // NaN and −∞ fail the comparison: replaced by 0, and their result by 0 below.
    let inside = x >= EXP_FLOOR;
    let y = if inside { x } else { 0.0 };
    let shifted = y * std::f64::consts::LOG2_E + ROUNDER;
    let k = shifted - ROUNDER;
    let r = (y - k * LN2_HI) - k * LN2_LO;
    let mut p = 1.0 / 6_227_020_800.0; // 1/13!
    for inverse_factorial in [
        1.0 / 479_001_600.0,
        1.0 / 39_916_800.0,
        1.0 / 3_628_800.0,
        1.0 / 362_880.0,
        1.0 / 40_320.0,
        1.0 / 5_040.0,
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
        1.0,
        1.0,
    ] {
        p = p * r + inverse_factorial;
    }
    // k in [−1022, 0] is in the low bits of `shifted`: 2ᵏ is a normal number whose exponent
    // field is k + 1023 (the higher bits shift out).
    let scale = f64::from_bits(shifted.to_bits().wrapping_add(1023) << 52);
    if inside { p * scale } else { 0.0 }
}

/// `ln u` for a normal `f32` `u` in `(0, 1]`, branch-free for vectorised loops: `u = 2ᵉ·m`
/// with `m` in `[√½, √2)`, `ln m = 2·atanh(s)` with `s = (m − 1)/(m + 1)`, `|s| ≤ 0.172`, by its
/// odd series to `s⁹` (truncation < 10⁻⁷ relative, single precision's own rounding).
#[inline(always)]
pub(crate) fn ln_unit_f32(u: f32) -> f32 {
    let bits = u.to_bits();
    // The biased exponent, and the mantissa bits with the exponent of 1: m in [1, 2).
    let biased = ((bits >> 23) & 0xff) as i32;
    let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    let high = m > std::f32::consts::SQRT_2;
    let m = if high { 0.5 * m } else { m };
    let e = (biased - 127 + i32::from(high)) as f32;
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let mut p = 1.0 / 9.0;
    for inverse_odd in [1.0 / 7.0, 1.0 / 5.0, 1.0 / 3.0, 1.0] {
        p = p * s2 + inverse_odd;
    }
    e * std::f32::consts::LN_2 + 2.0 * s * p
}

/// `(cos 2πv, sin 2πv)` in single precision for the turn `v = word·2⁻³²` in `[0, 1)`,
/// branch-free: the nearest quarter turn `q` and the rest `θ` in `[−π/4, π/4)` come exactly
/// from the word's bits, then Taylor polynomials of `cos θ` to `θ⁸` and `sin θ` to `θ⁹`
/// (truncation < 3·10⁻⁸), rotated by `q` quarter turns.
#[inline(always)]
pub(crate) fn cos_sin_turn_f32(word: u32) -> (f32, f32) {
    const EIGHTH: u32 = 1 << 29;
    let shifted = word.wrapping_add(EIGHTH);
    let quarter = shifted >> 30;
    let rest = (shifted & ((1 << 30) - 1)) as i32 - EIGHTH as i32;
    let theta = rest as f32 * (std::f32::consts::TAU / 4_294_967_296.0);
    let t2 = theta * theta;
    // cos θ = Σ (−1)ᵏ θ²ᵏ/(2k)!, sin θ = θ·Σ (−1)ᵏ θ²ᵏ/(2k+1)!, k ≤ 4.
    let mut cos = 1.0 / 40_320.0;
    for coefficient in [-1.0 / 720.0, 1.0 / 24.0, -0.5, 1.0] {
        cos = cos * t2 + coefficient;
    }
    let mut sin = 1.0 / 362_880.0;
    for coefficient in [-1.0 / 5_040.0, 1.0 / 120.0, -1.0 / 6.0, 1.0] {
        sin = sin * t2 + coefficient;
    }
    let sin = sin * theta;
    // Rotating (cos θ, sin θ) by q quarter turns: q = 1 → (−sin, cos), 2 → (−cos, −sin),
    // 3 → (sin, −cos).
    let swap = quarter & 1 == 1;
    let (c, s) = if swap { (sin, cos) } else { (cos, sin) };
    let negate_cos = quarter == 1 || quarter == 2;
    let negate_sin = quarter >= 2;
    (
        if negate_cos { -c } else { c },
        if negate_sin { -s } else { s },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;
    use sillage_core::rng_stream;

    #[test]
    fn exp_matches_the_library_over_its_domain() {
        let mut rng = rng_stream(1, 1);
        let mut worst: f64 = 0.0;
        for i in 0..200_000 {
            // Uniform over [−708, 0] and dense near 0, where most weights are.
            let x = if i % 2 == 0 {
                -708.0 * rng.random::<f64>()
            } else {
                -rng.random::<f64>() * 2.0
            };
            let (ours, exact) = (exp_nonpositive(x), x.exp());
            worst = worst.max(((ours - exact) / exact).abs());
        }
        assert!(worst < 1e-14, "worst relative error {worst:e}");
        assert_eq!(exp_nonpositive(0.0), 1.0);
        assert_eq!(exp_nonpositive(f64::NEG_INFINITY), 0.0);
        assert_eq!(exp_nonpositive(-709.0), 0.0);
        assert_eq!(exp_nonpositive(f64::NAN), 0.0);
    }

    #[test]
    fn ln_matches_the_library_on_the_unit_interval() {
        let mut rng = rng_stream(2, 3);
        let mut worst: f64 = 0.0;
        for i in 0..200_000 {
            // Uniform over (0, 1], and 2⁻³² steps near 0 where the exponentials' tails come from.
            let u = if i % 2 == 0 {
                1.0 - rng.random::<f32>()
            } else {
                (rng.random::<u32>() % 1_000 + 1) as f32 * 2f32.powi(-32)
            };
            let (ours, exact) = (f64::from(ln_unit_f32(u)), f64::from(u).ln());
            let error = (ours - exact).abs() / exact.abs().max(1e-30);
            worst = worst.max(if exact == 0.0 { ours.abs() } else { error });
        }
        assert!(worst < 3e-7, "worst relative error {worst:e}");
        assert_eq!(ln_unit_f32(1.0), 0.0);
    }

    #[test]
    fn cos_sin_match_the_library_on_every_quarter() {
        let mut rng = rng_stream(4, 5);
        let mut worst: f64 = 0.0;
        for i in 0..200_000u32 {
            // Random turns, and the edges of the eighths where the quarter changes.
            let word = if i % 4 == 0 {
                ((i / 4 % 8) << 29).wrapping_add(i / 32 % 3).wrapping_sub(1)
            } else {
                rng.random::<u32>()
            };
            let angle = f64::from(word) * std::f64::consts::TAU / 4_294_967_296.0;
            let (cos, sin) = cos_sin_turn_f32(word);
            let error = (f64::from(cos) - angle.cos())
                .abs()
                .max((f64::from(sin) - angle.sin()).abs());
            worst = worst.max(error);
        }
        assert!(worst < 3e-7, "worst absolute error {worst:e}");
        assert_eq!(cos_sin_turn_f32(0), (1.0, 0.0));
    }
}

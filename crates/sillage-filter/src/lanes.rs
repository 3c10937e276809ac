//! Random 32-bit words from [`LANES`] generators stepped side by side, for the loops that draw
//! a block of variates at once (the normals of the prediction, the exponentials of the
//! resampling): one step of every generator is element-wise integer arithmetic, which the
//! compiler vectorises.

use rand::Rng;
use sillage_core::RngStream;

/// Generators stepped side by side (sixteen 32-bit lanes fill one AVX-512 register).
pub(crate) const LANES: usize = 16;

/// [`LANES`] xoshiro128++ generators (Blackman & Vigna 2018), state word `k` of lane `l` in `s[k][l]`, so that one
/// step of all of them is element-wise arithmetic over arrays.
#[derive(Clone)]
pub(crate) struct LaneGenerators {
    s: [[u32; LANES]; 4],
}

impl LaneGenerators {
    /// States drawn from `rng` (an all-zero state, which xoshiro never leaves, is replaced).
    pub(crate) fn seeded(rng: &mut RngStream) -> Self {
        let mut s = [[0; LANES]; 4];
        for word in &mut s {
            for pair in word.chunks_exact_mut(2) {
                let bits = rng.next_u64();
                pair[0] = bits as u32;
                pair[1] = (bits >> 32) as u32;
            }
        }
        for lane in 0..LANES {
            if s.iter().all(|word| word[lane] == 0) {
                s[0][lane] = 1;
            }
        }
        Self { s }
    }

    /// One output word of every lane, and the step of every state.
    #[inline(always)]
    pub(crate) fn next(&mut self) -> [u32; LANES] {
        let [s0, s1, s2, s3] = &mut self.s;
        let mut out = [0; LANES];
        for l in 0..LANES {
            out[l] = s0[l].wrapping_add(s3[l]).rotate_left(7).wrapping_add(s0[l]);
            let t = s1[l] << 9;
            s2[l] ^= s0[l];
            s3[l] ^= s1[l];
            s1[l] ^= s2[l];
            s0[l] ^= s3[l];
            s2[l] ^= t;
            s3[l] = s3[l].rotate_left(11);
        }
        out
    }
}

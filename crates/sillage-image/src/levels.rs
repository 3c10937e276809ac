//! 8-bit grey levels: frames decoded from 8-bit images hold only the values `k / 255`
//! (`f32::from(k) / 255.0`, `k` in `0..=255`). Algorithms made only of comparisons (grey
//! morphology, reconstruction) give the same bits on the levels `k` as on those values, since
//! `k ↦ k / 255` is increasing, and the levels take a quarter of the memory and four times the
//! SIMD lanes; sums of levels are exact in integers.

use sillage_core::{GrayImage, Image};

/// Writes into `dst` (reshaped) the level `k` of each pixel `f32::from(k) / 255.0` of `src`;
/// false (and `dst` unspecified) as soon as a pixel is not exactly such a value (NaN, −0,
/// out of `[0, 1]` or between levels).
pub fn encode_levels(src: &GrayImage, dst: &mut Image<u8>) -> bool {
    dst.reshape(src.width(), src.height());
    let (src, dst) = (src.as_slice(), dst.as_mut_slice());
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx512bw") {
            // SAFETY: the CPU supports AVX-512F and AVX-512BW, checked just above.
            return unsafe { encode_avx512(src, dst) };
        }
    }
    encode(src, dst)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw")]
fn encode_avx512(src: &[f32], dst: &mut [u8]) -> bool {
    encode(src, dst)
}

/// 1.5·2²³: `x + ROUNDING_SHIFT` has `round(x)` in its low mantissa bits for `|x| < 2²²`.
const ROUNDING_SHIFT: f32 = 12_582_912.0;

/// See [`encode_levels`]; `dst` has the length of `src`.
#[inline(always)]
fn encode(src: &[f32], dst: &mut [u8]) -> bool {
    const CHUNK: usize = 64;
    for (values, out) in src.chunks(CHUNK).zip(dst.chunks_mut(CHUNK)) {
        let mut exact = true;
        for (&v, b) in values.iter().zip(out.iter_mut()) {
            // The nearest level for values in [0, 1]: adding 1.5·2²³ rounds `255·v` to an
            // integer held in the low mantissa bits (plain bit operations, which vectorise,
            // where a saturating float-to-int cast does not). Anything else (NaN, negative,
            // above 1, between levels) gives some byte that fails the check below.
            let k = ((v * 255.0 + ROUNDING_SHIFT).to_bits() & 0xff) as u8;
            exact &= (f32::from(k) / 255.0).to_bits() == v.to_bits();
            *b = k;
        }
        if !exact {
            return false;
        }
    }
    true
}

/// `dst` (reshaped) `= f32::from(k) / 255.0` for each level `k` of `src` (the values
/// [`encode_levels`] reads).
pub fn decode_levels(src: &Image<u8>, dst: &mut GrayImage) {
    dst.reshape(src.width(), src.height());
    let (src, dst) = (src.as_slice(), dst.as_mut_slice());
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx512bw") {
            // SAFETY: the CPU supports AVX-512F and AVX-512BW, checked just above.
            unsafe { decode_avx512(src, dst) };
            return;
        }
    }
    decode(src, dst);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw")]
fn decode_avx512(src: &[u8], dst: &mut [f32]) {
    decode(src, dst);
}

/// See [`decode_levels`].
#[inline(always)]
fn decode(src: &[u8], dst: &mut [f32]) {
    for (d, &k) in dst.iter_mut().zip(src) {
        *d = f32::from(k) / 255.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every level round-trips; anything that is not exactly a level is refused.
    #[test]
    fn levels_round_trip_and_other_values_are_refused() {
        let levels: Vec<f32> = (0..=255u8).map(|k| f32::from(k) / 255.0).collect();
        let src = GrayImage::from_vec(256, 1, levels.clone()).unwrap();
        let mut bytes = Image::default();
        assert!(encode_levels(&src, &mut bytes));
        assert!(bytes.as_slice().iter().copied().eq(0..=255u8));
        let mut back = GrayImage::default();
        decode_levels(&bytes, &mut back);
        assert!(back == src);
        let mut nudged = levels;
        nudged[77] = f32::from_bits(nudged[77].to_bits() + 1);
        let nudged = GrayImage::from_vec(256, 1, nudged).unwrap();
        assert!(!encode_levels(&nudged, &mut bytes));
        for bad in [f32::NAN, -0.0, 1.5, -1.0 / 255.0] {
            let image = GrayImage::from_vec(2, 1, vec![0.0, bad]).unwrap();
            assert!(!encode_levels(&image, &mut bytes), "{bad}");
        }
    }
}

//! Seeded inputs shared by the integration tests.

use sillage_core::GrayImage;

/// Seeded pseudo-random image with values in [0, 1) (SplitMix64).
pub fn random_image(width: usize, height: usize, seed: u64) -> GrayImage {
    let mut state = seed;
    let data = (0..width * height)
        .map(|_| {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        })
        .collect();
    GrayImage::from_vec(width, height, data).unwrap()
}

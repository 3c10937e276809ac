//! Per-pixel SIFT loops compiled for the widest SIMD the CPU offers, so that the compiler's
//! vectorisation of the DoG extremum search and of the gradients uses AVX-512 or AVX2 where
//! present. Only for loops whose results do not depend on the vector width (exact comparisons,
//! element-wise IEEE arithmetic, never reassociated or fused), so every path gives the same
//! bits.

/// Defines `fn $name(args)` that calls the `#[inline(always)]` function `$kernel` from a copy
/// compiled with AVX-512F, else AVX2, else the baseline, chosen at run time.
macro_rules! multiversion {
    ($(#[$doc:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),*) => $kernel:path) => {
        $(#[$doc])*
        $vis fn $name($($arg: $ty),*) {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f")]
                fn avx512($($arg: $ty),*) {
                    $kernel($($arg),*)
                }
                #[target_feature(enable = "avx2")]
                fn avx2($($arg: $ty),*) {
                    $kernel($($arg),*)
                }
                if std::is_x86_feature_detected!("avx512f") {
                    // SAFETY: the CPU supports AVX-512F, checked just above.
                    return unsafe { avx512($($arg),*) };
                }
                if std::is_x86_feature_detected!("avx2") {
                    // SAFETY: the CPU supports AVX2, checked just above.
                    return unsafe { avx2($($arg),*) };
                }
            }
            $kernel($($arg),*)
        }
    };
}

pub(crate) use multiversion;

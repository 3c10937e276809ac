//! Loops compiled for the widest SIMD the CPU offers, chosen at run time, so that the
//! compiler's vectorisation uses AVX-512 or AVX2 where present while the default build targets
//! the x86-64 baseline. Only for loops whose results do not depend on the vector width (exact
//! comparisons, integer arithmetic, element-wise IEEE arithmetic never reassociated or fused),
//! so every path gives the same bits.

/// Defines `fn $name(args)` that calls the `#[inline(always)]` function `$kernel` from a copy
/// compiled with AVX-512F, else AVX2, else the baseline, chosen at run time.
#[macro_export]
macro_rules! multiversion {
    ($(#[$doc:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),*) $(-> $ret:ty)? => $kernel:path) => {
        $(#[$doc])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f")]
                fn avx512($($arg: $ty),*) $(-> $ret)? {
                    $kernel($($arg),*)
                }
                #[target_feature(enable = "avx2")]
                fn avx2($($arg: $ty),*) $(-> $ret)? {
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

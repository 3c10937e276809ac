//! The band engine behind every Gaussian filter of this crate: separable symmetric FIR passes,
//! fused per tile so that the data stays in L1.
//!
//! The image is cut into bands of [`BAND_ROWS`] output rows (the unit of parallel work) and
//! each band into strips of at most [`strip_width`] columns. For one strip the engine walks the
//! needed input rows once: it blurs each row segment horizontally with each kernel into a
//! ring buffer of `2R+1` strip rows, and as soon as the ring holds the `2R+1` rows around an
//! output row, blurs vertically from the ring into the output. A strip's rings hold
//! `O(R · strip)` floats, sized to stay in L1, so the vertical pass — the one
//! that reads many rows per output — runs at L1 bandwidth; the image is read once and written
//! once. Interior strips read the source rows in place; only the two border strips copy their
//! row segments into a small padded buffer with the reflect-101 border. Bands run in parallel
//! with rayon, each with its own slice of an owned scratch buffer (no allocation once grown).
//!
//! Fast methods: the kernels are symmetric, so taps are folded by pairs, `w_j·(x[i−j] +
//! x[i+j])`, halving the multiplies; the SIMD paths keep 8 vectors of outputs in registers
//! across all taps; a difference of Gaussians blurs each row segment with both kernels in one
//! sweep (each tap pair loaded and summed once for both), and runs both vertical passes with
//! both accumulator sets in registers, writing `G₁ − G₂` once.
//!
//! Every output value is computed by the same sequence of f32 operations whatever the band,
//! the strip or the thread (no reduction across pixels, no fused multiply-add on any path), so
//! results are bit-identical whatever the number of threads and whichever SIMD path runs.

use rayon::prelude::*;
use sillage_core::GrayImage;

/// Output rows per band: large enough that the `2R` halo rows recomputed per band cost little
/// (≤ 7 % at R = 8), small enough that a 2048-row image gives 8 jobs. Fixed (not derived from
/// the thread count), though results would not depend on it anyway.
const BAND_ROWS: usize = 256;

/// Widest strip, in columns.
const MAX_STRIP: usize = 256;

/// Strip widths are multiples of this: a whole number of the SIMD paths' register blocks
/// (8 vectors of 16 lanes on AVX-512), whose remainder loop is slow.
const STRIP_STEP: usize = 128;

/// Bytes the rings of a strip may take, leaving room in a 32 KiB L1 for the row segment
/// being read and the output row.
const RING_BUDGET_BYTES: usize = 24 * 1024;

/// Columns per strip for `combine`: the widest multiple of [`STRIP_STEP`] up to
/// [`MAX_STRIP`] whose rings fit in [`RING_BUDGET_BYTES`] (never less than one step). The
/// two 17-row rings of a DoG at δ = 2 take 34 KiB at 256 columns, more than L1 holds: 128
/// columns ran that DoG 1.05-1.23× faster (BENCHMARKS.md), while a single Gaussian of
/// σ ≤ 2 keeps 256 columns, which were faster for it.
fn strip_width(combine: &Combine<'_>) -> usize {
    let ring_row_bytes = combine.kernel_count() * (2 * combine.radius() + 1) * 4;
    let fitting = RING_BUDGET_BYTES / ring_row_bytes / STRIP_STEP * STRIP_STEP;
    fitting.clamp(STRIP_STEP, MAX_STRIP)
}

/// Reflect-101 index (`… 2 1 | 0 1 2 … n-1 | n-2 n-3 …`, OpenCV's default border), repeated as
/// often as needed so that kernels wider than the image stay defined; `n` must be ≥ 1.
pub(crate) fn reflect101(i: isize, n: usize) -> usize {
    if n == 1 {
        return 0;
    }
    let period = 2 * (n as isize - 1);
    let m = i.rem_euclid(period);
    if m < n as isize {
        m as usize
    } else {
        (period - m) as usize
    }
}

/// How the outputs of the kernels combine into the output pixel.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Combine<'k> {
    /// One kernel: the blur itself.
    Single(&'k [f32]),
    /// Two kernels `(a, b)`: `a·I − b·I` (a difference of Gaussians).
    Difference(&'k [f32], &'k [f32]),
}

impl Combine<'_> {
    /// Largest kernel radius (the ring buffer and padding size).
    fn radius(&self) -> usize {
        match self {
            Combine::Single(k) => k.len() - 1,
            Combine::Difference(a, b) => a.len().max(b.len()) - 1,
        }
    }

    fn kernel_count(&self) -> usize {
        match self {
            Combine::Single(_) => 1,
            Combine::Difference(..) => 2,
        }
    }
}

/// Floats of scratch one band needs: a padded row segment and one ring per kernel.
fn band_scratch_len(combine: &Combine<'_>) -> usize {
    let r = combine.radius();
    let strip = strip_width(combine);
    (strip + 2 * r) + combine.kernel_count() * (2 * r + 1) * strip
}

/// Filters `src` into `dst` (reshaped to the size of `src`) with `combine`, growing `scratch`
/// if needed. Kernels are half-kernels: `k[0]` is the centre weight, `k[j]` the weight at ±j.
pub(crate) fn filter(
    src: &GrayImage,
    dst: &mut GrayImage,
    combine: Combine<'_>,
    scratch: &mut Vec<f32>,
) {
    let (width, height) = src.dimensions();
    dst.reshape(width, height);
    if width == 0 || height == 0 {
        return;
    }
    let per_band = band_scratch_len(&combine);
    let bands = height.div_ceil(BAND_ROWS);
    if scratch.len() < per_band * bands {
        scratch.resize(per_band * bands, 0.0);
    }
    dst.as_mut_slice()
        .par_chunks_mut(BAND_ROWS * width)
        .zip(scratch.par_chunks_mut(per_band))
        .enumerate()
        .for_each(|(band, (out, scratch))| {
            run_band(src, band * BAND_ROWS, out, combine, scratch);
        });
}

/// Runs one band on the widest SIMD path the CPU offers (same results on every path).
fn run_band(
    src: &GrayImage,
    y0: usize,
    out: &mut [f32],
    combine: Combine<'_>,
    scratch: &mut [f32],
) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU supports AVX-512F, checked just above.
            unsafe { band_avx512(src, y0, out, combine, scratch) };
            return;
        }
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            unsafe { band_avx2(src, y0, out, combine, scratch) };
            return;
        }
    }
    band::<Portable>(src, y0, out, combine, scratch);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn band_avx2(
    src: &GrayImage,
    y0: usize,
    out: &mut [f32],
    combine: Combine<'_>,
    scratch: &mut [f32],
) {
    band::<simd::Avx2>(src, y0, out, combine, scratch);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn band_avx512(
    src: &GrayImage,
    y0: usize,
    out: &mut [f32],
    combine: Combine<'_>,
    scratch: &mut [f32],
) {
    band::<simd::Avx512>(src, y0, out, combine, scratch);
}

/// One band: output rows `y0 .. y0 + out.len() / width`, strip by strip.
/// `F` is [`Portable`] or a SIMD version of it computing the same values.
#[inline(always)]
fn band<F: Fir>(
    src: &GrayImage,
    y0: usize,
    out: &mut [f32],
    combine: Combine<'_>,
    scratch: &mut [f32],
) {
    let (width, height) = src.dimensions();
    let r = combine.radius();
    let slots = 2 * r + 1;
    let rows = out.len() / width;
    let strip = strip_width(&combine);
    let (pad, rings) = scratch.split_at_mut(strip + 2 * r);
    let (ring_a, ring_b) = rings.split_at_mut(slots * strip);
    let (ka, kb) = match combine {
        Combine::Single(k) => (k, None),
        Combine::Difference(a, b) => (a, Some(b)),
    };
    let mut x0 = 0;
    while x0 < width {
        let sw = strip.min(width - x0);
        // Virtual rows v = y0 - r .. y0 + rows + r, stored in ring slot (v - (y0 - r)) % slots.
        let mut slot = 0;
        for i in 0..rows + 2 * r {
            let v = (y0 + i) as isize - r as isize;
            let row = src.row(reflect101(v, height));
            let ahead = src.row(reflect101(v + PREFETCH_ROWS as isize, height));
            prefetch(&ahead[x0.saturating_sub(r)..(x0 + sw + r).min(width)]);
            // Columns x0 - r .. x0 + sw + r of the row, read in place when inside it.
            let input: &[f32] = if x0 >= r && x0 + sw + r <= width {
                &row[x0 - r..x0 + sw + r]
            } else {
                pad_segment(row, x0, sw, r, pad);
                &pad[..sw + 2 * r]
            };
            let horizontal = |k: usize| (&input[r - k..], &input[r + k..]);
            let out_a = &mut ring_a[slot * sw..(slot + 1) * sw];
            match kb {
                // Both blurs from the same loads: each tap-pair sum `a + b` is formed once.
                Some(kb) => F::fir_pair(
                    out_a,
                    &mut ring_b[slot * sw..(slot + 1) * sw],
                    ka,
                    kb,
                    horizontal,
                ),
                None => F::fir::<false>(out_a, ka, horizontal),
            }
            slot = if slot + 1 == slots { 0 } else { slot + 1 };
            if i < 2 * r {
                continue;
            }
            // Output row y = v - r has all its 2r+1 source rows in the ring; its centre slot
            // is the one written r rows ago.
            let y = i - 2 * r;
            let centre = (i - r) % slots;
            if let Some(ahead) = out.get((y + PREFETCH_ROWS) * width + x0..) {
                prefetch(&ahead[..sw.min(ahead.len())]);
            }
            let out_row = &mut out[y * width + x0..y * width + x0 + sw];
            let taps_a = ring_taps(ring_a, sw, centre, slots);
            match kb {
                Some(kb) => F::fir_diff(
                    out_row,
                    ka,
                    taps_a,
                    kb,
                    ring_taps(ring_b, sw, centre, slots),
                ),
                None => F::fir::<false>(out_row, ka, taps_a),
            }
        }
        x0 += sw;
    }
}

/// How many rows ahead a strip asks for its input and its output rows: a strip reads and
/// writes a few hundred bytes of each row, a stride the hardware prefetcher does not follow,
/// so each row would otherwise come from memory while the filter waits (perf: the
/// horizontal pass's first loads and the output stores were the hottest instructions). Input
/// prefetch gave 1.1-1.2× on the 2048² DoG, output prefetch 1.28× more (BENCHMARKS.md).
const PREFETCH_ROWS: usize = 2;

/// Asks the CPU to bring `values` into cache (a hint: no effect on results).
#[inline(always)]
fn prefetch(values: &[f32]) {
    #[cfg(target_arch = "x86_64")]
    for line in values.chunks(16) {
        // SAFETY: a prefetch never faults and reads nothing architecturally; the address is
        // inside a live slice.
        unsafe {
            std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
                line.as_ptr().cast(),
            )
        };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = values;
}

/// The rows `k` above and below ring slot `centre`, for the vertical pass.
#[inline(always)]
fn ring_taps<'a>(
    ring: &'a [f32],
    width: usize,
    centre: usize,
    slots: usize,
) -> impl Fn(usize) -> (&'a [f32], &'a [f32]) {
    move |k| {
        let up = if centre >= k {
            centre - k
        } else {
            centre + slots - k
        };
        let down = if centre + k < slots {
            centre + k
        } else {
            centre + k - slots
        };
        (
            &ring[up * width..(up + 1) * width],
            &ring[down * width..(down + 1) * width],
        )
    }
}

/// Writes columns `x0 - r .. x0 + sw + r` of `row` into `pad[.. sw + 2r]`, reflect-101 outside
/// the row: the part inside is copied, only the (at most `r`-wide, or all when the kernel is
/// wider than the row) outside ends are reflected one by one.
#[inline(always)]
fn pad_segment(row: &[f32], x0: usize, sw: usize, r: usize, pad: &mut [f32]) {
    let n = row.len() as isize;
    let start = x0 as isize - r as isize;
    let end = (x0 + sw + r) as isize;
    let (lo, hi) = (start.max(0), end.min(n));
    if lo < hi {
        pad[(lo - start) as usize..(hi - start) as usize]
            .copy_from_slice(&row[lo as usize..hi as usize]);
    }
    for i in (start..lo).chain(hi.max(lo)..end) {
        pad[(i - start) as usize] = row[reflect101(i, row.len())];
    }
}

/// A symmetric FIR: `f[x] = k[0]·c[x] + Σ_j k[j]·(a_j[x] + b_j[x])`, `j` ascending, where
/// `(a_j, b_j) = taps(j)` (each at least `out.len()` long) and `c = taps(0).0`; then
/// `out[x] = f[x]`, or `out[x] = out[x] − f[x]` when `SUB`. The taps come from a row segment
/// (horizontal pass) or from ring rows (vertical pass). Implementations must perform exactly
/// these f32 operations in this order for every output.
trait Fir {
    fn fir<'a, const SUB: bool>(
        out: &mut [f32],
        kernel: &[f32],
        taps: impl Fn(usize) -> (&'a [f32], &'a [f32]),
    );

    /// `fir::<false>(out_a, ka, taps)` and `fir::<false>(out_b, kb, taps)` (same values, bit
    /// for bit), sharing the loads and the tap-pair sums of the two kernels.
    fn fir_pair<'a>(
        out_a: &mut [f32],
        out_b: &mut [f32],
        ka: &[f32],
        kb: &[f32],
        taps: impl Fn(usize) -> (&'a [f32], &'a [f32]),
    );

    /// `fir::<false>(out, ka, taps_a)` then `fir::<true>(out, kb, taps_b)` (same values, bit
    /// for bit), without storing and reloading the first result.
    fn fir_diff<'a, 'b>(
        out: &mut [f32],
        ka: &[f32],
        taps_a: impl Fn(usize) -> (&'a [f32], &'a [f32]),
        kb: &[f32],
        taps_b: impl Fn(usize) -> (&'b [f32], &'b [f32]),
    );
}

/// Plain Rust: chunks of [`Portable::CHUNK`] outputs accumulate in a stack buffer, one sweep
/// per tap pair, a loop the compiler vectorises for the target's baseline SIMD.
struct Portable;

impl Portable {
    const CHUNK: usize = 64;
}

impl Fir for Portable {
    #[inline(always)]
    fn fir<'a, const SUB: bool>(
        out: &mut [f32],
        kernel: &[f32],
        taps: impl Fn(usize) -> (&'a [f32], &'a [f32]),
    ) {
        let n = out.len();
        let w0 = kernel[0];
        let centre = taps(0).0;
        let mut x = 0;
        while x < n {
            let m = Self::CHUNK.min(n - x);
            let mut acc = [0.0f32; Self::CHUNK];
            let acc = &mut acc[..m];
            for (a, &c) in acc.iter_mut().zip(&centre[x..x + m]) {
                *a = w0 * c;
            }
            for (j, &w) in kernel.iter().enumerate().skip(1) {
                let (lo, hi) = taps(j);
                for ((a, &l), &h) in acc.iter_mut().zip(&lo[x..x + m]).zip(&hi[x..x + m]) {
                    *a += w * (l + h);
                }
            }
            let out = &mut out[x..x + m];
            if SUB {
                for (o, &a) in out.iter_mut().zip(acc.iter()) {
                    *o -= a;
                }
            } else {
                out.copy_from_slice(acc);
            }
            x += m;
        }
    }

    #[inline(always)]
    fn fir_pair<'a>(
        out_a: &mut [f32],
        out_b: &mut [f32],
        ka: &[f32],
        kb: &[f32],
        taps: impl Fn(usize) -> (&'a [f32], &'a [f32]),
    ) {
        Self::fir::<false>(out_a, ka, &taps);
        Self::fir::<false>(out_b, kb, &taps);
    }

    #[inline(always)]
    fn fir_diff<'a, 'b>(
        out: &mut [f32],
        ka: &[f32],
        taps_a: impl Fn(usize) -> (&'a [f32], &'a [f32]),
        kb: &[f32],
        taps_b: impl Fn(usize) -> (&'b [f32], &'b [f32]),
    ) {
        Self::fir::<false>(out, ka, taps_a);
        Self::fir::<true>(out, kb, taps_b);
    }
}

/// Register-blocked SIMD FIRs for x86-64, generated from one template per instruction set.
/// Multiplies and adds are separate (no FMA) and happen in the order of [`Portable`], so they
/// give exactly its results; each runs only inside a function compiled for its instruction
/// set, after a runtime check.
#[cfg(target_arch = "x86_64")]
mod simd {
    use std::arch::x86_64::*;

    use super::{Fir, Portable};

    macro_rules! simd_fir {
        ($name:ident, $vector:ty, $lanes:literal, $pair:literal, $set1:ident, $load:ident,
         $store:ident, $add:ident, $sub:ident, $mul:ident) => {
            /// Blocks of 8 vectors accumulate in registers across all taps (enough independent
            /// chains to hide the add latency): each tap costs two loads per vector, no store.
            pub(super) struct $name;

            impl Fir for $name {
                #[inline(always)]
                fn fir<'a, const SUB: bool>(
                    out: &mut [f32],
                    kernel: &[f32],
                    taps: impl Fn(usize) -> (&'a [f32], &'a [f32]),
                ) {
                    const BLOCK: usize = 8 * $lanes;
                    let n = out.len();
                    let blocks = n / BLOCK * BLOCK;
                    let centre = &taps(0).0[..n];
                    // SAFETY: the instruction set is available (this runs only inside the
                    // function compiled for it, called after a runtime check), and every
                    // load/store stays below `blocks <= n`, all slices holding `n` values.
                    unsafe {
                        let w0 = $set1(kernel[0]);
                        let mut x = 0;
                        while x < blocks {
                            // No closure here: a closure would not inherit the instruction set.
                            let mut acc: [$vector; 8] = [w0; 8];
                            for (v, acc) in acc.iter_mut().enumerate() {
                                *acc = $mul(w0, $load(centre.as_ptr().add(x + $lanes * v)));
                            }
                            for (j, &w) in kernel.iter().enumerate().skip(1) {
                                let (lo, hi) = taps(j);
                                let (lo, hi) = (&lo[..n], &hi[..n]);
                                let w = $set1(w);
                                for (v, acc) in acc.iter_mut().enumerate() {
                                    let a = $load(lo.as_ptr().add(x + $lanes * v));
                                    let b = $load(hi.as_ptr().add(x + $lanes * v));
                                    *acc = $add(*acc, $mul(w, $add(a, b)));
                                }
                            }
                            for (v, acc) in acc.iter().enumerate() {
                                let o = out.as_mut_ptr().add(x + $lanes * v);
                                if SUB {
                                    $store(o, $sub($load(o), *acc));
                                } else {
                                    $store(o, *acc);
                                }
                            }
                            x += BLOCK;
                        }
                    }
                    Portable::fir::<SUB>(&mut out[blocks..], kernel, |j| {
                        let (lo, hi) = taps(j);
                        (&lo[blocks..], &hi[blocks..])
                    });
                }

                /// Blocks of `$pair` vectors per kernel: both accumulator sets stay in
                /// registers, and each tap pair is loaded and summed once for both kernels.
                #[inline(always)]
                fn fir_pair<'a>(
                    out_a: &mut [f32],
                    out_b: &mut [f32],
                    ka: &[f32],
                    kb: &[f32],
                    taps: impl Fn(usize) -> (&'a [f32], &'a [f32]),
                ) {
                    const BLOCK: usize = $pair * $lanes;
                    let n = out_a.len();
                    assert_eq!(out_b.len(), n);
                    let blocks = n / BLOCK * BLOCK;
                    let centre = &taps(0).0[..n];
                    let taps_len = ka.len().max(kb.len());
                    // SAFETY: as in `fir`: the instruction set is available, and every
                    // load/store stays below `blocks <= n`, all slices holding `n` values.
                    unsafe {
                        let (wa0, wb0) = ($set1(ka[0]), $set1(kb[0]));
                        let mut x = 0;
                        while x < blocks {
                            let mut acc_a: [$vector; $pair] = [wa0; $pair];
                            let mut acc_b: [$vector; $pair] = [wb0; $pair];
                            for v in 0..$pair {
                                let c = $load(centre.as_ptr().add(x + $lanes * v));
                                acc_a[v] = $mul(wa0, c);
                                acc_b[v] = $mul(wb0, c);
                            }
                            for j in 1..taps_len {
                                let (lo, hi) = taps(j);
                                let (lo, hi) = (&lo[..n], &hi[..n]);
                                let mut sum: [$vector; $pair] = [wa0; $pair];
                                for (v, sum) in sum.iter_mut().enumerate() {
                                    let a = $load(lo.as_ptr().add(x + $lanes * v));
                                    let b = $load(hi.as_ptr().add(x + $lanes * v));
                                    *sum = $add(a, b);
                                }
                                if let Some(&w) = ka.get(j) {
                                    let w = $set1(w);
                                    for (acc, &s) in acc_a.iter_mut().zip(&sum) {
                                        *acc = $add(*acc, $mul(w, s));
                                    }
                                }
                                if let Some(&w) = kb.get(j) {
                                    let w = $set1(w);
                                    for (acc, &s) in acc_b.iter_mut().zip(&sum) {
                                        *acc = $add(*acc, $mul(w, s));
                                    }
                                }
                            }
                            for v in 0..$pair {
                                $store(out_a.as_mut_ptr().add(x + $lanes * v), acc_a[v]);
                                $store(out_b.as_mut_ptr().add(x + $lanes * v), acc_b[v]);
                            }
                            x += BLOCK;
                        }
                    }
                    let tail = |j| {
                        let (lo, hi) = taps(j);
                        (&lo[blocks..], &hi[blocks..])
                    };
                    Portable::fir::<false>(&mut out_a[blocks..], ka, tail);
                    Portable::fir::<false>(&mut out_b[blocks..], kb, tail);
                }

                /// Blocks of `$pair` vectors per kernel, both accumulator sets in registers;
                /// the difference is stored once.
                #[inline(always)]
                fn fir_diff<'a, 'b>(
                    out: &mut [f32],
                    ka: &[f32],
                    taps_a: impl Fn(usize) -> (&'a [f32], &'a [f32]),
                    kb: &[f32],
                    taps_b: impl Fn(usize) -> (&'b [f32], &'b [f32]),
                ) {
                    const BLOCK: usize = $pair * $lanes;
                    let n = out.len();
                    let blocks = n / BLOCK * BLOCK;
                    let (centre_a, centre_b) = (&taps_a(0).0[..n], &taps_b(0).0[..n]);
                    // SAFETY: as in `fir`: the instruction set is available, and every
                    // load/store stays below `blocks <= n`, all slices holding `n` values.
                    unsafe {
                        let (wa0, wb0) = ($set1(ka[0]), $set1(kb[0]));
                        let mut x = 0;
                        while x < blocks {
                            let mut acc_a: [$vector; $pair] = [wa0; $pair];
                            let mut acc_b: [$vector; $pair] = [wb0; $pair];
                            for v in 0..$pair {
                                let o = x + $lanes * v;
                                acc_a[v] = $mul(wa0, $load(centre_a.as_ptr().add(o)));
                                acc_b[v] = $mul(wb0, $load(centre_b.as_ptr().add(o)));
                            }
                            for (j, &w) in ka.iter().enumerate().skip(1) {
                                let (lo, hi) = taps_a(j);
                                let (lo, hi) = (&lo[..n], &hi[..n]);
                                let w = $set1(w);
                                for (v, acc) in acc_a.iter_mut().enumerate() {
                                    let a = $load(lo.as_ptr().add(x + $lanes * v));
                                    let b = $load(hi.as_ptr().add(x + $lanes * v));
                                    *acc = $add(*acc, $mul(w, $add(a, b)));
                                }
                            }
                            for (j, &w) in kb.iter().enumerate().skip(1) {
                                let (lo, hi) = taps_b(j);
                                let (lo, hi) = (&lo[..n], &hi[..n]);
                                let w = $set1(w);
                                for (v, acc) in acc_b.iter_mut().enumerate() {
                                    let a = $load(lo.as_ptr().add(x + $lanes * v));
                                    let b = $load(hi.as_ptr().add(x + $lanes * v));
                                    *acc = $add(*acc, $mul(w, $add(a, b)));
                                }
                            }
                            for v in 0..$pair {
                                $store(
                                    out.as_mut_ptr().add(x + $lanes * v),
                                    $sub(acc_a[v], acc_b[v]),
                                );
                            }
                            x += BLOCK;
                        }
                    }
                    Portable::fir::<false>(&mut out[blocks..], ka, |j| {
                        let (lo, hi) = taps_a(j);
                        (&lo[blocks..], &hi[blocks..])
                    });
                    Portable::fir::<true>(&mut out[blocks..], kb, |j| {
                        let (lo, hi) = taps_b(j);
                        (&lo[blocks..], &hi[blocks..])
                    });
                }
            }
        };
    }

    simd_fir!(
        Avx2,
        __m256,
        8,
        4,
        _mm256_set1_ps,
        _mm256_loadu_ps,
        _mm256_storeu_ps,
        _mm256_add_ps,
        _mm256_sub_ps,
        _mm256_mul_ps
    );
    simd_fir!(
        Avx512,
        __m512,
        16,
        8,
        _mm512_set1_ps,
        _mm512_loadu_ps,
        _mm512_storeu_ps,
        _mm512_add_ps,
        _mm512_sub_ps,
        _mm512_mul_ps
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflect101_matches_opencv_and_repeats() {
        let got: Vec<usize> = (-4..8).map(|i| reflect101(i, 4)).collect();
        assert_eq!(got, vec![2, 3, 2, 1, 0, 1, 2, 3, 2, 1, 0, 1]);
        assert_eq!(reflect101(-5, 1), 0);
        assert_eq!(reflect101(3, 2), 1);
    }

    /// Every SIMD path the CPU offers gives the portable path's bits, on a width that
    /// exercises interior strips, border strips and SIMD tails.
    #[test]
    fn simd_paths_match_portable_bit_for_bit() {
        let (width, height) = (600, 300);
        let data = (0..width * height)
            .map(|i| ((i * 7919 + 13) % 1009) as f32 / 1008.0)
            .collect();
        let src = GrayImage::from_vec(width, height, data).unwrap();
        let (a, b) = (
            crate::GaussianKernel::new(1.6).unwrap(),
            crate::GaussianKernel::new(2.4).unwrap(),
        );
        for combine in [
            Combine::Single(a.half_weights()),
            Combine::Difference(a.half_weights(), b.half_weights()),
        ] {
            let run = |path: fn(&GrayImage, usize, &mut [f32], Combine<'_>, &mut [f32])| {
                let mut out = vec![0.0; width * height];
                let mut scratch = vec![0.0; band_scratch_len(&combine)];
                for (band, out) in out.chunks_mut(BAND_ROWS * width).enumerate() {
                    path(&src, band * BAND_ROWS, out, combine, &mut scratch);
                }
                out
            };
            let portable = run(band::<Portable>);
            #[cfg(target_arch = "x86_64")]
            {
                if std::is_x86_feature_detected!("avx2") {
                    // SAFETY: AVX2 is available, checked just above.
                    let avx2 = run(|s, y, o, c, t| unsafe { band_avx2(s, y, o, c, t) });
                    assert!(avx2 == portable);
                }
                if std::is_x86_feature_detected!("avx512f") {
                    // SAFETY: AVX-512F is available, checked just above.
                    let avx512 = run(|s, y, o, c, t| unsafe { band_avx512(s, y, o, c, t) });
                    assert!(avx512 == portable);
                }
            }
        }
    }
}

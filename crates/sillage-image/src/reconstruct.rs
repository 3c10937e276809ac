//! Morphological reconstruction by erosion (8-connectivity) and the h-concave transform built
//! on it, the "hconvex" step of the MMPF+ paper's transparent-bead detector (§3.3.1; Soille,
//! *Morphological Image Analysis*, 1999), which BeadTracking computes as
//! `imhmin(f, h) − f`.
//!
//! Fast method: Vincent's hybrid algorithm (L. Vincent, "Morphological grayscale
//! reconstruction in image analysis", IEEE TIP 2(2), 1993): one raster and one anti-raster
//! scan propagate the marker along most paths, then a FIFO queue, seeded by the pixels the
//! anti-raster scan could still lower, finishes the job; linear in the number of pixels. The
//! result is the greatest fixed point of the propagation below the marker (only `min`/`max`
//! of input values), so it is exact and does not depend on any order.
//!
//! Parallel bands: the image is cut into one band of rows per thread, each band
//! reconstructed on its own (its result is a fixed point inside the band and, since a band
//! has fewer paths, at or above the whole image's reconstruction), then the queue, seeded
//! with the rows on either side of each seam, propagates across the seams. Every value the
//! propagation writes is justified by a neighbour, so it ends on the same greatest fixed
//! point: the result does not depend on the number of threads.
//!
//! 8-bit levels ([`Reconstruction::h_concave_levels`]): the same algorithm on `u16` levels
//! (the marker `f + h` may exceed 255), 32 lanes per AVX-512 vector instead of 16; since it
//! only takes `min`/`max`, it gives the levels of the `f32` result on the decoded image.

use std::collections::VecDeque;

use rayon::prelude::*;
use sillage_core::{Error, GrayImage, Image, Result};

use crate::mask::check_same_size;

/// The order of a scan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Direction {
    /// Raster: rows top to bottom, each left to right.
    Forward,
    /// Anti-raster: rows bottom to top, each right to left.
    Backward,
}

/// Offsets of the four neighbours that come before a pixel in raster order (8-connectivity),
/// as `(dx, dy)`; the other four are their opposites.
const BEFORE: [(isize, isize); 4] = [(-1, 0), (-1, -1), (0, -1), (1, -1)];

/// A pixel type the reconstruction runs on: `f32` grey levels or `u16` integer levels.
trait Level: Copy + PartialOrd + Send + Sync {
    /// The highest value (+∞ for `f32`): the clamp that leaves everything unchanged.
    const HIGHEST: Self;

    /// [`scans`] compiled for the widest SIMD this type has a clamp scan for, when the CPU
    /// has it (the same `min`/`max` results on every path).
    fn scans_dispatch(r: &mut [Self], m: &[Self], width: usize, queue: &mut VecDeque<usize>);

    /// The SIMD [`clamp_scan`] (full scan, tail included).
    ///
    /// # Safety
    /// Only from inside the function `scans_dispatch` compiles for the SIMD this type uses,
    /// itself called after the runtime check of that SIMD.
    unsafe fn simd_clamp_scan(row: &mut [Self], mask: &[Self], direction: Direction);
}

impl Level for f32 {
    const HIGHEST: f32 = f32::INFINITY;

    fn scans_dispatch(r: &mut [f32], m: &[f32], width: usize, queue: &mut VecDeque<usize>) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx512f") {
                // SAFETY: the CPU supports AVX-512F, checked just above.
                unsafe { scans_avx512f(r, m, width, queue) };
                return;
            }
        }
        scans::<f32, false>(r, m, width, queue);
    }

    #[inline(always)]
    unsafe fn simd_clamp_scan(row: &mut [f32], mask: &[f32], direction: Direction) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: AVX-512F is available (the caller's contract).
        unsafe {
            simd::f32x16::clamp_scan(row, mask, direction)
        };
        #[cfg(not(target_arch = "x86_64"))]
        clamp_scan(row, mask, direction, Self::HIGHEST);
    }
}

impl Level for u16 {
    const HIGHEST: u16 = u16::MAX;

    fn scans_dispatch(r: &mut [u16], m: &[u16], width: usize, queue: &mut VecDeque<usize>) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx512bw")
            {
                // SAFETY: the CPU supports AVX-512F and AVX-512BW, checked just above.
                unsafe { scans_avx512bw(r, m, width, queue) };
                return;
            }
        }
        scans::<u16, false>(r, m, width, queue);
    }

    #[inline(always)]
    unsafe fn simd_clamp_scan(row: &mut [u16], mask: &[u16], direction: Direction) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: AVX-512F and AVX-512BW are available (the caller's contract).
        unsafe {
            simd::u16x32::clamp_scan(row, mask, direction)
        };
        #[cfg(not(target_arch = "x86_64"))]
        clamp_scan(row, mask, direction, Self::HIGHEST);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn scans_avx512f(r: &mut [f32], m: &[f32], width: usize, queue: &mut VecDeque<usize>) {
    scans::<f32, true>(r, m, width, queue);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw")]
fn scans_avx512bw(r: &mut [u16], m: &[u16], width: usize, queue: &mut VecDeque<usize>) {
    scans::<u16, true>(r, m, width, queue);
}

/// The fewest rows a parallel band gets: thinner bands would spend more on their seams
/// than they save.
const MIN_BAND_ROWS: usize = 32;

/// Pixels per parallel task of the element-wise passes.
const PAR_CHUNK: usize = 1 << 15;

/// Reconstruction and h-transforms with reusable queues (one per band) and level buffers.
#[derive(Debug, Clone, Default)]
pub struct Reconstruction {
    queues: Vec<VecDeque<usize>>,
    /// The marker and the mask of the levels path.
    marker_levels: Vec<u16>,
    mask_levels: Vec<u16>,
}

impl Reconstruction {
    /// An engine with empty queues.
    pub fn new() -> Self {
        Self::default()
    }

    /// Reconstruction by erosion of `marker` over `mask`, in place: the largest image `R`
    /// with `mask ≤ R ≤ marker` whose every pixel is either on the mask or no higher than
    /// one of its 8 neighbours (the marker flooded down to the mask). Errors when the sizes
    /// differ or a marker pixel is below the mask (or NaN).
    pub fn erode_reconstruct(&mut self, marker: &mut GrayImage, mask: &GrayImage) -> Result<()> {
        check_same_size(mask, marker, "marker")?;
        if let Some(i) = marker
            .as_slice()
            .iter()
            .zip(mask.as_slice())
            .position(|(&r, &m)| r < m || r.is_nan() || m.is_nan())
        {
            let (x, y) = (i % mask.width(), i / mask.width());
            return Err(Error::input(format!(
                "the reconstruction marker is below the mask (or NaN) at pixel ({x}, {y}); \
                 the marker of a reconstruction by erosion must be ≥ the mask everywhere"
            )));
        }
        reconstruct(
            marker.as_mut_slice(),
            mask.as_slice(),
            mask.width(),
            &mut self.queues,
        );
        Ok(())
    }

    /// The h-concave transform `HMIN_h(f) − f` of `src` into `dst` (reshaped): each basin of
    /// `f` filled up to `h` above its floor or to its spill level, whichever is lower, minus
    /// `f` — bright where `f` has a regional minimum, at most `h`. `h` must be finite and
    /// `≥ 0`; NaN pixels give NaN.
    pub fn h_concave(&mut self, src: &GrayImage, h: f32, dst: &mut GrayImage) -> Result<()> {
        if !(h.is_finite() && h >= 0.0) {
            return Err(Error::parameter(
                "h",
                h,
                "must be a finite number ≥ 0 (grey levels)",
            ));
        }
        let (width, height) = src.dimensions();
        dst.reshape(width, height);
        for (d, &s) in dst.as_mut_slice().iter_mut().zip(src.as_slice()) {
            *d = s + h;
        }
        reconstruct(dst.as_mut_slice(), src.as_slice(), width, &mut self.queues);
        for (d, &s) in dst.as_mut_slice().iter_mut().zip(src.as_slice()) {
            *d -= s;
        }
        Ok(())
    }

    /// [`Reconstruction::h_concave`] on 8-bit levels: `dst` (reshaped) holds the levels
    /// `HMIN_h(f) − f` (each at most `h`) of the levels `f` of `src` — exactly, with no
    /// rounding (on the decoded image, `h_concave` gives these levels up to the `f32` rounding
    /// of `f + h` and of the difference).
    pub fn h_concave_levels(&mut self, src: &Image<u8>, h: u8, dst: &mut Image<u8>) {
        let (width, height) = src.dimensions();
        dst.reshape(width, height);
        let src = src.as_slice();
        self.mask_levels.resize(src.len(), 0);
        self.marker_levels.resize(src.len(), 0);
        self.mask_levels
            .par_chunks_mut(PAR_CHUNK)
            .zip(self.marker_levels.par_chunks_mut(PAR_CHUNK))
            .zip(src.par_chunks(PAR_CHUNK))
            .for_each(|((mask, marker), src)| {
                for ((m, r), &f) in mask.iter_mut().zip(marker.iter_mut()).zip(src) {
                    *m = u16::from(f);
                    *r = u16::from(f) + u16::from(h);
                }
            });
        reconstruct(
            &mut self.marker_levels,
            &self.mask_levels,
            width,
            &mut self.queues,
        );
        dst.as_mut_slice()
            .par_chunks_mut(PAR_CHUNK)
            .zip(self.marker_levels.par_chunks(PAR_CHUNK))
            .zip(src.par_chunks(PAR_CHUNK))
            .for_each(|((dst, marker), src)| {
                for ((d, &r), &f) in dst.iter_mut().zip(marker).zip(src) {
                    // r − f ≤ h ≤ 255.
                    *d = (r - u16::from(f)) as u8;
                }
            });
    }
}

/// The hybrid algorithm on a marker `r` known to be ≥ the mask `m` (rows of `width`), in
/// parallel bands of rows (one per thread, at least [`MIN_BAND_ROWS`] rows each) joined by
/// a propagation across their seams.
fn reconstruct<T: Level>(r: &mut [T], m: &[T], width: usize, queues: &mut Vec<VecDeque<usize>>) {
    if width == 0 || m.is_empty() {
        return;
    }
    let height = m.len() / width;
    let bands = rayon::current_num_threads()
        .min(height / MIN_BAND_ROWS)
        .max(1);
    reconstruct_in_bands(r, m, width, bands, queues);
}

/// [`reconstruct`] with `bands` bands of rows (the result does not depend on it).
fn reconstruct_in_bands<T: Level>(
    r: &mut [T],
    m: &[T],
    width: usize,
    bands: usize,
    queues: &mut Vec<VecDeque<usize>>,
) {
    let height = m.len() / width;
    let band_rows = height.div_ceil(bands);
    queues.resize_with(bands.max(1), VecDeque::new);
    r.par_chunks_mut(band_rows * width)
        .zip(m.par_chunks(band_rows * width))
        .zip(queues.par_iter_mut())
        .for_each(|((r, m), queue)| {
            queue.clear();
            T::scans_dispatch(r, m, width, queue);
            propagate(r, m, width, queue);
        });
    // The seams: the last row of a band and the first of the next may lower each other.
    let queue = &mut queues[0];
    for seam in (band_rows..height).step_by(band_rows) {
        queue.extend((seam - 1) * width..(seam + 1) * width);
    }
    propagate(r, m, width, queue);
}

/// Vincent's FIFO propagation: each queued pixel lowers the 8 neighbours above it and above
/// their mask to its own value (or their mask), queueing them in turn, until the queue is
/// empty.
fn propagate<T: Level>(r: &mut [T], m: &[T], width: usize, queue: &mut VecDeque<usize>) {
    let height = m.len() / width;
    let neighbour = |p: usize, (dx, dy): (isize, isize)| {
        let (x, y) = ((p % width) as isize + dx, (p / width) as isize + dy);
        (x >= 0 && y >= 0 && (x as usize) < width && (y as usize) < height)
            .then(|| y as usize * width + x as usize)
    };
    while let Some(p) = queue.pop_front() {
        let v = r[p];
        for (dx, dy) in BEFORE {
            for offset in [(dx, dy), (-dx, -dy)] {
                if let Some(q) = neighbour(p, offset)
                    && r[q] > v
                    && r[q] != m[q]
                {
                    r[q] = higher(v, m[q]);
                    queue.push_back(q);
                }
            }
        }
    }
}

/// The raster and anti-raster scans of `r` over `m` (rows of `width`), queueing what the
/// propagation must finish; `SIMD` is true only inside the functions compiled for the SIMD
/// of [`Level::simd_clamp_scan`].
#[inline(always)]
fn scans<T: Level, const SIMD: bool>(
    r: &mut [T],
    m: &[T],
    width: usize,
    queue: &mut VecDeque<usize>,
) {
    let height = m.len() / width;
    // Raster scan: R(p) = max(min(R(p), R(q) for the 4 neighbours q before p), mask(p)).
    for y in 0..height {
        let (done, rest) = r.split_at_mut(y * width);
        let row = &mut rest[..width];
        let previous = y.checked_sub(1).map(|_| &done[done.len() - width..]);
        scan_row::<T, SIMD>(row, previous, &m[y * width..][..width], Direction::Forward);
    }
    // Anti-raster scan, queueing the pixels that can still lower a neighbour after them.
    for y in (0..height).rev() {
        let (rest, done) = r.split_at_mut((y + 1) * width);
        let row = &mut rest[y * width..];
        let next = (y + 1 < height).then(|| (&done[..width], &m[(y + 1) * width..][..width]));
        let mask_row = &m[y * width..][..width];
        scan_row::<T, SIMD>(row, next.map(|n| n.0), mask_row, Direction::Backward);
        queue_row(row, mask_row, next, y * width, queue);
    }
}

/// `min(a, b)` as one vector instruction (`a` if either is NaN).
#[inline(always)]
fn lower<T: Level>(a: T, b: T) -> T {
    if b < a { b } else { a }
}

/// `max(a, b)` as one vector instruction (`a` if either is NaN).
#[inline(always)]
fn higher<T: Level>(a: T, b: T) -> T {
    if b > a { b } else { a }
}

/// One row of a scan: `row ← max(mask, min(row, the three pixels of the row already scanned
/// next to it, the pixel just scanned in this row))`.
///
/// The three pixels of `scanned` (the row above for a raster scan, below for an anti-raster
/// one) are folded in vectorised first, giving `hi = max(mask, min(row, scanned…))`; what is
/// left is the recurrence `r[x] = clamp(r[x∓1], mask[x], hi[x])` along the row. Clamps compose
/// into clamps, so on AVX-512 it is a parallel prefix over 16 lanes (4 shift-and-compose
/// steps) plus one clamp by the carry per 16 pixels, instead of a chain of two dependent
/// operations per pixel.
#[inline(always)]
fn scan_row<T: Level, const SIMD: bool>(
    row: &mut [T],
    scanned: Option<&[T]>,
    mask: &[T],
    direction: Direction,
) {
    if let Some(scanned) = scanned {
        let n = row.len();
        let fold = |v: T, x: usize| {
            let mut v = lower(v, scanned[x]);
            if x > 0 {
                v = lower(v, scanned[x - 1]);
            }
            if x + 1 < n {
                v = lower(v, scanned[x + 1]);
            }
            v
        };
        row[0] = fold(row[0], 0);
        if n > 1 {
            row[n - 1] = fold(row[n - 1], n - 1);
        }
        if n > 2 {
            // Fixed-size chunks, so that it vectorises for every lane type.
            const CHUNK: usize = 32;
            let (left, centre, right) = (&scanned[..n - 2], &scanned[1..n - 1], &scanned[2..]);
            let inner = &mut row[1..n - 1];
            let full = inner.len() / CHUNK * CHUNK;
            for start in (0..full).step_by(CHUNK) {
                let v: &mut [T; CHUNK] = (&mut inner[start..start + CHUNK]).try_into().unwrap();
                let at = |s: &[T]| -> [T; CHUNK] { s[start..start + CHUNK].try_into().unwrap() };
                let (a, b, c) = (at(left), at(centre), at(right));
                for i in 0..CHUNK {
                    v[i] = lower(lower(lower(v[i], a[i]), b[i]), c[i]);
                }
            }
            for (((v, &a), &b), &c) in inner[full..]
                .iter_mut()
                .zip(&left[full..])
                .zip(&centre[full..])
                .zip(&right[full..])
            {
                *v = lower(lower(lower(*v, a), b), c);
            }
        }
    }
    for (v, &m) in row.iter_mut().zip(mask) {
        *v = higher(*v, m);
    }
    if SIMD {
        // SAFETY: `SIMD` is true only inside the function `T::scans_dispatch` compiles for
        // `T`'s SIMD, called after the runtime check of that SIMD.
        unsafe { T::simd_clamp_scan(row, mask, direction) };
    } else {
        clamp_scan(row, mask, direction, T::HIGHEST);
    }
}

/// `row[x] = clamp(row[x ∓ 1], mask[x], row[x])` along the row in `direction`, one pixel at
/// a time, starting from `carry` (the value before the first pixel); returns the last value.
/// The reference the SIMD path must equal, and its tail.
fn clamp_scan<T: Level>(row: &mut [T], mask: &[T], direction: Direction, mut carry: T) -> T {
    let mut step = |v: &mut T, m: T| {
        *v = lower(*v, higher(m, carry));
        carry = *v;
    };
    match direction {
        Direction::Forward => row.iter_mut().zip(mask).for_each(|(v, &m)| step(v, m)),
        Direction::Backward => row
            .iter_mut()
            .zip(mask)
            .rev()
            .for_each(|(v, &m)| step(v, m)),
    }
    carry
}

/// Pushes onto `queue` (as `offset + x`) each pixel of the finished anti-raster `row` with a
/// neighbour after it — right in `row`, or in `next` (the row below and its mask) — that is
/// above it and above its own mask: such a neighbour may still be lowered from it. Interior
/// pixels are tested 32 at a time, branch-free, into a bit mask.
#[inline(always)]
fn queue_row<T: Level>(
    row: &[T],
    mask: &[T],
    next: Option<(&[T], &[T])>,
    offset: usize,
    queue: &mut VecDeque<usize>,
) {
    const LANES: usize = 32;
    let n = row.len();
    let lowerable = |v: T, q: T, qm: T| (q > v) & (q > qm);
    let test = |x: usize| {
        let v = row[x];
        let mut push = x + 1 < n && lowerable(v, row[x + 1], mask[x + 1]);
        if let Some((below, below_mask)) = next {
            for xx in x.saturating_sub(1)..(x + 2).min(n) {
                push |= lowerable(v, below[xx], below_mask[xx]);
            }
        }
        push
    };
    let mut x = 0;
    while x < n {
        let lanes = LANES.min(n - x);
        let mut bits = 0u64;
        if lanes == LANES && x > 0 && x + LANES < n {
            let at = |s: &[T], start: usize| -> [T; LANES] {
                s[start..start + LANES].try_into().unwrap()
            };
            let (v, right, right_mask) = (at(row, x), at(row, x + 1), at(mask, x + 1));
            for i in 0..LANES {
                bits |= u64::from(lowerable(v[i], right[i], right_mask[i])) << i;
            }
            if let Some((below, below_mask)) = next {
                for shift in [x - 1, x, x + 1] {
                    let (q, qm) = (at(below, shift), at(below_mask, shift));
                    for i in 0..LANES {
                        bits |= u64::from(lowerable(v[i], q[i], qm[i])) << i;
                    }
                }
            }
        } else {
            for i in 0..lanes {
                bits |= u64::from(test(x + i)) << i;
            }
        }
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            queue.push_back(offset + x + i);
        }
        x += lanes;
    }
}

/// The AVX-512 clamp scans, `f32` (16 lanes, AVX-512F) and `u16` (32 lanes, AVX-512BW), from
/// one template.
#[cfg(target_arch = "x86_64")]
mod simd {
    /// The permutation index that moves lane `i − k` (forward) or `i + k` (backward) to lane
    /// `i`, or takes lane `i` of the second source (the fill) where there is none.
    const fn shift_index<const LANES: usize>(k: usize, forward: bool) -> [u16; LANES] {
        let mut index = [0u16; LANES];
        let mut i = 0;
        while i < LANES {
            let inside = if forward { i >= k } else { i + k < LANES };
            index[i] = match (inside, forward) {
                (true, true) => (i - k) as u16,
                (true, false) => (i + k) as u16,
                (false, _) => (LANES + i) as u16,
            };
            i += 1;
        }
        index
    }

    macro_rules! clamp_scan_simd {
        ($module:ident, $features:literal, $t:ty, $lanes:literal, $steps:literal, $vector:ty,
         $lowest:expr, $highest:expr, $elem:ty, $set1:ident, $load:ident, $store:ident,
         $min:ident, $max:ident, $index_elem:ty, $index_load:ident, $permute2:ident,
         $permute:ident, $first:ident) => {
            /// The clamp scan on `$t`.
            pub(super) mod $module {
                use std::arch::x86_64::*;

                use super::super::Direction;
                use super::shift_index;

                /// The permutation indices of the shifts by 1, 2, 4, … lanes and of the broadcast
                /// of the last lane in scan order.
                #[target_feature(enable = $features)]
                fn indices(forward: bool) -> ([__m512i; $steps], __m512i) {
                    let load = |index: [u16; $lanes]| {
                        let index: [$index_elem; $lanes] = index.map(|i| i as $index_elem);
                        // SAFETY: `index` holds one vector.
                        unsafe { $index_load(index.as_ptr()) }
                    };
                    let shifts =
                        std::array::from_fn(|s| load(shift_index::<$lanes>(1 << s, forward)));
                    let last = if forward { $lanes - 1 } else { 0 };
                    (shifts, load([last; $lanes]))
                }

                /// `$lanes` pixels from `start`: a parallel prefix (Hillis–Steele) of their clamps
                /// `[mask, row]`, then the clamp of the carry; returns the new carry (the last
                /// pixel in scan order, broadcast).
                #[target_feature(enable = $features)]
                fn chunk(
                    row: &mut [$t],
                    mask: &[$t],
                    start: usize,
                    carry: $vector,
                    (shifts, last): &([__m512i; $steps], __m512i),
                ) -> $vector {
                    let (row, mask) = (
                        &mut row[start..start + $lanes],
                        &mask[start..start + $lanes],
                    );
                    let (low, high) = ($set1($lowest as $elem), $set1($highest as $elem));
                    // SAFETY: both slices hold exactly one vector.
                    let (mut lo, mut hi) = unsafe {
                        (
                            $load(mask.as_ptr() as *const $elem),
                            $load(row.as_ptr() as *const $elem),
                        )
                    };
                    for &shift in shifts {
                        let (slo, shi) = ($permute2(lo, shift, low), $permute2(hi, shift, high));
                        // The earlier clamp `[slo, shi]` then this one: its bounds, clamped.
                        (lo, hi) = ($min($max(slo, lo), hi), $min($max(shi, lo), hi));
                    }
                    let out = $min($max(carry, lo), hi);
                    // SAFETY: `row` holds exactly one vector.
                    unsafe { $store(row.as_mut_ptr() as *mut $elem, out) };
                    $permute(*last, out)
                }

                /// [`super::clamp_scan`] `$lanes` pixels at a time; the same `min`/`max` results.
                #[target_feature(enable = $features)]
                pub(in crate::reconstruct) fn clamp_scan(
                    row: &mut [$t],
                    mask: &[$t],
                    direction: Direction,
                ) {
                    let forward = direction == Direction::Forward;
                    let indices = indices(forward);
                    let n = row.len();
                    let full = n / $lanes * $lanes;
                    if forward {
                        let mut carry = $set1($highest as $elem);
                        for start in (0..full).step_by($lanes) {
                            carry = chunk(row, mask, start, carry, &indices);
                        }
                        let carry = $first(carry) as $t;
                        super::super::clamp_scan(
                            &mut row[full..],
                            &mask[full..n],
                            direction,
                            carry,
                        );
                    } else {
                        let tail = &mut row[full..];
                        let carry =
                            super::super::clamp_scan(tail, &mask[full..n], direction, $highest);
                        let mut carry = $set1(carry as $elem);
                        for start in (0..full).step_by($lanes).rev() {
                            carry = chunk(row, mask, start, carry, &indices);
                        }
                    }
                }
            }
        };
    }

    clamp_scan_simd!(
        f32x16,
        "avx512f",
        f32,
        16,
        4,
        __m512,
        f32::NEG_INFINITY,
        f32::INFINITY,
        f32,
        _mm512_set1_ps,
        _mm512_loadu_ps,
        _mm512_storeu_ps,
        _mm512_min_ps,
        _mm512_max_ps,
        i32,
        _mm512_loadu_epi32,
        _mm512_permutex2var_ps,
        _mm512_permutexvar_ps,
        _mm512_cvtss_f32
    );

    clamp_scan_simd!(
        u16x32,
        "avx512f,avx512bw",
        u16,
        32,
        5,
        __m512i,
        u16::MIN,
        u16::MAX,
        i16,
        _mm512_set1_epi16,
        _mm512_loadu_epi16,
        _mm512_storeu_epi16,
        _mm512_min_epu16,
        _mm512_max_epu16,
        i16,
        _mm512_loadu_epi16,
        _mm512_permutex2var_epi16,
        _mm512_permutexvar_epi16,
        _mm512_cvtsi512_si32
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every path of the row scan gives the scalar scan's values, in both directions, on rows
    /// with full SIMD chunks and tails, for `f32` values and `u16` levels.
    #[test]
    fn simd_clamp_scans_match_the_scalar_one() {
        let mut state = 7u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for n in [1, 15, 16, 17, 31, 32, 33, 64, 100] {
            let mask: Vec<f32> = (0..n).map(|_| next() * 0.5).collect();
            let hi: Vec<f32> = mask.iter().map(|&m| m + next() * 0.5).collect();
            let levels =
                |v: &[f32]| -> Vec<u16> { v.iter().map(|&x| (x * 600.0) as u16).collect() };
            let (mask_levels, hi_levels) = (levels(&mask), levels(&hi));
            for direction in [Direction::Forward, Direction::Backward] {
                let mut expected = hi.clone();
                clamp_scan(&mut expected, &mask, direction, f32::INFINITY);
                let mut got = hi.clone();
                scan_row::<f32, false>(&mut got, None, &mask, direction);
                assert_eq!(got, expected);
                let mut expected_levels = hi_levels.clone();
                clamp_scan(&mut expected_levels, &mask_levels, direction, u16::MAX);
                #[cfg(target_arch = "x86_64")]
                if std::is_x86_feature_detected!("avx512f") {
                    let mut simd = hi.clone();
                    // SAFETY: AVX-512F is available, checked just above.
                    unsafe { simd::f32x16::clamp_scan(&mut simd, &mask, direction) };
                    assert_eq!(simd, expected, "n = {n}, {direction:?}");
                }
                #[cfg(target_arch = "x86_64")]
                if std::is_x86_feature_detected!("avx512f")
                    && std::is_x86_feature_detected!("avx512bw")
                {
                    let mut simd = hi_levels.clone();
                    // SAFETY: AVX-512F and AVX-512BW are available, checked just above.
                    unsafe { simd::u16x32::clamp_scan(&mut simd, &mask_levels, direction) };
                    assert_eq!(simd, expected_levels, "n = {n}, {direction:?}");
                }
            }
        }
    }
}

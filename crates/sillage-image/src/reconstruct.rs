//! Morphological reconstruction by erosion (8-connectivity) and the h-concave transform built
//! on it, the "hconvex" step of the MMPF+ paper's transparent-bead detector (§3.3.1; Soille,
//! *Morphological Image Analysis*, 1999), which BeadTracking computes as
//! `imhmin(f, h) − f`.
//!
//! Fast method: Vincent's hybrid algorithm (L. Vincent, "Morphological grayscale
//! reconstruction in image analysis", IEEE TIP 2(2), 1993): one raster and one anti-raster
//! scan propagate the marker along most paths, then a FIFO queue, seeded by the pixels the
//! anti-raster scan could still lower, finishes the job; linear in the number of pixels. The
//! result is the unique fixed point of the propagation (only `min`/`max` of input values), so
//! it is exact and does not depend on any order.

use std::collections::VecDeque;

use sillage_core::{Error, GrayImage, Result};

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

/// Reconstruction and h-transforms with a reusable queue.
#[derive(Debug, Clone, Default)]
pub struct Reconstruction {
    queue: VecDeque<usize>,
}

impl Reconstruction {
    /// An engine with an empty queue.
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
        self.reconstruct(marker, mask);
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
        self.reconstruct(dst, src);
        for (d, &s) in dst.as_mut_slice().iter_mut().zip(src.as_slice()) {
            *d -= s;
        }
        Ok(())
    }

    /// The hybrid algorithm on a marker known to be ≥ the mask.
    fn reconstruct(&mut self, marker: &mut GrayImage, mask: &GrayImage) {
        let (width, height) = mask.dimensions();
        if width == 0 || height == 0 {
            return;
        }
        let r = marker.as_mut_slice();
        let m = mask.as_slice();
        self.queue.clear();
        scans_dispatch(r, m, width, &mut self.queue);
        // Propagation.
        let neighbour = |p: usize, (dx, dy): (isize, isize)| {
            let (x, y) = ((p % width) as isize + dx, (p / width) as isize + dy);
            (x >= 0 && y >= 0 && (x as usize) < width && (y as usize) < height)
                .then(|| y as usize * width + x as usize)
        };
        while let Some(p) = self.queue.pop_front() {
            let v = r[p];
            for (dx, dy) in BEFORE {
                for offset in [(dx, dy), (-dx, -dy)] {
                    if let Some(q) = neighbour(p, offset)
                        && r[q] > v
                        && r[q] != m[q]
                    {
                        r[q] = v.max(m[q]);
                        self.queue.push_back(q);
                    }
                }
            }
        }
    }
}

/// The raster and anti-raster scans of `r` over `m` (rows of `width`), queueing what the
/// propagation must finish; compiled for AVX-512 when the CPU has it.
fn scans_dispatch(r: &mut [f32], m: &[f32], width: usize, queue: &mut VecDeque<usize>) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU supports AVX-512F, checked just above.
            unsafe { scans_avx512(r, m, width, queue) };
            return;
        }
    }
    scans::<false>(r, m, width, queue);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn scans_avx512(r: &mut [f32], m: &[f32], width: usize, queue: &mut VecDeque<usize>) {
    scans::<true>(r, m, width, queue);
}

/// See [`scans_dispatch`]; `SIMD` is true only on the AVX-512 path.
#[inline(always)]
fn scans<const SIMD: bool>(r: &mut [f32], m: &[f32], width: usize, queue: &mut VecDeque<usize>) {
    let height = m.len() / width;
    // Raster scan: R(p) = max(min(R(p), R(q) for the 4 neighbours q before p), mask(p)).
    for y in 0..height {
        let (done, rest) = r.split_at_mut(y * width);
        let row = &mut rest[..width];
        let previous = y.checked_sub(1).map(|_| &done[done.len() - width..]);
        scan_row::<SIMD>(row, previous, &m[y * width..][..width], Direction::Forward);
    }
    // Anti-raster scan, queueing the pixels that can still lower a neighbour after them.
    for y in (0..height).rev() {
        let (rest, done) = r.split_at_mut((y + 1) * width);
        let row = &mut rest[y * width..];
        let next = (y + 1 < height).then(|| (&done[..width], &m[(y + 1) * width..][..width]));
        let mask_row = &m[y * width..][..width];
        scan_row::<SIMD>(row, next.map(|n| n.0), mask_row, Direction::Backward);
        queue_row(row, mask_row, next, y * width, queue);
    }
}

/// `min(a, b)` as one vector instruction (`a` if either is NaN).
#[inline(always)]
fn lower(a: f32, b: f32) -> f32 {
    if b < a { b } else { a }
}

/// `max(a, b)` as one vector instruction (`a` if either is NaN).
#[inline(always)]
fn higher(a: f32, b: f32) -> f32 {
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
fn scan_row<const SIMD: bool>(
    row: &mut [f32],
    scanned: Option<&[f32]>,
    mask: &[f32],
    direction: Direction,
) {
    if let Some(scanned) = scanned {
        let n = row.len();
        let fold = |v: f32, x: usize| {
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
            let (left, centre, right) = (&scanned[..n - 2], &scanned[1..n - 1], &scanned[2..]);
            for (((v, &a), &b), &c) in row[1..n - 1].iter_mut().zip(left).zip(centre).zip(right) {
                *v = lower(lower(lower(*v, a), b), c);
            }
        }
    }
    for (v, &m) in row.iter_mut().zip(mask) {
        *v = higher(*v, m);
    }
    #[cfg(target_arch = "x86_64")]
    {
        if SIMD {
            // SAFETY: `SIMD` is true only inside `scans_avx512`, called after checking that
            // the CPU supports AVX-512F.
            unsafe { simd::clamp_scan(row, mask, direction) };
            return;
        }
    }
    clamp_scan(row, mask, direction, f32::INFINITY);
}

/// `row[x] = clamp(row[x ∓ 1], mask[x], row[x])` along the row in `direction`, one pixel at
/// a time, starting from `carry` (the value before the first pixel); returns the last value.
/// The reference the SIMD path must equal, and its tail.
fn clamp_scan(row: &mut [f32], mask: &[f32], direction: Direction, mut carry: f32) -> f32 {
    let mut step = |v: &mut f32, m: f32| {
        *v = carry.max(m).min(*v);
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
fn queue_row(
    row: &[f32],
    mask: &[f32],
    next: Option<(&[f32], &[f32])>,
    offset: usize,
    queue: &mut VecDeque<usize>,
) {
    const LANES: usize = 32;
    let n = row.len();
    let lowerable = |v: f32, q: f32, qm: f32| (q > v) & (q > qm);
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
            let at = |s: &[f32], start: usize| -> [f32; LANES] {
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

/// The AVX-512 clamp scan.
#[cfg(target_arch = "x86_64")]
mod simd {
    use std::arch::x86_64::*;

    use super::Direction;

    /// Lanes per vector.
    const LANES: usize = 16;

    /// Lane `i` takes lane `i − K` (forward scans, `KC = 16 − K`) or `i + K` (backward), and
    /// `fill` where there is none.
    macro_rules! shift {
        ($forward:expr, $v:expr, $fill:expr, $k:literal, $kc:literal) => {{
            let (v, fill) = (_mm512_castps_si512($v), _mm512_castps_si512($fill));
            _mm512_castsi512_ps(if $forward {
                _mm512_alignr_epi32::<$kc>(v, fill)
            } else {
                _mm512_alignr_epi32::<$k>(fill, v)
            })
        }};
    }

    /// Composes each lane's clamp `[lo, hi]` with the one before it in scan order
    /// (`[slo, shi]`, applied first): the bounds of the earlier one, clamped by this one.
    #[target_feature(enable = "avx512f")]
    fn compose(lo: __m512, hi: __m512, slo: __m512, shi: __m512) -> (__m512, __m512) {
        (
            _mm512_min_ps(_mm512_max_ps(slo, lo), hi),
            _mm512_min_ps(_mm512_max_ps(shi, lo), hi),
        )
    }

    /// 16 pixels from `start`: a parallel prefix (Hillis–Steele) of the clamps, then the
    /// clamp of the carry; returns the new carry (the last pixel in scan order, broadcast).
    #[target_feature(enable = "avx512f")]
    fn chunk<const FORWARD: bool>(
        row: &mut [f32],
        mask: &[f32],
        start: usize,
        carry: __m512,
    ) -> __m512 {
        let (neg, pos) = (
            _mm512_set1_ps(f32::NEG_INFINITY),
            _mm512_set1_ps(f32::INFINITY),
        );
        let (row, mask) = (&mut row[start..start + LANES], &mask[start..start + LANES]);
        // SAFETY: both slices hold exactly 16 values.
        let (mut lo, mut hi) = unsafe {
            (
                _mm512_loadu_ps(mask.as_ptr()),
                _mm512_loadu_ps(row.as_ptr()),
            )
        };
        (lo, hi) = compose(
            lo,
            hi,
            shift!(FORWARD, lo, neg, 1, 15),
            shift!(FORWARD, hi, pos, 1, 15),
        );
        (lo, hi) = compose(
            lo,
            hi,
            shift!(FORWARD, lo, neg, 2, 14),
            shift!(FORWARD, hi, pos, 2, 14),
        );
        (lo, hi) = compose(
            lo,
            hi,
            shift!(FORWARD, lo, neg, 4, 12),
            shift!(FORWARD, hi, pos, 4, 12),
        );
        (lo, hi) = compose(
            lo,
            hi,
            shift!(FORWARD, lo, neg, 8, 8),
            shift!(FORWARD, hi, pos, 8, 8),
        );
        let out = _mm512_min_ps(_mm512_max_ps(carry, lo), hi);
        // SAFETY: `row` holds exactly 16 values.
        unsafe { _mm512_storeu_ps(row.as_mut_ptr(), out) };
        let last = if FORWARD { LANES as i32 - 1 } else { 0 };
        _mm512_permutexvar_ps(_mm512_set1_epi32(last), out)
    }

    /// [`super::clamp_scan`] 16 pixels at a time; the same `min`/`max` results.
    #[target_feature(enable = "avx512f")]
    pub(super) fn clamp_scan(row: &mut [f32], mask: &[f32], direction: Direction) {
        let n = row.len();
        let full = n / LANES * LANES;
        match direction {
            Direction::Forward => {
                let mut carry = _mm512_set1_ps(f32::INFINITY);
                for start in (0..full).step_by(LANES) {
                    carry = chunk::<true>(row, mask, start, carry);
                }
                let carry = _mm512_cvtss_f32(carry);
                super::clamp_scan(&mut row[full..], &mask[full..n], direction, carry);
            }
            Direction::Backward => {
                let tail = &mut row[full..];
                let carry = super::clamp_scan(tail, &mask[full..n], direction, f32::INFINITY);
                let mut carry = _mm512_set1_ps(carry);
                for start in (0..full).step_by(LANES).rev() {
                    carry = chunk::<false>(row, mask, start, carry);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every path of the row scan gives the scalar scan's values, in both directions, on rows
    /// with full 16-lane chunks and tails.
    #[test]
    fn simd_clamp_scan_matches_the_scalar_one() {
        let mut state = 7u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for n in [1, 15, 16, 17, 64, 100] {
            let mask: Vec<f32> = (0..n).map(|_| next() * 0.5).collect();
            let hi: Vec<f32> = mask.iter().map(|&m| m + next() * 0.5).collect();
            for direction in [Direction::Forward, Direction::Backward] {
                let mut expected = hi.clone();
                clamp_scan(&mut expected, &mask, direction, f32::INFINITY);
                let mut got = hi.clone();
                scan_row::<false>(&mut got, None, &mask, direction);
                assert_eq!(got, expected);
                #[cfg(target_arch = "x86_64")]
                if std::is_x86_feature_detected!("avx512f") {
                    let mut simd = hi.clone();
                    // SAFETY: AVX-512F is available, checked just above.
                    unsafe { simd::clamp_scan(&mut simd, &mask, direction) };
                    assert_eq!(simd, expected, "n = {n}, {direction:?}");
                }
            }
        }
    }
}

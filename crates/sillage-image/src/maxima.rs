//! Local maxima above a threshold in a `(2n+1)²` window (TracTrac's `maximaThresh`, with a
//! deterministic tie-break instead of its unseeded random one).

use rayon::prelude::*;
use sillage_core::GrayImage;

/// Rows per parallel job; fixed, so the output never depends on the thread count.
const BAND_ROWS: usize = 32;

/// Integer position of a local maximum, px.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Peak {
    /// Row.
    pub y: usize,
    /// Column.
    pub x: usize,
}

/// Finds local maxima; keeps per-band buffers so that repeated calls allocate nothing once
/// the buffers have grown. `T` is what each peak becomes: the peak itself ([`Self::find`]) or
/// what a caller makes of it while its rows are still in cache ([`Self::find_map`]).
#[derive(Debug, Clone)]
pub struct PeakFinder<T = Peak> {
    bands: Vec<Band<T>>,
}

/// One band's buffers: what it found, and the candidate masks of its current and previous
/// rows (see [`scan_band`]).
#[derive(Debug, Clone)]
struct Band<T> {
    found: Vec<T>,
    masks: [Vec<u32>; 2],
}

impl<T> Default for Band<T> {
    fn default() -> Self {
        Self {
            found: Vec::new(),
            masks: [Vec::new(), Vec::new()],
        }
    }
}

impl<T> Default for PeakFinder<T> {
    fn default() -> Self {
        Self { bands: Vec::new() }
    }
}

impl PeakFinder {
    /// An empty finder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Writes into `out` (cleared first), in raster order, every pixel `p` with
    /// `image[p] > threshold` that is the maximum of its `(2·half_window+1)²` window, ties
    /// going to the first pixel in raster order: `p` must be strictly greater than the window
    /// pixels before it (in raster order) and not smaller than those after it. A plateau that
    /// fits in one window thus gives exactly one peak, its first pixel. Pixels closer than
    /// `half_window` to the border are skipped (as TracTrac does). NaN is never a peak, and a
    /// NaN in a window rules out a peak there.
    ///
    /// Fast method, candidates first: only a pixel above the threshold that beats its left
    /// neighbour and is not beaten by its right one can be a peak. A branch-free compare over
    /// 32 pixels at a time (vectorised) gives a bit mask of those candidates,
    /// and only they get the full window check, so the cost is one read of the image plus
    /// work proportional to the number of candidates, with no intermediate image.
    pub fn find(
        &mut self,
        image: &GrayImage,
        half_window: usize,
        threshold: f32,
        out: &mut Vec<Peak>,
    ) {
        self.find_map(image, half_window, threshold, |peak| peak, out);
    }
}

impl<T: Copy + Send> PeakFinder<T> {
    /// [`PeakFinder::find`], each peak turned into `map(peak)` as soon as it is found, in the
    /// band of rows being scanned: a map that reads the pixels around the peak (a sub-pixel
    /// fit) finds them in cache instead of reading the image a second time. `out` (cleared
    /// first) is in the peaks' raster order, whatever the number of threads.
    pub fn find_map(
        &mut self,
        image: &GrayImage,
        half_window: usize,
        threshold: f32,
        map: impl Fn(Peak) -> T + Sync,
        out: &mut Vec<T>,
    ) {
        out.clear();
        let (width, height) = image.dimensions();
        let n = half_window;
        if width <= 2 * n || height <= 2 * n {
            return;
        }
        let bands = (height - 2 * n).div_ceil(BAND_ROWS);
        if self.bands.len() < bands {
            self.bands.resize_with(bands, Band::default);
        }
        self.bands[..bands]
            .par_iter_mut()
            .enumerate()
            .for_each(|(band, Band { found, masks })| {
                let y0 = n + band * BAND_ROWS;
                let y1 = (y0 + BAND_ROWS).min(height - n);
                found.clear();
                scan_band_dispatch(image, y0..y1, n, threshold, masks, &mut |peak| {
                    found.push(map(peak))
                });
            });
        for band in &self.bands[..bands] {
            out.extend_from_slice(&band.found);
        }
    }
}

/// Pixels compared at once when looking for candidates (one bit each in a `u32` mask).
const CANDIDATE_LANES: usize = 32;

/// [`scan_band`] compiled for AVX2 when the CPU has it (wider compares for the candidate
/// masks; compares are exact, so the peaks are the same on every path).
fn scan_band_dispatch(
    image: &GrayImage,
    ys: std::ops::Range<usize>,
    n: usize,
    threshold: f32,
    masks: &mut [Vec<u32>; 2],
    emit: &mut impl FnMut(Peak),
) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            unsafe { scan_band_avx2(image, ys, n, threshold, masks, emit) };
            return;
        }
    }
    scan_band(image, ys, n, threshold, masks, emit);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn scan_band_avx2(
    image: &GrayImage,
    ys: std::ops::Range<usize>,
    n: usize,
    threshold: f32,
    masks: &mut [Vec<u32>; 2],
    emit: &mut impl FnMut(Peak),
) {
    scan_band(image, ys, n, threshold, masks, emit);
}

/// Hands the peaks of rows `ys` to `emit`, in raster order (see [`PeakFinder::find`]);
/// `masks` is scratch, kept by the caller so that nothing is allocated per band.
///
/// Candidates of a row are checked one row late, once the candidate masks of the next row
/// have been computed: that streaming read has brought the row below into cache, where a
/// window check made right away would wait for memory at almost every candidate (perf: over
/// half of the scan's time on that one load).
#[inline(always)]
fn scan_band(
    image: &GrayImage,
    ys: std::ops::Range<usize>,
    n: usize,
    threshold: f32,
    masks: &mut [Vec<u32>; 2],
    emit: &mut impl FnMut(Peak),
) {
    let [pending, current] = masks;
    let mut pending_y = None;
    for y in ys {
        row_candidates(image.row(y), n, threshold, current);
        if let Some(py) = pending_y {
            check_candidates(image, py, n, pending, emit);
        }
        std::mem::swap(pending, current);
        pending_y = Some(y);
    }
    if let Some(py) = pending_y {
        check_candidates(image, py, n, pending, emit);
    }
}

/// The candidate masks of `row` (see [`is_candidate`]), one per [`CANDIDATE_LANES`] pixels
/// from column `n` to `width − n`, bit `i` of mask `m` for column `n + m·LANES + i`.
#[inline(always)]
fn row_candidates(row: &[f32], n: usize, threshold: f32, masks: &mut Vec<u32>) {
    masks.clear();
    let end = row.len() - n;
    let mut x = n;
    while x < end {
        let lanes = CANDIDATE_LANES.min(end - x);
        masks.push(if lanes == CANDIDATE_LANES {
            candidate_mask(row, x, threshold)
        } else {
            (0..lanes).fold(0u32, |m, i| {
                m | (u32::from(is_candidate(row, x + i, threshold)) << i)
            })
        });
        x += lanes;
    }
}

/// Window checks of the candidates of row `y` (`masks` from [`row_candidates`]), emitting
/// the peaks in column order.
#[inline(always)]
fn check_candidates(
    image: &GrayImage,
    y: usize,
    n: usize,
    masks: &[u32],
    emit: &mut impl FnMut(Peak),
) {
    let row = image.row(y);
    for (m, &mask) in masks.iter().enumerate() {
        let mut mask = mask;
        let x = n + m * CANDIDATE_LANES;
        while mask != 0 {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if is_first_window_max(image, x + i, y, n, row[x + i]) {
                emit(Peak { y, x: x + i });
            }
        }
    }
}

/// `row[x] > threshold`, `row[x] > row[x − 1]` and `row[x] >= row[x + 1]` (false for NaN).
#[inline(always)]
fn is_candidate(row: &[f32], x: usize, threshold: f32) -> bool {
    let v = row[x];
    (v > threshold) & (v > row[x - 1]) & (v >= row[x + 1])
}

/// Bit `i` set when `x + i` is a candidate, for `CANDIDATE_LANES` pixels from `x`: fixed-size
/// branch-free compares the compiler turns into SIMD compares and a mask extraction.
#[inline(always)]
fn candidate_mask(row: &[f32], x: usize, threshold: f32) -> u32 {
    let centre: &[f32; CANDIDATE_LANES] = row[x..x + CANDIDATE_LANES].try_into().unwrap();
    let left: &[f32; CANDIDATE_LANES] = row[x - 1..x - 1 + CANDIDATE_LANES].try_into().unwrap();
    let right: &[f32; CANDIDATE_LANES] = row[x + 1..x + 1 + CANDIDATE_LANES].try_into().unwrap();
    let mut mask = 0u32;
    for i in 0..CANDIDATE_LANES {
        let v = centre[i];
        let hit = (v > threshold) & (v > left[i]) & (v >= right[i]);
        mask |= u32::from(hit) << i;
    }
    mask
}

/// True when every pixel before `(x, y)` in its window is `< v` and every pixel after it is
/// `<= v` (so a NaN in the window rules the peak out).
#[inline(always)]
fn is_first_window_max(image: &GrayImage, x: usize, y: usize, n: usize, v: f32) -> bool {
    if n == 1 {
        // The 3×3 window (the default), branch-free: the same compares, no early exit.
        let (up, row, down) = (
            &image.row(y - 1)[x - 1..=x + 1],
            &image.row(y)[x - 1..=x + 1],
            &image.row(y + 1)[x - 1..=x + 1],
        );
        return (up[0] < v)
            & (up[1] < v)
            & (up[2] < v)
            & (row[0] < v)
            & (row[2] <= v)
            & (down[0] <= v)
            & (down[1] <= v)
            & (down[2] <= v);
    }
    for yy in y - n..=y + n {
        let r = &image.row(yy)[x - n..=x + n];
        let ok = match yy.cmp(&y) {
            std::cmp::Ordering::Less => r.iter().all(|&q| q < v),
            std::cmp::Ordering::Greater => r.iter().all(|&q| q <= v),
            std::cmp::Ordering::Equal => {
                r[..n].iter().all(|&q| q < v) && r[n + 1..].iter().all(|&q| q <= v)
            }
        };
        if !ok {
            return false;
        }
    }
    true
}

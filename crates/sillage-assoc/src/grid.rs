//! The fast index: a uniform grid (bucket grid) rebuilt in O(n) for every frame.
//!
//! Why a grid and not a k-d tree: PTV frames hold 10^3–10^5 particles seeded at a nearly
//! uniform density, and several indexes are built per frame. A counting sort into cells of
//! a few points builds in a fraction of the time of a k-d tree and answers nearest and
//! 10-nearest queries by scanning a few neighbouring cells, without any tree descent;
//! `benches/neighbours.rs` measures it against kiddo's `ImmutableKdTree`. The price:
//! strongly clustered sets (most points in a few cells) degrade towards brute force, where
//! a k-d tree would not.
//!
//! The algorithm is the classic cell-list ("bucketing") search of Bentley, Weide & Yao,
//! *Optimal expected-time algorithms for closest point problems*, ACM TOMS 6(4), 1980:
//! points are counting-sorted by cell into one contiguous structure-of-arrays (cell
//! starts, then x, y and original index), so a run of cells of a grid row is one
//! contiguous slice. A query visits its own cell, then its 8 neighbours nearest first, then
//! square rings of cells of growing Chebyshev radius; it skips rows and cells that lie
//! farther than the current k-th best distance, and stops as soon as every cell not yet
//! visited is farther than it. The k best
//! candidates are kept by insertion into a fixed array of k (no heap, no allocation for
//! k ≤ 32); batches of k-nearest queries take the first 3×3 block by a branch-free
//! selection instead ([`KBest::select_block`]).

use std::ops::Range;

use rayon::prelude::*;
use sillage_core::Point2;

use crate::index::{MIN_QUERIES_PER_TASK, Neighbour, NeighbourIndex};

/// Default mean number of points per grid cell: the 3×3 block first searched then holds
/// the nearest point of 96 % of uniform queries (1 − e^−π), and nearest-neighbour batches
/// run faster than with 2 points per cell (`benches/neighbours.rs`, group `occupancy`).
const DEFAULT_OCCUPANCY: f64 = 1.0;

/// Largest |cell coordinate| a query is mapped to, so ring arithmetic never overflows.
const MAX_CELL_COORD: f64 = (1u64 << 40) as f64;

/// Largest k whose candidate arrays live on the stack.
const STACK_K: usize = 32;

/// Queries per rayon task in [`PointIndex::map_k_nearest`].
const CHUNK: usize = 256;

/// Index meaning "no point" (never a valid index: an index holds fewer points).
const NO_POINT: u32 = u32::MAX;

/// Uniform-grid neighbour index over a set of points, with exact nearest and k-nearest
/// queries (ties to the lower index).
///
/// Build it once per frame ([`PointIndex::new`]) or rebuild it in place
/// ([`PointIndex::rebuild`], [`PointIndex::rebuild_concat`]) to reuse its memory from frame
/// to frame. The cell size is chosen so that cells hold `occupancy` points on average over
/// the bounding box. An index holds fewer than 2³² − 1 points.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct PointIndex {
    occupancy: f64,
    len: usize,
    origin: Point2,
    cell: f64,
    inv_cell: f64,
    slack: f64,
    nx: usize,
    ny: usize,
    /// `starts[c]..starts[c + 1]` are the entries of cell `c = row * nx + column`.
    starts: Vec<u32>,
    /// Entries sorted by cell (structure of arrays): coordinates and original index.
    xs: Vec<f64>,
    ys: Vec<f64>,
    ids: Vec<u32>,
    /// Build scratch: the cell of every point (`NO_POINT` when not finite).
    cell_of: Vec<u32>,
}

impl Default for PointIndex {
    fn default() -> Self {
        Self::with_occupancy(DEFAULT_OCCUPANCY)
    }
}

impl PointIndex {
    /// An index over `points` (one point per cell on average).
    ///
    /// # Panics
    /// If `points` holds 2³² − 1 points or more.
    pub fn new(points: &[Point2]) -> Self {
        let mut index = Self::default();
        index.rebuild(points);
        index
    }

    /// An empty index whose cells will hold `points_per_cell` points on average (values
    /// that are not finite and positive fall back to 1). About 1 suits nearest-neighbour
    /// queries, about `k / 5` suits k-nearest queries.
    pub fn with_occupancy(points_per_cell: f64) -> Self {
        let occupancy = if points_per_cell.is_finite() && points_per_cell > 0.0 {
            points_per_cell
        } else {
            DEFAULT_OCCUPANCY
        };
        Self {
            occupancy,
            len: 0,
            origin: Point2::default(),
            cell: 1.0,
            inv_cell: 1.0,
            slack: 0.0,
            nx: 0,
            ny: 0,
            starts: vec![0],
            xs: Vec::new(),
            ys: Vec::new(),
            ids: Vec::new(),
            cell_of: Vec::new(),
        }
    }

    /// Re-indexes `points`, keeping this index's allocations.
    ///
    /// # Panics
    /// If `points` holds 2³² − 1 points or more.
    pub fn rebuild(&mut self, points: &[Point2]) {
        self.rebuild_parts(&[points]);
    }

    /// Re-indexes the concatenation of `first` and `second` without copying it: the points
    /// of `second` get indexes `first.len()..`. Keeps this index's allocations.
    ///
    /// # Panics
    /// If the two sets hold 2³² − 1 points or more together.
    pub fn rebuild_concat(&mut self, first: &[Point2], second: &[Point2]) {
        self.rebuild_parts(&[first, second]);
    }

    /// Indexes the concatenation of `parts`.
    fn rebuild_parts(&mut self, parts: &[&[Point2]]) {
        let len: usize = parts.iter().map(|p| p.len()).sum();
        assert!(
            len < NO_POINT as usize,
            "a PointIndex holds fewer than 2^32 - 1 points (got {len})"
        );
        self.len = len;
        self.cell_of.clear();
        self.starts.clear();
        let all = || parts.iter().flat_map(|p| p.iter());
        let (lo, hi, n_finite) = bounding_box(all());
        if n_finite == 0 {
            self.nx = 0;
            self.ny = 0;
            self.starts.push(0);
            self.xs.clear();
            self.ys.clear();
            self.ids.clear();
            return;
        }
        self.layout(lo, hi, n_finite);
        let n_cells = self.nx * self.ny;
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        self.starts.resize(n_cells + 1, 0);
        self.cell_of.resize(len, NO_POINT);
        // Local slices, so that the loops do not reload the vectors' pointers after every
        // store (they did: perf put 28 % of the build's samples on those loads, and the
        // slices took 14 % off it).
        let (inv_cell, row_len) = (self.inv_cell, self.nx);
        let (starts, cell_of) = (&mut self.starts[..], &mut self.cell_of[..]);
        for (p, cell) in all().zip(cell_of.iter_mut()) {
            if p.is_finite() {
                let cx = floor_cell((p.x - lo.x) * inv_cell).clamp(0, nx - 1) as usize;
                let cy = floor_cell((p.y - lo.y) * inv_cell).clamp(0, ny - 1) as usize;
                let c = cy * row_len + cx;
                starts[c] += 1;
                *cell = c as u32;
            }
        }
        // Counting sort: inclusive prefix sums give each cell's end; filling from the last
        // point backwards moves every end down to its cell's start and keeps each cell's
        // points in increasing index order.
        let mut total = 0;
        for s in &mut self.starts[..n_cells] {
            total += *s;
            *s = total;
        }
        self.starts[n_cells] = total;
        let total = total as usize;
        self.xs.resize(total, 0.0);
        self.ys.resize(total, 0.0);
        self.ids.resize(total, 0);
        let (starts, cell_of) = (&mut self.starts[..], &self.cell_of[..]);
        let (xs, ys, ids) = (&mut self.xs[..], &mut self.ys[..], &mut self.ids[..]);
        let mut end = len;
        for part in parts.iter().rev() {
            end -= part.len();
            for (j, p) in part.iter().enumerate().rev() {
                let index = end + j;
                let c = cell_of[index];
                if c != NO_POINT {
                    let slot = &mut starts[c as usize];
                    *slot -= 1;
                    let at = *slot as usize;
                    xs[at] = p.x;
                    ys[at] = p.y;
                    ids[at] = index as u32;
                }
            }
        }
    }

    /// Chooses the cell size and grid shape for a box `lo..hi` holding `n` finite points.
    fn layout(&mut self, lo: Point2, hi: Point2, n: usize) {
        let (w, h) = (hi.x - lo.x, hi.y - lo.y);
        let extent = w.max(h);
        let nf = n as f64;
        let max_cells = 4 * n + 16;
        let mut cell = (w * h * self.occupancy / nf)
            .sqrt()
            .max(extent * self.occupancy / nf);
        let (mut nx, mut ny) = (1, 1);
        if cell.is_finite() && cell > 0.0 {
            nx = (w / cell) as usize + 1;
            ny = (h / cell) as usize + 1;
        }
        if !(cell.is_finite() && cell > 0.0) || nx.saturating_mul(ny) > max_cells {
            // Degenerate box (one point repeated, or coordinates too large to subtract):
            // a single cell, which the queries scan exhaustively.
            (nx, ny) = (1, 1);
            cell = f64::INFINITY;
        }
        self.origin = lo;
        self.nx = nx;
        self.ny = ny;
        self.cell = cell;
        self.inv_cell = if cell.is_finite() { 1.0 / cell } else { 0.0 };
        // Rounding in the cell assignment can put a point a few ulps beyond its cell's
        // walls; every distance bound is lowered by this much so the search stays exact.
        let scale = lo.x.abs() + lo.y.abs() + hi.x.abs() + hi.y.abs();
        self.slack = 1e-9 * (scale + if cell.is_finite() { cell } else { 0.0 });
    }

    /// Cell coordinate of an offset from the origin (unclamped, saturating).
    #[inline]
    fn cell_coord(&self, offset: f64) -> i64 {
        floor_cell(offset * self.inv_cell)
    }

    /// Lower bound on the distance along one axis from `p` to the slab of cells `c`
    /// (walls at `origin + c·cell` and `origin + (c + 1)·cell`); 0 inside it, and 0 when
    /// the walls are not finite (degenerate single-cell grid).
    #[inline]
    fn gap(&self, p: f64, origin: f64, c: i64) -> f64 {
        let lo = origin + c as f64 * self.cell;
        let hi = origin + (c + 1) as f64 * self.cell;
        ((lo - p).max(p - hi) - self.slack).max(0.0)
    }

    /// Visits cells in square rings of growing Chebyshev radius around `p`'s cell, handing
    /// their points to `visitor`. A row or cell of a ring is skipped when it lies farther
    /// than the squared distance a point must beat, and the search stops when every cell
    /// not yet visited does.
    ///
    /// Visitors with [`Visitor::BLOCK_FIRST`] start with the whole 3×3 block around `p`'s
    /// cell; the others with `p`'s own cell, so that a search within a small distance
    /// touches the cells that distance reaches only.
    #[inline]
    fn search<V: Visitor>(&self, p: Point2, visitor: &mut V) {
        if self.xs.is_empty() || !p.is_finite() {
            return;
        }
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        let cx = self.cell_coord(p.x - self.origin.x);
        let cy = self.cell_coord(p.y - self.origin.y);
        let mut r_first = 0.max(-cx).max(cx - (nx - 1)).max(-cy).max(cy - (ny - 1));
        let r_last = cx.max(nx - 1 - cx).max(cy).max(ny - 1 - cy);
        if r_first == 0 && V::BLOCK_FIRST {
            // Inside the grid: the 3×3 block first, as three row runs (each run of cells is
            // contiguous in storage), the query's own row first and then the row on its side,
            // so the k-th best tightens early and farther cells are skipped or rejected point
            // by point without insertion.
            let (x_lo, x_hi) = ((cx - 1).max(0) as usize, (cx + 1).min(nx - 1) as usize);
            let below = (p.y - self.origin.y) * self.inv_cell - (cy as f64) < 0.5;
            let rows = if below {
                [cy, cy - 1, cy + 1]
            } else {
                [cy, cy + 1, cy - 1]
            };
            let mut runs = [0..0, 0..0, 0..0];
            let mut n_runs = 0;
            for y in rows {
                if (0..ny).contains(&y) {
                    let row = y as usize * self.nx;
                    runs[n_runs] =
                        self.starts[row + x_lo] as usize..self.starts[row + x_hi + 1] as usize;
                    n_runs += 1;
                }
            }
            visitor.visit_block(self, &runs[..n_runs]);
            if r_last <= 1 {
                return;
            }
            let bound = self.unvisited_bound(p, cx, cy, 1);
            if bound > 0.0 && visitor.worst_d2() < bound * bound {
                return;
            }
            r_first = 2;
        }
        for r in r_first..=r_last {
            let (x_lo, x_hi) = ((cx - r).max(0), (cx + r).min(nx - 1));
            let (y_lo, y_hi) = ((cy - r).max(0), (cy + r).min(ny - 1));
            for y in y_lo..=y_hi {
                let row = (y * nx) as usize;
                let gy = self.gap(p.y, self.origin.y, y);
                let gy2 = gy * gy;
                if gy2 > visitor.worst_d2() {
                    continue;
                }
                if y == cy - r || y == cy + r {
                    self.visit_cells(row + x_lo as usize, row + x_hi as usize, visitor);
                } else {
                    // Here r > 0, so the two side cells are distinct.
                    for x in [cx - r, cx + r] {
                        if (0..nx).contains(&x) {
                            let gx = self.gap(p.x, self.origin.x, x);
                            if gx * gx + gy2 <= visitor.worst_d2() {
                                let c = row + x as usize;
                                self.visit_cells(c, c, visitor);
                            }
                        }
                    }
                }
            }
            if r < r_last {
                let bound = self.unvisited_bound(p, cx, cy, r);
                if bound > 0.0 && visitor.worst_d2() < bound * bound {
                    return;
                }
            }
        }
    }

    /// [`NeighbourIndex::nearest_batch`] for queries that mostly lie much closer to their
    /// nearest point than the spacing between points, as predicted positions to their
    /// matches in particle tracking: each query first looks in its own cell only and stops
    /// there when nothing outside can be closer. Same answers; faster on such queries
    /// (PTV's forward association), ~15-20 % slower on queries scattered at random.
    pub fn nearest_batch_near(&self, queries: &[Point2], out: &mut Vec<Option<Neighbour>>) {
        queries
            .par_iter()
            .with_min_len(MIN_QUERIES_PER_TASK)
            .map(|&q| self.nearest_from(q, true))
            .collect_into_vec(out);
    }

    /// The nearest point to `p`, trying `p`'s own cell alone first when `own_cell_first`.
    #[inline]
    fn nearest_from(&self, p: Point2, own_cell_first: bool) -> Option<Neighbour> {
        let mut nearest = Nearest {
            px: p.x,
            py: p.y,
            d2: f64::INFINITY,
            id: NO_POINT,
        };
        if !(own_cell_first && self.settled_in_own_cell(p, &mut nearest)) {
            self.search(p, &mut nearest);
        }
        (nearest.id != NO_POINT).then(|| (nearest.id as usize, nearest.d2.sqrt()))
    }

    /// Visits the points of `p`'s own cell and returns true when the nearest of them is
    /// closer than any point outside the cell can be: then the search is over after one
    /// cell. Queries that sit on an indexed point, as a well-predicted position sits on its
    /// match, mostly end here; the others go on with the full search, which visits the
    /// cell again (harmless for a nearest point: a point never ranks before itself).
    #[inline]
    fn settled_in_own_cell(&self, p: Point2, nearest: &mut Nearest) -> bool {
        if self.xs.is_empty() || !p.is_finite() {
            return false;
        }
        let cx = self.cell_coord(p.x - self.origin.x);
        let cy = self.cell_coord(p.y - self.origin.y);
        if !((0..self.nx as i64).contains(&cx) && (0..self.ny as i64).contains(&cy)) {
            return false;
        }
        let cell = cy as usize * self.nx + cx as usize;
        self.visit_cells(cell, cell, nearest);
        let bound = self.unvisited_bound(p, cx, cy, 0);
        bound > 0.0 && nearest.d2 < bound * bound
    }

    /// Hands the points of cells `first..=last` (contiguous in storage) to `visitor`.
    #[inline]
    fn visit_cells(&self, first: usize, last: usize, visitor: &mut impl Visitor) {
        let run = self.starts[first] as usize..self.starts[last + 1] as usize;
        self.visit_runs(std::slice::from_ref(&run), visitor);
    }

    /// Hands the points of runs of storage slots to `visitor`, run by run.
    #[inline]
    fn visit_runs(&self, runs: &[Range<usize>], visitor: &mut impl Visitor) {
        for run in runs {
            visitor.visit(
                run.start,
                &self.xs[run.clone()],
                &self.ys[run.clone()],
                &self.ids[run.clone()],
            );
        }
    }

    /// Lower bound on the distance from `p` to any point outside the block of cells within
    /// Chebyshev radius `r` of `(cx, cy)`; block sides at the grid's edge do not count.
    fn unvisited_bound(&self, p: Point2, cx: i64, cy: i64, r: i64) -> f64 {
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        let wall = |origin: f64, c: i64| origin + c as f64 * self.cell;
        let mut bound = f64::INFINITY;
        if cx - r > 0 {
            bound = bound.min(p.x - wall(self.origin.x, cx - r));
        }
        if cx + r < nx - 1 {
            bound = bound.min(wall(self.origin.x, cx + r + 1) - p.x);
        }
        if cy - r > 0 {
            bound = bound.min(p.y - wall(self.origin.y, cy - r));
        }
        if cy + r < ny - 1 {
            bound = bound.min(wall(self.origin.y, cy + r + 1) - p.y);
        }
        bound - self.slack
    }

    /// The fewest nearest points of `p` that stand for `k` samples together (all points when
    /// they stand for fewer), as (squared distance, [`slot_key`]), nearest first, written to
    /// the front of `d2` / `keys` (both at least `k + 1` long: one more for the insertion);
    /// returns how many points and how many samples they stand for.
    #[inline]
    fn k_nearest_into<M: Multiplicity>(
        &self,
        p: Point2,
        k: usize,
        counts: M,
        d2: &mut [f64],
        keys: &mut [u64],
        block: Option<&mut BlockCandidates>,
    ) -> (usize, usize) {
        let mut best = KBest {
            px: p.x,
            py: p.y,
            block,
            k,
            n: 0,
            samples: 0,
            counts,
            d2,
            keys,
            worst: f64::INFINITY,
            worst_key: u64::MAX,
        };
        if k > 0 {
            self.search(p, &mut best);
            if let Some(block) = best.block.as_deref_mut().filter(|_| best.samples >= k) {
                block.last_worst = best.worst;
            }
        }
        (best.n, best.samples)
    }

    /// Whether the indexed point `candidate`, held at `candidate_at`, is the nearest indexed
    /// point to `p` (ties to the lower index), i.e. whether [`NeighbourIndex::nearest`]
    /// would answer it. Only the cells within the candidate's distance are searched, and
    /// the search stops at the first point that ranks before it: when the candidate is
    /// close to `p`, as a predicted position to its match, this is a small fraction of a
    /// nearest query. `candidate_at` must be the position the index was built from.
    pub fn is_nearest(&self, p: Point2, candidate: usize, candidate_at: Point2) -> bool {
        let (dx, dy) = (p.x - candidate_at.x, p.y - candidate_at.y);
        let mut rival = Rival {
            px: p.x,
            py: p.y,
            d2: dx * dx + dy * dy,
            id: candidate as u32,
            found: false,
        };
        self.search(p, &mut rival);
        !rival.found
    }

    /// Calls `f(index, squared distance)` for every point within `radius` of `p` (distance
    /// ≤ `radius`; none for a non-finite `p` or a negative or NaN `radius`), in an order fixed
    /// by the indexed set: gating (association search regions, contacts, truncated kernels).
    pub fn for_each_within(&self, p: Point2, radius: f64, f: impl FnMut(usize, f64)) {
        if radius >= 0.0 {
            let mut within = Within {
                px: p.x,
                py: p.y,
                r2: radius * radius,
                f,
            };
            self.search(p, &mut within);
        }
    }

    /// For every query, `f(indexes, slots)` of its `min(k, len)` nearest points, nearest
    /// first (ties to the lower index), in parallel; `out[i]` answers `queries[i]`. Same
    /// neighbours as [`NeighbourIndex::k_nearest`], without the distances and without any
    /// per-query allocation; `out` is overwritten and its allocation reused. The result
    /// does not depend on the number of rayon threads.
    ///
    /// `slots` are the neighbours' places in the index's cell-sorted storage (see
    /// [`PointIndex::slot_indexes`]): data laid out in that order is read from a few
    /// contiguous runs, where data in the original order would be read at random.
    pub fn map_k_nearest<T: Send + Default>(
        &self,
        queries: &[Point2],
        k: usize,
        out: &mut Vec<T>,
        f: impl Fn(&[u32], &[u32]) -> T + Sync,
    ) {
        let k = k.min(self.xs.len());
        self.map_nearest_samples(queries, k, Single, out, |ids, slots, _| f(ids, slots));
    }

    /// [`PointIndex::map_k_nearest`] over points that each stand for several samples at the
    /// same place (`counts_by_slot[slot]` samples, in storage order; 0 counts as 1): for every query,
    /// `f(slots, last_taken)` of the fewest nearest points whose samples reach `k` (all points
    /// when they hold fewer), nearest first, ties to the lower index. The last point gives
    /// only `last_taken` of its samples when the k-th sample falls inside it.
    ///
    /// This is the k-nearest of the multiset where each point is repeated, without indexing
    /// the repeats: the PTV motion model's samples are mostly two per point (a tracklet and
    /// the stored model at the same position). Repeats of different points at exactly the
    /// same distance are ordered by point, not interleaved.
    ///
    /// # Panics
    /// If `counts_by_slot` is shorter than the index.
    pub fn map_k_nearest_counted<T: Send + Default>(
        &self,
        queries: &[Point2],
        k: usize,
        counts_by_slot: &[u8],
        out: &mut Vec<T>,
        f: impl Fn(&[u32], usize) -> T + Sync,
    ) {
        assert!(
            counts_by_slot.len() >= self.xs.len(),
            "one count per indexed point"
        );
        let counts = BySlot(counts_by_slot);
        let all_samples = (0..self.xs.len()).map(|slot| counts.of(slot)).sum();
        let k = k.min(all_samples);
        self.map_nearest_samples(queries, k, counts, out, |_, slots, samples| {
            let last_taken = slots.last().map_or(0, |&slot| {
                let count = counts.of(slot as usize);
                count - samples.saturating_sub(k).min(count - 1)
            });
            f(slots, last_taken)
        });
    }

    /// The shared body of the batch k-nearest queries: `f(indexes, slots, samples)`.
    fn map_nearest_samples<T: Send + Default, M: Multiplicity>(
        &self,
        queries: &[Point2],
        k: usize,
        counts: M,
        out: &mut Vec<T>,
        f: impl Fn(&[u32], &[u32], usize) -> T + Sync,
    ) {
        out.clear();
        out.resize_with(queries.len(), T::default);
        queries
            .par_chunks(CHUNK)
            .zip(out.par_chunks_mut(CHUNK))
            .for_each(|(queries, out)| {
                with_scratch(k + 1, |d2, keys| {
                    let (mut ids, mut slots) = (vec![0; k + 1], vec![0; k + 1]);
                    let mut block = BlockCandidates::new();
                    for (&q, o) in queries.iter().zip(out) {
                        let (n, samples) =
                            self.k_nearest_into(q, k, counts, d2, keys, Some(&mut block));
                        for ((&key, id), slot) in keys[..n].iter().zip(&mut ids).zip(&mut slots) {
                            (*id, *slot) = split_key(key);
                        }
                        *o = f(&ids[..n], &slots[..n], samples);
                    }
                })
            });
    }

    /// The original index of the point held in each storage slot: points are stored sorted
    /// by cell (row-major), in increasing index order within a cell. Lay per-point data out
    /// in this order to read it along with [`PointIndex::map_k_nearest`]'s slots.
    pub fn slot_indexes(&self) -> &[u32] {
        &self.ids
    }
}

/// The cell coordinate of an offset already divided by the cell size: its floor, saturated
/// at ±[`MAX_CELL_COORD`] (NaN maps to 0).
#[inline]
fn floor_cell(scaled: f64) -> i64 {
    // The clamp keeps the truncation exact, and the truncation minus one for negative
    // non-integers is the floor (without a libm call on baseline x86).
    let c = scaled.clamp(-MAX_CELL_COORD, MAX_CELL_COORD);
    if c.is_nan() {
        return 0;
    }
    let t = c as i64;
    t - i64::from(c < t as f64)
}

/// Packs a point's original index (high half, so that keys order as indexes do) and its
/// storage slot into one candidate key.
#[inline]
fn slot_key(id: u32, slot: usize) -> u64 {
    (u64::from(id) << 32) | slot as u64
}

/// (original index, storage slot) of a [`slot_key`].
#[inline]
fn split_key(key: u64) -> (u32, u32) {
    ((key >> 32) as u32, key as u32)
}

/// Runs `f` on candidate arrays of length `k`: on the stack when `k` ≤ [`STACK_K`] + 1.
#[inline]
fn with_scratch<R>(k: usize, f: impl FnOnce(&mut [f64], &mut [u64]) -> R) -> R {
    if k <= STACK_K + 1 {
        let (mut d2, mut keys) = ([0.0; STACK_K + 1], [0; STACK_K + 1]);
        f(&mut d2[..k], &mut keys[..k])
    } else {
        f(&mut vec![0.0; k], &mut vec![0; k])
    }
}

/// What a grid search collects.
trait Visitor {
    /// Whether the search starts with the whole 3×3 block around the query's cell (the
    /// fastest start when the answer is usually found there) rather than its own cell.
    const BLOCK_FIRST: bool = true;

    /// Offers the points of a run of cells: coordinates and original indexes, held in the
    /// storage slots `first_slot..`.
    fn visit(&mut self, first_slot: usize, xs: &[f64], ys: &[f64], ids: &[u32]);

    /// Offers the first block of a search as runs of storage slots, the query's own row
    /// first; by default run by run through [`Visitor::visit`].
    #[inline]
    fn visit_block(&mut self, index: &PointIndex, runs: &[Range<usize>])
    where
        Self: Sized,
    {
        index.visit_runs(runs, self);
    }

    /// Squared distance a point must not exceed to still matter.
    fn worst_d2(&self) -> f64;
}

/// Collects the nearest point (ties to the lower index).
struct Nearest {
    px: f64,
    py: f64,
    d2: f64,
    id: u32,
}

impl Visitor for Nearest {
    #[inline]
    fn visit(&mut self, _first_slot: usize, xs: &[f64], ys: &[f64], ids: &[u32]) {
        for ((&x, &y), &id) in xs.iter().zip(ys).zip(ids) {
            // Computed as `index::dist2`, so that ties are exact.
            let (dx, dy) = (self.px - x, self.py - y);
            let d = dx * dx + dy * dy;
            if d < self.d2 || (d == self.d2 && id < self.id) {
                (self.d2, self.id) = (d, id);
            }
        }
    }

    #[inline]
    fn worst_d2(&self) -> f64 {
        self.d2
    }
}

/// Looks for a point that ranks before a candidate (closer, or as close with a lower
/// index); once one is found nothing more can matter, so the distance to beat drops below
/// zero and the search ends.
struct Rival {
    px: f64,
    py: f64,
    d2: f64,
    id: u32,
    found: bool,
}

impl Visitor for Rival {
    const BLOCK_FIRST: bool = false;

    #[inline]
    fn visit(&mut self, _first_slot: usize, xs: &[f64], ys: &[f64], ids: &[u32]) {
        if self.found {
            return;
        }
        for ((&x, &y), &id) in xs.iter().zip(ys).zip(ids) {
            // Computed as `Nearest::visit`, so that ties are decided alike.
            let (dx, dy) = (self.px - x, self.py - y);
            let d = dx * dx + dy * dy;
            if d < self.d2 || (d == self.d2 && id < self.id) {
                self.found = true;
                return;
            }
        }
    }

    #[inline]
    fn worst_d2(&self) -> f64 {
        if self.found { -1.0 } else { self.d2 }
    }
}

/// Hands every point within a fixed squared distance to a callback.
struct Within<F> {
    px: f64,
    py: f64,
    r2: f64,
    f: F,
}

impl<F: FnMut(usize, f64)> Visitor for Within<F> {
    #[inline]
    fn visit(&mut self, _first_slot: usize, xs: &[f64], ys: &[f64], ids: &[u32]) {
        for ((&x, &y), &id) in xs.iter().zip(ys).zip(ids) {
            let (dx, dy) = (self.px - x, self.py - y);
            let d = dx * dx + dy * dy;
            if d <= self.r2 {
                (self.f)(id as usize, d);
            }
        }
    }

    #[inline]
    fn worst_d2(&self) -> f64 {
        self.r2
    }
}

/// How many samples each indexed point stands for, in the k-nearest searches.
trait Multiplicity: Copy + Sync {
    /// Samples of the point in storage slot `slot` (≥ 1).
    fn of(self, slot: usize) -> usize;
}

/// Every point is one sample: the plain k-nearest.
#[derive(Clone, Copy)]
struct Single;

impl Multiplicity for Single {
    #[inline]
    fn of(self, _slot: usize) -> usize {
        1
    }
}

/// Samples per point given in storage order.
#[derive(Clone, Copy)]
struct BySlot<'a>(&'a [u8]);

impl Multiplicity for BySlot<'_> {
    #[inline]
    fn of(self, slot: usize) -> usize {
        usize::from(self.0[slot]).max(1)
    }
}

/// Collects the fewest nearest points that stand for `k` samples, sorted by (squared
/// distance, index), by insertion into fixed arrays (of `k + 1`, the point being inserted
/// included). A candidate's key packs its index and storage slot ([`slot_key`]), so
/// comparing keys compares indexes.
struct KBest<'a, M> {
    px: f64,
    py: f64,
    /// Scratch for the first block, carried from query to query (batches only: a single
    /// query has no previous one to guess from).
    block: Option<&'a mut BlockCandidates>,
    k: usize,
    /// Points held, and the samples they stand for.
    n: usize,
    samples: usize,
    counts: M,
    d2: &'a mut [f64],
    keys: &'a mut [u64],
    /// The farthest point held once they stand for k samples (infinite and `u64::MAX`
    /// before).
    worst: f64,
    worst_key: u64,
}

impl<M: Multiplicity> KBest<'_, M> {
    /// Samples of the point of `key`.
    #[inline]
    fn count(&self, key: u64) -> usize {
        self.counts.of(split_key(key).1 as usize)
    }

    /// Inserts a candidate that ranks before the current farthest point (or any while
    /// fewer than k samples are held), shifting the farther ones up one place, then drops
    /// the farthest points the others make unnecessary.
    #[inline]
    fn insert(&mut self, d: f64, key: u64) {
        let mut at = self.n;
        self.n += 1;
        while at > 0 {
            let (prev_d, prev_key) = (self.d2[at - 1], self.keys[at - 1]);
            if d < prev_d || (d == prev_d && key < prev_key) {
                self.d2[at] = prev_d;
                self.keys[at] = prev_key;
                at -= 1;
            } else {
                break;
            }
        }
        self.d2[at] = d;
        self.keys[at] = key;
        self.samples += self.count(key);
        while self.n > 1 {
            let last = self.count(self.keys[self.n - 1]);
            if self.samples - last < self.k {
                break;
            }
            self.samples -= last;
            self.n -= 1;
        }
        if self.samples >= self.k {
            self.worst = self.d2[self.n - 1];
            self.worst_key = self.keys[self.n - 1];
        }
    }
}

/// Capacity of [`BlockCandidates`]; a first block holding more points (a cluster) is
/// visited point by point.
const BLOCK_CAP: usize = 96;

/// The radii, as factors of the previous query's k-th squared distance, within which the
/// first block's points are taken as candidates in [`KBest::select_block`], tried in turn
/// until the candidates stand for k samples. The choice hardly matters: in a one-thread
/// probe (25k uniform queries, counted 10-nearest, k/8 positions per cell) 1.3 then 2.5,
/// 1.6 then 3, and 1.6 alone all ran at 145-154 ns per query, 2 then 4 at 153-156.
const GUESS_FACTORS: [f64; 3] = [1.3, 2.5, f64::INFINITY];

/// Scratch of [`KBest::select_block`], carried from query to query: the first block's
/// squared distances and slots, the candidates chosen among them, and the previous
/// query's k-th squared distance (neighbouring queries of a batch see about the same
/// density of points).
struct BlockCandidates {
    all_d2: [f64; BLOCK_CAP],
    all_slots: [u32; BLOCK_CAP],
    d2: [f64; BLOCK_CAP],
    slots: [u32; BLOCK_CAP],
    last_worst: f64,
}

impl BlockCandidates {
    fn new() -> Self {
        Self {
            all_d2: [0.0; BLOCK_CAP],
            all_slots: [0; BLOCK_CAP],
            d2: [0.0; BLOCK_CAP],
            slots: [0; BLOCK_CAP],
            last_worst: f64::INFINITY,
        }
    }
}

impl<M: Multiplicity> KBest<'_, M> {
    /// The first block by selection rather than insertion, without data-dependent
    /// branches in the inner loops (the insertion's mispredictions were most of a query's
    /// time): every squared distance of the block is computed, the points within a guessed
    /// radius ([`GUESS_FACTORS`]) are gathered, widening it until they stand for k samples,
    /// and each candidate is placed at its rank, the number of candidates strictly closer.
    /// Ranks are a sort only when no two candidates are at the same distance; then, or for
    /// a block larger than [`BLOCK_CAP`], or with no guess yet, it returns false having
    /// kept nothing, and the block is visited point by point.
    #[inline]
    fn select_block(&mut self, index: &PointIndex, runs: &[Range<usize>]) -> bool {
        let total: usize = runs.iter().map(|r| r.len()).sum();
        let Some(block) = self.block.as_deref_mut() else {
            return false;
        };
        if self.n > 0 || total > BLOCK_CAP || !block.last_worst.is_finite() {
            return false;
        }
        let counts = self.counts;
        let mut t = 0;
        for run in runs {
            let (xs, ys) = (&index.xs[run.clone()], &index.ys[run.clone()]);
            for (slot, (&x, &y)) in (run.start..).zip(xs.iter().zip(ys)) {
                let (dx, dy) = (self.px - x, self.py - y);
                block.all_d2[t] = dx * dx + dy * dy;
                block.all_slots[t] = slot as u32;
                t += 1;
            }
        }
        let mut m = 0;
        for factor in GUESS_FACTORS {
            let radius2 = block.last_worst * factor;
            m = 0;
            for (&d, &slot) in block.all_d2[..t].iter().zip(&block.all_slots[..t]) {
                block.d2[m] = d;
                block.slots[m] = slot;
                m += usize::from(d <= radius2);
            }
            let held: usize = block.slots[..m]
                .iter()
                .map(|&slot| counts.of(slot as usize))
                .sum();
            if held >= self.k {
                break;
            }
            if factor == f64::INFINITY {
                return false;
            }
        }
        // Ranks k and beyond all land in the spare last place: only the first k matter,
        // as each point stands for at least one sample.
        let spare = self.d2.len() - 1;
        let mut tied = false;
        for i in 0..m {
            let d = block.d2[i];
            let (mut closer, mut level) = (0u64, 0u64);
            for &other in &block.d2[..m] {
                closer += u64::from(other < d);
                level += u64::from(other == d);
            }
            tied |= level > 1;
            let at = (closer as usize).min(spare);
            let slot = block.slots[i] as usize;
            self.d2[at] = d;
            self.keys[at] = slot_key(index.ids[slot], slot);
        }
        if tied {
            return false;
        }
        let (mut n, mut samples) = (0, 0);
        while samples < self.k {
            samples += counts.of(split_key(self.keys[n]).1 as usize);
            n += 1;
        }
        self.n = n;
        self.samples = samples;
        self.worst = self.d2[n - 1];
        self.worst_key = self.keys[n - 1];
        true
    }
}

impl<M: Multiplicity> Visitor for KBest<'_, M> {
    #[inline]
    fn visit_block(&mut self, index: &PointIndex, runs: &[Range<usize>]) {
        if !self.select_block(index, runs) {
            index.visit_runs(runs, self);
        }
    }

    #[inline]
    fn visit(&mut self, first_slot: usize, xs: &[f64], ys: &[f64], ids: &[u32]) {
        for (slot, ((&x, &y), &id)) in (first_slot..).zip(xs.iter().zip(ys).zip(ids)) {
            let (dx, dy) = (self.px - x, self.py - y);
            let d = dx * dx + dy * dy;
            if d <= self.worst {
                let key = slot_key(id, slot);
                if d < self.worst || key < self.worst_key {
                    self.insert(d, key);
                }
            }
        }
    }

    #[inline]
    fn worst_d2(&self) -> f64 {
        self.worst
    }
}

impl NeighbourIndex for PointIndex {
    fn len(&self) -> usize {
        self.len
    }

    fn nearest(&self, p: Point2) -> Option<Neighbour> {
        self.nearest_from(p, false)
    }

    fn k_nearest(&self, p: Point2, k: usize, out: &mut Vec<Neighbour>) {
        out.clear();
        let k = k.min(self.xs.len());
        with_scratch(k + 1, |d2, ids| {
            let (n, _) = self.k_nearest_into(p, k, Single, d2, ids, None);
            out.extend(
                ids[..n]
                    .iter()
                    .zip(&d2[..n])
                    .map(|(&key, &d)| (split_key(key).0 as usize, d.sqrt())),
            );
        });
    }
}

/// Bounding box of the finite points and their number.
fn bounding_box<'a>(points: impl Iterator<Item = &'a Point2>) -> (Point2, Point2, usize) {
    let mut lo = Point2::new(f64::INFINITY, f64::INFINITY);
    let mut hi = Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
    let mut n = 0;
    for p in points.filter(|p| p.is_finite()) {
        lo.x = lo.x.min(p.x);
        lo.y = lo.y.min(p.y);
        hi.x = hi.x.max(p.x);
        hi.y = hi.y.max(p.y);
        n += 1;
    }
    (lo, hi, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_sets_are_handled() {
        let same = vec![Point2::new(3.0, 3.0); 5];
        let index = PointIndex::new(&same);
        assert_eq!(index.nearest(Point2::new(0.0, 0.0)).map(|n| n.0), Some(0));
        let line: Vec<_> = (0..100).map(|i| Point2::new(i as f64, 7.0)).collect();
        let index = PointIndex::new(&line);
        assert_eq!(
            index.nearest(Point2::new(41.4, -1e3)).map(|n| n.0),
            Some(41)
        );
        let huge = [Point2::new(-1e308, 0.0), Point2::new(1e308, 1.0)];
        let index = PointIndex::new(&huge);
        assert!(index.nearest(Point2::new(1e307, 0.0)).is_some());
        let index = PointIndex::new(&[Point2::new(f64::NAN, 0.0)]);
        assert_eq!(index.len(), 1);
        assert_eq!(index.nearest(Point2::new(0.0, 0.0)), None);
    }

    /// `n` points on a lattice of `columns` columns spaced `step`, each shifted by a
    /// deterministic jitter in [0, 1), then `repeated` three times (exact duplicates).
    fn jittered_lattice(
        n: usize,
        columns: usize,
        step: (f64, f64),
        repeated: Point2,
    ) -> Vec<Point2> {
        (0..n)
            .map(|i| {
                let j = (i * 7919 % 101) as f64 / 101.0;
                Point2::new(
                    (i % columns) as f64 * step.0 + j,
                    (i / columns) as f64 * step.1 - j,
                )
            })
            .chain([repeated; 3])
            .collect()
    }

    #[test]
    fn radius_queries_match_brute_force() {
        // A jittered lattice with repeated points, queried inside, on and outside the box.
        let pts = jittered_lattice(400, 23, (1.7, 2.3), Point2::new(5.0, 5.0));
        let index = PointIndex::new(&pts);
        for q in 0..200 {
            let p = Point2::new(q as f64 * 0.31 - 8.0, (q * 37 % 60) as f64 - 5.0);
            for radius in [0.0, 0.5, 2.0, 6.5, 100.0] {
                let mut found = Vec::new();
                index.for_each_within(p, radius, |i, d2| found.push((i, d2)));
                found.sort_by_key(|&(i, _)| i);
                let expected: Vec<_> = pts
                    .iter()
                    .enumerate()
                    .map(|(i, x)| (i, (p.x - x.x).powi(2) + (p.y - x.y).powi(2)))
                    .filter(|&(_, d2)| d2 <= radius * radius)
                    .collect();
                assert_eq!(found, expected, "query {p:?} radius {radius}");
            }
        }
        let mut none = 0;
        index.for_each_within(Point2::new(f64::NAN, 0.0), 10.0, |_, _| none += 1);
        index.for_each_within(Point2::new(5.0, 5.0), -1.0, |_, _| none += 1);
        assert_eq!(none, 0);
    }

    #[test]
    fn near_queries_get_the_nearest_batch_answers() {
        // A jittered lattice with repeated points; queries on the points, slightly off
        // them, exactly between them (ties), scattered, and outside the box.
        let pts = jittered_lattice(900, 30, (3.0, 3.0), Point2::new(20.0, 20.0));
        let index = PointIndex::new(&pts);
        let queries: Vec<_> = pts
            .iter()
            .enumerate()
            .map(|(i, p)| match i % 4 {
                0 => *p,
                1 => Point2::new(p.x + 0.2, p.y - 0.1),
                2 => Point2::new((i % 30) as f64 * 3.0 + 1.5, (i / 30) as f64 * 3.0),
                _ => Point2::new((i * 37 % 113) as f64 - 10.0, (i * 53 % 97) as f64 - 5.0),
            })
            .collect();
        let (mut near, mut plain) = (Vec::new(), Vec::new());
        index.nearest_batch_near(&queries, &mut near);
        index.nearest_batch(&queries, &mut plain);
        assert_eq!(near, plain);
    }

    #[test]
    fn far_queries_terminate() {
        let pts: Vec<_> = (0..50)
            .map(|i| Point2::new((i % 7) as f64, (i / 7) as f64))
            .collect();
        let index = PointIndex::new(&pts);
        assert_eq!(index.nearest(Point2::new(1e6, -1e6)).map(|n| n.0), Some(6));
        assert_eq!(index.nearest(Point2::new(f64::INFINITY, 0.0)), None);
    }
}

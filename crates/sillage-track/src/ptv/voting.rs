//! Displacement voting: the local displacement between two frames, estimated from the point
//! sets alone, to start and to correct the motion model in fast flows.
//!
//! TracTrac's predictor is built from tracklets, and the first tracklets come from plain
//! nearest neighbours, which are wrong as soon as displacements exceed the spacing between
//! objects (p⁻¹ ≳ 0.5); the model then learns from wrong links, and a region where it has
//! gone wrong never recovers, since wrong links agree with a wrong model. This module does
//! what PIV's cross-correlation does, on point sets. In each cell of a grid, every point of
//! frame `a` votes for its displacement to every point of frame `b` within a search radius
//! of its prior (zero, or the model's prediction); the true displacement, shared by the
//! cell's points, collects about one vote per point while the wrong pairs scatter over the
//! histogram. The cell's residual is the median of the votes at the histogram's peak.
//! Cells without a significant peak, and outliers of the normalised median test
//! (Westerweel & Scarano 2005, Exp. Fluids 39:1096), take the median of their neighbours.
//! A second pass on a grid twice as fine searches a small radius around the first estimate
//! (PIV's multi-pass refinement). Each point's displacement is its prior plus the bilinear
//! interpolation of the residual fields.

use rayon::prelude::*;
use sillage_core::{Point2, Vec2};

/// Points of frame `a` per cell of the first pass: enough votes for a clear peak.
const POINTS_PER_CELL: f64 = 24.0;
/// Histogram bins across the search radius in the first pass.
const BINS_PER_RADIUS: f64 = 25.0;
/// Smallest histogram bin, px (sub-pixel bins only split the peak).
const MIN_BIN_PX: f64 = 0.5;
/// Second pass: search radius in first-pass bins, and bin as a share of the first bin.
const REFINE_RADIUS_BINS: f64 = 3.0;
const REFINE_BIN_SHARE: f64 = 0.25;
/// Normalised median test: residual threshold and noise floor in bins (Westerweel &
/// Scarano's 2 and 0.1 px, the floor scaled to the bin).
const MEDIAN_TEST_THRESHOLD: f64 = 2.0;
const MEDIAN_TEST_FLOOR_BINS: f64 = 0.1;
/// A peak is significant when it exceeds the count expected from random pairs by this
/// many Poisson standard deviations, and holds at least [`MIN_PEAK_VOTES`].
const PEAK_SIGMAS: f64 = 4.0;
const MIN_PEAK_VOTES: f64 = 3.0;
/// Fewest grid cells a rayon task tests or fills.
const CELLS_PER_TASK: usize = 256;

/// What a vote found besides the displacements.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Vote {
    /// The last histogram bin, px: the resolution of the voted displacements.
    pub resolution_px: f64,
    /// Mean spacing between the points of `a`, `√(area / n)`, px.
    pub spacing_px: f64,
    /// Share of the points of `a` whose first-pass cell found its own displacement (a
    /// significant peak that passed the median test), in `[0, 1]`; the others took their
    /// neighbours'. PIV's valid-vector ratio: low when the flow varies too much within a
    /// cell for its points to agree on one displacement.
    pub valid_share: f64,
}

/// The displacement from frame `a` to frame `b` at each point of `a`, written to `out`
/// (same order as `a`), and what the vote found ([`Vote`]); `None` (and `out`
/// left empty) when no cell found a significant displacement. `prior` (per point of `a`,
/// zero when `None`) is the first guess and `search_px` the largest error of it searched.
pub(crate) fn voted_displacements(
    a: &[Point2],
    b: &[Point2],
    prior: Option<&[Vec2]>,
    search_px: f64,
    out: &mut Vec<Vec2>,
) -> Option<Vote> {
    out.clear();
    if a.is_empty() || b.is_empty() {
        return None;
    }
    let extent = Extent::covering(a.iter().chain(b));
    let spacing_px = (extent.area() / a.len() as f64).sqrt();
    let cell = spacing_px * POINTS_PER_CELL.sqrt();
    let bin = (search_px / BINS_PER_RADIUS).max(MIN_BIN_PX);
    let coarse_grid = Grid::new(&extent, cell);
    let zero;
    let prior = match prior {
        Some(prior) => prior,
        None => {
            zero = vec![Vec2::ZERO; a.len()];
            &zero
        }
    };
    let (coarse, valid) = vote_field(a, b, prior, &coarse_grid, search_px, bin)?;
    let valid_points = a
        .iter()
        .filter(|&&p| {
            let (cx, cy) = coarse_grid.cell_of(p);
            valid[cy * coarse_grid.nx + cx]
        })
        .count();
    let valid_share = valid_points as f64 / a.len() as f64;
    let refined: Vec<Vec2> = a
        .iter()
        .zip(prior)
        .map(|(&p, &d)| d + coarse_grid.interpolate(&coarse, p))
        .collect();
    let fine_grid = Grid::new(&extent, cell / 2.0);
    let fine_bin = (bin * REFINE_BIN_SHARE).max(MIN_BIN_PX);
    let fine_radius = bin * REFINE_RADIUS_BINS;
    match vote_field(a, b, &refined, &fine_grid, fine_radius, fine_bin) {
        Some((fine, _)) => {
            out.extend(
                a.iter()
                    .zip(&refined)
                    .map(|(&p, &d)| d + fine_grid.interpolate(&fine, p)),
            );
            Some(Vote {
                resolution_px: fine_bin,
                spacing_px,
                valid_share,
            })
        }
        None => {
            out.extend_from_slice(&refined);
            Some(Vote {
                resolution_px: bin,
                spacing_px,
                valid_share,
            })
        }
    }
}

/// Mean spacing between `points`, `√(bounding-box area / n)`, px (0 without points).
pub(crate) fn mean_spacing(points: &[Point2]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    (Extent::covering(points.iter()).area() / points.len() as f64).sqrt()
}

/// Bounding box of the points of both frames.
struct Extent {
    min: Point2,
    max: Point2,
}

impl Extent {
    fn covering<'a>(points: impl Iterator<Item = &'a Point2>) -> Self {
        let mut min = Point2::new(f64::INFINITY, f64::INFINITY);
        let mut max = Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
        for p in points {
            min = Point2::new(min.x.min(p.x), min.y.min(p.y));
            max = Point2::new(max.x.max(p.x), max.y.max(p.y));
        }
        Self { min, max }
    }

    /// Area in px², at least 1 (all points may share a row).
    fn area(&self) -> f64 {
        ((self.max.x - self.min.x).max(1.0)) * ((self.max.y - self.min.y).max(1.0))
    }
}

/// A grid of square cells over an [`Extent`], with cells bucketing points.
struct Grid {
    origin: Point2,
    cell: f64,
    nx: usize,
    ny: usize,
}

impl Grid {
    fn new(extent: &Extent, cell: f64) -> Self {
        let cell = cell.max(1.0);
        let count = |span: f64| ((span / cell).floor() as usize + 1).max(1);
        Self {
            origin: extent.min,
            cell,
            nx: count(extent.max.x - extent.min.x),
            ny: count(extent.max.y - extent.min.y),
        }
    }

    fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// The (column, row) of the cell holding `p`, clamped to the grid.
    fn cell_of(&self, p: Point2) -> (usize, usize) {
        let clamp = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
        (
            clamp((p.x - self.origin.x) / self.cell, self.nx),
            clamp((p.y - self.origin.y) / self.cell, self.ny),
        )
    }

    /// Counting sort of `points` by cell: `(starts, order)` with the points of cell `c` at
    /// `order[starts[c]..starts[c + 1]]`, in increasing index order.
    fn bucket(&self, points: &[Point2]) -> (Vec<usize>, Vec<usize>) {
        let mut starts = vec![0usize; self.len() + 1];
        let cells: Vec<usize> = points
            .iter()
            .map(|&p| {
                let (cx, cy) = self.cell_of(p);
                cy * self.nx + cx
            })
            .collect();
        for &c in &cells {
            starts[c + 1] += 1;
        }
        for c in 0..self.len() {
            starts[c + 1] += starts[c];
        }
        let mut fill = starts.clone();
        let mut order = vec![0usize; points.len()];
        for (i, &c) in cells.iter().enumerate() {
            order[fill[c]] = i;
            fill[c] += 1;
        }
        (starts, order)
    }

    /// Bilinear interpolation at `p` of a field given at the cell centres.
    fn interpolate(&self, field: &[Vec2], p: Point2) -> Vec2 {
        let axis = |v: f64, n: usize| {
            let t = ((v / self.cell) - 0.5).clamp(0.0, (n - 1) as f64);
            let i0 = (t.floor() as usize).min(n.saturating_sub(2));
            let i1 = (i0 + 1).min(n - 1);
            (i0, i1, t - i0 as f64)
        };
        let (x0, x1, fx) = axis(p.x - self.origin.x, self.nx);
        let (y0, y1, fy) = axis(p.y - self.origin.y, self.ny);
        let at = |cx: usize, cy: usize| field[cy * self.nx + cx];
        let top = at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx;
        let bottom = at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

/// One voting pass: per cell of `grid`, the residual displacement of its points of `a`
/// beyond their `prior`, searched within `radius` of each point's `prior` displacement with bins of `bin`
/// px; invalid cells are filled from their neighbours. With the field, which cells found
/// their own (valid) displacement. `None` when no cell has a peak.
fn vote_field(
    a: &[Point2],
    b: &[Point2],
    prior: &[Vec2],
    grid: &Grid,
    radius: f64,
    bin: f64,
) -> Option<(Vec<Vec2>, Vec<bool>)> {
    let (a_starts, a_order) = grid.bucket(a);
    let search = SearchGrid::new(grid, b, radius);
    let half = (radius / bin).ceil() as usize;
    let side = 2 * half + 1;
    // Cells are independent: voted in parallel, each with its own histogram, so the result
    // does not depend on the number of threads.
    let mut field: Vec<Option<Vec2>> = vec![None; grid.len()];
    field.par_iter_mut().enumerate().for_each_init(
        || CellVotes::new(side),
        |votes, (c, slot)| {
            let members = &a_order[a_starts[c]..a_starts[c + 1]];
            if members.is_empty() {
                return;
            }
            votes.pairs.clear();
            for &i in members {
                search.pairs_near(a[i] + prior[i], &mut votes.pairs);
            }
            let (peak_count, peak) = votes.peak(bin, half);
            // Random pairs spread over the search disc: their expected count in 3×3 bins.
            let expected =
                votes.pairs.len() as f64 * 9.0 / (std::f64::consts::PI * (radius / bin).powi(2));
            let significant = (peak_count as f64) >= MIN_PEAK_VOTES
                && (peak_count as f64) > expected + PEAK_SIGMAS * expected.sqrt();
            if !significant {
                return;
            }
            let centre = Vec2::new(
                (peak.0 as f64 - half as f64) * bin,
                (peak.1 as f64 - half as f64) * bin,
            );
            // The median of the votes near the peak: robust to the random pairs among them.
            votes.near_peak.clear();
            let near = votes
                .pairs
                .iter()
                .filter(|&&d| (d - centre).max_abs() <= 1.5 * bin);
            votes.near_peak.extend(near);
            votes.sorted.resize(votes.near_peak.len(), 0.0);
            *slot = Some(median_vec(&votes.near_peak, &mut votes.sorted));
        },
    );
    reject_outliers(&mut field, grid, bin);
    let valid = field.iter().map(Option::is_some).collect();
    fill_gaps(field, grid).map(|field| (field, valid))
}

/// The points of frame `b` bucketed for the pair search: cells about half the search radius
/// (at least half the points' spacing), so that a query tests few more points than the disc
/// holds, whatever the size of the voting cells.
struct SearchGrid {
    grid: Grid,
    /// The points of cell `c` are `points[starts[c]..starts[c + 1]]`.
    starts: Vec<usize>,
    /// The points in cell order, so that a query reads them contiguously.
    points: Vec<Point2>,
    reach: usize,
    radius_sq: f64,
}

impl SearchGrid {
    fn new(voting: &Grid, points: &[Point2], radius: f64) -> Self {
        let (width, height) = (
            voting.nx as f64 * voting.cell,
            voting.ny as f64 * voting.cell,
        );
        let spacing = (width * height / points.len().max(1) as f64).sqrt();
        let cell = (0.5 * radius).max(0.5 * spacing).max(1.0);
        let count = |span: f64| ((span / cell).ceil() as usize).max(1);
        let grid = Grid {
            origin: voting.origin,
            cell,
            nx: count(width),
            ny: count(height),
        };
        let (starts, order) = grid.bucket(points);
        Self {
            reach: (radius / cell).ceil() as usize,
            radius_sq: radius * radius,
            grid,
            starts,
            points: order.iter().map(|&k| points[k]).collect(),
        }
    }

    /// Appends `p − target` for every point `p` within the radius of `target`.
    fn pairs_near(&self, target: Point2, out: &mut Vec<Vec2>) {
        let grid = &self.grid;
        let (tx, ty) = grid.cell_of(target);
        for cy in ty.saturating_sub(self.reach)..=(ty + self.reach).min(grid.ny - 1) {
            let row = cy * grid.nx;
            let (x0, x1) = (
                tx.saturating_sub(self.reach),
                (tx + self.reach).min(grid.nx - 1),
            );
            // The cells of a row are contiguous.
            for &p in &self.points[self.starts[row + x0]..self.starts[row + x1 + 1]] {
                let d = p - target;
                if d.x * d.x + d.y * d.y <= self.radius_sq {
                    out.push(d);
                }
            }
        }
    }
}

/// One voting cell's scratch: its pairs' residuals and their histogram.
struct CellVotes {
    /// Residual displacements of the cell's pairs within the search radius.
    pairs: Vec<Vec2>,
    /// Vote counts per bin, `side × side` bins inside a border of empty bins (so that every
    /// bin has 8 neighbours), all zero between cells.
    histogram: Vec<u32>,
    /// The bins that hold votes (indices into `histogram`), each once.
    voted: Vec<usize>,
    /// The residuals near the peak.
    near_peak: Vec<Vec2>,
    /// Their components, sorted for the median.
    sorted: Vec<f64>,
    side: usize,
}

impl CellVotes {
    fn new(side: usize) -> Self {
        Self {
            pairs: Vec::new(),
            histogram: vec![0; (side + 2) * (side + 2)],
            voted: Vec::new(),
            near_peak: Vec::new(),
            sorted: Vec::new(),
            side,
        }
    }

    /// Bins the pairs (bins of `bin` px, `half` bins each side of zero) and returns the bin
    /// whose 3×3 neighbourhood holds the most votes (ties to the first in raster order) with
    /// that count; only the bins that hold votes are visited, and the histogram is left zero.
    fn peak(&mut self, bin: f64, half: usize) -> (u32, (usize, usize)) {
        let (side, stride) = (self.side, self.side + 2);
        self.voted.clear();
        for d in &self.pairs {
            let ix = ((d.x / bin).round() as i64 + half as i64) as usize;
            let iy = ((d.y / bin).round() as i64 + half as i64) as usize;
            let at = (iy.min(side - 1) + 1) * stride + ix.min(side - 1) + 1;
            if self.histogram[at] == 0 {
                self.voted.push(at);
            }
            self.histogram[at] += 1;
        }
        let h = &self.histogram;
        let mut best = (0u32, usize::MAX);
        for &at in &self.voted {
            let row = |r: usize| h[r - 1] + h[r] + h[r + 1];
            let sum = row(at - stride) + row(at) + row(at + stride);
            // Padded indices keep the raster order.
            if sum > best.0 || (sum == best.0 && at < best.1) {
                best = (sum, at);
            }
        }
        for &at in &self.voted {
            self.histogram[at] = 0;
        }
        if best.1 == usize::MAX {
            return (0, (side / 2, side / 2));
        }
        (best.0, (best.1 % stride - 1, best.1 / stride - 1))
    }
}

/// The valid values among the 8 neighbours of a cell, on the stack.
struct Around {
    values: [Vec2; 8],
    len: usize,
}

impl Around {
    fn as_slice(&self) -> &[Vec2] {
        &self.values[..self.len]
    }

    /// Their component-wise median (at least one value), sorted on the stack.
    fn median(&self) -> Vec2 {
        median_vec(self.as_slice(), &mut [0.0; 8][..self.len])
    }
}

/// The valid values among the 8 neighbours of cell (cx, cy).
fn neighbours(field: &[Option<Vec2>], grid: &Grid, cx: usize, cy: usize) -> Around {
    let mut out = Around {
        values: [Vec2::ZERO; 8],
        len: 0,
    };
    for y in cy.saturating_sub(1)..=(cy + 1).min(grid.ny - 1) {
        for x in cx.saturating_sub(1)..=(cx + 1).min(grid.nx - 1) {
            if (x, y) != (cx, cy)
                && let Some(v) = field[y * grid.nx + x]
            {
                out.values[out.len] = v;
                out.len += 1;
            }
        }
    }
    out
}

/// Component-wise median of `values` (non-empty); each component is sorted in `buffer`, as
/// long as `values`.
fn median_vec(values: &[Vec2], buffer: &mut [f64]) -> Vec2 {
    let mut median = |component: fn(&Vec2) -> f64| {
        for (slot, v) in buffer.iter_mut().zip(values) {
            *slot = component(v);
        }
        buffer.sort_unstable_by(f64::total_cmp);
        let n = buffer.len();
        if n % 2 == 1 {
            buffer[n / 2]
        } else {
            0.5 * (buffer[n / 2 - 1] + buffer[n / 2])
        }
    };
    Vec2::new(median(|v| v.x), median(|v| v.y))
}

/// Normalised median test on every valid cell with at least two valid neighbours: a cell
/// whose residual to the neighbours' median exceeds the threshold becomes invalid. All
/// cells are tested against the field as it was before the test.
fn reject_outliers(field: &mut [Option<Vec2>], grid: &Grid, bin: f64) {
    let floor = MEDIAN_TEST_FLOOR_BINS * bin;
    let before: &[Option<Vec2>] = field;
    let outlier = |c: usize| {
        let Some(v) = before[c] else {
            return false;
        };
        let mut around = neighbours(before, grid, c % grid.nx, c / grid.nx);
        if around.len < 2 {
            return false;
        }
        let median = around.median();
        for u in &mut around.values[..around.len] {
            *u = Vec2::new((u.x - median.x).abs(), (u.y - median.y).abs());
        }
        let scale = around.median();
        let rx = (v.x - median.x).abs() / (scale.x + floor);
        let ry = (v.y - median.y).abs() / (scale.y + floor);
        rx.max(ry) > MEDIAN_TEST_THRESHOLD
    };
    let outliers: Vec<bool> = (0..grid.len())
        .into_par_iter()
        .with_min_len(CELLS_PER_TASK)
        .map(outlier)
        .collect();
    for (slot, outlier) in field.iter_mut().zip(outliers) {
        if outlier {
            *slot = None;
        }
    }
}

/// Fills invalid cells with the median of their valid neighbours, ring after ring, until
/// every cell has a value; `None` when no cell is valid.
fn fill_gaps(mut field: Vec<Option<Vec2>>, grid: &Grid) -> Option<Vec<Vec2>> {
    if field.iter().all(Option::is_none) {
        return None;
    }
    while field.iter().any(Option::is_none) {
        let ring = &field;
        field = (0..grid.len())
            .into_par_iter()
            .with_min_len(CELLS_PER_TASK)
            .map(|c| {
                ring[c].or_else(|| {
                    let around = neighbours(ring, grid, c % grid.nx, c / grid.nx);
                    (around.len > 0).then(|| around.median())
                })
            })
            .collect();
    }
    Some(field.into_iter().flatten().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    use rand::RngExt;

    /// `n` uniformly random points in a `side × side` square (seeded).
    fn random_points(n: usize, side: f64) -> Vec<Point2> {
        let mut rng = sillage_core::rng_stream(3, 0);
        (0..n)
            .map(|_| Point2::new(rng.random_range(0.0..side), rng.random_range(0.0..side)))
            .collect()
    }

    #[test]
    fn uniform_shift_larger_than_the_spacing_is_found() {
        let a = random_points(1600, 400.0);
        let shift = Vec2::new(23.3, -17.8);
        let b: Vec<Point2> = a.iter().map(|&p| p + shift).collect();
        let mut out = Vec::new();
        let vote = voted_displacements(&a, &b, None, 40.0, &mut out).unwrap();
        assert_eq!(out.len(), a.len());
        for d in &out {
            assert!((*d - shift).norm() < 0.05, "{d:?}");
        }
        // Every cell agrees on the one displacement.
        assert!(vote.valid_share > 0.95, "{}", vote.valid_share);
    }

    #[test]
    fn a_flow_turning_within_the_cells_is_not_resolved() {
        // A cellular array of vortices (ψ ∝ sin kx · sin ky) whose cells, 64 px across, are
        // about as wide as the voting cells (≈ 49 px here): the displacement spans ±5 px
        // within a voting cell, so few cells find one peak.
        let a = random_points(4000, 512.0);
        let k = std::f64::consts::PI / 64.0;
        let b: Vec<Point2> = a
            .iter()
            .map(|&p| {
                p + Vec2::new(
                    5.0 * (k * p.x).sin() * (k * p.y).cos(),
                    -5.0 * (k * p.x).cos() * (k * p.y).sin(),
                )
            })
            .collect();
        let mut out = Vec::new();
        let vote = voted_displacements(&a, &b, None, 12.0, &mut out).unwrap();
        assert!(vote.valid_share < 0.5, "{}", vote.valid_share);
        // The same points shifted as a whole are resolved.
        let shifted: Vec<Point2> = a.iter().map(|&p| p + Vec2::new(4.0, -3.0)).collect();
        let vote = voted_displacements(&a, &shifted, None, 12.0, &mut out).unwrap();
        assert!(vote.valid_share > 0.95, "{}", vote.valid_share);
    }

    #[test]
    fn smooth_rotation_is_followed() {
        // Rigid rotation about the centre: displacements up to 4× the spacing (10 px).
        let a = random_points(3600, 600.0);
        let centre = Point2::new(300.0, 300.0);
        let angle: f64 = 0.1;
        let (s, c) = angle.sin_cos();
        let moved = |p: Point2| {
            let r = p - centre;
            centre + Vec2::new(c * r.x - s * r.y, s * r.x + c * r.y)
        };
        let b: Vec<Point2> = a.iter().map(|&p| moved(p)).collect();
        let mut out = Vec::new();
        assert!(voted_displacements(&a, &b, None, 40.0, &mut out).is_some());
        let spacing = 10.0;
        let within_half_spacing = a
            .iter()
            .zip(&out)
            .filter(|&(&p, &d)| ((p + d) - moved(p)).norm() < spacing / 2.0)
            .count();
        assert!(
            within_half_spacing as f64 > 0.97 * a.len() as f64,
            "{within_half_spacing} of {}",
            a.len()
        );
    }

    #[test]
    fn the_pair_search_finds_exactly_the_points_within_the_radius() {
        let b = random_points(2000, 300.0);
        let extent = Extent::covering(b.iter());
        let mut rng = sillage_core::rng_stream(4, 0);
        for (cell, radius) in [(40.0, 19.4), (20.0, 2.3), (60.0, 45.0), (5.0, 30.0)] {
            let search = SearchGrid::new(&Grid::new(&extent, cell), &b, radius);
            // Targets inside and up to a radius outside the points' extent.
            for _ in 0..300 {
                let range = -radius..300.0 + radius;
                let target = Point2::new(
                    rng.random_range(range.clone()),
                    rng.random_range(range.clone()),
                );
                let mut found = Vec::new();
                search.pairs_near(target, &mut found);
                let mut expected: Vec<Vec2> = b
                    .iter()
                    .map(|&p| p - target)
                    .filter(|d| d.x * d.x + d.y * d.y <= radius * radius)
                    .collect();
                let key = |d: &Vec2| (d.x.to_bits(), d.y.to_bits());
                found.sort_by_key(key);
                expected.sort_by_key(key);
                assert_eq!(
                    found, expected,
                    "cell {cell}, radius {radius}, at {target:?}"
                );
            }
        }
    }

    #[test]
    fn the_peak_is_the_raster_scans_peak_and_the_histogram_is_left_zero() {
        // The peak over the whole histogram in raster order, ties to the first.
        fn raster_peak(histogram: &[u32], side: usize) -> (u32, (usize, usize)) {
            let mut best = (0u32, (side / 2, side / 2));
            for y in 0..side {
                for x in 0..side {
                    if histogram[y * side + x] == 0 {
                        continue;
                    }
                    let mut sum = 0;
                    for yy in y.saturating_sub(1)..=(y + 1).min(side - 1) {
                        for xx in x.saturating_sub(1)..=(x + 1).min(side - 1) {
                            sum += histogram[yy * side + xx];
                        }
                    }
                    if sum > best.0 {
                        best = (sum, (x, y));
                    }
                }
            }
            best
        }
        let (bin, half) = (1.0, 6);
        let side = 2 * half + 1;
        let mut votes = CellVotes::new(side);
        let mut rng = sillage_core::rng_stream(5, 0);
        for trial in 0..200 {
            // Few votes on a coarse lattice: many ties.
            votes.pairs.clear();
            for _ in 0..(1 + trial % 12) {
                let mut d = || f64::from(rng.random_range(-6i32..=6)) * 0.9;
                votes.pairs.push(Vec2::new(d(), d()));
            }
            let mut histogram = vec![0u32; side * side];
            for d in &votes.pairs {
                let ix = ((d.x / bin).round() as i64 + half as i64) as usize;
                let iy = ((d.y / bin).round() as i64 + half as i64) as usize;
                histogram[iy * side + ix] += 1;
            }
            assert_eq!(votes.peak(bin, half), raster_peak(&histogram, side));
            assert!(votes.histogram.iter().all(|&count| count == 0));
        }
    }

    #[test]
    fn the_vote_does_not_depend_on_the_number_of_threads() {
        // A swirl with a noisy fifth of the points: peaks, outliers and gaps to fill.
        let a = random_points(6000, 800.0);
        let mut rng = sillage_core::rng_stream(7, 0);
        let b: Vec<Point2> = a
            .iter()
            .map(|&p| {
                let swirl = Vec2::new(-(p.y - 400.0), p.x - 400.0) * 0.02;
                if rng.random_range(0.0..1.0) < 0.2 {
                    Point2::new(rng.random_range(0.0..800.0), rng.random_range(0.0..800.0))
                } else {
                    p + swirl
                }
            })
            .collect();
        let vote_with = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut out = Vec::new();
            pool.install(|| voted_displacements(&a, &b, None, 20.0, &mut out));
            out
        };
        let one = vote_with(1);
        assert_eq!(one.len(), a.len());
        assert_eq!(one, vote_with(3));
    }

    #[test]
    fn no_motion_to_find_without_points() {
        let mut out = vec![Vec2::ZERO];
        assert!(voted_displacements(&[], &[Point2::new(1.0, 1.0)], None, 10.0, &mut out).is_none());
        assert!(out.is_empty());
    }
}

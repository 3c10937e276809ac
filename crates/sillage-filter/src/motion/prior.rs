//! The learned motion prior (MP) of the pedestrian IMM particle filter (Madrigal & Hayet §5.1,
//! after their ref. \[9\]): the image is divided into cells of 30×30 px and, in each cell, the
//! probability of moving from this cell towards each neighbouring direction is learned from
//! trajectories; "for a given particle, we determine its corresponding cell and then sample a
//! velocity from the prior".
//!
//! Each cell holds 9 bins: *stay* (a step slower than
//! [`MotionPriorParams::min_speed_px_per_frame`]) and the 8 compass directions (45° sectors
//! centred on east, north-east, ..., with north up the image, i.e. towards −y). Each bin has a
//! probability (counts plus a Dirichlet pseudo-count) and the mean velocity of its samples, so
//! sampling a velocity is: pick a bin by its probability, take its mean velocity, add the
//! model's velocity noise.
//!
//! ```
//! use sillage_core::{Point2, rng_stream};
//! use sillage_filter::motion::prior::{MotionPrior, MotionPriorParams};
//! use sillage_filter::{Gauss2, Normals};
//! // One walker going right at 2 px/frame along y = 10.
//! let track: Vec<(u64, Point2)> = (0..50).map(|f| (f, Point2::new(2.0 * f as f64, 10.0))).collect();
//! let prior = MotionPrior::fit(&[track], 120, 60, &MotionPriorParams::default()).unwrap();
//! let mut rng = rng_stream(1, 0);
//! let mut normals = Normals::new(&mut rng);
//! let u = normals.uniform();
//! let v = prior.sample_velocity(Point2::new(15.0, 10.0), u, &Gauss2::ZERO, &mut normals);
//! assert!(v.x.is_finite() && v.y.is_finite());
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};
use sillage_core::{Error, FrameIndex, Point2, Result, Vec2};

use crate::noise::Gauss2;
use crate::normal::Normals;

/// The version of the JSON layout [`MotionPrior::to_json`] writes and [`MotionPrior::from_json`]
/// reads.
pub const MOTION_PRIOR_FORMAT_VERSION: u32 = 1;

/// Bins per cell: stay and the 8 compass directions.
pub const BIN_COUNT: usize = 9;

/// The bins, in order: index 0 is *stay*, index `1 + k` the 45° sector centred on `k·45°`
/// counter-clockwise from east as seen on screen (north is up the image, −y).
pub const BIN_NAMES: [&str; BIN_COUNT] = [
    "stay",
    "east",
    "north-east",
    "north",
    "north-west",
    "west",
    "south-west",
    "south",
    "south-east",
];

/// Largest number of cells a grid may have (a typo such as `cell_px = 0.001` would otherwise
/// allocate without bound).
const MAX_CELLS: usize = 10_000_000;

/// Parameters of the learned motion prior (§5.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MotionPriorParams {
    /// Side of a square cell, px; default 30 (§5.1: "cells of 30 × 30 pixels").
    pub cell_px: f64,
    /// Steps slower than this count as *stay*, px/frame. Default 0.5: box annotations and
    /// detections are given to the pixel, so a foot point that moved less than half a pixel
    /// cannot be told from one standing still. (On PETS09-S2L1 at 7 fps the median foot speed
    /// of the ground truth is 3.2 px/frame and 10 % of the steps are below 0.12 px/frame, the
    /// people standing.)
    pub min_speed_px_per_frame: f64,
    /// Dirichlet pseudo-count added to every bin of every cell, so a direction never seen in
    /// a cell keeps a small probability and an empty cell is uniform; default 1 (Laplace).
    pub smoothing: f64,
}

impl Default for MotionPriorParams {
    fn default() -> Self {
        Self {
            cell_px: 30.0,
            min_speed_px_per_frame: 0.5,
            smoothing: 1.0,
        }
    }
}

impl MotionPriorParams {
    /// Checks every value; the error names the key and its allowed range.
    pub fn validate(&self) -> Result<()> {
        if !(self.cell_px.is_finite() && self.cell_px >= 1.0) {
            return Err(Error::parameter(
                "cell_px",
                self.cell_px,
                "must be a finite size ≥ 1 px (the paper uses 30)",
            ));
        }
        if !(self.min_speed_px_per_frame.is_finite() && self.min_speed_px_per_frame >= 0.0) {
            return Err(Error::parameter(
                "min_speed_px_per_frame",
                self.min_speed_px_per_frame,
                "must be a finite speed ≥ 0 px/frame (default 0.5)",
            ));
        }
        if !(self.smoothing.is_finite() && self.smoothing >= 0.0) {
            return Err(Error::parameter(
                "smoothing",
                self.smoothing,
                "must be a finite pseudo-count ≥ 0 (default 1)",
            ));
        }
        Ok(())
    }
}

/// The bin of a step `vel` (px/frame): 0 (*stay*) below `min_speed`, else `1 + k` for the
/// 45° sector `k` (see [`BIN_NAMES`]).
pub fn direction_bin(vel: Vec2, min_speed: f64) -> usize {
    let speed = vel.norm();
    if speed.is_nan() || speed < min_speed || speed == 0.0 {
        return 0;
    }
    // Counter-clockwise angle on screen: y points down, so up is −y.
    let angle = (-vel.y).atan2(vel.x);
    let sector = (angle / std::f64::consts::FRAC_PI_4).round() as i64;
    1 + sector.rem_euclid(8) as usize
}

/// One cell of the prior.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellPrior {
    /// Steps that started in this cell, per bin.
    pub counts: [u64; BIN_COUNT],
    /// p(bin | cell) = (count + smoothing) / (total + 9·smoothing); uniform for an empty cell
    /// without smoothing.
    pub probability: [f64; BIN_COUNT],
    /// Mean step of the bin's samples in this cell, px/frame; the bin's mean over all cells
    /// where this cell has none.
    pub mean_vel_px_per_frame: [Vec2; BIN_COUNT],
}

/// The learned motion prior over an image: a grid of [`CellPrior`]s.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionPrior {
    params: MotionPriorParams,
    width_px: u32,
    height_px: u32,
    columns: usize,
    rows: usize,
    cells: Vec<CellPrior>,
    /// Cumulative probabilities per cell, for inverse-CDF sampling.
    cumulative: Vec<[f64; BIN_COUNT]>,
}

/// The JSON layout of a saved prior.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct MotionPriorFile {
    format_version: u32,
    params: MotionPriorParams,
    width_px: u32,
    height_px: u32,
    columns: usize,
    rows: usize,
    cells: Vec<CellPrior>,
}

/// Columns and rows of the grid covering a `width_px` × `height_px` image.
fn grid_size(width_px: u32, height_px: u32, cell_px: f64) -> Result<(usize, usize)> {
    if width_px == 0 || height_px == 0 {
        return Err(Error::input(format!(
            "image size {width_px} × {height_px} px: give the image's width and height (≥ 1)"
        )));
    }
    let columns = (f64::from(width_px) / cell_px).ceil() as usize;
    let rows = (f64::from(height_px) / cell_px).ceil() as usize;
    if columns.saturating_mul(rows) > MAX_CELLS {
        return Err(Error::parameter(
            "cell_px",
            cell_px,
            format!(
                "gives {columns} × {rows} cells over a {width_px} × {height_px} image, more \
                 than {MAX_CELLS}; use larger cells (the paper uses 30 px)"
            ),
        ));
    }
    Ok((columns, rows))
}

impl MotionPrior {
    /// Learns the prior from trajectories over a `width_px` × `height_px` image. Each track is
    /// its points `(frame, pos_px)` in increasing frame order; a step is a pair of points in
    /// consecutive frames, counted in the cell of its first point (points outside the image
    /// count in the nearest cell); pairs across a gap are skipped. No step at all, a
    /// non-finite position or bad parameters are errors.
    pub fn fit<T: AsRef<[(FrameIndex, Point2)]>>(
        tracks: &[T],
        width_px: u32,
        height_px: u32,
        params: &MotionPriorParams,
    ) -> Result<Self> {
        params.validate()?;
        let (columns, rows) = grid_size(width_px, height_px, params.cell_px)?;
        let mut counts = vec![[0u64; BIN_COUNT]; columns * rows];
        let mut sums = vec![[Vec2::ZERO; BIN_COUNT]; columns * rows];
        for (t, track) in tracks.iter().enumerate() {
            let points = track.as_ref();
            if let Some(k) = points.iter().position(|(_, p)| !p.is_finite()) {
                return Err(Error::input(format!(
                    "track {} (in the order given), point {}: the position is not finite; fix \
                     or remove it",
                    t + 1,
                    k + 1
                )));
            }
            for pair in points.windows(2) {
                let ((f0, p0), (f1, p1)) = (pair[0], pair[1]);
                if f0.checked_add(1) != Some(f1) {
                    continue;
                }
                let vel = p1 - p0;
                let cell = cell_index(p0, params.cell_px, columns, rows);
                let bin = direction_bin(vel, params.min_speed_px_per_frame);
                counts[cell][bin] += 1;
                sums[cell][bin] = sums[cell][bin] + vel;
            }
        }
        let moves: u64 = counts.iter().flatten().sum();
        if moves == 0 {
            return Err(Error::input(format!(
                "no step to learn from in {} track(s): a step is two points of one track in \
                 consecutive frames; give trajectories (ground truth or tracker output), not \
                 single detections",
                tracks.len()
            )));
        }
        // The bins' means over all cells, the fallback of cells without samples.
        let mut global_counts = [0u64; BIN_COUNT];
        let mut global_sums = [Vec2::ZERO; BIN_COUNT];
        for (c, s) in counts.iter().zip(&sums) {
            for b in 0..BIN_COUNT {
                global_counts[b] += c[b];
                global_sums[b] = global_sums[b] + s[b];
            }
        }
        let moving: u64 = global_counts[1..].iter().sum();
        let mean_speed = if moving > 0 {
            // Steps of one 45° sector nearly align, so |Σ v| / n is close to their mean speed.
            global_sums[1..].iter().map(|s| s.norm()).sum::<f64>() / moving as f64
        } else {
            params.min_speed_px_per_frame.max(1.0)
        };
        let global_mean: [Vec2; BIN_COUNT] = std::array::from_fn(|b| {
            if global_counts[b] > 0 {
                global_sums[b] / global_counts[b] as f64
            } else if b == 0 {
                Vec2::ZERO
            } else {
                // A direction never seen: its unit vector at the typical speed.
                let angle = (b - 1) as f64 * std::f64::consts::FRAC_PI_4;
                Vec2::new(angle.cos(), -angle.sin()) * mean_speed
            }
        });
        let cells = counts
            .iter()
            .zip(&sums)
            .map(|(c, s)| {
                let total = c.iter().sum::<u64>() as f64;
                let denominator = total + BIN_COUNT as f64 * params.smoothing;
                CellPrior {
                    counts: *c,
                    probability: std::array::from_fn(|b| {
                        if denominator > 0.0 {
                            (c[b] as f64 + params.smoothing) / denominator
                        } else {
                            1.0 / BIN_COUNT as f64
                        }
                    }),
                    mean_vel_px_per_frame: std::array::from_fn(|b| {
                        if c[b] > 0 {
                            s[b] / c[b] as f64
                        } else {
                            global_mean[b]
                        }
                    }),
                }
            })
            .collect();
        Ok(Self::from_cells(
            *params, width_px, height_px, columns, rows, cells,
        ))
    }

    fn from_cells(
        params: MotionPriorParams,
        width_px: u32,
        height_px: u32,
        columns: usize,
        rows: usize,
        cells: Vec<CellPrior>,
    ) -> Self {
        let cumulative = cells
            .iter()
            .map(|c| {
                let mut acc = 0.0;
                c.probability.map(|p| {
                    acc += p;
                    acc
                })
            })
            .collect();
        Self {
            params,
            width_px,
            height_px,
            columns,
            rows,
            cells,
            cumulative,
        }
    }

    /// The parameters it was learned with.
    pub fn params(&self) -> &MotionPriorParams {
        &self.params
    }

    /// The image size it covers, px (width, height).
    pub fn image_size_px(&self) -> (u32, u32) {
        (self.width_px, self.height_px)
    }

    /// The grid size in cells (columns, rows).
    pub fn grid_size(&self) -> (usize, usize) {
        (self.columns, self.rows)
    }

    /// Every cell, row by row from the top-left.
    pub fn cells(&self) -> &[CellPrior] {
        &self.cells
    }

    /// Number of cells where at least one step started.
    pub fn cells_with_data(&self) -> usize {
        self.cells
            .iter()
            .filter(|c| c.counts.iter().any(|&n| n > 0))
            .count()
    }

    /// Number of steps learned from.
    pub fn moves(&self) -> u64 {
        self.cells.iter().flat_map(|c| c.counts).sum()
    }

    /// The index in [`MotionPrior::cells`] of the cell holding `pos_px`; positions outside the
    /// image (or not finite) go to the nearest cell.
    pub fn cell_index(&self, pos_px: Point2) -> usize {
        cell_index(pos_px, self.params.cell_px, self.columns, self.rows)
    }

    /// The cell holding `pos_px` (clamped as [`MotionPrior::cell_index`]).
    pub fn cell_at(&self, pos_px: Point2) -> &CellPrior {
        &self.cells[self.cell_index(pos_px)]
    }

    /// The bin drawn by `uniform` ∈ [0, 1) in the cell of `pos_px` (inverse of the cumulative
    /// probabilities; ties go to the lower bin).
    #[inline]
    pub fn sample_bin(&self, pos_px: Point2, uniform: f64) -> usize {
        let cumulative = &self.cumulative[self.cell_index(pos_px)];
        cumulative
            .iter()
            .position(|&c| uniform < c)
            .unwrap_or_else(|| {
                // Rounding left the last sum below `uniform`: the last bin with mass.
                let probability = &self.cells[self.cell_index(pos_px)].probability;
                probability.iter().rposition(|&p| p > 0.0).unwrap_or(0)
            })
    }

    /// A velocity (px/frame) for a particle at `pos_px` (§5.1, "determine its corresponding
    /// cell and then sample a velocity from the prior"): the bin drawn by `uniform` ∈ [0, 1),
    /// its mean velocity, plus one draw of `vel_noise` (pass [`Gauss2::ZERO`] for the bare
    /// mean). Positions outside the grid use the nearest cell.
    #[inline]
    pub fn sample_velocity(
        &self,
        pos_px: Point2,
        uniform: f64,
        vel_noise: &Gauss2,
        normals: &mut Normals<'_>,
    ) -> Vec2 {
        let cell = &self.cells[self.cell_index(pos_px)];
        let mean = cell.mean_vel_px_per_frame[self.sample_bin(pos_px, uniform)];
        let (du, dv) = vel_noise.sample(1.0, normals);
        Vec2::new(mean.x + du, mean.y + dv)
    }

    /// The prior as JSON (with [`MOTION_PRIOR_FORMAT_VERSION`]): one key per line and one
    /// cell per line, row by row from the top-left, so the file stays small and readable.
    pub fn to_json(&self) -> String {
        let mut text = String::from("{\n");
        text.push_str(&format!(
            "  \"format_version\": {MOTION_PRIOR_FORMAT_VERSION},\n  \"params\": {},\n  \
             \"width_px\": {},\n  \"height_px\": {},\n  \"columns\": {},\n  \"rows\": {},\n  \
             \"cells\": [\n",
            compact(&self.params),
            self.width_px,
            self.height_px,
            self.columns,
            self.rows
        ));
        for (k, cell) in self.cells.iter().enumerate() {
            text.push_str("    ");
            text.push_str(&compact(cell));
            text.push_str(if k + 1 < self.cells.len() {
                ",\n"
            } else {
                "\n"
            });
        }
        text.push_str("  ]\n}");
        text
    }

    /// Reads a prior from JSON text; `path` names the source in errors. A wrong format
    /// version, an inconsistent grid or probabilities that are not a distribution are
    /// errors naming the file and the fix.
    pub fn from_json(path: &Path, text: &str) -> Result<Self> {
        let refit = "write it again with `sillage fit motion-prior`";
        let error = |message: String| Error::format(path, None, message);
        let file: MotionPriorFile = serde_json::from_str(text).map_err(|e| {
            Error::format(
                path,
                Some(e.line()),
                format!("not a motion prior file ({e}); {refit}"),
            )
        })?;
        if file.format_version != MOTION_PRIOR_FORMAT_VERSION {
            return Err(error(format!(
                "format_version {} is not the {MOTION_PRIOR_FORMAT_VERSION} this sillage reads; \
                 {refit}",
                file.format_version
            )));
        }
        file.params
            .validate()
            .map_err(|e| error(format!("params: {e}; {refit}")))?;
        let (columns, rows) = grid_size(file.width_px, file.height_px, file.params.cell_px)
            .map_err(|e| error(format!("{e}; {refit}")))?;
        if (columns, rows) != (file.columns, file.rows) || file.cells.len() != columns * rows {
            return Err(error(format!(
                "the grid ({} × {} cells, {} given) does not cover a {} × {} image with \
                 {} px cells ({columns} × {rows}); {refit}",
                file.columns,
                file.rows,
                file.cells.len(),
                file.width_px,
                file.height_px,
                file.params.cell_px
            )));
        }
        for (k, cell) in file.cells.iter().enumerate() {
            let sum: f64 = cell.probability.iter().sum();
            let valid = cell.probability.iter().all(|p| p.is_finite() && *p >= 0.0)
                && (sum - 1.0).abs() <= 1e-6
                && cell.mean_vel_px_per_frame.iter().all(|v| v.is_finite());
            if !valid {
                return Err(error(format!(
                    "cell {k} (row {}, column {}): probabilities must be finite, ≥ 0 and sum to \
                     1 (they sum to {sum}) and velocities finite; {refit}",
                    k / columns,
                    k % columns
                )));
            }
        }
        Ok(Self::from_cells(
            file.params,
            file.width_px,
            file.height_px,
            columns,
            rows,
            file.cells,
        ))
    }
}

/// Compact JSON of a part of the prior file (plain structs of numbers always serialise).
fn compact<T: Serialize>(value: &T) -> String {
    serde_json::to_string(value).unwrap_or_default()
}

/// The cell of `pos_px` in a `columns` × `rows` grid of `cell_px` cells whose top-left corner
/// is the top-left pixel's outer corner (−0.5, −0.5); clamped to the grid.
#[inline]
fn cell_index(pos_px: Point2, cell_px: f64, columns: usize, rows: usize) -> usize {
    // `as usize` saturates: negative and NaN give 0, +∞ the maximum, then clamped.
    let column = (((pos_px.x + 0.5) / cell_px).floor().max(0.0) as usize).min(columns - 1);
    let row = (((pos_px.y + 0.5) / cell_px).floor().max(0.0) as usize).min(rows - 1);
    row * columns + column
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::Noise2;
    use rand::RngExt;
    use sillage_core::rng_stream;

    const EAST: usize = 1;
    const SOUTH: usize = 7;

    /// Walkers at 2 px/frame: rightwards in the top half (y < 150), downwards in the bottom
    /// half (y ≥ 150) of a 300 × 300 image.
    fn walkers() -> Vec<Vec<(FrameIndex, Point2)>> {
        let mut tracks = Vec::new();
        for k in 0..10 {
            let y = 5.0 + 14.0 * k as f64;
            tracks.push(
                (0..149)
                    .map(|f| (f as u64, Point2::new(2.0 * f as f64, y)))
                    .collect(),
            );
            let x = 5.0 + 29.0 * k as f64;
            tracks.push(
                (0..74)
                    .map(|f| (f as u64 + 7, Point2::new(x, 150.0 + 2.0 * f as f64)))
                    .collect(),
            );
        }
        tracks
    }

    #[test]
    fn bins_follow_the_compass_on_screen() {
        assert_eq!(direction_bin(Vec2::new(2.0, 0.0), 0.5), EAST);
        assert_eq!(direction_bin(Vec2::new(0.0, 2.0), 0.5), SOUTH);
        assert_eq!(BIN_NAMES[direction_bin(Vec2::new(0.0, -2.0), 0.5)], "north");
        assert_eq!(
            BIN_NAMES[direction_bin(Vec2::new(-1.0, -1.0), 0.5)],
            "north-west"
        );
        assert_eq!(
            BIN_NAMES[direction_bin(Vec2::new(1.0, 1.0), 0.5)],
            "south-east"
        );
        assert_eq!(direction_bin(Vec2::new(0.3, 0.3), 0.5), 0);
        assert_eq!(direction_bin(Vec2::ZERO, 0.0), 0);
        assert_eq!(direction_bin(Vec2::new(f64::NAN, 0.0), 0.5), 0);
    }

    #[test]
    fn learns_the_direction_of_each_half() {
        let prior = MotionPrior::fit(&walkers(), 300, 300, &MotionPriorParams::default()).unwrap();
        assert_eq!(prior.grid_size(), (10, 10));
        for (pos, bin, vel) in [
            (Point2::new(100.0, 60.0), EAST, Vec2::new(2.0, 0.0)),
            (Point2::new(20.0, 130.0), EAST, Vec2::new(2.0, 0.0)),
            (Point2::new(150.0, 200.0), SOUTH, Vec2::new(0.0, 2.0)),
            (Point2::new(250.0, 280.0), SOUTH, Vec2::new(0.0, 2.0)),
        ] {
            let cell = prior.cell_at(pos);
            let best = (0..BIN_COUNT)
                .max_by(|&a, &b| cell.probability[a].total_cmp(&cell.probability[b]))
                .unwrap();
            assert_eq!(best, bin, "{pos:?}: {:?}", cell.probability);
            assert!(cell.probability[bin] > 0.6, "{:?}", cell.probability);
            assert!((cell.mean_vel_px_per_frame[bin] - vel).norm() < 1e-12);
            // Bins without samples fall back to the global mean of the bin.
            let other = if bin == EAST { SOUTH } else { EAST };
            assert_eq!(cell.counts[other], 0);
            let expected = if other == EAST {
                Vec2::new(2.0, 0.0)
            } else {
                Vec2::new(0.0, 2.0)
            };
            assert!((cell.mean_vel_px_per_frame[other] - expected).norm() < 1e-12);
        }
        // Outside the image: the nearest cell.
        assert_eq!(prior.cell_index(Point2::new(-50.0, -50.0)), 0);
        assert_eq!(prior.cell_index(Point2::new(1e9, f64::INFINITY)), 99);
        assert_eq!(prior.cell_index(Point2::new(f64::NAN, 10.0)), 0);
        let moves: u64 = walkers().iter().map(|t| t.len() as u64 - 1).sum();
        assert_eq!(prior.moves(), moves);
        // The 50 cells of the top half are crossed; in the bottom half the downward walkers
        // (x = 5 + 29k) cover columns 0 to 8 (two share column 5): 9 × 5 cells.
        assert_eq!(prior.cells_with_data(), 95);
        let empty = prior.cell_at(Point2::new(290.0, 280.0));
        assert!(
            empty
                .probability
                .iter()
                .all(|&p| (p - 1.0 / 9.0).abs() < 1e-15)
        );
    }

    #[test]
    fn gaps_are_skipped_and_no_step_is_an_error() {
        let track = vec![
            (0, Point2::new(10.0, 10.0)),
            (2, Point2::new(50.0, 10.0)),
            (3, Point2::new(50.0, 12.0)),
        ];
        let prior = MotionPrior::fit(
            std::slice::from_ref(&track),
            100,
            100,
            &MotionPriorParams::default(),
        )
        .unwrap();
        assert_eq!(prior.moves(), 1);
        assert_eq!(prior.cell_at(Point2::new(50.0, 10.0)).counts[SOUTH], 1);
        let err = MotionPrior::fit(
            &[track[..1].to_vec()],
            100,
            100,
            &MotionPriorParams::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("no step"), "{err}");
        let bad = MotionPriorParams {
            cell_px: 0.0,
            ..MotionPriorParams::default()
        };
        let err = MotionPrior::fit(&[track], 100, 100, &bad)
            .unwrap_err()
            .to_string();
        assert!(err.contains("`cell_px`"), "{err}");
    }

    #[test]
    fn sampling_frequencies_match_the_probabilities() {
        // A cell with a mixture: 60 steps east, 30 stay, 10 south.
        let mut tracks = Vec::new();
        for (count, step) in [
            (60, Vec2::new(3.0, 0.0)),
            (30, Vec2::ZERO),
            (10, Vec2::new(0.0, 3.0)),
        ] {
            for _ in 0..count {
                let p = Point2::new(10.0, 10.0);
                tracks.push(vec![(0, p), (1, p + step)]);
            }
        }
        let prior = MotionPrior::fit(&tracks, 60, 60, &MotionPriorParams::default()).unwrap();
        let pos = Point2::new(12.0, 14.0);
        let probability = prior.cell_at(pos).probability;
        assert!((probability[EAST] - 61.0 / 109.0).abs() < 1e-12);
        let mut rng = rng_stream(2024, 3);
        let draws = 20_000;
        let mut seen = [0u64; BIN_COUNT];
        for _ in 0..draws {
            seen[prior.sample_bin(pos, rng.random::<f64>())] += 1;
        }
        let chi2: f64 = (0..BIN_COUNT)
            .map(|b| {
                let expected = probability[b] * draws as f64;
                (seen[b] as f64 - expected).powi(2) / expected
            })
            .sum();
        // 8 degrees of freedom: the 99.9 % quantile is 26.12.
        assert!(chi2 < 26.12, "χ² = {chi2}, seen {seen:?}");
        // Velocities: the bin means exactly without noise, scattered around them with it.
        let mut normals_rng = rng_stream(2024, 4);
        let mut normals = Normals::new(&mut normals_rng);
        let v = prior.sample_velocity(pos, 0.0, &Gauss2::ZERO, &mut normals);
        assert_eq!(v, Vec2::ZERO);
        let v = prior.sample_velocity(pos, 0.5, &Gauss2::ZERO, &mut normals);
        assert_eq!(v, Vec2::new(3.0, 0.0));
        let noise = Noise2::diagonal(0.25, 0.25).factor("vel_noise").unwrap();
        let mean_x = (0..4000)
            .map(|_| prior.sample_velocity(pos, 0.5, &noise, &mut normals).x)
            .sum::<f64>()
            / 4000.0;
        assert!((mean_x - 3.0).abs() < 0.05, "{mean_x}");
    }

    #[test]
    fn json_round_trips_and_bad_text_names_the_file() {
        let path = Path::new("prior.json");
        let prior = MotionPrior::fit(&walkers(), 300, 300, &MotionPriorParams::default()).unwrap();
        let text = prior.to_json();
        assert_eq!(MotionPrior::from_json(path, &text).unwrap(), prior);
        assert!(text.contains("\"format_version\": 1"), "{}", &text[..80]);
        let cases = [
            (
                text.replacen("\"format_version\": 1", "\"format_version\": 7", 1),
                "format_version 7",
            ),
            (
                text.replacen("\"columns\": 10", "\"columns\": 11", 1),
                "does not cover",
            ),
            ("{\"oops\": 1}".to_string(), "not a motion prior file"),
        ];
        for (bad, expected) in cases {
            let err = MotionPrior::from_json(Path::new("bad.json"), &bad)
                .unwrap_err()
                .to_string();
            assert!(err.contains("bad.json") && err.contains(expected), "{err}");
        }
    }
}

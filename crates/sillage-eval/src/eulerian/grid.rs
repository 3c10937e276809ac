//! Tracks binned on a regular grid, one pass over the rows: per bin the number of points,
//! the concentration, the mean velocity, the Reynolds-stress terms, the turbulent kinetic
//! energy, the mean speed and the mean log prediction error (the time-averaged Eulerian
//! fields of the TracTrac paper's §5.1, Fig. 6c-d).

use std::collections::HashMap;

use sillage_core::{Calibration, Error, FrameIndex, Point2, Result, TrackPoint, Vec2};

use super::moments::{RunningMean, VelocityMoments};

/// How the grid is laid over the image and in which units it reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridParams {
    /// Bin side, in the output units (px, or m with a calibration).
    pub bin_size: f64,
    /// The grid's origin and rotation pivot in the image, px: bin `(0, 0)` starts there.
    pub origin_px: Point2,
    /// Rotation of the grid's axes from the image's, degrees, counter-clockwise as seen on
    /// the image (with `y` down): `u` is then the component along the rotated `x` axis, e.g.
    /// the streamwise direction of a tilted channel.
    pub rotation_deg: f64,
    /// Pixel size and frame rate: positions and bins in metres, velocities in m/s. Without
    /// it, px and px/frame.
    pub calibration: Option<Calibration>,
}

impl Default for GridParams {
    /// 16 px bins from the image's top-left pixel centre, unrotated, in px and px/frame.
    fn default() -> Self {
        Self {
            bin_size: 16.0,
            origin_px: Point2::new(0.0, 0.0),
            rotation_deg: 0.0,
            calibration: None,
        }
    }
}

impl GridParams {
    /// Checks every value; the error names the key and its allowed range.
    pub fn validate(&self) -> Result<()> {
        if !(self.bin_size.is_finite() && self.bin_size > 0.0) {
            return Err(Error::parameter(
                "bin",
                self.bin_size,
                "must be a finite size greater than 0",
            ));
        }
        if !self.origin_px.is_finite() {
            return Err(Error::parameter(
                "origin",
                format!("{},{}", self.origin_px.x, self.origin_px.y),
                "must be two finite numbers (px)",
            ));
        }
        if !self.rotation_deg.is_finite() {
            return Err(Error::parameter(
                "rotate",
                self.rotation_deg,
                "must be a finite angle in degrees",
            ));
        }
        Ok(())
    }

    /// Length of one px in the output units.
    fn length_scale(&self) -> f64 {
        self.calibration.map_or(1.0, |c| c.m_per_px)
    }

    /// One px/frame in the output velocity units.
    fn velocity_scale(&self) -> f64 {
        self.calibration.map_or(1.0, |c| c.m_per_px * c.fps)
    }
}

/// What is accumulated in one bin.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BinAccumulator {
    /// Points that fell in the bin, with or without a velocity.
    pub points: u64,
    /// Velocities of the points that have one (output units).
    pub velocity: VelocityMoments,
    /// log10 of the prediction error, px, of the points that have one (TracTrac Eq. 10).
    pub log10_pred_err: RunningMean,
}

impl BinAccumulator {
    /// Adds every sample of `other`.
    pub fn merge(&mut self, other: &Self) {
        self.points += other.points;
        self.velocity.merge(&other.velocity);
        self.log10_pred_err.merge(&other.log10_pred_err);
    }
}

/// The statistics of one bin (or one pooled row/column of bins, for a profile).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BinStats {
    /// Column index of the bin along the (rotated) `x` axis; may be negative.
    pub column: i64,
    /// Row index along the (rotated) `y` axis; may be negative.
    pub row: i64,
    /// Centre of the bin in the grid's axes, output units.
    pub centre: Vec2,
    /// Points counted.
    pub points: u64,
    /// Mean number of points per unit area per frame (per px² or m², over the frames the
    /// table spans).
    pub concentration: f64,
    /// Points with a velocity.
    pub velocities: u64,
    /// Mean velocity ⟨u⟩, ⟨v⟩ (NaN without velocities).
    pub mean_velocity: Vec2,
    /// ⟨u'²⟩, ⟨v'²⟩, ⟨u'v'⟩ (NaN without velocities).
    pub stresses: [f64; 3],
    /// ½(⟨u'²⟩ + ⟨v'²⟩).
    pub turbulent_kinetic_energy: f64,
    /// ⟨|u|⟩.
    pub mean_speed: f64,
    /// Mean log10 prediction error, px (NaN where the table has none).
    pub mean_log10_pred_err: f64,
}

/// Tracks binned on a grid as the rows stream by; memory grows with the number of occupied
/// bins, never with the number of rows.
#[derive(Debug, Clone)]
pub struct EulerianGrid {
    params: GridParams,
    /// `(cos, sin)` of the rotation.
    rotation: (f64, f64),
    bins: HashMap<(i64, i64), BinAccumulator>,
    frames: Option<(FrameIndex, FrameIndex)>,
    rows: u64,
}

impl EulerianGrid {
    /// An empty grid; `params` are validated.
    pub fn new(params: GridParams) -> Result<Self> {
        params.validate()?;
        let angle = params.rotation_deg.to_radians();
        Ok(Self {
            params,
            rotation: (angle.cos(), angle.sin()),
            bins: HashMap::new(),
            frames: None,
            rows: 0,
        })
    }

    /// The grid's parameters.
    pub fn params(&self) -> &GridParams {
        &self.params
    }

    /// Number of rows pushed.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// First and last frame seen.
    pub fn frame_span(&self) -> Option<(FrameIndex, FrameIndex)> {
        self.frames
    }

    /// The components of `vector` (image axes) along the grid's axes: turned θ
    /// counter-clockwise on screen, the grid's `x` axis is `(cos θ, −sin θ)` in `y`-down
    /// image axes and its `y` axis `(sin θ, cos θ)`.
    fn to_grid_axes(&self, vector: Vec2) -> Vec2 {
        let (c, s) = self.rotation;
        Vec2::new(c * vector.x - s * vector.y, s * vector.x + c * vector.y)
    }

    /// The position of `pos_px` in the grid's axes and output units.
    pub fn grid_position(&self, pos_px: Point2) -> Vec2 {
        self.to_grid_axes(pos_px - self.params.origin_px) * self.params.length_scale()
    }

    /// The bin of a position in the grid's axes, or `None` far outside any usable range.
    fn bin_of(&self, position: Vec2) -> Option<(i64, i64)> {
        let index = |coordinate: f64| {
            let i = (coordinate / self.params.bin_size).floor();
            (i.abs() < 1e15).then_some(i as i64)
        };
        Some((index(position.x)?, index(position.y)?))
    }

    /// Adds one track row. Rows with a non-finite position are errors; a velocity or
    /// prediction error that is missing or not finite only leaves those statistics out.
    pub fn push(&mut self, point: &TrackPoint) -> Result<()> {
        let position = self.grid_position(point.pos_px);
        let Some(key) = self.bin_of(position) else {
            return Err(Error::input(format!(
                "frame {}, track {}: position ({}, {}) is not a finite pixel position",
                point.frame, point.track_id, point.pos_px.x, point.pos_px.y
            )));
        };
        let velocity = point
            .vel_px_per_frame
            .filter(|v| v.x.is_finite() && v.y.is_finite())
            .map(|v| self.to_grid_axes(v) * self.params.velocity_scale());
        let bin = self.bins.entry(key).or_default();
        bin.points += 1;
        if let Some(v) = velocity {
            bin.velocity.push(v.x, v.y);
        }
        if let Some(err) = point.log10_pred_err.filter(|e| e.is_finite()) {
            bin.log10_pred_err.push(err);
        }
        self.frames = Some(match self.frames {
            None => (point.frame, point.frame),
            Some((first, last)) => (first.min(point.frame), last.max(point.frame)),
        });
        self.rows += 1;
        Ok(())
    }

    /// Number of frames the rows span (first to last, inclusive); 0 when empty.
    pub fn frame_count(&self) -> u64 {
        self.frames.map_or(0, |(first, last)| last - first + 1)
    }

    /// The occupied bins' accumulators keyed by `(column, row)`.
    pub fn accumulators(&self) -> &HashMap<(i64, i64), BinAccumulator> {
        &self.bins
    }

    /// The statistics of every occupied bin, row by row (`row`, then `column`, ascending).
    pub fn bins(&self) -> Vec<BinStats> {
        let mut keys: Vec<_> = self.bins.keys().copied().collect();
        keys.sort_unstable_by_key(|&(column, row)| (row, column));
        let size = self.params.bin_size;
        keys.into_iter()
            .map(|(column, row)| {
                let centre = Vec2::new((column as f64 + 0.5) * size, (row as f64 + 0.5) * size);
                self.stats(column, row, centre, size * size, &self.bins[&(column, row)])
            })
            .collect()
    }

    /// The statistics of `accumulator` covering `area` (output units²).
    pub(crate) fn stats(
        &self,
        column: i64,
        row: i64,
        centre: Vec2,
        area: f64,
        accumulator: &BinAccumulator,
    ) -> BinStats {
        let velocity = &accumulator.velocity;
        let (mean_u, mean_v) = velocity.mean().unwrap_or((f64::NAN, f64::NAN));
        let (uu, vv, uv) = velocity
            .stresses()
            .unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        BinStats {
            column,
            row,
            centre,
            points: accumulator.points,
            concentration: accumulator.points as f64 / (area * self.frame_count().max(1) as f64),
            velocities: velocity.count(),
            mean_velocity: Vec2::new(mean_u, mean_v),
            stresses: [uu, vv, uv],
            turbulent_kinetic_energy: velocity.turbulent_kinetic_energy().unwrap_or(f64::NAN),
            mean_speed: velocity.mean_speed().unwrap_or(f64::NAN),
            mean_log10_pred_err: accumulator.log10_pred_err.mean().unwrap_or(f64::NAN),
        }
    }
}

//! Track points buffered column by column for the binary formats (Parquet, HDF5), so they
//! are written a row group / chunk at a time.

use std::path::Path;

use sillage_core::{Error, MotionState, ObjectClass, Point2, Result, TrackPoint};

use super::columns::{check_position, kinematics, point_from_values};

/// Track points held column by column (the layout of Parquet row groups and HDF5 datasets).
/// Missing values are `None`; the state columns are always held, and written only by the
/// state layout (a reader of a table without them fills them with class 0, unknown, `None`).
#[derive(Debug, Default, Clone, PartialEq)]
pub(crate) struct TrackColumns {
    pub(crate) frame: Vec<i64>,
    pub(crate) particle: Vec<i64>,
    pub(crate) x: Vec<f64>,
    pub(crate) y: Vec<f64>,
    pub(crate) kinematics: [Vec<Option<f64>>; 7],
    pub(crate) class: Vec<ObjectClass>,
    pub(crate) motion_state: Vec<MotionState>,
    pub(crate) spread_px: Vec<Option<f64>>,
}

impl TrackColumns {
    /// Number of rows held.
    pub(crate) fn len(&self) -> usize {
        self.frame.len()
    }

    /// Empties the columns, keeping their allocations.
    pub(crate) fn clear(&mut self) {
        self.frame.clear();
        self.particle.clear();
        self.x.clear();
        self.y.clear();
        self.kinematics.iter_mut().for_each(Vec::clear);
        self.class.clear();
        self.motion_state.clear();
        self.spread_px.clear();
    }

    /// Fills the state columns with "class 0, unknown, no spread" for a table without them.
    pub(crate) fn default_states(&mut self) {
        let n = self.len();
        self.class = vec![0; n];
        self.motion_state = vec![MotionState::Unknown; n];
        self.spread_px = vec![None; n];
    }

    /// Appends one point (frame and track id are stored as i64, losslessly).
    pub(crate) fn push(&mut self, point: &TrackPoint) -> Result<()> {
        check_position(point)?;
        let to_i64 = |v: u64, what: &str| {
            i64::try_from(v).map_err(|_| {
                Error::input(format!("{what} {v} does not fit a signed 64-bit column"))
            })
        };
        self.frame.push(to_i64(point.frame, "frame")?);
        self.particle.push(to_i64(point.track_id, "track id")?);
        self.x.push(point.pos_px.x);
        self.y.push(point.pos_px.y);
        for (column, value) in self.kinematics.iter_mut().zip(kinematics(point)) {
            column.push(value);
        }
        self.class.push(point.class);
        self.motion_state.push(point.motion_state);
        self.spread_px
            .push(point.spread_px.filter(|s| s.is_finite()));
        Ok(())
    }

    /// The points held, checked: frames and ids non-negative, positions finite. Errors name
    /// `path` and the 1-based row (`first_row` is the 1-based row of the first one held).
    pub(crate) fn to_points(&self, path: &Path, first_row: usize) -> Result<Vec<TrackPoint>> {
        (0..self.len())
            .map(|i| {
                let row = first_row + i;
                let bad = |what: String| Error::format(path, None, format!("row {row}: {what}"));
                let frame = u64::try_from(self.frame[i])
                    .map_err(|_| bad(format!("frame {} is negative", self.frame[i])))?;
                let id = u64::try_from(self.particle[i])
                    .map_err(|_| bad(format!("particle {} is negative", self.particle[i])))?;
                let pos = Point2::new(self.x[i], self.y[i]);
                if !pos.is_finite() {
                    return Err(bad(format!(
                        "position ({}, {}) is not finite; positions are required",
                        pos.x, pos.y
                    )));
                }
                Ok(TrackPoint {
                    class: self.class[i],
                    motion_state: self.motion_state[i],
                    spread_px: self.spread_px[i].filter(|s| s.is_finite()),
                    ..point_from_values(frame, id, pos, self.kinematics.each_ref().map(|c| c[i]))
                })
            })
            .collect()
    }
}

//! The column layouts shared by the CSV, Parquet and HDF5 track tables (trackpy-compatible
//! names), and the conversions between [`TrackPoint`]s and column values.

use sillage_core::{Error, ObjectClass, Point2, Result, TrackPoint, Vec2};

/// Column names of the CSV, Parquet and HDF5 track tables, in order.
pub const TRACK_COLUMNS: [&str; 11] = [
    "frame", "particle", "x", "y", "vx", "vy", "ax", "ay", "vx_pred", "vy_pred", "log_err",
];

/// Columns that [`TrackLayout::WithStates`] appends to [`TRACK_COLUMNS`]: the object class
/// (bead category: 0 black, 1 transparent), the motion state (`resting`, `rolling`,
/// `saltating`, `unknown`; BeadTracking's codes 0–3 in HDF5) and the spread of the estimate
/// in px.
pub const STATE_COLUMNS: [&str; 3] = ["class", "motion_state", "spread_px"];

/// Which columns a CSV, Parquet or HDF5 track table carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum TrackLayout {
    /// The eleven [`TRACK_COLUMNS`]: positions and TracTrac's kinematics (PTV).
    #[default]
    Kinematics,
    /// [`TRACK_COLUMNS`] then [`STATE_COLUMNS`], for trackers that estimate classes and
    /// motion states (the bedload trackers). TracTrac's `_track.txt` cannot carry them.
    WithStates,
}

impl TrackLayout {
    /// The column names of this layout, in order.
    pub fn columns(self) -> Vec<&'static str> {
        match self {
            Self::Kinematics => TRACK_COLUMNS.to_vec(),
            Self::WithStates => TRACK_COLUMNS
                .iter()
                .chain(&STATE_COLUMNS)
                .copied()
                .collect(),
        }
    }
}

/// The class as stored in a table; refuses a class that does not fit `u32` (a corrupt file).
pub(crate) fn class_from_value<T>(value: T) -> std::result::Result<ObjectClass, String>
where
    T: TryInto<ObjectClass> + std::fmt::Display + Copy,
{
    value
        .try_into()
        .map_err(|_| format!("class {value} is not a non-negative 32-bit integer"))
}

/// The seven optional kinematic values of `point` in column order (vx, vy, ax, ay, vx_pred,
/// vy_pred, log_err); non-finite values count as missing.
pub(crate) fn kinematics(point: &TrackPoint) -> [Option<f64>; 7] {
    let split = |v: Option<Vec2>| (v.map(|v| v.x), v.map(|v| v.y));
    let (vx, vy) = split(point.vel_px_per_frame);
    let (ax, ay) = split(point.acc_px_per_frame2);
    let (px, py) = split(point.vel_pred_px_per_frame);
    [vx, vy, ax, ay, px, py, point.log10_pred_err].map(|v| v.filter(|v| v.is_finite()))
}

/// A point from its column values; a vector is known only when both its components are.
pub(crate) fn point_from_values(
    frame: u64,
    track_id: u64,
    pos_px: Point2,
    kinematics: [Option<f64>; 7],
) -> TrackPoint {
    let [vx, vy, ax, ay, px, py, err] = kinematics.map(|v| v.filter(|v| v.is_finite()));
    let vec = |x: Option<f64>, y: Option<f64>| Some(Vec2::new(x?, y?));
    TrackPoint {
        vel_px_per_frame: vec(vx, vy),
        acc_px_per_frame2: vec(ax, ay),
        vel_pred_px_per_frame: vec(px, py),
        log10_pred_err: err,
        ..TrackPoint::at(frame, track_id, pos_px)
    }
}

/// Refuses a point whose position is not finite (a tracker bug): files stay readable.
pub(crate) fn check_position(point: &TrackPoint) -> Result<()> {
    if point.pos_px.is_finite() {
        Ok(())
    } else {
        Err(Error::input(format!(
            "track {} at frame {} has a non-finite position ({}, {}); it cannot be written",
            point.track_id, point.frame, point.pos_px.x, point.pos_px.y
        )))
    }
}

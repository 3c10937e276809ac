//! The column layout shared by the CSV, Parquet and HDF5 track tables (trackpy-compatible
//! names), and the conversions between [`TrackPoint`]s and column values.

use sillage_core::{Error, Point2, Result, TrackPoint, Vec2};

/// Column names of the CSV, Parquet and HDF5 track tables, in order.
pub const TRACK_COLUMNS: [&str; 11] = [
    "frame", "particle", "x", "y", "vx", "vy", "ax", "ay", "vx_pred", "vy_pred", "log_err",
];

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

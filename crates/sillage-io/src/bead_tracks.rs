//! Bead tracks written in the layout of BeadTracking's ground truth (see [`crate::BEAD_HEADER`]),
//! so that a bedload tracker's output and the truth are read by the same reader and scored by
//! `sillage eval mot` with motion states; one more column, `spread_px`, carries the particle
//! spread of each estimate.
//!
//! Frames and pixels are written 1-based as the truth files (`frame + 1`, `x + 1`, `y + 1`);
//! motion states as BeadTracking's codes (0 resting, 1 rolling, 2 saltating, 3 unknown).

use std::fmt::Write as _;
use std::path::Path;

use sillage_core::{Error, Result, TrackPoint, TrackSink};

use crate::WrittenSummary;
use crate::text_table::{RowWriter, push_opt};

/// The header of bead track files: [`crate::BEAD_HEADER`] and the spread.
pub const BEAD_TRACK_HEADER: &str = "frame,id,x,y,category,vx,vy,motion_state,spread_px";

/// Writes bead track points batch by batch into `.NAME.partial`, renamed on
/// [`BeadCsvWriter::finish`]: an interrupted run leaves only whole rows behind.
#[derive(Debug)]
pub struct BeadCsvWriter {
    rows: RowWriter,
}

impl BeadCsvWriter {
    /// Creates the writer and writes the header.
    pub fn create(path: impl AsRef<Path>) -> Result<Self> {
        Ok(Self {
            rows: RowWriter::create(path.as_ref(), &format!("{BEAD_TRACK_HEADER}\n"))?,
        })
    }

    /// Closes the file under its final name.
    pub fn finish(self) -> Result<WrittenSummary> {
        self.rows.finish()
    }
}

impl TrackSink for BeadCsvWriter {
    /// Refuses a point whose class is not a bead category (0 or 1) or whose position is not
    /// finite (a tracker bug): files stay readable.
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        self.rows.write_rows(points, |out, p| {
            if p.class > 1 || !(p.pos_px.x.is_finite() && p.pos_px.y.is_finite()) {
                return Err(Error::input(format!(
                    "track {} at frame {} has class {} and position ({}, {}); bead tracks \
                     need class 0 (black) or 1 (transparent) and a finite position",
                    p.track_id, p.frame, p.class, p.pos_px.x, p.pos_px.y
                )));
            }
            let state = p.motion_state.bead_tracking_code();
            // Writing to a String cannot fail.
            let _ = write!(
                out,
                "{},{},{},{},{},",
                p.frame + 1,
                p.track_id,
                p.pos_px.x + 1.0,
                p.pos_px.y + 1.0,
                p.class
            );
            push_opt(out, p.vel_px_per_frame.map(|v| v.x));
            out.push(',');
            push_opt(out, p.vel_px_per_frame.map(|v| v.y));
            let _ = write!(out, ",{state},");
            push_opt(out, p.spread_px);
            Ok(())
        })
    }
}

#[cfg(test)]
mod tests {
    use sillage_core::{MotionState, Point2, Vec2};

    use super::*;
    use crate::{BeadCategory, read_bead_csv};

    #[test]
    fn round_trips_through_the_truth_reader() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("tracks.csv");
        let mut writer = BeadCsvWriter::create(&path).unwrap();
        let mut point = TrackPoint::at(4, 7, Point2::new(10.25, 3.5));
        point.class = 1;
        point.vel_px_per_frame = Some(Vec2::new(-2.5, 0.125));
        point.motion_state = MotionState::Saltating;
        point.spread_px = Some(0.75);
        let still = TrackPoint::at(5, 8, Point2::new(0.0, 0.0));
        writer.accept(&[point, still]).unwrap();
        assert!(!path.exists(), "written under a partial name until finish");
        assert_eq!(writer.finish().unwrap().rows, 2);
        let read = read_bead_csv(&path).unwrap();
        assert_eq!(read.len(), 2);
        assert_eq!((read[0].frame, read[0].id), (4, 7));
        assert_eq!(read[0].pos_px, Point2::new(10.25, 3.5));
        assert_eq!(read[0].category, BeadCategory::Transparent);
        assert_eq!(read[0].vel_px_per_frame, Some(Vec2::new(-2.5, 0.125)));
        assert_eq!(read[0].motion_state, MotionState::Saltating);
        assert_eq!(read[1].category, BeadCategory::Black);
        assert_eq!(
            (read[1].vel_px_per_frame, read[1].motion_state),
            (None, MotionState::Unknown)
        );
    }

    #[test]
    fn refuses_points_that_are_not_beads() {
        let dir = tempfile::tempdir().unwrap();
        let mut writer = BeadCsvWriter::create(dir.path().join("t.csv")).unwrap();
        let mut point = TrackPoint::at(0, 1, Point2::new(1.0, 1.0));
        point.class = 2;
        let e = writer.accept(&[point]).unwrap_err().to_string();
        assert!(e.contains("class 2"), "{e}");
        point.class = 0;
        point.pos_px.x = f64::NAN;
        assert!(writer.accept(&[point]).is_err());
    }
}

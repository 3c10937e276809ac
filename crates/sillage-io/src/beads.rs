//! Bead ground truth in the layout of BeadTracking, the MMPF+ paper's code (Lafaye de
//! Micheaux, Ducottet & Frey 2018): points with a bead category and a motion state, as a
//! CSV `frame,id,x,y,category,vx,vy,motion_state` flattened from its `trackData` (frames
//! and pixels 1-based, MATLAB), and the sequence's `sequence_param.txt` (bead diameters and
//! scale, from which the bead radii in pixels follow).
//!
//! Frames and coordinates are converted to sillage's 0-based ones on reading (`frame − 1`,
//! `x − 1`, `y − 1`); velocities are kept.

use std::path::Path;

use sillage_core::{
    BLACK_BEAD_CLASS, Error, FrameIndex, MotionState, Point2, Result, TRANSPARENT_BEAD_CLASS,
    TrackPoint, Vec2,
};

use crate::text_table::CsvTable;

/// The header of BeadTracking ground-truth CSV files.
pub const BEAD_HEADER: &str = "frame,id,x,y,category,vx,vy,motion_state";

/// The two kinds of beads of the bedload experiments (BeadTracking's `category`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BeadCategory {
    /// Black beads (`0`; 6 mm in the paper's experiments).
    Black,
    /// Transparent beads (`1`; 4 mm).
    Transparent,
}

/// One bead in one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeadPoint {
    /// 0-based frame (the file's frame − 1).
    pub frame: FrameIndex,
    /// Bead (trajectory) id.
    pub id: u64,
    /// Centre, px, 0-based (the file's `x − 1`, `y − 1`).
    pub pos_px: Point2,
    /// Black or transparent.
    pub category: BeadCategory,
    /// Displacement from the previous frame, px/frame, when given and finite.
    pub vel_px_per_frame: Option<Vec2>,
    /// Motion state (`0` resting, `1` rolling, `2` saltating, `3` or absent: unknown).
    pub motion_state: MotionState,
}

impl BeadPoint {
    /// The bead a tracker's point stands for (class 0 black, 1 transparent); `None` for
    /// another class — the inverse of [`BeadPoint::track_point`].
    pub fn from_track_point(point: &TrackPoint) -> Option<Self> {
        let category = match point.class {
            BLACK_BEAD_CLASS => BeadCategory::Black,
            TRANSPARENT_BEAD_CLASS => BeadCategory::Transparent,
            _ => return None,
        };
        Some(Self {
            frame: point.frame,
            id: point.track_id,
            pos_px: point.pos_px,
            category,
            vel_px_per_frame: point.vel_px_per_frame,
            motion_state: point.motion_state,
        })
    }

    /// The point as a track point: `id` as the track id, the category as the class
    /// (`BLACK_BEAD_CLASS`, `TRANSPARENT_BEAD_CLASS`), velocity and motion state kept — the
    /// form trackers emit and `score_bead_tracks` compares.
    pub fn track_point(&self) -> TrackPoint {
        TrackPoint {
            class: match self.category {
                BeadCategory::Black => BLACK_BEAD_CLASS,
                BeadCategory::Transparent => TRANSPARENT_BEAD_CLASS,
            },
            vel_px_per_frame: self.vel_px_per_frame,
            motion_state: self.motion_state,
            ..TrackPoint::at(self.frame, self.id, self.pos_px)
        }
    }
}

/// Reads a BeadTracking ground-truth CSV (header [`BEAD_HEADER`]; `vx`, `vy` and
/// `motion_state` optional). A frame below 1, a category other than 0 or 1, a motion state
/// other than 0 to 3, or a missing or non-finite position is an error naming the line.
pub fn read_bead_csv(path: impl AsRef<Path>) -> Result<Vec<BeadPoint>> {
    let table = CsvTable::open(
        path.as_ref(),
        &["frame", "id", "x", "y", "category"],
        &["vx", "vy", "motion_state"],
        BEAD_HEADER,
    )?;
    let mut points = Vec::new();
    table.for_each_row(|row| {
        let frame = row.index(0)?.checked_sub(1).ok_or_else(|| {
            row.error("`frame` is 0; BeadTracking frames start at 1, renumber them from 1")
        })?;
        let category = match row.index(4)? {
            0 => BeadCategory::Black,
            1 => BeadCategory::Transparent,
            other => {
                return Err(row.error(format!(
                    "`category` = {other}; it is 0 (black bead) or 1 (transparent bead)"
                )));
            }
        };
        let velocity = match (row.optional(5)?, row.optional(6)?) {
            (Some(vx), Some(vy)) if vx.is_finite() && vy.is_finite() => Some(Vec2::new(vx, vy)),
            _ => None,
        };
        let motion_state = match row.optional(7)? {
            None => MotionState::Unknown,
            Some(s) if s.is_nan() => MotionState::Unknown,
            Some(s) => MotionState::from_bead_tracking_code(s).ok_or_else(|| {
                row.error(format!(
                    "`motion_state` = {s}; it is 0 (resting), 1 (rolling), 2 (saltating) or 3 \
                     (unknown)"
                ))
            })?,
        };
        points.push(BeadPoint {
            frame,
            id: row.index(1)?,
            pos_px: Point2::new(row.finite(2)? - 1.0, row.finite(3)? - 1.0),
            category,
            vel_px_per_frame: velocity,
            motion_state,
        });
        Ok(())
    })?;
    Ok(points)
}

/// What BeadTracking's `sequence_param.txt` says about the beads' size in the images.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeadSequenceParams {
    /// `diamBlackBead`, m.
    pub black_diameter_m: f64,
    /// `diamTransBead`, m.
    pub transparent_diameter_m: f64,
    /// `mByPx`: image scale, m/px.
    pub m_per_px: f64,
}

impl BeadSequenceParams {
    /// The bead radius in pixels as BeadTracking computes it (`SetDetectionParameters`:
    /// `round(round(diameter / mByPx) / 2)`): 15 px for black and 10 px for transparent beads
    /// in the shared sequence.
    pub fn radius_px(&self, category: BeadCategory) -> f64 {
        let diameter_m = match category {
            BeadCategory::Black => self.black_diameter_m,
            BeadCategory::Transparent => self.transparent_diameter_m,
        };
        ((diameter_m / self.m_per_px).round() / 2.0).round()
    }
}

/// Writes `params` as a BeadTracking `sequence_param.txt` (`name<TAB>value<TAB>unit`),
/// through a partial file renamed when complete.
pub fn write_bead_sequence_params(
    path: impl AsRef<Path>,
    params: &BeadSequenceParams,
) -> Result<()> {
    let text = format!(
        "diamBlackBead\t{}\tm\ndiamTransBead\t{}\tm\nmByPx\t{}\tm/px\n",
        params.black_diameter_m, params.transparent_diameter_m, params.m_per_px
    );
    let mut file = crate::partial::PartialFile::create(path.as_ref())?;
    file.write_all(text.as_bytes())?;
    file.commit().map(drop)
}

/// Reads a BeadTracking `sequence_param.txt` (see [`parse_bead_sequence_params`]).
pub fn read_bead_sequence_params(path: impl AsRef<Path>) -> Result<BeadSequenceParams> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let text = std::str::from_utf8(&bytes)
        .map_err(|_| Error::format(path, None, "not valid UTF-8 text; save the file as UTF-8"))?;
    parse_bead_sequence_params(path, text)
}

/// Parses a BeadTracking `sequence_param.txt`: one `name value [unit]` per line, tab- or
/// space-separated. `diamBlackBead`, `diamTransBead` and `mByPx` are required, each a finite
/// number above 0; other names are ignored. A line without a value, a bad number or a name
/// given twice is an error naming the line.
pub fn parse_bead_sequence_params(path: &Path, text: &str) -> Result<BeadSequenceParams> {
    const KEYS: [&str; 3] = ["diamBlackBead", "diamTransBead", "mByPx"];
    let mut values: [Option<f64>; 3] = [None; 3];
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let mut fields = raw.split_whitespace();
        let Some(name) = fields.next() else {
            continue;
        };
        let Some(k) = KEYS.iter().position(|key| key.eq_ignore_ascii_case(name)) else {
            continue;
        };
        let error = |message: String| Error::format(path, Some(line), message);
        let value = fields
            .next()
            .ok_or_else(|| error(format!("`{name}` has no value; write `{name}<TAB>VALUE`")))?;
        let number = value
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| error(format!("`{name}` = `{value}` is not a number > 0")))?;
        if values[k].replace(number).is_some() {
            return Err(error(format!("`{name}` is given twice; keep one")));
        }
    }
    let value = |k: usize| {
        values[k].ok_or_else(|| {
            Error::format(
                path,
                None,
                format!(
                    "no `{}` line; the file needs diamBlackBead, diamTransBead and mByPx \
                     (`name<TAB>value<TAB>unit`)",
                    KEYS[k]
                ),
            )
        })
    };
    Ok(BeadSequenceParams {
        black_diameter_m: value(0)?,
        transparent_diameter_m: value(1)?,
        m_per_px: value(2)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Vec<BeadPoint>> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("truth.csv");
        std::fs::write(&path, text).unwrap();
        read_bead_csv(&path)
    }

    #[test]
    fn sequence_params_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sequence_param.txt");
        let params = BeadSequenceParams {
            black_diameter_m: 0.006,
            transparent_diameter_m: 0.004,
            m_per_px: 2.056e-4,
        };
        write_bead_sequence_params(&path, &params).unwrap();
        assert_eq!(read_bead_sequence_params(&path).unwrap(), params);
    }

    #[test]
    fn rows_are_converted_to_zero_based() {
        let points = read(
            "frame,id,x,y,category,vx,vy,motion_state\n\
             1,7,2.0,183.0,0,0,0,3\n\
             2,7,1.0,184.5,0,-1.0,1.5,1\n\
             2,8,50,60,1,NaN,0,2\n",
        )
        .unwrap();
        assert_eq!(points.len(), 3);
        assert_eq!(points[0].frame, 0);
        assert_eq!(points[0].pos_px, Point2::new(1.0, 182.0));
        assert_eq!(points[0].motion_state, MotionState::Unknown);
        assert_eq!(points[1].vel_px_per_frame, Some(Vec2::new(-1.0, 1.5)));
        assert_eq!(points[1].motion_state, MotionState::Rolling);
        assert_eq!(points[2].category, BeadCategory::Transparent);
        assert_eq!(points[2].vel_px_per_frame, None);
        assert_eq!(points[2].motion_state, MotionState::Saltating);
        // The optional columns may be absent.
        let bare = read("frame,id,x,y,category\n3,1,5,5,1\n").unwrap();
        assert_eq!(bare[0].motion_state, MotionState::Unknown);
    }

    #[test]
    fn malformed_rows_name_the_file_and_line() {
        let header = "frame,id,x,y,category,vx,vy,motion_state\n";
        let cases = [
            ("1,1,2,3,0,0,0,0\n0,1,2,3,0,0,0,0\n", ":3:", "frame"),
            ("1,1,2,3,2,0,0,0\n", ":2:", "category"),
            ("1,1,2,3,0,0,0,4\n", ":2:", "motion_state"),
            ("1,1,,3,0,0,0,0\n", ":2:", "`x`"),
            ("1,-1,2,3,0,0,0,0\n", ":2:", "`id`"),
        ];
        for (body, line, what) in cases {
            let err = read(&format!("{header}{body}")).unwrap_err().to_string();
            assert!(
                err.contains(&format!("truth.csv{line}")) && err.contains(what),
                "{err}"
            );
        }
        let err = read("frame,id,x,y\n1,1,2,3\n").unwrap_err().to_string();
        assert!(err.contains("missing column `category`"), "{err}");
    }

    #[test]
    fn sequence_parameters_give_the_radii() {
        let path = Path::new("sequence_param.txt");
        let params = parse_bead_sequence_params(
            path,
            "diamBlackBead\t0.006\tm\ndiamTransBead\t0.004\tm\nrateDiamTransBeadInside\t0.6\t\
             oftotaldiam\nmByPx\t0.0002056\tm/px\nacqFreq\t130\tim/s\n",
        )
        .unwrap();
        assert_eq!(params.radius_px(BeadCategory::Black), 15.0);
        assert_eq!(params.radius_px(BeadCategory::Transparent), 10.0);
        let err = parse_bead_sequence_params(path, "diamBlackBead\t0.006\nmByPx\tx\n")
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("sequence_param.txt:2: `mByPx`"), "{err}");
        let err = parse_bead_sequence_params(path, "diamBlackBead 0.006\nmByPx 0.1\n")
            .unwrap_err()
            .to_string();
        assert!(err.contains("no `diamTransBead` line"), "{err}");
        assert!(parse_bead_sequence_params(path, "mByPx 1\nmByPx 2\n").is_err());
    }
}

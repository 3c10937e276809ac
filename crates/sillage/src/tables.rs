//! Any track table read as track points, whatever wrote it: our own tables (TracTrac
//! `_track.txt`, CSV, Parquet, HDF5), point truth CSV, the bead CSV of `track bedload`, and
//! MOTChallenge results of `track immpf` / `track siftpf` (a box becomes its centre).

use std::path::Path;

use sillage_core::{Error, Point2, Result, TrackPoint};
use sillage_io::{
    MotRow, TableFormat, TrackLayout, detect_table_format, read_bead_csv, read_mot_rows,
    read_track_table, read_truth_csv,
};

/// A track table read as points.
#[derive(Debug, Clone)]
pub struct LoadedTracks {
    /// Every point, in file order.
    pub points: Vec<TrackPoint>,
    /// Whether the table has motion states (bedload tables).
    pub has_states: bool,
    /// Whether the table has velocities (else they are finite differences of positions).
    pub has_velocities: bool,
}

/// Extensions of the tables whose format [`read_track_points`] tells by itself, and of the
/// prediction files of a folder that `sillage::evaluate` pairs with ground truth.
pub const TABLE_EXTENSIONS: [&str; 5] = ["txt", "csv", "parquet", "h5", "hdf5"];

/// Reads `path` in `format`, or in the format its extension and first line tell
/// ([`detect_table_format`]; then the extension must be one of a track table); an empty
/// table is an error.
pub fn read_track_points(path: &Path, format: Option<TableFormat>) -> Result<LoadedTracks> {
    let format = match format {
        Some(format) => format,
        None if has_extension(path, &TABLE_EXTENSIONS) => detect_table_format(path)?,
        None => {
            return Err(Error::format(
                path,
                None,
                "cannot tell the track format from the extension; use .txt (TracTrac or \
                 MOTChallenge), .csv, .parquet or .h5, or give --format",
            ));
        }
    };
    let (points, has_states) = match format {
        TableFormat::Tracks(format) => {
            let table = read_track_table(path, format)?;
            (table.points, table.layout == TrackLayout::WithStates)
        }
        TableFormat::Beads => {
            let beads = read_bead_csv(path)?;
            (beads.iter().map(|b| b.track_point()).collect(), true)
        }
        TableFormat::Truth => (truth_points(path)?, false),
        TableFormat::Mot => (box_centres(path, &read_mot_rows(path)?)?, false),
    };
    if points.is_empty() {
        return Err(Error::format(
            path,
            None,
            "the table holds no track point; check that the tracker found objects",
        ));
    }
    let has_velocities = points.iter().any(|p| p.vel_px_per_frame.is_some());
    Ok(LoadedTracks {
        points,
        has_states,
        has_velocities,
    })
}

/// Whether `path` ends in one of `extensions` (any case).
pub(crate) fn has_extension(path: &Path, extensions: &[&str]) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| extensions.iter().any(|x| x.eq_ignore_ascii_case(e)))
}

/// The points of a truth CSV, with their true velocities.
fn truth_points(path: &Path) -> Result<Vec<TrackPoint>> {
    Ok(read_truth_csv(path)?
        .iter()
        .map(|t| TrackPoint {
            vel_px_per_frame: t.vel_px_per_frame,
            ..TrackPoint::at(t.frame, t.track_id, t.pos_px)
        })
        .collect())
}

/// MOTChallenge rows as points at their box centres; rows without an id (detections) are
/// refused.
fn box_centres(path: &Path, rows: &[MotRow]) -> Result<Vec<TrackPoint>> {
    rows.iter()
        .map(|row| match row.id {
            Some(id) => Ok(TrackPoint::at(
                row.frame,
                id,
                Point2::new(
                    row.left_px + 0.5 * row.width_px,
                    row.top_px + 0.5 * row.height_px,
                ),
            )),
            None => Err(Error::format(
                path,
                None,
                format!(
                    "a row of frame {} has id -1 (a detection, not a track); give tracker \
                     results",
                    row.frame + 1
                ),
            )),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn truth_csv_reads_as_tracks_with_velocities() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("truth.csv");
        let truth = [sillage_core::TruthPoint {
            frame: 2,
            track_id: 5,
            pos_px: Point2::new(1.5, 2.5),
            vel_px_per_frame: Some(sillage_core::Vec2::new(0.5, -1.0)),
        }];
        sillage_io::write_truth_csv(&path, &truth).unwrap();
        let tracks = read_track_points(&path, None).unwrap();
        assert_eq!(tracks.points.len(), 1);
        assert_eq!(tracks.points[0].track_id, 5);
        assert_eq!(tracks.points[0].vel_px_per_frame, truth[0].vel_px_per_frame);
        assert!(tracks.has_velocities && !tracks.has_states);
    }

    #[test]
    fn detections_are_not_tracks() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("det.txt");
        std::fs::write(&path, "1,-1,10,10,4,4,0.9,-1,-1,-1\n").unwrap();
        let message = read_track_points(&path, None).unwrap_err().to_string();
        assert!(message.contains("frame 1 has id -1"), "{message}");
    }
}

//! The track tables `sillage plot` and `sillage overlay` read, whatever wrote them: our own
//! tables (TracTrac `_track.txt`, CSV, Parquet, HDF5), the bead CSV of `track bedload`, and
//! the MOTChallenge results of `track immpf` / `track siftpf` (a box becomes its centre).

use std::path::Path;

use anyhow::{Result, bail};
use sillage::core::{Point2, TrackPoint};
use sillage::io::{
    BEAD_HEADER, MotRow, TRACK_COLUMNS, TrackFormat, TrackLayout, read_bead_csv, read_mot_rows,
    read_track_table,
};

use crate::cli::TableFormatArg;
use crate::eval_inputs::first_line;

/// A track table read for drawing.
#[derive(Debug, Clone)]
pub struct LoadedTracks {
    /// Every point, in file order.
    pub points: Vec<TrackPoint>,
    /// Whether the table has motion states (bedload tables).
    pub has_states: bool,
    /// Whether the table has velocities (else they are finite differences of positions).
    pub has_velocities: bool,
}

/// Reads `path` in `format`, or in the format its extension and first line tell; an empty
/// table is an error.
pub fn read_tracks_for_drawing(
    path: &Path,
    format: Option<TableFormatArg>,
) -> Result<LoadedTracks> {
    let format = match format {
        Some(format) => format,
        None => sniff(path)?,
    };
    let table = |format| read_track_table(path, format);
    let (points, has_states) = match format {
        TableFormatArg::Tractrac => (table(TrackFormat::Tractrac)?.points, false),
        TableFormatArg::Csv | TableFormatArg::Parquet | TableFormatArg::Hdf5 => {
            let format = match format {
                TableFormatArg::Csv => TrackFormat::Csv,
                TableFormatArg::Parquet => TrackFormat::Parquet,
                _ => TrackFormat::Hdf5,
            };
            let table = table(format)?;
            (table.points, table.layout == TrackLayout::WithStates)
        }
        TableFormatArg::Beads => {
            let beads = read_bead_csv(path)?;
            (beads.iter().map(|b| b.track_point()).collect(), true)
        }
        TableFormatArg::Mot => (box_centres(path, &read_mot_rows(path)?)?, false),
    };
    if points.is_empty() {
        bail!(
            "{}: the table holds no track point; check that the tracker found objects",
            path.display()
        );
    }
    let has_velocities = points.iter().any(|p| p.vel_px_per_frame.is_some());
    Ok(LoadedTracks {
        points,
        has_states,
        has_velocities,
    })
}

/// The format of `path` from its extension and, for `.txt` and `.csv`, its first line.
fn sniff(path: &Path) -> Result<TableFormatArg> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("parquet") => Ok(TableFormatArg::Parquet),
        Some("h5" | "hdf5") => Ok(TableFormatArg::Hdf5),
        // TracTrac's header lines start with `#`; MOTChallenge files are bare numbers.
        Some("txt") if first_line(path)?.starts_with('#') => Ok(TableFormatArg::Tractrac),
        Some("txt") => Ok(TableFormatArg::Mot),
        Some("csv") => {
            let header = first_line(path)?.to_ascii_lowercase();
            let has = |name: &str| header.split(',').any(|c| c.trim() == name);
            if has("category") {
                Ok(TableFormatArg::Beads)
            } else if has("particle") {
                Ok(TableFormatArg::Csv)
            } else {
                bail!(
                    "{}: a CSV with the header `{header}` is no track table; expected tracks \
                     ({}) or beads ({BEAD_HEADER})",
                    path.display(),
                    TRACK_COLUMNS.join(",")
                )
            }
        }
        _ => bail!(
            "{}: cannot tell the track format from the extension; use .txt (TracTrac or \
             MOTChallenge), .csv, .parquet or .h5, or give --format",
            path.display()
        ),
    }
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
            None => bail!(
                "{}: a row of frame {} has id -1 (a detection, not a track); give tracker \
                 results",
                path.display(),
                row.frame + 1
            ),
        })
        .collect()
}

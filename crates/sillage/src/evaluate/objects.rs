//! The objects of one evaluation file, read in the format its extension and first line tell
//! ([`detect_table_format`]): MOTChallenge boxes, beads with categories and motion states, or
//! points.

use std::path::Path;

use sillage_core::{Error, FrameIndex, Point2, Result};
use sillage_io::{
    BeadPoint, MotFileRole, MotRow, TableFormat, TrackFormat, TrackLayout, detect_table_format,
    read_bead_csv, read_mot_rows, read_mot_sequence, read_track_table, read_truth_csv,
};

/// The objects a file holds.
pub(super) enum Objects {
    /// MOTChallenge rows (boxes).
    Boxes(Vec<MotRow>),
    /// Beads with categories and motion states.
    Beads(Vec<BeadPoint>),
    /// Points: truth CSV or sillage tracks.
    Points(Vec<(FrameIndex, u64, Point2)>),
}

/// Reads `path` in the format its extension and first line tell; for ground truth
/// (`with_seqinfo`), a MOTChallenge file comes with the `seqLength` of its `seqinfo.ini`
/// (beside it or one folder up), when there is one.
pub(super) fn read_objects(path: &Path, with_seqinfo: bool) -> Result<(Objects, Option<u64>)> {
    let objects = match detect_table_format(path)? {
        TableFormat::Tracks(format) => read_tracks(path, format)?,
        TableFormat::Beads => Objects::Beads(read_bead_csv(path)?),
        TableFormat::Truth => Objects::Points(
            read_truth_csv(path)?
                .iter()
                .map(|p| (p.frame, p.track_id, p.pos_px))
                .collect(),
        ),
        TableFormat::Mot if with_seqinfo => {
            let file = read_mot_sequence(path, MotFileRole::GroundTruth)?;
            let frame_count = file.seqinfo.and_then(|info| info.frame_count);
            return Ok((Objects::Boxes(file.rows), frame_count));
        }
        TableFormat::Mot => Objects::Boxes(read_mot_rows(path)?),
    };
    Ok((objects, None))
}

/// A track table of ours: beads when it has motion states (bedload trackers), else points.
fn read_tracks(path: &Path, format: TrackFormat) -> Result<Objects> {
    let table = read_track_table(path, format)?;
    if table.layout != TrackLayout::WithStates {
        return Ok(Objects::Points(
            table
                .points
                .iter()
                .map(|p| (p.frame, p.track_id, p.pos_px))
                .collect(),
        ));
    }
    let beads = table
        .points
        .iter()
        .map(|p| {
            BeadPoint::from_track_point(p).ok_or_else(|| {
                Error::format(
                    path,
                    None,
                    format!(
                        "track {} at frame {} has class {}; bead tracks have class 0 (black) or \
                         1 (transparent)",
                        p.track_id, p.frame, p.class
                    ),
                )
            })
        })
        .collect::<Result<_>>()?;
    Ok(Objects::Beads(beads))
}

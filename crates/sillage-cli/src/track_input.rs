//! The track table of `sillage plot` and `sillage overlay`: `--format` mapped to the
//! library's table formats, the reading itself in [`sillage::tables`].

use std::path::Path;

use anyhow::Result;
use sillage::io::{TableFormat, TrackFormat};
use sillage::tables::{LoadedTracks, read_track_points};

use crate::shared_args::TableFormatArg;

/// Reads `path` in `format`, or in the format its extension and first line tell; an empty
/// table is an error.
pub fn read_tracks_for_drawing(
    path: &Path,
    format: Option<TableFormatArg>,
) -> Result<LoadedTracks> {
    Ok(read_track_points(path, format.map(table_format))?)
}

/// The library's name of a `--format`.
fn table_format(format: TableFormatArg) -> TableFormat {
    match format {
        TableFormatArg::Tractrac => TableFormat::Tracks(TrackFormat::Tractrac),
        TableFormatArg::Csv => TableFormat::Tracks(TrackFormat::Csv),
        TableFormatArg::Parquet => TableFormat::Tracks(TrackFormat::Parquet),
        TableFormatArg::Hdf5 => TableFormat::Tracks(TrackFormat::Hdf5),
        TableFormatArg::Beads => TableFormat::Beads,
        TableFormatArg::Mot => TableFormat::Mot,
    }
}

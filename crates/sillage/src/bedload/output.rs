//! Where the bedload trackers write their trajectories: BeadTracking's CSV layout (what
//! `sillage eval mot` compares with bead truth) or a track table of the project (CSV with
//! trackpy's column names, Parquet, HDF5) with the class, motion-state and spread columns.

use std::path::Path;

use sillage_core::{Error, Result, TrackPoint, TrackSink};
use sillage_io::{
    BeadCsvWriter, TrackFileHeader, TrackFormat, TrackLayout, TrackWriter, WrittenSummary,
    create_track_writer, read_bead_csv, read_tracks,
};
use sillage_track::bedload::BedloadTrackerParams;

use crate::toml_config::dotted_keys;

/// The kind of file a [`BeadTrackOutput`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BeadTrackKind {
    /// BeadTracking's layout.
    Beads,
    /// A track table of this format with the state columns.
    Table(TrackFormat),
}

impl BeadTrackKind {
    /// The kind `path`'s extension names: `.csv` is BeadTracking's layout, `.parquet` and
    /// `.h5` track tables; TracTrac's `_track.txt` is refused (it has no state columns).
    pub fn from_path(path: &Path) -> Result<Self> {
        match TrackFormat::from_path(path)? {
            TrackFormat::Csv => Ok(Self::Beads),
            TrackFormat::Tractrac => Err(Error::input(format!(
                "{}: TracTrac's _track.txt has no columns for bead categories and motion \
                 states; write .csv (BeadTracking's layout), .parquet or .h5",
                path.display()
            ))),
            table => Ok(Self::Table(table)),
        }
    }

    /// Reads back the points a finished writer of this kind wrote to `path`.
    pub fn read(self, path: &Path) -> Result<Vec<TrackPoint>> {
        Ok(match self {
            Self::Beads => read_bead_csv(path)?
                .iter()
                .map(|b| b.track_point())
                .collect(),
            Self::Table(format) => read_tracks(path, format)?,
        })
    }
}

/// A bead-track writer of one [`BeadTrackKind`].
pub enum BeadTrackOutput {
    /// BeadTracking's layout.
    Beads(BeadCsvWriter),
    /// A track table with [`TrackLayout::WithStates`], and its format.
    Table(Box<dyn TrackWriter + Send>, TrackFormat),
}

impl BeadTrackOutput {
    /// Creates the writer of `kind` (or of the kind `path`'s extension names, see
    /// [`BeadTrackKind::from_path`]) at `path`; tables record `params` in their header.
    pub fn create(
        path: &Path,
        kind: Option<BeadTrackKind>,
        params: &BedloadTrackerParams,
    ) -> Result<Self> {
        let kind = match kind {
            Some(kind) => kind,
            None => BeadTrackKind::from_path(path)?,
        };
        Ok(match kind {
            BeadTrackKind::Beads => Self::Beads(BeadCsvWriter::create(path)?),
            BeadTrackKind::Table(format) => {
                let header = TrackFileHeader {
                    program_version: format!("sillage {}", env!("CARGO_PKG_VERSION")),
                    parameters: dotted_keys(params)?,
                    layout: TrackLayout::WithStates,
                };
                Self::Table(create_track_writer(path, format, &header)?, format)
            }
        })
    }

    /// Closes the file under its final name.
    pub fn finish(self) -> Result<WrittenSummary> {
        match self {
            Self::Beads(writer) => writer.finish(),
            Self::Table(writer, _) => writer.finish(),
        }
    }

    /// Which kind of file this writer makes (to read it back once finished).
    pub fn kind(&self) -> BeadTrackKind {
        match self {
            Self::Beads(_) => BeadTrackKind::Beads,
            Self::Table(_, format) => BeadTrackKind::Table(*format),
        }
    }
}

impl TrackSink for BeadTrackOutput {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        match self {
            Self::Beads(writer) => writer.accept(points),
            Self::Table(writer, _) => writer.accept(points),
        }
    }
}

impl TrackWriter for BeadTrackOutput {
    fn finish(self: Box<Self>) -> Result<WrittenSummary> {
        BeadTrackOutput::finish(*self)
    }
}

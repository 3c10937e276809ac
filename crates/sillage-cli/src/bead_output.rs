//! Where `sillage track bedload` writes its trajectories: BeadTracking's CSV layout (what
//! `eval mot` compares with bead truth) or a track table of the project (CSV, Parquet, HDF5)
//! with the class, motion-state and spread columns.

use std::path::Path;

use anyhow::{Result, bail};
use sillage::core::{TrackPoint, TrackSink};
use sillage::io::{
    BeadCsvWriter, TrackFileHeader, TrackFormat, TrackLayout, TrackWriter, WrittenSummary,
    create_track_writer, read_bead_csv, read_tracks,
};
use sillage::toml_config::dotted_keys;
use sillage::track::bedload::BedloadTrackerParams;

use crate::cli::BeadFormatArg;

/// A bead-track writer of the chosen format.
pub enum BeadTrackOutput {
    /// BeadTracking's layout.
    Beads(BeadCsvWriter),
    /// A track table with [`TrackLayout::WithStates`], and its format.
    Table(Box<dyn TrackWriter>, TrackFormat),
}

impl BeadTrackOutput {
    /// Creates the writer of `format` (or the one `path`'s extension names: `.csv` is
    /// BeadTracking's layout) at `path`; tables record `params` in their header.
    pub fn create(
        path: &Path,
        format: Option<BeadFormatArg>,
        params: &BedloadTrackerParams,
    ) -> Result<Self> {
        let format = match format {
            Some(BeadFormatArg::Beads) => None,
            Some(BeadFormatArg::Csv) => Some(TrackFormat::Csv),
            Some(BeadFormatArg::Parquet) => Some(TrackFormat::Parquet),
            Some(BeadFormatArg::Hdf5) => Some(TrackFormat::Hdf5),
            None => match TrackFormat::from_path(path)? {
                TrackFormat::Csv => None,
                TrackFormat::Tractrac => bail!(
                    "{}: TracTrac's _track.txt has no columns for bead categories and motion \
                     states; write .csv (BeadTracking's layout), .parquet or .h5",
                    path.display()
                ),
                table => Some(table),
            },
        };
        Ok(match format {
            None => Self::Beads(BeadCsvWriter::create(path)?),
            Some(format) => {
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
        Ok(match self {
            Self::Beads(writer) => writer.finish()?,
            Self::Table(writer, _) => writer.finish()?,
        })
    }

    /// Which kind of file this writer makes (to read it back once finished).
    pub fn kind(&self) -> BeadTrackKind {
        match self {
            Self::Beads(_) => BeadTrackKind::Beads,
            Self::Table(_, format) => BeadTrackKind::Table(*format),
        }
    }
}

/// The kind of file a [`BeadTrackOutput`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BeadTrackKind {
    /// BeadTracking's layout.
    Beads,
    /// A track table of this format with the state columns.
    Table(TrackFormat),
}

impl BeadTrackKind {
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

impl TrackSink for BeadTrackOutput {
    fn accept(&mut self, points: &[TrackPoint]) -> sillage::core::Result<()> {
        match self {
            Self::Beads(writer) => writer.accept(points),
            Self::Table(writer, _) => writer.accept(points),
        }
    }
}

//! Track tables: writers (streaming, through [`TrackSink`]) and readers for TracTrac's
//! `_track.txt`, CSV, Parquet (feature `parquet`) and HDF5 (feature `hdf5`).

#[cfg(any(feature = "parquet", feature = "hdf5"))]
mod background;
mod column_buffer;
mod columns;
#[cfg(feature = "hdf5")]
mod hdf5;
#[cfg(feature = "parquet")]
mod parquet;
mod text;

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use sillage_core::{Error, Result, TrackPoint, TrackSink};

pub use background::{BackgroundWriter, QUEUED_BATCHES, write_in_background};
pub use columns::{STATE_COLUMNS, TRACK_COLUMNS, TrackLayout};
pub use text::TRACTRAC_COLUMNS_LINE;

/// The file formats of a track table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TrackFormat {
    /// TracTrac's ASCII `_track.txt` (3 `#` header lines, 11 space-separated columns).
    Tractrac,
    /// CSV with the header `frame,particle,x,y,vx,vy,ax,ay,vx_pred,vy_pred,log_err`
    /// (then `class,motion_state,spread_px` with [`TrackLayout::WithStates`]).
    Csv,
    /// Apache Parquet with the CSV's column names (feature `parquet`).
    Parquet,
    /// HDF5, one dataset per column (feature `hdf5`).
    Hdf5,
}

impl TrackFormat {
    /// All formats, in the order `--format` lists them.
    pub const ALL: [TrackFormat; 4] = [Self::Tractrac, Self::Csv, Self::Parquet, Self::Hdf5];

    /// The format named by the extension of `path`: `.txt` (including `_track.txt`) is
    /// TracTrac, then `.csv`, `.parquet`, `.h5`/`.hdf5`.
    pub fn from_path(path: &Path) -> Result<Self> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("txt") => Ok(Self::Tractrac),
            Some("csv") => Ok(Self::Csv),
            Some("parquet") => Ok(Self::Parquet),
            Some("h5" | "hdf5") => Ok(Self::Hdf5),
            _ => Err(Error::input(format!(
                "{}: cannot tell the track format from the extension; use .txt (TracTrac), \
                 .csv, .parquet or .h5, or give the format (--format tractrac|csv|parquet|hdf5)",
                path.display()
            ))),
        }
    }

    /// The name `--format` takes.
    pub fn name(self) -> &'static str {
        match self {
            Self::Tractrac => "tractrac",
            Self::Csv => "csv",
            Self::Parquet => "parquet",
            Self::Hdf5 => "hdf5",
        }
    }

    /// The file extension [`TrackFormat::from_path`] reads as this format.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Tractrac => "txt",
            Self::Csv => "csv",
            Self::Parquet => "parquet",
            Self::Hdf5 => "h5",
        }
    }
}

impl fmt::Display for TrackFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for TrackFormat {
    type Err = Error;

    /// Parses `tractrac`, `csv`, `parquet` or `hdf5` (also `txt` and `h5`), any case.
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "tractrac" | "txt" => Ok(Self::Tractrac),
            "csv" => Ok(Self::Csv),
            "parquet" => Ok(Self::Parquet),
            "hdf5" | "h5" => Ok(Self::Hdf5),
            _ => Err(Error::parameter(
                "format",
                s,
                "expected tractrac, csv, parquet or hdf5",
            )),
        }
    }
}

/// What a track file records about the run that made it.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct TrackFileHeader {
    /// Version text; TracTrac's first header line is `# TracTrac v{program_version} `, so
    /// give e.g. `"3.0 (sillage 0.1.0)"`.
    pub program_version: String,
    /// The run's parameters as `(key, value)` text (TracTrac's header line 2, Parquet
    /// key-value metadata `param:KEY`, HDF5 attributes `param:KEY`).
    pub parameters: Vec<(String, String)>,
    /// The columns to write (CSV, Parquet, HDF5; TracTrac's layout is fixed).
    pub layout: TrackLayout,
}

/// A whole track table read back: its points and the layout of its columns.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackTable {
    /// The rows, in file order.
    pub points: Vec<TrackPoint>,
    /// [`TrackLayout::WithStates`] when the table has a motion-state column.
    pub layout: TrackLayout,
}

/// What a finished writer wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WrittenSummary {
    /// Number of data rows.
    pub rows: u64,
    /// The final path of the file.
    pub path: PathBuf,
}

/// A streaming track-table writer: accepts points batch by batch (as a [`TrackSink`]) into
/// `.NAME.partial`, and renames it to its final name on [`TrackWriter::finish`].
pub trait TrackWriter: TrackSink {
    /// Flushes, closes and renames the file; returns what was written.
    fn finish(self: Box<Self>) -> Result<WrittenSummary>;
}

/// Creates a writer of `format` at `path` (written as `.NAME.partial` until finished).
/// TracTrac's format refuses [`TrackLayout::WithStates`]: its 11 columns are fixed.
pub fn create_track_writer(
    path: &Path,
    format: TrackFormat,
    header: &TrackFileHeader,
) -> Result<Box<dyn TrackWriter + Send>> {
    match format {
        TrackFormat::Tractrac if header.layout == TrackLayout::WithStates => {
            Err(Error::input(format!(
                "{}: TracTrac's _track.txt has no columns for classes and motion states; \
                 write csv, parquet or hdf5 instead",
                path.display()
            )))
        }
        TrackFormat::Tractrac => Ok(Box::new(text::TextTrackWriter::create(
            path,
            text::TextStyle::Tractrac,
            header,
        )?)),
        TrackFormat::Csv => Ok(Box::new(text::TextTrackWriter::create(
            path,
            text::TextStyle::Csv(header.layout),
            header,
        )?)),
        #[cfg(feature = "parquet")]
        TrackFormat::Parquet => Ok(Box::new(parquet::ParquetTrackWriter::create(path, header)?)),
        #[cfg(not(feature = "parquet"))]
        TrackFormat::Parquet => Err(not_built(format)),
        #[cfg(feature = "hdf5")]
        TrackFormat::Hdf5 => Ok(Box::new(hdf5::Hdf5TrackWriter::create(path, header)?)),
        #[cfg(not(feature = "hdf5"))]
        TrackFormat::Hdf5 => Err(not_built(format)),
    }
}

/// Reads the points of a whole track table of `format` at `path` (class, motion state and
/// spread included when the table has them).
pub fn read_tracks(path: &Path, format: TrackFormat) -> Result<Vec<TrackPoint>> {
    Ok(read_track_table(path, format)?.points)
}

/// Reads a whole track table of `format` at `path`, with the layout its columns had.
pub fn read_track_table(path: &Path, format: TrackFormat) -> Result<TrackTable> {
    let mut points = Vec::new();
    let layout = for_each_track_point(path, format, |point| {
        points.push(point);
        Ok(())
    })?;
    Ok(TrackTable { points, layout })
}

/// Streams the points of the track table of `format` at `path` to `each`, in file order,
/// and returns the layout of its columns. Memory does not grow with the table's length
/// (TracTrac and CSV: row by row; Parquet: one record batch at a time), except for HDF5,
/// whose datasets are read whole. The first error of `each` stops the reading.
pub fn for_each_track_point(
    path: &Path,
    format: TrackFormat,
    mut each: impl FnMut(TrackPoint) -> Result<()>,
) -> Result<TrackLayout> {
    let each: &mut dyn FnMut(TrackPoint) -> Result<()> = &mut each;
    match format {
        TrackFormat::Tractrac => text::read_tractrac(path, each),
        TrackFormat::Csv => text::read_csv(path, each),
        #[cfg(feature = "parquet")]
        TrackFormat::Parquet => parquet::read_parquet(path, each),
        #[cfg(not(feature = "parquet"))]
        TrackFormat::Parquet => Err(not_built(format)),
        #[cfg(feature = "hdf5")]
        TrackFormat::Hdf5 => hdf5::read_hdf5(path, each),
        #[cfg(not(feature = "hdf5"))]
        TrackFormat::Hdf5 => Err(not_built(format)),
    }
}

#[cfg(not(all(feature = "parquet", feature = "hdf5")))]
fn not_built(format: TrackFormat) -> Error {
    Error::input(format!(
        "this build of sillage has no {format} support; rebuild with `--features {format}` \
         or choose another format (tractrac, csv)"
    ))
}

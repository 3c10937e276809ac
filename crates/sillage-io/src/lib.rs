//! Reading and writing everything that crosses the file system: frame sources (image
//! folders, glob patterns, multi-page TIFF stacks, videos through the `ffmpeg` program),
//! track tables (TracTrac `_track.txt`, CSV, Parquet, HDF5), ground truth and detections
//! (CSV), MOTChallenge files, and TracTrac parameter files.
//!
//! Roles:
//! - [`open_frames`] turns an INPUT string into a [`FrameSource`], an iterator of
//!   [`Frame`]s decoded ahead on a background thread (bounded memory);
//! - [`create_track_writer`] gives a [`TrackWriter`], a [`sillage_core::TrackSink`] that
//!   streams points into a file (with classes and motion states in the
//!   [`TrackLayout::WithStates`] columns); [`read_tracks`] / [`read_track_table`] read one
//!   back, [`for_each_track_point`] streams one row by row (memory independent of length);
//! - [`write_numeric_table`] writes a small [`NumericTable`] of statistics as CSV, Parquet
//!   or NumPy `.npy`;
//! - [`TruthCsvWriter`] / [`read_truth_csv`], [`DetectionsCsvWriter`] /
//!   [`read_detections_csv`] for ground truth and saved detections;
//! - [`Mp4Writer`] encodes pictures (overlays) into an MP4 through `ffmpeg`;
//! - [`read_tractrac_par`] / [`write_tractrac_par`] for TracTrac's `*_par.txt`;
//! - [`read_mot_sequence`] / [`read_mot_rows`] / [`read_seqinfo`] for MOTChallenge
//!   `gt.txt`, `det.txt`, results and `seqinfo.ini` (a file or a sequence folder), and
//!   [`MotResultsWriter`] / [`write_mot_results`] for results;
//! - [`MotEventsCsvWriter`] for the per-frame events of an evaluation;
//! - [`detect_table_format`] tells a table's [`TableFormat`] from its extension and first line;
//! - [`read_bead_csv`] / [`read_bead_sequence_params`] for bead ground truth with categories
//!   and motion states (BeadTracking, the MMPF+ paper's code).
//!
//! Every file is written as `.NAME.partial` in the destination folder and renamed when
//! complete. Errors name the file, the line or frame, and the fix.
//!
//! ```
//! use sillage_core::{Point2, TrackPoint, TrackSink};
//! use sillage_io::{
//!     FrameOptions, TrackFileHeader, TrackFormat, create_track_writer, open_frames,
//!     read_tracks, write_png16,
//! };
//!
//! # fn main() -> sillage_core::Result<()> {
//! let dir = tempfile::tempdir().unwrap();
//! // Two 16-bit frames, then read them back as a sequence.
//! let mut image = sillage_core::GrayImage::new(8, 4);
//! image.set(3, 2, 0.5);
//! write_png16(dir.path().join("frame_1.png"), &image)?;
//! write_png16(dir.path().join("frame_2.png"), &image)?;
//! let frames = open_frames(dir.path().to_str().unwrap(), &FrameOptions::default())?;
//! assert_eq!(frames.dimensions(), (8, 4));
//! for frame in frames {
//!     let frame = frame?;
//!     assert!((frame.image.get(3, 2) - 0.5).abs() < 1e-4);
//! }
//!
//! // Stream track points into a TracTrac `_track.txt`, then read them back.
//! let path = dir.path().join("seq_track.txt");
//! let mut writer = create_track_writer(&path, TrackFormat::Tractrac, &TrackFileHeader::default())?;
//! writer.accept(&[TrackPoint::at(1, 7, Point2::new(3.25, 2.5))])?;
//! let summary = writer.finish()?;
//! assert_eq!(summary.rows, 1);
//! let points = read_tracks(&path, TrackFormat::from_path(&path)?)?;
//! assert_eq!(points[0].track_id, 7);
//! # Ok(())
//! # }
//! ```

mod bead_tracks;
mod beads;
mod detections;
mod frames;
mod matrix;
mod mot;
mod mot_events;
mod numeric_table;
mod partial;
mod spool;
mod table_format;
mod text_table;
mod tracks;
mod tractrac_par;
mod truth;

pub use bead_tracks::{BEAD_TRACK_HEADER, BeadCsvWriter};
pub use beads::{
    BEAD_HEADER, BeadCategory, BeadPoint, BeadSequenceParams, parse_bead_sequence_params,
    read_bead_csv, read_bead_sequence_params, write_bead_sequence_params,
};
pub use detections::{
    DETECTIONS_HEADER, DetectionsCsvWriter, read_detections_csv, write_detections_csv,
};
pub use frames::{
    BadFramePolicy, Frame, FrameOptions, FrameSource, Mp4Writer, SkippedFrame, SkippedFrames,
    open_frames, read_image, read_image_from_bytes, write_png_rgb, write_png16, write_text,
};
pub use matrix::read_matrix_csv;
pub use mot::{
    MotFileRole, MotGroundTruthWriter, MotResultsWriter, MotRow, MotSequenceFile, SeqInfo,
    check_seqinfo_frames, parse_mot_rows, parse_seqinfo, read_mot_rows, read_mot_sequence,
    read_seqinfo, write_mot_results, write_seqinfo,
};
pub use mot_events::{MOT_EVENTS_HEADER, MotEventKind, MotEventRow, MotEventsCsvWriter};
pub use numeric_table::{ColumnValues, NumericFormat, NumericTable, write_numeric_table};
pub use partial::PartialFile;
pub use spool::{SpoolWriter, decode_points, encode_points, replay_spool, spool_path};
pub use table_format::{TableFormat, detect_table_format};
pub use tracks::{
    BackgroundWriter, QUEUED_BATCHES, STATE_COLUMNS, TRACK_COLUMNS, TRACTRAC_COLUMNS_LINE,
    TrackFileHeader, TrackFormat, TrackLayout, TrackTable, TrackWriter, WrittenSummary,
    create_track_writer, for_each_track_point, read_track_table, read_tracks, write_in_background,
};
pub use tractrac_par::{
    TRACTRAC_KEYS, TractracPar, parse_tractrac_par, read_tractrac_par, write_tractrac_par,
};
pub use truth::{TRUTH_HEADER, TruthCsvWriter, read_truth_csv, write_truth_csv};

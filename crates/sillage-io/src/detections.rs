//! Detection tables: CSV with the header `frame,x,y,strength`, so a detector's output can be
//! saved once and fed to trackers (`--detections FILE`).

use std::fmt::Write as _;
use std::path::Path;

use sillage_core::{Detection, FrameIndex, Point2, Result};

use crate::WrittenSummary;
use crate::text_table::{CsvTable, RowWriter};

/// The header of detection CSV files.
pub const DETECTIONS_HEADER: &str = "frame,x,y,strength";

/// Writes detections frame by frame into `.NAME.partial`, renamed on
/// [`DetectionsCsvWriter::finish`].
#[derive(Debug)]
pub struct DetectionsCsvWriter {
    rows: RowWriter,
}

impl DetectionsCsvWriter {
    /// Creates the writer and writes the header.
    pub fn create(path: impl AsRef<Path>) -> Result<Self> {
        Ok(Self {
            rows: RowWriter::create(path.as_ref(), &format!("{DETECTIONS_HEADER}\n"))?,
        })
    }

    /// Appends the detections of `frame` (whole rows, one write).
    pub fn push(&mut self, frame: FrameIndex, detections: &[Detection]) -> Result<()> {
        self.rows.write_rows(detections, |out, d| {
            // Writing to a String cannot fail.
            let _ = write!(out, "{frame},{},{},{}", d.pos_px.x, d.pos_px.y, d.strength);
            Ok(())
        })
    }

    /// Closes the file under its final name.
    pub fn finish(self) -> Result<WrittenSummary> {
        self.rows.finish()
    }
}

/// Writes per-frame detections `(frame, detections)` at `path` in one go.
pub fn write_detections_csv(
    path: impl AsRef<Path>,
    frames: &[(FrameIndex, Vec<Detection>)],
) -> Result<()> {
    let mut writer = DetectionsCsvWriter::create(path)?;
    for (frame, detections) in frames {
        writer.push(*frame, detections)?;
    }
    writer.finish().map(drop)
}

/// Reads a detection CSV, grouped by frame in increasing frame order (frames with no
/// detection are absent). A missing `strength` reads as 0.
pub fn read_detections_csv(path: impl AsRef<Path>) -> Result<Vec<(FrameIndex, Vec<Detection>)>> {
    let table = CsvTable::open(
        path.as_ref(),
        &["frame", "x", "y"],
        &["strength"],
        DETECTIONS_HEADER,
    )?;
    let mut rows = Vec::new();
    table.for_each_row(|row| {
        let strength = row.optional(3)?.unwrap_or(0.0) as f32;
        let position = Point2::new(row.finite(1)?, row.finite(2)?);
        rows.push((row.index(0)?, Detection::new(position, strength)));
        Ok(())
    })?;
    rows.sort_by_key(|(frame, _)| *frame);
    let mut frames: Vec<(FrameIndex, Vec<Detection>)> = Vec::new();
    for (frame, detection) in rows {
        match frames.last_mut() {
            Some((last, group)) if *last == frame => group.push(detection),
            _ => frames.push((frame, vec![detection])),
        }
    }
    Ok(frames)
}

//! Detection tables: CSV with the header `frame,x,y,class,score`, so a detector's output can
//! be saved once and fed to trackers (`--detections FILE`), and the detector-confidence
//! candidates of the MMPF+ paper's Eq. (1) in the same layout (`--candidates FILE`).
//!
//! On reading, `class` is optional (0 when absent) and the score may also be named
//! `strength` (the layout of sillage 0.1); frames are 0-based and need not be sorted.

use std::fmt::Write as _;
use std::path::Path;

use sillage_core::{Detection, FrameIndex, ObjectClass, Point2, Result};

use crate::WrittenSummary;
use crate::text_table::{CsvTable, RowWriter, push_f64};

/// The header of detection CSV files.
pub const DETECTIONS_HEADER: &str = "frame,x,y,class,score";

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
            let _ = write!(out, "{frame},");
            push_f64(out, d.pos_px.x);
            out.push(',');
            push_f64(out, d.pos_px.y);
            let _ = write!(out, ",{},{}", d.class, d.strength);
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
/// detection are absent; within a frame, rows keep the file's order). A missing `class` reads
/// as 0, a missing score as 0; a score that is not finite or a class that is not a small
/// non-negative integer is an error naming the line.
pub fn read_detections_csv(path: impl AsRef<Path>) -> Result<Vec<(FrameIndex, Vec<Detection>)>> {
    let table = CsvTable::open(
        path.as_ref(),
        &["frame", "x", "y"],
        &["class", "score", "strength"],
        DETECTIONS_HEADER,
    )?;
    let mut rows = Vec::new();
    table.for_each_row(|row| {
        let class = match row.optional(3)? {
            None => 0,
            Some(_) => ObjectClass::try_from(row.index(3)?).map_err(|_| {
                row.error("`class` is too large; classes are integers from 0 to 4294967295")
            })?,
        };
        let score = match row.optional(4)? {
            Some(score) => Some(score),
            None => row.optional(5)?,
        };
        if let Some(bad) = score.filter(|s| !s.is_finite()) {
            return Err(row.error(format!("`score` = {bad}; give a finite number")));
        }
        let position = Point2::new(row.finite(1)?, row.finite(2)?);
        let detection = Detection::of_class(position, score.unwrap_or(0.0) as f32, class);
        rows.push((row.index(0)?, detection));
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

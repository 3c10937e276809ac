//! Ground-truth tables: CSV with the header `frame,track_id,x,y,vx,vy` (`vx,vy` optional
//! when reading), written in streaming fashion for long synthetic sequences.

use std::fmt::Write as _;
use std::path::Path;

use sillage_core::{Point2, Result, TruthPoint, Vec2};

use crate::WrittenSummary;
use crate::text_table::{CsvTable, RowWriter, push_opt};

/// The header of truth CSV files.
pub const TRUTH_HEADER: &str = "frame,track_id,x,y,vx,vy";

/// Writes a truth CSV batch by batch into `.NAME.partial`, renamed on
/// [`TruthCsvWriter::finish`].
#[derive(Debug)]
pub struct TruthCsvWriter {
    rows: RowWriter,
}

impl TruthCsvWriter {
    /// Creates the writer and writes the header.
    pub fn create(path: impl AsRef<Path>) -> Result<Self> {
        Ok(Self {
            rows: RowWriter::create(path.as_ref(), &format!("{TRUTH_HEADER}\n"))?,
        })
    }

    /// Appends `points` (whole rows, one write).
    pub fn push(&mut self, points: &[TruthPoint]) -> Result<()> {
        self.rows.write_rows(points, |out, p| {
            // Writing to a String cannot fail.
            let _ = write!(
                out,
                "{},{},{},{},",
                p.frame, p.track_id, p.pos_px.x, p.pos_px.y
            );
            push_opt(out, p.vel_px_per_frame.map(|v| v.x));
            out.push(',');
            push_opt(out, p.vel_px_per_frame.map(|v| v.y));
            Ok(())
        })
    }

    /// Closes the file under its final name.
    pub fn finish(self) -> Result<WrittenSummary> {
        self.rows.finish()
    }
}

/// Writes `points` as a truth CSV at `path` in one go.
pub fn write_truth_csv(path: impl AsRef<Path>, points: &[TruthPoint]) -> Result<()> {
    let mut writer = TruthCsvWriter::create(path)?;
    writer.push(points)?;
    writer.finish().map(drop)
}

/// Reads a truth CSV (`frame,track_id,x,y[,vx,vy]`); a missing or non-finite `x`/`y` is an
/// error naming the line.
pub fn read_truth_csv(path: impl AsRef<Path>) -> Result<Vec<TruthPoint>> {
    let table = CsvTable::open(
        path.as_ref(),
        &["frame", "track_id", "x", "y"],
        &["vx", "vy"],
        TRUTH_HEADER,
    )?;
    let mut points = Vec::new();
    table.for_each_row(|row| {
        let velocity = match (row.optional(4)?, row.optional(5)?) {
            (Some(vx), Some(vy)) if vx.is_finite() && vy.is_finite() => Some(Vec2::new(vx, vy)),
            _ => None,
        };
        points.push(TruthPoint {
            frame: row.index(0)?,
            track_id: row.index(1)?,
            pos_px: Point2::new(row.finite(2)?, row.finite(3)?),
            vel_px_per_frame: velocity,
        });
        Ok(())
    })?;
    Ok(points)
}

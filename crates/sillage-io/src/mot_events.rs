//! The per-frame events of a multi-object tracking evaluation as CSV, for debugging a
//! tracker: which true object matched which estimate, where each identity switch happened,
//! what was missed and which estimates were false positives. Frames are 0-based, as in every
//! sillage table (a MOTChallenge frame is `frame + 1`).

use std::fmt::Write as _;
use std::path::Path;

use sillage_core::{FrameIndex, Result};

use crate::WrittenSummary;
use crate::text_table::{RowWriter, push_opt};

/// The header of event CSV files.
pub const MOT_EVENTS_HEADER: &str =
    "sequence,frame,truth_id,estimate_id,similarity,event,previous_estimate_id";

/// What happened to an object in a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotEventKind {
    /// A true object matched by the estimate it was last matched to (or its first match).
    Match,
    /// A true object matched by another estimate than the one it was last matched to.
    Switch,
    /// A true object left unmatched (false negative).
    Miss,
    /// An estimate left unmatched.
    FalsePositive,
}

impl MotEventKind {
    /// The name written in the `event` column.
    pub fn name(self) -> &'static str {
        match self {
            MotEventKind::Match => "match",
            MotEventKind::Switch => "switch",
            MotEventKind::Miss => "miss",
            MotEventKind::FalsePositive => "false_positive",
        }
    }
}

/// One row of an event CSV; absent fields are written empty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotEventRow<'a> {
    /// The sequence's name.
    pub sequence: &'a str,
    /// 0-based frame.
    pub frame: FrameIndex,
    /// The true object (none for a false positive).
    pub truth_id: Option<u64>,
    /// The estimate (none for a miss).
    pub estimate_id: Option<u64>,
    /// The pair's similarity (matches and switches).
    pub similarity: Option<f64>,
    /// What happened.
    pub kind: MotEventKind,
    /// For a switch, the estimate the true object was matched to before.
    pub previous_estimate_id: Option<u64>,
}

/// Writes an event CSV batch by batch into `.NAME.partial`, renamed on
/// [`MotEventsCsvWriter::finish`].
#[derive(Debug)]
pub struct MotEventsCsvWriter {
    rows: RowWriter,
}

impl MotEventsCsvWriter {
    /// Creates the writer and writes the header.
    pub fn create(path: impl AsRef<Path>) -> Result<Self> {
        Ok(Self {
            rows: RowWriter::create(path.as_ref(), &format!("{MOT_EVENTS_HEADER}\n"))?,
        })
    }

    /// Appends `rows` (whole rows, one write).
    pub fn push(&mut self, rows: &[MotEventRow<'_>]) -> Result<()> {
        self.rows.write_rows(rows, |out, row| {
            push_csv_text(out, row.sequence);
            // Writing to a String cannot fail.
            let _ = write!(out, ",{},", row.frame);
            push_opt_id(out, row.truth_id);
            out.push(',');
            push_opt_id(out, row.estimate_id);
            out.push(',');
            push_opt(out, row.similarity);
            let _ = write!(out, ",{},", row.kind.name());
            push_opt_id(out, row.previous_estimate_id);
            Ok(())
        })
    }

    /// Closes the file under its final name.
    pub fn finish(self) -> Result<WrittenSummary> {
        self.rows.finish()
    }
}

/// Appends an id, or nothing.
fn push_opt_id(out: &mut String, id: Option<u64>) {
    if let Some(id) = id {
        // Writing to a String cannot fail.
        let _ = write!(out, "{id}");
    }
}

/// Appends `text` as a CSV field, quoted (quotes doubled) when it holds a comma, a quote or
/// a line break.
fn push_csv_text(out: &mut String, text: &str) {
    if text.contains([',', '"', '\n', '\r']) {
        out.push('"');
        out.push_str(&text.replace('"', "\"\""));
        out.push('"');
    } else {
        out.push_str(text);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_written_with_empty_fields_and_quoted_names() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("events.csv");
        let mut writer = MotEventsCsvWriter::create(&path).unwrap();
        let row = MotEventRow {
            sequence: "seq,1",
            frame: 4,
            truth_id: Some(2),
            estimate_id: Some(9),
            similarity: Some(0.75),
            kind: MotEventKind::Switch,
            previous_estimate_id: Some(8),
        };
        let miss = MotEventRow {
            sequence: "b",
            estimate_id: None,
            similarity: None,
            kind: MotEventKind::Miss,
            previous_estimate_id: None,
            ..row
        };
        writer.push(&[row, miss]).unwrap();
        assert!(!path.exists(), "written under a temporary name first");
        writer.finish().unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text,
            format!("{MOT_EVENTS_HEADER}\n\"seq,1\",4,2,9,0.75,switch,8\nb,4,2,,,miss,\n")
        );
    }
}

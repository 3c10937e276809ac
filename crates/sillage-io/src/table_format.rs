//! Telling what a table file holds from its extension and first line, for the commands
//! that read any table (`eval mot`, `plot`, `overlay`).

use std::io::BufRead;
use std::path::Path;

use sillage_core::{Error, Result};

use crate::{BEAD_HEADER, TRACK_COLUMNS, TRUTH_HEADER, TrackFormat};

/// What a table file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableFormat {
    /// A track table of ours (TracTrac `_track.txt`, CSV with a `particle` column, Parquet,
    /// HDF5), read by [`read_track_table`](crate::read_track_table).
    Tracks(TrackFormat),
    /// BeadTracking's bead CSV (a `category` column), read by
    /// [`read_bead_csv`](crate::read_bead_csv).
    Beads,
    /// Point ground truth (a `track_id` column), read by
    /// [`read_truth_csv`](crate::read_truth_csv).
    Truth,
    /// MOTChallenge rows (`gt.txt`, `det.txt`, results: bare numbers), read by
    /// [`read_mot_rows`](crate::read_mot_rows).
    Mot,
}

/// The format of `path`: `.parquet` and `.h5`/`.hdf5` are track tables; a `.csv` is told by
/// the columns of its header (`category`, then `track_id`, then `particle`); any other file
/// is text, TracTrac's when its first line starts with `#` (its header), else MOTChallenge.
pub fn detect_table_format(path: &Path) -> Result<TableFormat> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("parquet" | "h5" | "hdf5") => Ok(TableFormat::Tracks(TrackFormat::from_path(path)?)),
        Some("csv") => {
            let header = first_line(path)?;
            let columns: Vec<String> = header
                .split(',')
                .map(|c| c.trim().to_ascii_lowercase())
                .collect();
            let has = |name: &str| columns.iter().any(|c| c == name);
            if has("category") {
                Ok(TableFormat::Beads)
            } else if has("track_id") {
                Ok(TableFormat::Truth)
            } else if has("particle") {
                Ok(TableFormat::Tracks(TrackFormat::Csv))
            } else {
                Err(Error::format(
                    path,
                    None,
                    format!(
                        "a CSV with the header `{header}` is none of the tables sillage reads: \
                         bead ground truth ({BEAD_HEADER}), truth ({TRUTH_HEADER}) or tracks \
                         ({})",
                        TRACK_COLUMNS.join(",")
                    ),
                ))
            }
        }
        _ if first_line(path)?.starts_with('#') => Ok(TableFormat::Tracks(TrackFormat::Tractrac)),
        _ => Ok(TableFormat::Mot),
    }
}

/// The first non-blank line of `path` (empty for an empty file), trimmed.
fn first_line(path: &Path) -> Result<String> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut reader = std::io::BufReader::new(file);
    let mut line = Vec::new();
    loop {
        line.clear();
        let read = reader
            .read_until(b'\n', &mut line)
            .map_err(|e| Error::io(path, e))?;
        let text = String::from_utf8_lossy(&line).trim().to_owned();
        if read == 0 || !text.is_empty() {
            return Ok(text);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The format detected for a file named `name` holding `text`.
    fn detect(name: &str, text: &str) -> Result<TableFormat> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        detect_table_format(&path)
    }

    #[test]
    fn extensions_and_first_lines_tell_the_format() {
        let tracks = TableFormat::Tracks;
        assert_eq!(
            detect("a.parquet", "").unwrap(),
            tracks(TrackFormat::Parquet)
        );
        assert_eq!(detect("a.H5", "").unwrap(), tracks(TrackFormat::Hdf5));
        assert_eq!(
            detect("a.csv", &format!("\n{BEAD_HEADER}\n")).unwrap(),
            TableFormat::Beads
        );
        assert_eq!(detect("a.csv", TRUTH_HEADER).unwrap(), TableFormat::Truth);
        assert_eq!(
            detect("a.csv", "Frame, Particle, x, y").unwrap(),
            tracks(TrackFormat::Csv)
        );
        assert_eq!(
            detect("a_track.txt", "# TracTrac\n1 2").unwrap(),
            tracks(TrackFormat::Tractrac)
        );
        assert_eq!(
            detect("gt.txt", "1,1,10,10,5,5,1,-1,-1,-1").unwrap(),
            TableFormat::Mot
        );
        assert_eq!(detect("results", "").unwrap(), TableFormat::Mot);
    }

    #[test]
    fn unknown_csv_headers_and_missing_files_are_named() {
        let message = detect("a.csv", "u,v").unwrap_err().to_string();
        assert!(
            message.contains("a.csv: a CSV with the header `u,v`"),
            "{message}"
        );
        let missing = detect_table_format(Path::new("no/such.txt")).unwrap_err();
        assert!(missing.to_string().contains("no/such.txt"), "{missing}");
    }
}

//! Small numeric matrices saved as CSV (one image row per line, values separated by commas),
//! such as BeadTracking's ring template exported from its `.mat` file.

use std::path::Path;

use sillage_core::{Error, GrayImage, Result};

/// Reads a CSV matrix of finite numbers as an image (rows are image rows); blank lines are
/// skipped. A ragged row, a value that is not a finite number or an empty file is an error
/// naming the line.
pub fn read_matrix_csv(path: impl AsRef<Path>) -> Result<GrayImage> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let mut values = Vec::new();
    let (mut width, mut height) = (0, 0);
    for (n, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let before = values.len();
        for field in line.split(',') {
            let value: f32 = field.trim().parse().map_err(|_| {
                Error::format(
                    path,
                    Some(n + 1),
                    format!("`{}` is not a number", field.trim()),
                )
            })?;
            if !value.is_finite() {
                return Err(Error::format(path, Some(n + 1), "values must be finite"));
            }
            values.push(value);
        }
        let row = values.len() - before;
        if height > 0 && row != width {
            return Err(Error::format(
                path,
                Some(n + 1),
                format!(
                    "this row has {row} values, the first has {width}; every row needs the same count"
                ),
            ));
        }
        width = row;
        height += 1;
    }
    if height == 0 {
        return Err(Error::format(
            path,
            None,
            "no values; a matrix CSV needs at least one row",
        ));
    }
    GrayImage::from_vec(width, height, values)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_rows_and_names_bad_lines() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.csv");
        std::fs::write(&path, "1, 2.5,-1\n\n0,0,3\n").unwrap();
        let m = read_matrix_csv(&path).unwrap();
        assert_eq!((m.width(), m.height()), (3, 2));
        assert_eq!((m.get(1, 0), m.get(2, 1)), (2.5, 3.0));
        for (body, expected) in [
            ("1,2\n3\n", ":2"),
            ("1,x\n", "`x`"),
            ("", "no values"),
            ("1,inf\n", "finite"),
        ] {
            std::fs::write(&path, body).unwrap();
            let e = read_matrix_csv(&path).unwrap_err().to_string();
            assert!(e.contains(expected), "{e}");
        }
    }
}

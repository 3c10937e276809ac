//! Small tables of numbers written whole (summary statistics such as Eulerian fields): CSV,
//! Parquet (feature `parquet`) and NumPy's `.npy` (a structured array, one named field per
//! column, which `numpy.load` and `pandas.DataFrame` read directly). Missing values are NaN
//! (empty in CSV, null in Parquet).

mod npy;
#[cfg(feature = "parquet")]
mod parquet;

use std::path::Path;

use sillage_core::{Error, Result};

use crate::partial::PartialFile;
use crate::text_table::push_f64;

/// The values of one column.
#[derive(Debug, Clone, PartialEq)]
pub enum ColumnValues {
    /// Integers (indices, counts).
    Int(Vec<i64>),
    /// Floats; NaN is a missing value.
    Float(Vec<f64>),
}

impl ColumnValues {
    fn len(&self) -> usize {
        match self {
            Self::Int(values) => values.len(),
            Self::Float(values) => values.len(),
        }
    }
}

/// A table of named numeric columns of one length.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NumericTable {
    columns: Vec<(String, ColumnValues)>,
}

impl NumericTable {
    /// Adds a column; every column must have the length of the first.
    pub fn push(&mut self, name: impl Into<String>, values: ColumnValues) -> Result<()> {
        let name = name.into();
        if let Some((first, other)) = self.columns.first()
            && other.len() != values.len()
        {
            return Err(Error::input(format!(
                "column `{name}` has {} values but `{first}` has {}",
                values.len(),
                other.len()
            )));
        }
        self.columns.push((name, values));
        Ok(())
    }

    /// The columns, in order.
    pub fn columns(&self) -> &[(String, ColumnValues)] {
        &self.columns
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |(_, values)| values.len())
    }
}

/// The formats a [`NumericTable`] is written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NumericFormat {
    /// Comma-separated text with a header line; NaN written as an empty field.
    Csv,
    /// Apache Parquet, Int64/Float64 columns (NaN as null), zstd-compressed.
    Parquet,
    /// NumPy `.npy` version 1.0, a structured array of `<i8`/`<f8` fields.
    Npy,
}

impl NumericFormat {
    /// The format named by the extension of `path`: `.csv`, `.parquet` or `.npy`.
    pub fn from_path(path: &Path) -> Result<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("csv") => Ok(Self::Csv),
            Some("parquet") => Ok(Self::Parquet),
            Some("npy") => Ok(Self::Npy),
            _ => Err(Error::input(format!(
                "{}: cannot tell the table format from the extension; use .csv, .parquet or \
                 .npy",
                path.display()
            ))),
        }
    }
}

/// Writes `table` to `path` in the format of its extension, through a `.NAME.partial` file
/// renamed at the end.
pub fn write_numeric_table(path: &Path, table: &NumericTable) -> Result<()> {
    let format = NumericFormat::from_path(path)?;
    let mut file = PartialFile::create(path)?;
    let written = match format {
        NumericFormat::Csv => file.write_all(csv_text(table).as_bytes()),
        NumericFormat::Npy => file.write_all(&npy::encode(table)),
        #[cfg(feature = "parquet")]
        NumericFormat::Parquet => parquet::write(&mut file, table),
        #[cfg(not(feature = "parquet"))]
        NumericFormat::Parquet => Err(Error::input(
            "this build of sillage has no parquet support; rebuild with `--features parquet` \
             or write .csv or .npy",
        )),
    };
    match written {
        Ok(()) => file.commit().map(drop),
        Err(e) => {
            file.abandon();
            Err(e)
        }
    }
}

fn csv_text(table: &NumericTable) -> String {
    let mut out = String::new();
    let names: Vec<&str> = table.columns.iter().map(|(n, _)| n.as_str()).collect();
    out.push_str(&names.join(","));
    out.push('\n');
    for row in 0..table.rows() {
        for (k, (_, values)) in table.columns.iter().enumerate() {
            if k > 0 {
                out.push(',');
            }
            match values {
                ColumnValues::Int(v) => out.push_str(&v[row].to_string()),
                ColumnValues::Float(v) if v[row].is_nan() => {}
                ColumnValues::Float(v) => push_f64(&mut out, v[row]),
            }
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> NumericTable {
        let mut table = NumericTable::default();
        table.push("i", ColumnValues::Int(vec![0, -3])).unwrap();
        table
            .push("u", ColumnValues::Float(vec![1.5, f64::NAN]))
            .unwrap();
        table
    }

    #[test]
    fn csv_leaves_nan_empty() {
        assert_eq!(csv_text(&table()), "i,u\n0,1.5\n-3,\n");
    }

    #[test]
    fn columns_of_different_lengths_are_refused() {
        let mut table = table();
        let error = table
            .push("v", ColumnValues::Float(vec![1.0]))
            .unwrap_err()
            .to_string();
        assert!(error.contains("`v` has 1 values but `i` has 2"), "{error}");
    }

    #[test]
    fn unknown_extensions_are_named() {
        let error = NumericFormat::from_path(Path::new("stats.xlsx"))
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("stats.xlsx") && error.contains(".npy"),
            "{error}"
        );
    }
}

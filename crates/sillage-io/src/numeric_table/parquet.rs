//! A [`NumericTable`] as one Parquet row group: Int64 and Float64 columns, NaN as null.

use std::sync::Arc;

use arrow_array::{ArrayRef, Float64Array, Int64Array, RecordBatch};
use arrow_schema::{DataType, Field, Schema};
use parquet::arrow::ArrowWriter;
use parquet::basic::{Compression, ZstdLevel};
use parquet::file::properties::WriterProperties;
use sillage_core::{Error, Result};

use super::{ColumnValues, NumericTable};
use crate::partial::PartialFile;

/// Writes `table` into `file`.
pub(super) fn write(file: &mut PartialFile, table: &NumericTable) -> Result<()> {
    let path = file.partial_path().to_path_buf();
    let error = |e: &dyn std::fmt::Display| {
        Error::format(&path, None, format!("cannot write Parquet: {e}"))
    };
    let mut fields = Vec::new();
    let mut arrays: Vec<ArrayRef> = Vec::new();
    for (name, values) in table.columns() {
        match values {
            ColumnValues::Int(v) => {
                fields.push(Field::new(name, DataType::Int64, false));
                arrays.push(Arc::new(Int64Array::from(v.clone())));
            }
            ColumnValues::Float(v) => {
                fields.push(Field::new(name, DataType::Float64, true));
                let nullable: Float64Array =
                    v.iter().map(|x| (!x.is_nan()).then_some(*x)).collect();
                arrays.push(Arc::new(nullable));
            }
        }
    }
    let schema = Arc::new(Schema::new(fields));
    let batch = RecordBatch::try_new(schema.clone(), arrays).map_err(|e| error(&e))?;
    let properties = WriterProperties::builder()
        .set_compression(Compression::ZSTD(ZstdLevel::default()))
        .build();
    let mut writer = ArrowWriter::try_new(file, schema, Some(properties)).map_err(|e| error(&e))?;
    writer.write(&batch).map_err(|e| error(&e))?;
    writer.close().map_err(|e| error(&e))?;
    Ok(())
}

//! Parquet track tables: the CSV's column names, `frame`/`particle` as Int64, the other
//! columns Float64 (nullable for the kinematics); with the state layout also `class` UInt32,
//! `motion_state` Utf8 (the state's name) and `spread_px` Float64 (nullable). zstd-compressed,
//! one row group per [`ROW_GROUP_ROWS`] rows so memory stays bounded. Readable by
//! pandas/pyarrow directly.

use std::fs::File;
use std::path::Path;
use std::sync::Arc;

use arrow_array::types::{Float64Type, Int64Type, UInt32Type};
use arrow_array::{
    Array, ArrayRef, Float64Array, Int64Array, RecordBatch, StringArray, UInt32Array, cast::AsArray,
};
use arrow_schema::{DataType, Field, Schema, SchemaRef};
use parquet::arrow::ArrowWriter;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use parquet::basic::{Compression, ZstdLevel};
use parquet::file::metadata::{KeyValue, ParquetMetaData};
use parquet::file::properties::WriterProperties;
use sillage_core::{Error, MotionState, Result, TrackPoint, TrackSink};

use super::column_buffer::TrackColumns;
use super::columns::{STATE_COLUMNS, TRACK_COLUMNS, TrackLayout};
use super::{TrackFileHeader, TrackWriter, WrittenSummary};
use crate::partial::PartialFile;

/// Rows buffered before a row group is written.
const ROW_GROUP_ROWS: usize = 65_536;

fn schema(layout: TrackLayout) -> SchemaRef {
    let fields: Vec<Field> = layout
        .columns()
        .into_iter()
        .enumerate()
        .map(|(i, name)| match i {
            0 | 1 => Field::new(name, DataType::Int64, false),
            2 | 3 => Field::new(name, DataType::Float64, false),
            11 => Field::new(name, DataType::UInt32, false),
            12 => Field::new(name, DataType::Utf8, false),
            _ => Field::new(name, DataType::Float64, true),
        })
        .collect();
    Arc::new(Schema::new(fields))
}

fn parquet_error(path: &Path, action: &str, error: impl std::fmt::Display) -> Error {
    Error::format(path, None, format!("cannot {action} Parquet: {error}"))
}

/// Runs a step of the `parquet` decoder on the file at `path`, turning its errors and its
/// panics into an error naming the file. `parquet` 60 asserts on some damaged files instead
/// of returning an error (found by the `parquet_tracks` fuzz target: definition levels
/// shorter than a page's values, a dictionary page missing); a user's damaged file must not
/// crash the program.
fn without_panics<T>(path: &Path, step: impl FnOnce() -> Result<T>) -> Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(step)).unwrap_or_else(|_| {
        Err(Error::format(
            path,
            None,
            "cannot read Parquet: the file is damaged (its pages do not decode); write it again",
        ))
    })
}

/// Refuses a footer whose column chunks start or span a negative number of bytes (`parquet`
/// asserts on them when it reads the pages).
fn check_column_chunks(path: &Path, metadata: &ParquetMetaData) -> Result<()> {
    for (g, group) in metadata.row_groups().iter().enumerate() {
        for column in group.columns() {
            let start = column
                .dictionary_page_offset()
                .unwrap_or(column.data_page_offset());
            if start < 0 || column.compressed_size() < 0 {
                return Err(Error::format(
                    path,
                    None,
                    format!(
                        "cannot read Parquet: row group {g}, column `{}` starts at byte {start} \
                         and spans {} bytes; the file is damaged, write it again",
                        column.column_path(),
                        column.compressed_size()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Streams track points into a Parquet file.
pub(crate) struct ParquetTrackWriter {
    writer: ArrowWriter<PartialFile>,
    schema: SchemaRef,
    layout: TrackLayout,
    buffer: TrackColumns,
    rows: u64,
    partial: std::path::PathBuf,
}

impl std::fmt::Debug for ParquetTrackWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ParquetTrackWriter")
            .field("partial", &self.partial)
            .field("rows", &self.rows)
            .finish_non_exhaustive()
    }
}

impl ParquetTrackWriter {
    /// Creates `.NAME.partial` beside `path`; `header` goes into the key-value metadata
    /// (`program_version`, `param:KEY`).
    pub(crate) fn create(path: &Path, header: &TrackFileHeader) -> Result<Self> {
        let file = PartialFile::create(path)?;
        let partial = file.partial_path().to_path_buf();
        let mut metadata = vec![KeyValue::new(
            "program_version".into(),
            header.program_version.clone(),
        )];
        metadata.extend(
            header
                .parameters
                .iter()
                .map(|(k, v)| KeyValue::new(format!("param:{k}"), v.clone())),
        );
        let properties = WriterProperties::builder()
            .set_compression(Compression::ZSTD(ZstdLevel::default()))
            .set_max_row_group_row_count(Some(ROW_GROUP_ROWS))
            .set_key_value_metadata(Some(metadata))
            .build();
        let schema = schema(header.layout);
        let writer = ArrowWriter::try_new(file, schema.clone(), Some(properties))
            .map_err(|e| parquet_error(&partial, "start", e))?;
        Ok(Self {
            writer,
            schema,
            layout: header.layout,
            buffer: TrackColumns::default(),
            rows: 0,
            partial,
        })
    }

    fn flush_buffer(&mut self) -> Result<()> {
        if self.buffer.len() == 0 {
            return Ok(());
        }
        let b = &self.buffer;
        let mut arrays: Vec<ArrayRef> = vec![
            Arc::new(Int64Array::from(b.frame.clone())),
            Arc::new(Int64Array::from(b.particle.clone())),
            Arc::new(Float64Array::from(b.x.clone())),
            Arc::new(Float64Array::from(b.y.clone())),
        ];
        arrays.extend(
            b.kinematics
                .iter()
                .map(|c| Arc::new(Float64Array::from(c.clone())) as ArrayRef),
        );
        if self.layout == TrackLayout::WithStates {
            let names = b.motion_state.iter().map(|s| s.name());
            arrays.extend([
                Arc::new(UInt32Array::from(b.class.clone())) as ArrayRef,
                Arc::new(StringArray::from_iter_values(names)),
                Arc::new(Float64Array::from(b.spread_px.clone())),
            ]);
        }
        let batch = RecordBatch::try_new(self.schema.clone(), arrays)
            .map_err(|e| parquet_error(&self.partial, "assemble", e))?;
        self.writer
            .write(&batch)
            .map_err(|e| parquet_error(&self.partial, "write", e))?;
        self.rows += self.buffer.len() as u64;
        self.buffer.clear();
        Ok(())
    }
}

impl TrackSink for ParquetTrackWriter {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        for point in points {
            self.buffer.push(point)?;
            if self.buffer.len() >= ROW_GROUP_ROWS {
                self.flush_buffer()?;
            }
        }
        Ok(())
    }
}

impl TrackWriter for ParquetTrackWriter {
    fn finish(mut self: Box<Self>) -> Result<WrittenSummary> {
        self.flush_buffer()?;
        let Self {
            writer,
            rows,
            partial,
            ..
        } = *self;
        let file = writer
            .into_inner()
            .map_err(|e| parquet_error(&partial, "finish", e))?;
        let path = file.commit()?;
        Ok(WrittenSummary { rows, path })
    }
}

/// Reads a Parquet track table. `frame`, `particle`, `x`, `y` are required; integer and
/// float columns of other widths are converted. The layout is [`TrackLayout::WithStates`]
/// when the table has a `motion_state` column.
pub(crate) fn read_parquet(
    path: &Path,
    each: &mut dyn FnMut(TrackPoint) -> Result<()>,
) -> Result<TrackLayout> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let read_error = |e: &dyn std::fmt::Display| parquet_error(path, "read", e);
    let mut reader = without_panics(path, || {
        let builder = ParquetRecordBatchReaderBuilder::try_new(file).map_err(|e| read_error(&e))?;
        check_column_chunks(path, builder.metadata())?;
        builder.build().map_err(|e| read_error(&e))
    })?;
    let mut rows_read = 0;
    let mut layout = TrackLayout::Kinematics;
    let mut columns = TrackColumns::default();
    while let Some(batch) = without_panics(path, || {
        reader.next().transpose().map_err(|e| read_error(&e))
    })? {
        columns.clear();
        let column = |name: &str, ty: &DataType| -> Result<Option<ArrayRef>> {
            batch
                .column_by_name(name)
                .map(|c| arrow_cast::cast(c, ty))
                .transpose()
                .map_err(|e| {
                    Error::format(
                        path,
                        None,
                        format!("column `{name}` cannot be read as {ty}: {e}"),
                    )
                })
        };
        let required = |name: &str, ty: &DataType| -> Result<ArrayRef> {
            column(name, ty)?.ok_or_else(|| {
                Error::format(
                    path,
                    None,
                    format!(
                        "missing column `{name}`; expected columns {}",
                        TRACK_COLUMNS.join(",")
                    ),
                )
            })
        };
        let ints = |name: &str| -> Result<Vec<i64>> {
            let array = required(name, &DataType::Int64)?;
            no_nulls(path, name, &array)?;
            Ok(array.as_primitive::<Int64Type>().values().to_vec())
        };
        let floats = |name: &str| -> Result<Vec<f64>> {
            let array = required(name, &DataType::Float64)?;
            no_nulls(path, name, &array)?;
            Ok(array.as_primitive::<Float64Type>().values().to_vec())
        };
        columns.frame = ints(TRACK_COLUMNS[0])?;
        columns.particle = ints(TRACK_COLUMNS[1])?;
        columns.x = floats(TRACK_COLUMNS[2])?;
        columns.y = floats(TRACK_COLUMNS[3])?;
        for (slot, name) in columns.kinematics.iter_mut().zip(&TRACK_COLUMNS[4..]) {
            *slot = match column(name, &DataType::Float64)? {
                Some(array) => array.as_primitive::<Float64Type>().iter().collect(),
                None => vec![None; batch.num_rows()],
            };
        }
        columns.default_states();
        let [class, motion_state, spread] = STATE_COLUMNS;
        if let Some(array) = column(class, &DataType::UInt32)? {
            // A negative or too large class casts to null.
            no_nulls(path, class, &array)?;
            columns.class = array.as_primitive::<UInt32Type>().values().to_vec();
        }
        if let Some(array) = column(motion_state, &DataType::Utf8)? {
            layout = TrackLayout::WithStates;
            let first_row = rows_read + 1;
            for (i, name) in array.as_string::<i32>().iter().enumerate() {
                columns.motion_state[i] = match name {
                    None => MotionState::Unknown,
                    Some(name) => MotionState::from_name(name).ok_or_else(|| {
                        Error::format(
                            path,
                            None,
                            format!(
                                "row {}: `motion_state` = `{name}`; it is resting, rolling, \
                                 saltating or unknown",
                                first_row + i
                            ),
                        )
                    })?,
                };
            }
        }
        if let Some(array) = column(spread, &DataType::Float64)? {
            columns.spread_px = array.as_primitive::<Float64Type>().iter().collect();
        }
        for point in columns.to_points(path, rows_read + 1)? {
            each(point)?;
        }
        rows_read += batch.num_rows();
    }
    Ok(layout)
}

fn no_nulls(path: &Path, name: &str, array: &ArrayRef) -> Result<()> {
    if array.null_count() == 0 {
        Ok(())
    } else {
        Err(Error::format(
            path,
            None,
            format!(
                "column `{name}` has {} missing or out-of-range values; it is required in \
                 every row",
                array.null_count()
            ),
        ))
    }
}

//! HDF5 track tables (feature `hdf5`, needs the system HDF5 library, Debian `libhdf5-dev`):
//! one 1-D dataset per column of [`TRACK_COLUMNS`], `frame` and `particle` as i64 (no uint16
//! wrap as in TracTrac's HDF5), the others f64 with NaN for missing values; chunked,
//! deflate-compressed and extended [`CHUNK_ROWS`] rows at a time so memory stays bounded.
//! The state layout adds `class` (u32), `motion_state` (u8, BeadTracking's codes, listed in
//! the dataset's `codes` attribute) and `spread_px` (f64, NaN when unknown).
//! File attributes: `program_version` and `param:KEY` for each parameter.

use std::path::{Path, PathBuf};
use std::str::FromStr;

use hdf5::types::VarLenUnicode;
use sillage_core::{Error, MotionState, Result, TrackPoint, TrackSink};

use super::column_buffer::TrackColumns;
use super::columns::{STATE_COLUMNS, TRACK_COLUMNS, TrackLayout};
use super::{TrackFileHeader, TrackWriter, WrittenSummary};
use crate::partial::{partial_path, writes_in_place};

/// Rows buffered before the datasets are extended.
const CHUNK_ROWS: usize = 65_536;

/// The `codes` attribute of the `motion_state` dataset.
const MOTION_STATE_CODES: &str = "0 resting, 1 rolling, 2 saltating, 3 unknown (BeadTracking)";

fn hdf5_error(path: &Path, action: &str, error: impl std::fmt::Display) -> Error {
    Error::format(path, None, format!("cannot {action} HDF5: {error}"))
}

/// Streams track points into an HDF5 file.
pub(crate) struct Hdf5TrackWriter {
    file: hdf5::File,
    datasets: Vec<hdf5::Dataset>,
    buffer: TrackColumns,
    rows: usize,
    partial: PathBuf,
    path: PathBuf,
}

impl std::fmt::Debug for Hdf5TrackWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Hdf5TrackWriter")
            .field("partial", &self.partial)
            .field("rows", &self.rows)
            .finish_non_exhaustive()
    }
}

impl Hdf5TrackWriter {
    /// Creates `.NAME.partial` beside `path` with empty resizable datasets and the header
    /// attributes.
    pub(crate) fn create(path: &Path, header: &TrackFileHeader) -> Result<Self> {
        if writes_in_place(path) {
            return Err(Error::input(format!(
                "{}: an HDF5 file needs a regular file path (not a device or a pipe); give \
                 e.g. `tracks.h5`",
                path.display()
            )));
        }
        let partial = partial_path(path)?;
        let error = |action: &str, e: hdf5::Error| hdf5_error(&partial, action, e);
        let file = hdf5::File::create(&partial).map_err(|e| error("create", e))?;
        let mut datasets = Vec::new();
        for (i, name) in header.layout.columns().into_iter().enumerate() {
            let builder = match i {
                0 | 1 => file.new_dataset::<i64>(),
                11 => file.new_dataset::<u32>(),
                12 => file.new_dataset::<u8>(),
                _ => file.new_dataset::<f64>(),
            };
            let dataset = builder
                .chunk(CHUNK_ROWS)
                .deflate(4)
                .shape(0..)
                .create(name)
                .map_err(|e| error("create a dataset in", e))?;
            datasets.push(dataset);
        }
        if let Some(states) = datasets.get(12) {
            write_text_attribute(states, "codes", MOTION_STATE_CODES)
                .map_err(|e| error("write an attribute to", e))?;
        }
        let mut attributes = vec![(
            "program_version".to_string(),
            header.program_version.clone(),
        )];
        attributes.extend(
            header
                .parameters
                .iter()
                .map(|(k, v)| (format!("param:{k}"), v.clone())),
        );
        for (name, value) in attributes {
            write_text_attribute(&file, &name, &value)
                .map_err(|e| error("write an attribute to", e))?;
        }
        Ok(Self {
            file,
            datasets,
            buffer: TrackColumns::default(),
            rows: 0,
            partial,
            path: path.to_path_buf(),
        })
    }

    fn flush_buffer(&mut self) -> Result<()> {
        let n = self.buffer.len();
        if n == 0 {
            return Ok(());
        }
        let (start, end) = (self.rows, self.rows + n);
        let error = |e: hdf5::Error| hdf5_error(&self.partial, "write", e);
        for dataset in &self.datasets {
            dataset.resize(end).map_err(error)?;
        }
        let b = &self.buffer;
        self.datasets[0]
            .write_slice(&b.frame[..], start..end)
            .map_err(error)?;
        self.datasets[1]
            .write_slice(&b.particle[..], start..end)
            .map_err(error)?;
        self.datasets[2]
            .write_slice(&b.x[..], start..end)
            .map_err(error)?;
        self.datasets[3]
            .write_slice(&b.y[..], start..end)
            .map_err(error)?;
        let nan_for_none = |column: &[Option<f64>]| -> Vec<f64> {
            column.iter().map(|v| v.unwrap_or(f64::NAN)).collect()
        };
        for (dataset, column) in self.datasets[4..11].iter().zip(&b.kinematics) {
            dataset
                .write_slice(&nan_for_none(column)[..], start..end)
                .map_err(error)?;
        }
        if let [class, states, spread] = &self.datasets[11..] {
            class.write_slice(&b.class[..], start..end).map_err(error)?;
            let codes: Vec<u8> = b
                .motion_state
                .iter()
                .map(|s| s.bead_tracking_code())
                .collect();
            states.write_slice(&codes[..], start..end).map_err(error)?;
            spread
                .write_slice(&nan_for_none(&b.spread_px)[..], start..end)
                .map_err(error)?;
        }
        self.rows = end;
        self.buffer.clear();
        Ok(())
    }
}

impl TrackSink for Hdf5TrackWriter {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        for point in points {
            self.buffer.push(point)?;
            if self.buffer.len() >= CHUNK_ROWS {
                self.flush_buffer()?;
            }
        }
        Ok(())
    }
}

impl TrackWriter for Hdf5TrackWriter {
    fn finish(mut self: Box<Self>) -> Result<WrittenSummary> {
        self.flush_buffer()?;
        let Self {
            file,
            datasets,
            rows,
            partial,
            path,
            ..
        } = *self;
        drop(datasets);
        file.close().map_err(|e| hdf5_error(&partial, "close", e))?;
        std::fs::rename(&partial, &path).map_err(|e| Error::io(&path, e))?;
        Ok(WrittenSummary {
            rows: rows as u64,
            path,
        })
    }
}

/// Writes the text attribute `name` = `value` on `location` (the file or a dataset).
fn write_text_attribute(location: &hdf5::Location, name: &str, value: &str) -> hdf5::Result<()> {
    let text = VarLenUnicode::from_str(value).map_err(|e| hdf5::Error::from(e.to_string()))?;
    location
        .new_attr::<VarLenUnicode>()
        .create(name)
        .and_then(|a| a.write_scalar(&text))
}

/// Reads an HDF5 track table written by [`Hdf5TrackWriter`] (datasets named as
/// [`TRACK_COLUMNS`] and [`STATE_COLUMNS`]; all but frame, particle, x and y optional). The
/// layout is [`TrackLayout::WithStates`] when the file has a `motion_state` dataset.
pub(crate) fn read_hdf5(
    path: &Path,
    each: &mut dyn FnMut(TrackPoint) -> Result<()>,
) -> Result<TrackLayout> {
    std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    let file = hdf5::File::open(path).map_err(|e| hdf5_error(path, "open", e))?;
    let read = |name: &str| -> Result<Option<Vec<f64>>> {
        if !file.link_exists(name) {
            return Ok(None);
        }
        file.dataset(name)
            .and_then(|d| d.read_raw::<f64>())
            .map(Some)
            .map_err(|e| hdf5_error(path, &format!("read dataset `{name}` of"), e))
    };
    let required_ints = |name: &str| -> Result<Vec<i64>> {
        file.dataset(name)
            .and_then(|d| d.read_raw::<i64>())
            .map_err(|e| {
                Error::format(
                    path,
                    None,
                    format!(
                        "cannot read dataset `{name}` ({e}); expected datasets {}",
                        TRACK_COLUMNS.join(",")
                    ),
                )
            })
    };
    let required_floats = |name: &str| -> Result<Vec<f64>> {
        read(name)?.ok_or_else(|| {
            Error::format(
                path,
                None,
                format!(
                    "missing dataset `{name}`; expected datasets {}",
                    TRACK_COLUMNS.join(",")
                ),
            )
        })
    };
    let mut columns = TrackColumns {
        frame: required_ints(TRACK_COLUMNS[0])?,
        particle: required_ints(TRACK_COLUMNS[1])?,
        x: required_floats(TRACK_COLUMNS[2])?,
        y: required_floats(TRACK_COLUMNS[3])?,
        ..TrackColumns::default()
    };
    let n = columns.frame.len();
    if [columns.particle.len(), columns.x.len(), columns.y.len()] != [n; 3] {
        return Err(Error::format(
            path,
            None,
            "datasets frame, particle, x and y have different lengths; the file is damaged",
        ));
    }
    let same_length = |name: &str, len: usize| {
        if len == n {
            Ok(())
        } else {
            Err(Error::format(
                path,
                None,
                format!("dataset `{name}` does not have {n} rows like `frame`"),
            ))
        }
    };
    let optional = |name: &str| -> Result<Vec<Option<f64>>> {
        match read(name)? {
            Some(values) => {
                same_length(name, values.len())?;
                Ok(values.into_iter().map(Some).collect())
            }
            None => Ok(vec![None; n]),
        }
    };
    for (slot, name) in columns.kinematics.iter_mut().zip(&TRACK_COLUMNS[4..]) {
        *slot = optional(name)?;
    }
    columns.default_states();
    let [class, motion_state, spread] = STATE_COLUMNS;
    let read_codes = |name: &str| {
        file.dataset(name)
            .and_then(|d| d.read_raw::<u32>())
            .map_err(|e| hdf5_error(path, &format!("read dataset `{name}` of"), e))
    };
    if file.link_exists(class) {
        columns.class = read_codes(class)?;
        same_length(class, columns.class.len())?;
    }
    let mut layout = TrackLayout::Kinematics;
    if file.link_exists(motion_state) {
        layout = TrackLayout::WithStates;
        let codes = read_codes(motion_state)?;
        same_length(motion_state, codes.len())?;
        for (row, (slot, code)) in columns.motion_state.iter_mut().zip(codes).enumerate() {
            *slot = MotionState::from_bead_tracking_code(f64::from(code)).ok_or_else(|| {
                Error::format(
                    path,
                    None,
                    format!(
                        "row {}: `{motion_state}` = {code}; {MOTION_STATE_CODES}",
                        row + 1
                    ),
                )
            })?;
        }
    }
    columns.spread_px = optional(spread)?;
    for point in columns.to_points(path, 1)? {
        each(point)?;
    }
    Ok(layout)
}

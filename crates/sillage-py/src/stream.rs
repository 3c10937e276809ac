//! Streaming PTV: one frame in, the points that became final out (Python's `ptv_iter`), so a
//! long sequence is tracked in bounded memory.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sillage::core::TrackPoint;
use sillage::io::{Frame, FrameOptions, FrameSource, open_frames};
use sillage::{FrameInput, Pipeline};

use crate::errors::to_py;
use crate::frames::{FrameArrays, frames_of};
use crate::{config_of, track_columns};

/// A PTV run fed one frame at a time: from a path it opened, or from arrays given to `step`.
#[pyclass(module = "sillage._sillage")]
pub struct PtvStream {
    pipeline: Pipeline,
    source: Option<FrameSource>,
    next_index: u64,
    shape: Option<(usize, usize)>,
}

#[pymethods]
impl PtvStream {
    /// A run with `overrides` (`key=value`), reading frames from `path` when given.
    #[new]
    #[pyo3(signature = (overrides, path=None))]
    fn new(py: Python<'_>, overrides: Vec<String>, path: Option<String>) -> PyResult<Self> {
        let config = config_of(&overrides)?;
        let pipeline = Pipeline::from_config(&config).map_err(to_py)?;
        let source = path
            .map(|path| py.detach(|| open_frames(&path, &FrameOptions::default())))
            .transpose()
            .map_err(to_py)?;
        Ok(Self {
            pipeline,
            source,
            next_index: 0,
            shape: None,
        })
    }

    /// Tracks the next frame (`frame`, a 2-D array, or the next one of the path) and returns
    /// the columns of the points that became final; `None` when the path has no more frames.
    #[pyo3(signature = (frame=None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        frame: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Option<Bound<'py, PyDict>>> {
        let image = match (frame, &mut self.source) {
            (None, Some(source)) => match py.detach(|| source.next()) {
                None => return Ok(None),
                Some(frame) => frame.map_err(to_py)?,
            },
            (Some(array), None) => self.frame_of(py, array)?,
            _ => {
                return Err(PyValueError::new_err(
                    "give a frame to step() when the stream has no path, and none when it has",
                ));
            }
        };
        let pipeline = &mut self.pipeline;
        let points = py.detach(|| {
            let mut points: Vec<TrackPoint> = Vec::new();
            pipeline
                .step(&FrameInput::Image(image), &mut points)
                .map(|_| points)
        });
        track_columns(py, &points.map_err(to_py)?).map(Some)
    }

    /// Ends the run: the columns of the points the tracker still held.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let mut points: Vec<TrackPoint> = Vec::new();
        self.pipeline.finish(&mut points).map_err(to_py)?;
        track_columns(py, &points)
    }
}

impl PtvStream {
    /// The sillage frame of one 2-D array, numbered after the previous ones; its shape must
    /// be the first frame's.
    fn frame_of(&mut self, py: Python<'_>, array: &Bound<'_, PyAny>) -> PyResult<Frame> {
        let arrays = FrameArrays::borrow(array)?;
        let views = arrays.views()?;
        let [pixels] = views.as_slice() else {
            return Err(PyValueError::new_err(format!(
                "step() takes one 2-D frame; got {} frames",
                views.len()
            )));
        };
        let shape = pixels.shape();
        if let Some(first) = self.shape.filter(|&first| first != shape) {
            return Err(PyValueError::new_err(format!(
                "frame {} is {shape:?} but the first frame is {first:?}; frames must all have \
                 the same shape",
                self.next_index
            )));
        }
        self.shape = Some(shape);
        let mut frame = py
            .detach(|| frames_of(&views).next().expect("one view"))
            .map_err(to_py)?;
        frame.index = self.next_index;
        self.next_index += 1;
        Ok(frame)
    }
}

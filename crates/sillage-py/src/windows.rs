//! Time windows from Python (`sillage.dask`, `sillage.track(..., window=W)`): the plan, one
//! window tracked on a worker (its tracks handed back as bytes), the stitcher that joins them
//! in order, and the local runner of `sillage ptv --window`.

use std::collections::HashMap;
use std::path::PathBuf;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use sillage::Tracking;
use sillage::core::TrackPoint;
use sillage::track::stitch::{Stitcher as WindowStitcher, WindowTracks};
use sillage::windows::{
    Measured, Window, WindowPlan, WindowedRun, decode_window, encode_window, min_window,
    on_threads, stitch_params, track_window as track_one_window,
    track_window_frames as track_array_window,
};

use crate::errors::to_py;
use crate::frames::{FrameArrays, frames_of};
use crate::hooks::Between;
use crate::sources::{SceneFiles, all_track_columns, tracking};

/// A tracking from Python's arguments: the tracker's name, its overrides, the seed and the
/// files it reads.
fn tracking_of(
    tracker: &str,
    overrides: &[String],
    seed: u64,
    files: HashMap<String, PathBuf>,
) -> PyResult<Tracking> {
    tracking(tracker, overrides, seed, &SceneFiles::from_dict(files)?)
}

/// The number of frames of `source` (a folder, glob, TIFF stack or video); `ValueError` when
/// a video does not record it.
#[pyfunction]
pub fn frame_count(source: String) -> PyResult<u64> {
    sillage::windows::frame_count(&source).map_err(to_py)
}

/// The windows `(index, first, last)` of `frames` frames cut into windows of `window` frames
/// overlapping by `overlap`, for `tracker` (validated with its configuration, so that bad
/// parameters raise before any worker starts).
#[pyfunction]
#[pyo3(signature = (frames, window, overlap, tracker, overrides, seed, files))]
pub fn plan_windows(
    frames: u64,
    window: usize,
    overlap: usize,
    tracker: &str,
    overrides: Vec<String>,
    seed: u64,
    files: HashMap<String, PathBuf>,
) -> PyResult<Vec<(usize, u64, u64)>> {
    let tracking = tracking_of(tracker, &overrides, seed, files)?;
    let plan = WindowPlan::new(frames, window, overlap, min_window(&tracking)).map_err(to_py)?;
    Ok(plan
        .windows()
        .iter()
        .map(|w| (w.index, w.first, w.last))
        .collect())
}

/// What a run decides on the first frames of `source` (a path, or frames as for `ptv`) and
/// every window adopts, as JSON: measured once by the planner, for [`track_window`]'s
/// `measured`.
#[pyfunction]
#[pyo3(signature = (source, tracker, overrides, seed, files))]
pub fn measure_first_frames(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    tracker: &str,
    overrides: Vec<String>,
    seed: u64,
    files: HashMap<String, PathBuf>,
) -> PyResult<String> {
    let tracking = tracking_of(tracker, &overrides, seed, files)?;
    let measured = if let Ok(path) = source.extract::<String>() {
        py.detach(|| Measured::on_source(&path, &tracking))
    } else {
        let Tracking::Pipeline(config) = &tracking else {
            return to_json(&Measured::default());
        };
        let arrays = FrameArrays::borrow(source)?;
        let views = arrays.views()?;
        py.detach(|| Measured::on_frames(config, || Ok(frames_of(&views))))
    }
    .map_err(to_py)?;
    to_json(&measured)
}

/// The decisions of [`measure_first_frames`]' JSON (none: each window decides its own).
fn measured_of(measured: Option<String>) -> PyResult<Measured> {
    measured.map_or(Ok(Measured::default()), |json| {
        serde_json::from_str(&json).map_err(|e| {
            PyValueError::new_err(format!(
                "measured is not what measure_first_frames returned: {e}"
            ))
        })
    })
}

/// Tracks window `index` (frames `first..=last`) of the frames at `source` with its kernels
/// on `threads` threads (`None`: all cores), adopting the decisions `measured` of
/// [`measure_first_frames`]; returns its tracks as bytes for [`Stitcher::push`].
#[pyfunction]
#[pyo3(signature = (source, tracker, overrides, seed, files, index, first, last,
    measured=None, threads=None))]
#[allow(clippy::too_many_arguments)] // one argument each, as Python passes them
pub fn track_window<'py>(
    py: Python<'py>,
    source: String,
    tracker: &str,
    overrides: Vec<String>,
    seed: u64,
    files: HashMap<String, PathBuf>,
    index: usize,
    first: u64,
    last: u64,
    measured: Option<String>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyBytes>> {
    let tracking = tracking_of(tracker, &overrides, seed, files)?;
    let measured = measured_of(measured)?;
    let window = Window { index, first, last };
    let bytes = py
        .detach(|| {
            on_threads(threads, || {
                track_one_window(&source, &tracking, &window, &measured)
            })
            .map(|tracks| encode_window(&without_diagnostics(tracks)))
        })
        .map_err(to_py)?;
    Ok(PyBytes::new(py, &bytes))
}

/// [`track_window`] on frames held in memory (PTV and bedload): `frames` are the window's
/// frames `first..=last`.
#[pyfunction]
#[pyo3(signature = (frames, tracker, overrides, seed, files, index, first, last,
    measured=None, threads=None))]
#[allow(clippy::too_many_arguments)] // one argument each, as Python passes them
pub fn track_window_frames<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    tracker: &str,
    overrides: Vec<String>,
    seed: u64,
    files: HashMap<String, PathBuf>,
    index: usize,
    first: u64,
    last: u64,
    measured: Option<String>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyBytes>> {
    let measured = measured_of(measured)?;
    let Tracking::Pipeline(config) = tracking_of(tracker, &overrides, seed, files)? else {
        return Err(PyValueError::new_err(format!(
            "frames in memory are tracked by ptv and bedload only; give the pedestrian \
             trackers (`{tracker}`) a path"
        )));
    };
    let arrays = FrameArrays::borrow(frames)?;
    let views = arrays.views()?;
    if views.len() as u64 != last - first + 1 {
        return Err(PyValueError::new_err(format!(
            "window {index} spans frames {first}–{last} but {} frames were given",
            views.len()
        )));
    }
    let window = Window { index, first, last };
    let bytes = py
        .detach(|| {
            let frames = || {
                Ok(frames_of(&views).map(move |frame| {
                    frame.map(|mut frame| {
                        frame.index += first;
                        frame
                    })
                }))
            };
            on_threads(threads, || {
                track_array_window(&config, &window, &measured, frames)
            })
            .map(|tracks| encode_window(&without_diagnostics(tracks)))
        })
        .map_err(to_py)?;
    Ok(PyBytes::new(py, &bytes))
}

/// `tracks` without the fields no Python column carries (the motion model's predicted
/// velocity and error, the estimate's spread, the detection index): 28 of a PTV point's 99
/// bytes, which need not travel from the worker.
fn without_diagnostics(mut tracks: WindowTracks) -> WindowTracks {
    for p in &mut tracks.points {
        p.vel_pred_px_per_frame = None;
        p.log10_pred_err = None;
        p.spread_px = None;
        p.detection = None;
    }
    tracks
}

/// Joins the windows of one run, pushed in order, into one set of trajectories.
#[pyclass]
pub struct Stitcher {
    inner: Option<WindowStitcher>,
}

#[pymethods]
impl Stitcher {
    /// A stitcher for `tracker`'s windows (its join distances).
    #[new]
    #[pyo3(signature = (tracker, overrides, seed, files))]
    fn new(
        tracker: &str,
        overrides: Vec<String>,
        seed: u64,
        files: HashMap<String, PathBuf>,
    ) -> PyResult<Self> {
        let tracking = tracking_of(tracker, &overrides, seed, files)?;
        let inner = WindowStitcher::new(stitch_params(&tracking)).map_err(to_py)?;
        Ok(Self { inner: Some(inner) })
    }

    /// Adds the next window's tracks (bytes of `track_window`); returns the columns of the
    /// points now final.
    fn push<'py>(
        &mut self,
        py: Python<'py>,
        tracks: &Bound<'py, PyBytes>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let window = decode_window(tracks.as_bytes()).map_err(to_py)?;
        let points = self.stitcher()?.push(window).map_err(to_py)?;
        all_track_columns(py, &points)
    }

    /// The last points' columns and the seams (JSON); the stitcher is then spent.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<(Bound<'py, PyDict>, String)> {
        self.stitcher()?;
        let (points, seams) = self
            .inner
            .take()
            .map(WindowStitcher::finish)
            .unwrap_or_default();
        Ok((all_track_columns(py, &points)?, to_json(&seams)?))
    }
}

impl Stitcher {
    fn stitcher(&mut self) -> PyResult<&mut WindowStitcher> {
        self.inner
            .as_mut()
            .ok_or_else(|| PyValueError::new_err("this stitcher has finished; make a new one"))
    }
}

fn to_json(value: &impl serde::Serialize) -> PyResult<String> {
    serde_json::to_string(value).map_err(|e| PyValueError::new_err(format!("JSON: {e}")))
}

/// Tracks `source` in windows of `window` frames overlapping by `overlap`, `jobs` at once on
/// local threads (as `sillage ptv --window`); returns the stitched points' columns and the
/// run's summary (JSON). `progress(1)` is called as each window is stitched.
#[pyfunction]
#[pyo3(signature = (source, tracker, overrides, seed, files, window, overlap, jobs,
    progress=None))]
#[allow(clippy::too_many_arguments)] // one argument each, as Python passes them
pub fn track_windows<'py>(
    py: Python<'py>,
    source: String,
    tracker: &str,
    overrides: Vec<String>,
    seed: u64,
    files: HashMap<String, PathBuf>,
    window: usize,
    overlap: usize,
    jobs: usize,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Bound<'py, PyDict>, String)> {
    let tracking = tracking_of(tracker, &overrides, seed, files)?;
    let (points, summary) = py.detach(|| {
        let between = Between::new(progress);
        let run = || {
            let plan = WindowPlan::for_source(&source, window, overlap, &tracking)?;
            let mut points: Vec<TrackPoint> = Vec::new();
            let summary = WindowedRun::new(&tracking, plan).jobs(jobs).run(
                &source,
                &mut points,
                &mut |_| between.advance(),
            )?;
            Ok((points, summary))
        };
        between.result(run())
    })?;
    Ok((all_track_columns(py, &points)?, to_json(&summary)?))
}

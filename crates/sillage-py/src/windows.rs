//! Time windows from Python (`sillage.dask`, `sillage.track(..., window=W)`): the plan, one
//! window tracked on a worker (its tracks handed back as bytes), the pieces of a run stitched
//! apart (each window's edges, each seam, each window's share, made where the windows are; the
//! identities planned in one place) and the local runner of `sillage ptv --window`.

use std::collections::HashMap;
use std::path::PathBuf;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use sillage::Tracking;
use sillage::assoc::SparseLapSolver;
use sillage::core::TrackPoint;
use sillage::track::stitch::{
    PartPlanner as StitchPlanner, WindowTracks, join_seam as join_window_seam,
};
use sillage::windows::{
    Measured, Window, WindowPlan, WindowedRun, decode_edges, decode_ids, decode_plan, decode_seam,
    decode_window, encode_edges, encode_ids, encode_plan, encode_seam, encode_window, min_window,
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

/// A window's tracks and its edges, as bytes.
type WindowBytes<'py> = (Bound<'py, PyBytes>, Bound<'py, PyBytes>);

/// Tracks window `index` (frames `first..=last`) of the frames at `source` with its kernels
/// on `threads` threads (`None`: all cores), adopting the decisions `measured` of
/// [`measure_first_frames`]; returns its tracks as bytes for [`window_share`], and its edges
/// for [`join_seam`] and [`window_ids`] (the window before ends at `previous_last`, the one
/// after starts at `next_first`; `None` where there is none).
#[pyfunction]
#[pyo3(signature = (source, tracker, overrides, seed, files, index, first, last,
    measured=None, threads=None, previous_last=None, next_first=None))]
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
    previous_last: Option<u64>,
    next_first: Option<u64>,
) -> PyResult<WindowBytes<'py>> {
    let tracking = tracking_of(tracker, &overrides, seed, files)?;
    let measured = measured_of(measured)?;
    let window = Window { index, first, last };
    let bytes = py
        .detach(|| {
            on_threads(threads, || {
                track_one_window(&source, &tracking, &window, &measured)
            })
            .map(|tracks| encoded(tracks, previous_last, next_first))
        })
        .map_err(to_py)?;
    Ok(window_bytes(py, bytes))
}

/// [`track_window`] on frames held in memory (PTV and bedload): `frames` are the window's
/// frames `first..=last`.
#[pyfunction]
#[pyo3(signature = (frames, tracker, overrides, seed, files, index, first, last,
    measured=None, threads=None, previous_last=None, next_first=None))]
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
    previous_last: Option<u64>,
    next_first: Option<u64>,
) -> PyResult<WindowBytes<'py>> {
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
            .map(|tracks| encoded(tracks, previous_last, next_first))
        })
        .map_err(to_py)?;
    Ok(window_bytes(py, bytes))
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

/// The window's tracks and edges encoded, without the fields no Python column carries.
fn encoded(
    tracks: WindowTracks,
    previous_last: Option<u64>,
    next_first: Option<u64>,
) -> (Vec<u8>, Vec<u8>) {
    let tracks = without_diagnostics(tracks).in_frame_order();
    let edges = tracks.edges(previous_last, next_first);
    (encode_window(&tracks), encode_edges(&edges))
}

/// The bytes of [`encoded`] handed to Python.
fn window_bytes(py: Python<'_>, (tracks, edges): (Vec<u8>, Vec<u8>)) -> WindowBytes<'_> {
    (PyBytes::new(py, &tracks), PyBytes::new(py, &edges))
}

/// What [`PartPlanner::push`] needs of a window's edges (of [`track_window`]): its first
/// frame and track ids.
#[pyfunction]
pub fn window_ids<'py>(
    py: Python<'py>,
    edges: &Bound<'py, PyBytes>,
) -> PyResult<Bound<'py, PyBytes>> {
    let edges = decode_edges(edges.as_bytes()).map_err(to_py)?;
    Ok(PyBytes::new(py, &encode_ids(edges.first, &edges.ids)))
}

/// Joins the seam between two consecutive windows from their edges ([`track_window`]), with
/// `tracker`'s join distances; returns the seam as bytes for [`PartPlanner::push`].
#[pyfunction]
#[pyo3(signature = (earlier, later, tracker, overrides, seed, files))]
pub fn join_seam<'py>(
    py: Python<'py>,
    earlier: &Bound<'py, PyBytes>,
    later: &Bound<'py, PyBytes>,
    tracker: &str,
    overrides: Vec<String>,
    seed: u64,
    files: HashMap<String, PathBuf>,
) -> PyResult<Bound<'py, PyBytes>> {
    let params = stitch_params(&tracking_of(tracker, &overrides, seed, files)?);
    let earlier = decode_edges(earlier.as_bytes()).map_err(to_py)?;
    let later = decode_edges(later.as_bytes()).map_err(to_py)?;
    let bytes = py
        .detach(|| {
            params.validate()?;
            join_window_seam(&params, &mut SparseLapSolver::new(), &earlier, &later)
                .map(|seam| encode_seam(&seam))
        })
        .map_err(to_py)?;
    Ok(PyBytes::new(py, &bytes))
}

/// Hands out the run's global identities from the windows' ids and seams, pushed in window
/// order, and plans each window's share of the stitched run.
#[pyclass]
pub struct PartPlanner {
    inner: Option<StitchPlanner>,
}

#[pymethods]
impl PartPlanner {
    /// A planner for a run's first window.
    #[new]
    fn new() -> Self {
        Self {
            inner: Some(StitchPlanner::new()),
        }
    }

    /// Adds the next window: its ids ([`window_ids`]) and the seam with the window before
    /// ([`join_seam`]; `None` for the first window). Returns the plan of the window before
    /// (bytes for [`window_share`]), or `None` after the first window.
    #[pyo3(signature = (ids, seam=None))]
    fn push<'py>(
        &mut self,
        py: Python<'py>,
        ids: &Bound<'py, PyBytes>,
        seam: Option<&Bound<'py, PyBytes>>,
    ) -> PyResult<Option<Bound<'py, PyBytes>>> {
        let (first, ids) = decode_ids(ids.as_bytes()).map_err(to_py)?;
        let seam = seam
            .map(|seam| decode_seam(seam.as_bytes()))
            .transpose()
            .map_err(to_py)?;
        let plan = self.planner()?.push(first, &ids, seam).map_err(to_py)?;
        Ok(plan.map(|plan| PyBytes::new(py, &encode_plan(&plan))))
    }

    /// The last window's plan (`None` when no window was pushed) and the seams' reports
    /// (JSON); the planner is then spent.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<(Option<Bound<'py, PyBytes>>, String)> {
        self.planner()?;
        let (plan, seams) = self
            .inner
            .take()
            .map(StitchPlanner::finish)
            .unwrap_or_default();
        Ok((
            plan.map(|plan| PyBytes::new(py, &encode_plan(&plan))),
            to_json(&seams)?,
        ))
    }
}

impl PartPlanner {
    fn planner(&mut self) -> PyResult<&mut StitchPlanner> {
        self.inner
            .as_mut()
            .ok_or_else(|| PyValueError::new_err("this planner has finished; make a new one"))
    }
}

/// One window's share of the stitched run: its tracks (bytes of [`track_window`]) under the
/// `plan` [`PartPlanner::push`] made for it, as the columns of `sillage.track`. Runs where
/// the window's tracks are.
#[pyfunction]
pub fn window_share<'py>(
    py: Python<'py>,
    tracks: &Bound<'py, PyBytes>,
    plan: &Bound<'py, PyBytes>,
) -> PyResult<Bound<'py, PyDict>> {
    let (tracks, plan) = (tracks.as_bytes(), plan.as_bytes());
    let points = py
        .detach(|| decode_plan(plan)?.apply(decode_window(tracks)?.in_frame_order()))
        .map_err(to_py)?;
    all_track_columns(py, &points)
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

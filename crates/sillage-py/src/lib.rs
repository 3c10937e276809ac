//! `sillage._sillage`, the native half of the `sillage` Python package: numpy in, columns of
//! numpy arrays out (the pure-Python half, `python/sillage/__init__.py`, makes DataFrames of
//! them and maps keyword arguments to configuration keys). Every function releases the GIL
//! while it computes, taking it back between frames only to check for Ctrl-C and to advance
//! the progress bar.

mod bedload;
mod errors;
mod eval;
mod experiments;
mod frames;
mod hooks;
mod linking;
mod sources;
mod stream;
mod synth;
mod windows;

use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sillage::config::OPTIONAL_KEYS;
use sillage::core::{FrameIndex, Point2, TrackId, TrackPoint, Vec2};
use sillage::detect::blob::Calibration;
use sillage::io::{FrameOptions, open_frames};
use sillage::ptv_run::too_few_frames_warning;
use sillage::toml_config::dotted_keys;
use sillage::{Pipeline, PipelineConfig};

use crate::errors::to_py;
use crate::frames::{FrameArrays, frames_of};
use crate::hooks::Between;

/// The configuration of `overrides` (`key=value` with dotted keys) on the defaults, validated;
/// a bad key or value raises `ValueError` naming the key.
fn config_of(overrides: &[String]) -> PyResult<PipelineConfig> {
    let mut config = PipelineConfig::default();
    for assignment in overrides {
        config.set(assignment).map_err(to_py)?;
    }
    config.validate().map_err(to_py)?;
    Ok(config)
}

/// Every configuration key, dotted (`detector.scale_px`), the optional ones included.
#[pyfunction]
fn config_keys() -> PyResult<Vec<String>> {
    let mut keys: Vec<String> = dotted_keys(&PipelineConfig::default())
        .map_err(to_py)?
        .into_iter()
        .map(|(key, _)| key)
        .collect();
    keys.extend(OPTIONAL_KEYS.iter().map(|(key, _, _)| key.to_string()));
    Ok(keys)
}

/// Detects objects in every frame of `frames` (see `frames::FrameArrays::borrow`); returns
/// the columns `frame`, `x`, `y`, `signal`.
#[pyfunction]
#[pyo3(signature = (frames, overrides, progress=None))]
fn locate<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    overrides: Vec<String>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let config = config_of(&overrides)?;
    let arrays = FrameArrays::borrow(frames)?;
    let views = arrays.views()?;
    let (frame, x, y, signal, calibration) = py.detach(|| {
        let between = Between::new(progress);
        let run = || {
            let mut pipeline = Pipeline::from_config(&config)?;
            let (mut frame, mut x, mut y, mut signal) = (vec![], vec![], vec![], vec![]);
            for image in between.frames(frames_of(&views)) {
                let image = image?;
                for d in pipeline.locate(&image)? {
                    frame.push(image.index as i64);
                    x.push(d.pos_px.x);
                    y.push(d.pos_px.y);
                    signal.push(f64::from(d.strength));
                }
                between.advance();
            }
            Ok((frame, x, y, signal, pipeline.calibration()))
        };
        between.result(run())
    })?;
    let columns = PyDict::new(py);
    set_measured(&columns, calibration.as_ref(), None, None)?;
    columns.set_item("frame", frame.into_pyarray(py))?;
    columns.set_item("x", x.into_pyarray(py))?;
    columns.set_item("y", y.into_pyarray(py))?;
    columns.set_item("signal", signal.into_pyarray(py))?;
    Ok(columns)
}

/// Detects and tracks `source` (frames as for `locate`, or a path: a folder, a glob pattern,
/// a TIFF stack or a video); returns the columns of `track_columns`.
#[pyfunction]
#[pyo3(signature = (source, overrides, progress=None))]
fn ptv<'py>(
    py: Python<'py>,
    source: &Bound<'py, PyAny>,
    overrides: Vec<String>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let config = config_of(&overrides)?;
    let points = if let Ok(path) = source.extract::<String>() {
        py.detach(|| {
            let between = Between::new(progress);
            let run = || {
                let mut pipeline = Pipeline::from_config(&config)?;
                if pipeline.background_init_frames() > 0 {
                    pipeline.prime_background(open_frames(&path, &FrameOptions::default())?)?;
                }
                let frames = open_frames(&path, &FrameOptions::default())?;
                let mut points: Vec<TrackPoint> = Vec::new();
                let summary = pipeline.run(between.frames(frames), &mut points, &mut |_| {
                    between.advance()
                })?;
                Ok((points, summary))
            };
            between.result(run())
        })?
    } else {
        let arrays = FrameArrays::borrow(source)?;
        let views = arrays.views()?;
        py.detach(|| {
            let between = Between::new(progress);
            let run = || {
                let mut pipeline = Pipeline::from_config(&config)?;
                if pipeline.background_init_frames() > 0 {
                    pipeline.prime_background(frames_of(&views))?;
                }
                let mut points: Vec<TrackPoint> = Vec::new();
                let summary =
                    pipeline.run(between.frames(frames_of(&views)), &mut points, &mut |_| {
                        between.advance()
                    })?;
                Ok((points, summary))
            };
            between.result(run())
        })?
    };
    let (points, summary) = points;
    let columns = track_columns(py, &points)?;
    set_measured(
        &columns,
        summary.detector.as_ref(),
        summary.measured_displacement_px,
        summary.vote_search_px,
    )?;
    let frames = usize::try_from(summary.frames).unwrap_or(usize::MAX);
    if let Some(warning) = too_few_frames_warning(frames)
        && let Some(measured) = columns.get_item("measured")?
    {
        measured.set_item("frames_warning", warning)?;
    }
    Ok(columns)
}

/// Adds to `columns`, under `"measured"`, what the run measured from the frames (the Python
/// side moves it to the DataFrame's `attrs`): the particle images' σ, the blob scale and
/// polarity in use, and for PTV the first frames' displacement and the voting radius.
fn set_measured(
    columns: &Bound<'_, PyDict>,
    calibration: Option<&Calibration>,
    displacement_px: Option<f64>,
    vote_search_px: Option<f64>,
) -> PyResult<()> {
    let measured = PyDict::new(columns.py());
    if let Some(calibration) = calibration
        && let Some(images) = &calibration.measured
    {
        measured.set_item("particle_sigma_px", images.sigma_px)?;
        measured.set_item("scale_px", calibration.scale_px)?;
        measured.set_item("polarity", calibration.polarity.name())?;
        measured.set_item("source_density", images.source_density)?;
        measured.set_item("density_warning", images.density_warning())?;
    }
    if let Some(displacement) = displacement_px {
        measured.set_item("displacement_px", displacement)?;
        measured.set_item("vote_search_px", vote_search_px)?;
    }
    columns.set_item("measured", measured)
}

/// One point's identity and motion: frame, track id, position and velocity, px and px/frame.
type Kinematics = (FrameIndex, TrackId, Point2, Option<Vec2>);

/// The columns `frame`, `particle`, `x`, `y`, `vx`, `vy` (NaN where no velocity) of `points`,
/// each point read through `kinematics`: shared by tracks and synthetic truth.
fn kinematic_columns<'py, P>(
    py: Python<'py>,
    points: &[P],
    kinematics: impl Fn(&P) -> Kinematics,
) -> PyResult<Bound<'py, PyDict>> {
    let columns = PyDict::new(py);
    let rows: Vec<Kinematics> = points.iter().map(kinematics).collect();
    let frame: Vec<i64> = rows.iter().map(|r| r.0 as i64).collect();
    let particle: Vec<i64> = rows.iter().map(|r| r.1 as i64).collect();
    columns.set_item("frame", frame.into_pyarray(py))?;
    columns.set_item("particle", particle.into_pyarray(py))?;
    let column = |name: &str, value: &dyn Fn(&Kinematics) -> f64| {
        let values: Vec<f64> = rows.iter().map(value).collect();
        columns.set_item(name, values.into_pyarray(py))
    };
    column("x", &|r| r.2.x)?;
    column("y", &|r| r.2.y)?;
    column("vx", &|r| r.3.map_or(f64::NAN, |v| v.x))?;
    column("vy", &|r| r.3.map_or(f64::NAN, |v| v.y))?;
    Ok(columns)
}

/// The columns of track points: those of [`kinematic_columns`], then `ax`, `ay`
/// (accelerations in px/frame², NaN where not estimated).
pub(crate) fn track_columns<'py>(
    py: Python<'py>,
    points: &[TrackPoint],
) -> PyResult<Bound<'py, PyDict>> {
    let columns = kinematic_columns(py, points, |p| {
        (p.frame, p.track_id, p.pos_px, p.vel_px_per_frame)
    })?;
    let acceleration = |component: fn(Vec2) -> f64| -> Vec<f64> {
        points
            .iter()
            .map(|p| p.acc_px_per_frame2.map_or(f64::NAN, component))
            .collect()
    };
    columns.set_item("ax", acceleration(|a| a.x).into_pyarray(py))?;
    columns.set_item("ay", acceleration(|a| a.y).into_pyarray(py))?;
    Ok(columns)
}

/// Links detections given as columns (`frame`, `x`, `y`, one row each) with the PTV
/// tracker; returns `particle` (a trajectory id per row; rows in no trajectory get ids of
/// their own, as trackpy gives) and the rows' velocities `vx`, `vy` (NaN where unlinked).
#[pyfunction]
#[pyo3(signature = (frame, x, y, overrides, progress=None))]
fn link<'py>(
    py: Python<'py>,
    frame: PyReadonlyArray1<'py, i64>,
    x: PyReadonlyArray1<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    overrides: Vec<String>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let config = config_of(&overrides)?;
    let (frame, x, y) = (frame.as_array(), x.as_array(), y.as_array());
    let linked = py.detach(|| {
        let between = Between::new(progress);
        between.result(linking::link_rows(&config, frame, x, y, &between))
    })?;
    let columns = PyDict::new(py);
    columns.set_item("particle", linked.particle.into_pyarray(py))?;
    columns.set_item("vx", linked.vx.into_pyarray(py))?;
    columns.set_item("vy", linked.vy.into_pyarray(py))?;
    Ok(columns)
}

/// The native module.
#[pymodule]
fn _sillage(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_function(wrap_pyfunction!(config_keys, module)?)?;
    module.add_function(wrap_pyfunction!(locate, module)?)?;
    module.add_function(wrap_pyfunction!(ptv, module)?)?;
    module.add_function(wrap_pyfunction!(link, module)?)?;
    module.add_function(wrap_pyfunction!(synth::synth_vortex, module)?)?;
    module.add_function(wrap_pyfunction!(synth::synth_bedload, module)?)?;
    module.add_class::<stream::PtvStream>()?;
    module.add_function(wrap_pyfunction!(eval::evaluate, module)?)?;
    module.add_function(wrap_pyfunction!(bedload::track_bedload, module)?)?;
    module.add_function(wrap_pyfunction!(sources::track, module)?)?;
    module.add_function(wrap_pyfunction!(sources::detect, module)?)?;
    module.add_function(wrap_pyfunction!(experiments::fit, module)?)?;
    module.add_function(wrap_pyfunction!(experiments::bench_immpf, module)?)?;
    module.add_function(wrap_pyfunction!(experiments::bench_siftpf, module)?)?;
    module.add_function(wrap_pyfunction!(windows::frame_count, module)?)?;
    module.add_function(wrap_pyfunction!(windows::plan_windows, module)?)?;
    module.add_function(wrap_pyfunction!(windows::measure_first_frames, module)?)?;
    module.add_function(wrap_pyfunction!(windows::track_window, module)?)?;
    module.add_function(wrap_pyfunction!(windows::track_window_frames, module)?)?;
    module.add_function(wrap_pyfunction!(windows::track_windows, module)?)?;
    module.add_function(wrap_pyfunction!(windows::window_ids, module)?)?;
    module.add_function(wrap_pyfunction!(windows::join_seam, module)?)?;
    module.add_function(wrap_pyfunction!(windows::window_share, module)?)?;
    module.add_class::<windows::PartPlanner>()?;
    module.add("DEFAULT_OVERLAP", sillage::windows::DEFAULT_OVERLAP)?;
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

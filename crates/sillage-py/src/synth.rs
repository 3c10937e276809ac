//! The synthetic generators: frames as numpy arrays, ground truth and detections as columns.

use std::path::PathBuf;

use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sillage::core::{Detection, Error, FrameIndex, Result, TrackPoint, TruthPoint};
use sillage::synth::vortex::{VortexParams, VortexSequence};
use sillage::synth::{BedloadDetectionParams, BedloadSceneParams, BedloadSequence};
use sillage::toml_config::set_key;
use sillage::vortex_files::write_vortex;

use crate::bedload::add_state_and_class;
use crate::errors::to_py;
use crate::kinematic_columns;

/// Renders the vortex flow of the TracTrac paper (§4.1.1) with `overrides` (`key=value`,
/// keys of `VortexParams`: `width`, `n_particles`, `snr`...); returns the frames as a
/// float32 array `(frames, rows, columns)` in `[0, 1]` and the truth's columns `frame`,
/// `particle`, `x`, `y`, `vx`, `vy`. With `out`, the frames are also written there as
/// `frame_NNNNN.png` (16-bit) with `truth.csv`, as `sillage synth vortex` writes them.
#[pyfunction]
#[pyo3(signature = (overrides, out=None))]
pub fn synth_vortex<'py>(
    py: Python<'py>,
    overrides: Vec<String>,
    out: Option<PathBuf>,
) -> PyResult<(Bound<'py, PyArray3<f32>>, Bound<'py, PyDict>)> {
    let mut params = VortexParams::default();
    for assignment in &overrides {
        set_key(&mut params, assignment).map_err(to_py)?;
    }
    params.validate().map_err(to_py)?;
    if let Some(out) = &out {
        py.detach(|| write_vortex(&params, out, &mut || {}))
            .map_err(to_py)?;
    }
    let (pixels, truth) = py.detach(|| render(&params)).map_err(to_py)?;
    let frames = Array3::from_shape_vec((params.n_frames, params.height, params.width), pixels)
        .map_err(|e| to_py(Error::input(format!("frames of unexpected size: {e}"))))?;
    let columns = kinematic_columns(py, &truth, |p: &TruthPoint| {
        (p.frame, p.track_id, p.pos_px, p.vel_px_per_frame)
    })?;
    Ok((frames.into_pyarray(py), columns))
}

/// Every frame's pixels, one after the other, and the truth of all frames.
fn render(params: &VortexParams) -> Result<(Vec<f32>, Vec<TruthPoint>)> {
    let mut pixels = Vec::with_capacity(params.n_frames * params.width * params.height);
    let mut truth = Vec::new();
    for frame in VortexSequence::new(params.clone())? {
        pixels.extend_from_slice(frame.image.as_slice());
        truth.extend_from_slice(&frame.truth);
    }
    Ok((pixels, truth))
}

/// Generates the synthetic bedload sequence of `scene_overrides` (`key=value`, keys of
/// `BedloadSceneParams`: `n_frames`, `n_black`, `n_transparent`, `seed`...) seen through the
/// detector model of `detection_overrides` (keys of `BedloadDetectionParams`:
/// `position_sigma_px`...); returns the truth's columns (`frame`, `particle`, `x`, `y`, `vx`,
/// `vy` as the displacement from the previous frame, `state`, `class`), and the columns
/// `frame`, `x`, `y`, `class`, `score` of the detections and of the candidates, as
/// `track_bedload` reads them.
#[pyfunction]
pub fn synth_bedload<'py>(
    py: Python<'py>,
    scene_overrides: Vec<String>,
    detection_overrides: Vec<String>,
) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyDict>, Bound<'py, PyDict>)> {
    let mut scene = BedloadSceneParams::default();
    for assignment in &scene_overrides {
        set_key(&mut scene, assignment).map_err(to_py)?;
    }
    let mut detection = BedloadDetectionParams::default();
    for assignment in &detection_overrides {
        set_key(&mut detection, assignment).map_err(to_py)?;
    }
    scene.validate().map_err(to_py)?;
    detection.validate().map_err(to_py)?;
    let (truth, detections, candidates) = py
        .detach(|| {
            let (mut truth, mut detections, mut candidates) = (vec![], vec![], vec![]);
            for sample in BedloadSequence::new(scene, detection)? {
                let frame = sample.truth.index;
                truth.extend(sample.truth.track_points());
                let observation = sample.observation;
                detections.extend(observation.detections.into_iter().map(|d| (frame, d)));
                candidates.extend(observation.candidates.into_iter().map(|d| (frame, d)));
            }
            Ok((truth, detections, candidates))
        })
        .map_err(to_py)?;
    let truth_columns = kinematic_columns(py, &truth, |p: &TrackPoint| {
        (p.frame, p.track_id, p.pos_px, p.vel_px_per_frame)
    })?;
    add_state_and_class(&truth_columns, &truth)?;
    Ok((
        truth_columns,
        detection_columns(py, &detections)?,
        detection_columns(py, &candidates)?,
    ))
}

/// The columns `frame`, `x`, `y`, `class`, `score` (the detection's strength) of `rows`.
fn detection_columns<'py>(
    py: Python<'py>,
    rows: &[(FrameIndex, Detection)],
) -> PyResult<Bound<'py, PyDict>> {
    let columns = PyDict::new(py);
    let frame: Vec<i64> = rows.iter().map(|(f, _)| *f as i64).collect();
    let x: Vec<f64> = rows.iter().map(|(_, d)| d.pos_px.x).collect();
    let y: Vec<f64> = rows.iter().map(|(_, d)| d.pos_px.y).collect();
    let class: Vec<i64> = rows.iter().map(|(_, d)| i64::from(d.class)).collect();
    let score: Vec<f64> = rows.iter().map(|(_, d)| f64::from(d.strength)).collect();
    columns.set_item("frame", frame.into_pyarray(py))?;
    columns.set_item("x", x.into_pyarray(py))?;
    columns.set_item("y", y.into_pyarray(py))?;
    columns.set_item("class", class.into_pyarray(py))?;
    columns.set_item("score", score.into_pyarray(py))?;
    Ok(columns)
}

//! The synthetic generators: frames as numpy arrays, ground truth as columns.

use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sillage::core::{Error, Result, TruthPoint};
use sillage::synth::vortex::{VortexParams, VortexSequence};
use sillage::toml_config::set_key;

use crate::errors::to_py;
use crate::kinematic_columns;

/// Renders the vortex flow of the TracTrac paper (§4.1.1) with `overrides` (`key=value`,
/// keys of `VortexParams`: `width`, `n_particles`, `snr`...); returns the frames as a
/// float32 array `(frames, rows, columns)` in `[0, 1]` and the truth's columns `frame`,
/// `particle`, `x`, `y`, `vx`, `vy`.
#[pyfunction]
pub fn synth_vortex<'py>(
    py: Python<'py>,
    overrides: Vec<String>,
) -> PyResult<(Bound<'py, PyArray3<f32>>, Bound<'py, PyDict>)> {
    let mut params = VortexParams::default();
    for assignment in &overrides {
        set_key(&mut params, assignment).map_err(to_py)?;
    }
    params.validate().map_err(to_py)?;
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

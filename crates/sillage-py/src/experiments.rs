//! The fits and the paper benches of the command line (`sillage fit ...`, `sillage bench
//! immpf|siftpf`) as calls returning JSON, which the Python half turns into dicts and
//! DataFrames.

use std::path::{Path, PathBuf};

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use serde::Serialize;
use sillage::bedload::fit::fit_bedload_files;
use sillage::core::{Error, Result};
use sillage::experiments::immpf::BenchInput;
use sillage::experiments::{immpf, siftpf};
use sillage::filter::{BedloadParams, FitOptions, MotionPriorParams};
use sillage::io::write_text;
use sillage::pedestrian::homography::{HomographySource, fit_homography};
use sillage::pedestrian::immpf::Scene;
use sillage::pedestrian::motion_prior::{fit_motion_prior, write_motion_prior};
use sillage::pedestrian::{GroundPlaneFile, ImmpfSettings, SiftPfSettings};
use sillage::toml_config::load;
use sillage::track::bedload::SmootherParams;
use sillage::track::immpf::ModelName;
use sillage::track::siftpf::FeatureSelection;

use crate::errors::to_py;
use crate::hooks::Between;

/// `value` as JSON text.
fn json(value: &impl Serialize) -> Result<String> {
    serde_json::to_string(value).map_err(|e| Error::input(format!("cannot write JSON: {e}")))
}

/// Fits `kind` (`bedload`, `homography`, `motion-prior`) to the ground truth `truth`, writes
/// the result to `out` when given (the file the command line writes), and returns what was
/// fitted as JSON. `tracks` (bedload only): a tracker's output on the truth's frames, from
/// which the motion-state smoother's evidence is learnt.
#[pyfunction]
#[pyo3(signature = (kind, truth, out=None, tracks=None))]
pub fn fit(
    py: Python<'_>,
    kind: &str,
    truth: PathBuf,
    out: Option<PathBuf>,
    tracks: Option<PathBuf>,
) -> PyResult<String> {
    if tracks.is_some() && kind != "bedload" {
        return Err(PyValueError::new_err(format!(
            "`tracks` is for fit(\"bedload\", ...) only, not `{kind}`"
        )));
    }
    py.detach(|| match kind {
        "bedload" => fit_bedload_file(&truth, tracks.as_deref(), out.as_deref()),
        "homography" => fit_homography_file(&truth, out.as_deref()),
        "motion-prior" => fit_motion_prior_file(&truth, out.as_deref()),
        other => Err(Error::input(format!(
            "unknown fit `{other}`; choose bedload, homography or motion-prior"
        ))),
    })
    .map_err(to_py)
}

/// The MMPF+ motion parameters of a BeadTracking truth with motion states, and the smoother's
/// evidence with `tracks`.
fn fit_bedload_file(truth: &Path, tracks: Option<&Path>, out: Option<&Path>) -> Result<String> {
    let fitted = fit_bedload_files(
        truth,
        tracks,
        &FitOptions::default(),
        SmootherParams::default().half_window,
    )?;
    if let Some(path) = out {
        write_text(path, &fitted.text)?;
    }
    #[derive(Serialize)]
    struct Fitted<'a> {
        tracks: usize,
        tracks_without_state: usize,
        motion: &'a BedloadParams,
        #[serde(skip_serializing_if = "Option::is_none")]
        emission: Option<&'a sillage::track::bedload::EmissionParams>,
        config: &'a str,
    }
    json(&Fitted {
        tracks: fitted.tracks,
        tracks_without_state: fitted.tracks_without_state,
        motion: &fitted.fit.params,
        emission: fitted.emission.as_ref().map(|(e, _)| e),
        config: &fitted.text,
    })
}

/// The ground plane (homography and adult box size) of a MOT15 ground truth.
fn fit_homography_file(truth: &Path, out: Option<&Path>) -> Result<String> {
    let fit = fit_homography(HomographySource::GroundTruth(truth))?;
    if let Some(path) = out {
        fit.file.write(path)?;
    }
    #[derive(Serialize)]
    struct Fitted<'a> {
        ground_plane: &'a GroundPlaneFile,
        boxes: usize,
    }
    json(&Fitted {
        ground_plane: &fit.file,
        boxes: fit.boxes,
    })
}

/// The learned motion prior (30-px cells) of a MOTChallenge ground truth.
fn fit_motion_prior_file(truth: &Path, out: Option<&Path>) -> Result<String> {
    let fit = fit_motion_prior(truth, None, None, &MotionPriorParams::default())?;
    if let Some(path) = out {
        write_motion_prior(path, &fit.prior)?;
    }
    #[derive(Serialize)]
    struct Fitted {
        width_px: u32,
        height_px: u32,
        tracks: usize,
        ignored_rows: usize,
        /// The prior as its file holds it.
        prior: serde_json::Value,
    }
    let prior = serde_json::from_str(&fit.prior.to_json())
        .map_err(|e| Error::input(format!("cannot read the prior back: {e}")))?;
    json(&Fitted {
        width_px: fit.width_px,
        height_px: fit.height_px,
        tracks: fit.tracks,
        ignored_rows: fit.ignored_rows,
        prior,
    })
}

/// The IMM-PF paper's table on the sequence `folders`: each model combination of
/// `combinations` (`CV_CA_MP`, ...), medians over the seeds `1..=runs`; rows as JSON.
#[pyfunction]
#[pyo3(signature = (folders, combinations, runs, overrides, ground_plane=None, max_frames=None,
    progress=None))]
#[allow(clippy::too_many_arguments)] // one keyword each, as Python passes them
pub fn bench_immpf(
    py: Python<'_>,
    folders: Vec<PathBuf>,
    combinations: Vec<String>,
    runs: usize,
    overrides: Vec<String>,
    ground_plane: Option<PathBuf>,
    max_frames: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    py.detach(|| {
        let between = Between::new(progress);
        let run = || {
            let settings: ImmpfSettings = load(None, &overrides)?;
            let scene = Scene::load(ground_plane.as_deref(), None)?;
            let combinations = combinations
                .iter()
                .map(|c| ModelName::parse_combination(c))
                .collect::<Result<Vec<_>>>()?;
            let input = BenchInput {
                max_frames,
                ..BenchInput::default()
            };
            let rows = immpf::bench(
                &folders,
                input,
                &settings,
                &scene,
                &combinations,
                runs,
                &mut |step| {
                    if let immpf::BenchProgress::Row(_) = step {
                        between.advance();
                    }
                },
            )?;
            json(&rows)
        };
        between.result(run())
    })
}

/// The SIFT-PF paper's table on the sequence `folders`: each feature selection of
/// `selections`, medians over the seeds `1..=runs`; the report as JSON.
#[pyfunction]
#[pyo3(signature = (folders, selections, runs, overrides, ground_plane=None, max_frames=None,
    progress=None))]
#[allow(clippy::too_many_arguments)] // one keyword each, as Python passes them
pub fn bench_siftpf(
    py: Python<'_>,
    folders: Vec<PathBuf>,
    selections: Vec<String>,
    runs: u64,
    overrides: Vec<String>,
    ground_plane: Option<PathBuf>,
    max_frames: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    py.detach(|| {
        let between = Between::new(progress);
        let run = || {
            let settings: SiftPfSettings = load(None, &overrides)?;
            let selections = selections
                .iter()
                .map(|s| FeatureSelection::parse(s))
                .collect::<Result<Vec<_>>>()?;
            let homography = ground_plane
                .as_deref()
                .map(GroundPlaneFile::read_homography)
                .transpose()?;
            let report = siftpf::bench(
                &folders,
                &settings,
                &selections,
                homography,
                siftpf::seeds(1, runs.max(1))?,
                max_frames,
                &mut |step| {
                    if let siftpf::BenchProgress::Run(..) = step {
                        between.advance();
                    }
                },
            )?;
            json(&report)
        };
        between.result(run())
    })
}

//! `track` and `detect` on a frame source (a folder, a glob pattern, a TIFF stack or a video):
//! any of the four trackers and three detectors of `sillage::tracking`, their settings given
//! as dotted `key=value` overrides of each one's configuration.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sillage::bedload::detector::BeadDetectorSources;
use sillage::core::{BoundingBox, Result, TrackPoint};
use sillage::detect::motion::MotionParams;
use sillage::io::FrameOptions;
use sillage::pedestrian::immpf::Scene;
use sillage::pedestrian::{GroundPlaneFile, ImmpfSettings, SiftPfSettings};
use sillage::toml_config::load;
use sillage::track::bedload::BedloadTrackerParams;
use sillage::tracking::{ImmpfSetup, SiftPfSetup};
use sillage::{
    Detecting, DetectorConfig, PipelineConfig, TrackerConfig, Tracking, detect_source, track_source,
};

use crate::bedload::add_state_and_class;
use crate::errors::to_py;
use crate::hooks::Between;
use crate::track_columns;

/// The files some trackers and detectors read besides their frames.
#[derive(Debug, Default)]
pub(crate) struct SceneFiles {
    /// BeadTracking `sequence_param.txt` (bead detector).
    sequence_params: Option<PathBuf>,
    /// Image of the fixed flume base (bead detector).
    base_mask: Option<PathBuf>,
    /// Ground plane TOML of `sillage fit homography` (pedestrian trackers).
    ground_plane: Option<PathBuf>,
    /// Motion prior JSON of `sillage fit motion-prior` (IMM-PF's MP model).
    motion_prior: Option<PathBuf>,
    /// MOTChallenge detections as birth candidates (IMM-PF).
    detections: Option<PathBuf>,
}

/// The bead detector of `files` (sizes from its sequence parameters, its base mask).
fn bead_detector(files: &SceneFiles) -> Result<DetectorConfig> {
    let sources = BeadDetectorSources {
        sequence_params: files.sequence_params.clone(),
        base_mask: files.base_mask.clone(),
        ..BeadDetectorSources::default()
    };
    Ok(DetectorConfig::Bead(sources.load()?))
}

/// A [`PipelineConfig`] with `detector` and `tracker`, then `overrides`, validated.
fn pipeline_config(
    detector: Option<DetectorConfig>,
    tracker: Option<TrackerConfig>,
    overrides: &[String],
) -> Result<PipelineConfig> {
    let mut config = PipelineConfig::default();
    if let Some(detector) = detector {
        config.detector = detector;
    }
    if let Some(tracker) = tracker {
        config.tracker = tracker;
    }
    for assignment in overrides {
        config.set(assignment)?;
    }
    config.validate()?;
    Ok(config)
}

impl SceneFiles {
    /// The files of a dict of `sequence_params`, `mask`, `ground_plane`, `motion_prior`,
    /// `detections` (each optional); another key raises `ValueError`.
    pub(crate) fn from_dict(files: HashMap<String, PathBuf>) -> PyResult<Self> {
        let mut scene = SceneFiles::default();
        for (key, path) in files {
            let slot = match key.as_str() {
                "sequence_params" => &mut scene.sequence_params,
                "mask" => &mut scene.base_mask,
                "ground_plane" => &mut scene.ground_plane,
                "motion_prior" => &mut scene.motion_prior,
                "detections" => &mut scene.detections,
                other => {
                    return Err(PyValueError::new_err(format!(
                        "unknown file `{other}`; give sequence_params, mask, ground_plane, \
                         motion_prior or detections"
                    )));
                }
            };
            *slot = Some(path);
        }
        Ok(scene)
    }
}

/// The tracking named `tracker` with `overrides` of its configuration.
pub(crate) fn tracking(
    tracker: &str,
    overrides: &[String],
    seed: u64,
    files: &SceneFiles,
) -> PyResult<Tracking> {
    let setup = match tracker {
        "ptv" => pipeline_config(None, None, overrides).map(|c| Tracking::Pipeline(Box::new(c))),
        "bedload" => bead_detector(files).and_then(|detector| {
            let tracker = TrackerConfig::Bedload(Box::new(BedloadTrackerParams {
                seed,
                ..BedloadTrackerParams::default()
            }));
            pipeline_config(Some(detector), Some(tracker), overrides)
                .map(|c| Tracking::Pipeline(Box::new(c)))
        }),
        "immpf" => load::<ImmpfSettings>(None, overrides).and_then(|settings| {
            let scene = Scene::load(files.ground_plane.as_deref(), files.motion_prior.as_deref())?;
            Ok(Tracking::Immpf(Box::new(ImmpfSetup {
                settings,
                scene,
                seed,
                detections: files.detections.clone(),
            })))
        }),
        "siftpf" => load::<SiftPfSettings>(None, overrides).and_then(|settings| {
            let homography = files
                .ground_plane
                .as_deref()
                .map(GroundPlaneFile::read_homography)
                .transpose()?;
            Ok(Tracking::Siftpf(Box::new(SiftPfSetup {
                settings,
                homography,
                seed,
            })))
        }),
        other => {
            return Err(PyValueError::new_err(format!(
                "unknown tracker `{other}`; choose ptv, bedload, immpf or siftpf"
            )));
        }
    };
    setup.map_err(to_py)
}

/// Adds the box columns `bb_left`, `bb_top`, `bb_width`, `bb_height` (px, NaN where a row
/// has no box) of `boxes` to `columns`.
fn add_boxes<'a>(
    columns: &Bound<'_, PyDict>,
    boxes: impl Iterator<Item = Option<&'a BoundingBox>> + Clone,
) -> PyResult<()> {
    let py = columns.py();
    let column = |name: &str, value: fn(&BoundingBox) -> f64| {
        let values: Vec<f64> = boxes.clone().map(|b| b.map_or(f64::NAN, value)).collect();
        columns.set_item(name, values.into_pyarray(py))
    };
    column("bb_left", |b| b.left_px)?;
    column("bb_top", |b| b.top_px)?;
    column("bb_width", |b| b.width_px)?;
    column("bb_height", |b| b.height_px)
}

/// The columns of any tracker's points: those of `track_columns`, then `state`, `class` and
/// the box columns.
pub(crate) fn all_track_columns<'py>(
    py: Python<'py>,
    points: &[TrackPoint],
) -> PyResult<Bound<'py, PyDict>> {
    let columns = track_columns(py, points)?;
    add_state_and_class(&columns, points)?;
    add_boxes(&columns, points.iter().map(|p| p.bbox.as_ref()))?;
    Ok(columns)
}

/// Tracks the frames of `source` with `tracker` (`ptv`, `bedload`, `immpf`, `siftpf`);
/// returns the columns of `all_track_columns`.
#[pyfunction]
#[pyo3(signature = (source, tracker, overrides, seed=1, sequence_params=None, mask=None,
    ground_plane=None, motion_prior=None, detections=None, max_frames=None, progress=None))]
#[allow(clippy::too_many_arguments)] // one keyword each, as Python passes them
pub fn track<'py>(
    py: Python<'py>,
    source: String,
    tracker: &str,
    overrides: Vec<String>,
    seed: u64,
    sequence_params: Option<PathBuf>,
    mask: Option<PathBuf>,
    ground_plane: Option<PathBuf>,
    motion_prior: Option<PathBuf>,
    detections: Option<PathBuf>,
    max_frames: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let files = SceneFiles {
        sequence_params,
        base_mask: mask,
        ground_plane,
        motion_prior,
        detections,
    };
    let setup = tracking(tracker, &overrides, seed, &files)?;
    let points = py.detach(|| {
        let between = Between::new(progress);
        let run = || {
            let mut points: Vec<TrackPoint> = Vec::new();
            let frames = FrameOptions {
                max_frames,
                ..FrameOptions::default()
            };
            track_source(&source, &setup, &frames, &mut points, &mut || {
                between.advance()
            })?;
            Ok(points)
        };
        between.result(run())
    })?;
    all_track_columns(py, &points)
}

/// Detects objects in the frames of `source` with `detector` (`blob`, `bead`, `motion`);
/// returns the columns `frame`, `x`, `y`, `signal`, `class` and the box columns.
#[pyfunction]
#[pyo3(signature = (source, detector, overrides, sequence_params=None, mask=None,
    max_frames=None, progress=None))]
#[allow(clippy::too_many_arguments)] // one keyword each, as Python passes them
pub fn detect<'py>(
    py: Python<'py>,
    source: String,
    detector: &str,
    overrides: Vec<String>,
    sequence_params: Option<PathBuf>,
    mask: Option<PathBuf>,
    max_frames: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let files = SceneFiles {
        sequence_params,
        base_mask: mask,
        ..SceneFiles::default()
    };
    let detecting = match detector {
        "blob" => pipeline_config(None, None, &overrides).map(|c| Detecting::Pipeline(Box::new(c))),
        "bead" => bead_detector(&files)
            .and_then(|bead| pipeline_config(Some(bead), None, &overrides))
            .map(|c| Detecting::Pipeline(Box::new(c))),
        "motion" => motion_params(&overrides).map(Detecting::Motion),
        other => {
            return Err(PyValueError::new_err(format!(
                "unknown detector `{other}`; choose blob, bead or motion"
            )));
        }
    }
    .map_err(to_py)?;
    let rows = py.detach(|| {
        let between = Between::new(progress);
        let mut rows = DetectionRows::default();
        let run = detect_source(
            &source,
            &detecting,
            max_frames,
            &mut |frame, found, boxes| {
                for (i, d) in found.iter().enumerate() {
                    rows.frame.push(frame.index as i64);
                    rows.x.push(d.pos_px.x);
                    rows.y.push(d.pos_px.y);
                    rows.signal.push(f64::from(d.strength));
                    rows.class.push(i64::from(d.class));
                    rows.boxes.push(boxes.get(i).copied());
                }
                between.advance();
                between.check()
            },
        );
        between.result(run).map(|()| rows)
    })?;
    let columns = PyDict::new(py);
    columns.set_item("frame", rows.frame.into_pyarray(py))?;
    columns.set_item("x", rows.x.into_pyarray(py))?;
    columns.set_item("y", rows.y.into_pyarray(py))?;
    columns.set_item("signal", rows.signal.into_pyarray(py))?;
    columns.set_item("class", rows.class.into_pyarray(py))?;
    add_boxes(&columns, rows.boxes.iter().map(Option::as_ref))?;
    Ok(columns)
}

/// The motion detector's parameters: its defaults with `overrides`, validated.
fn motion_params(overrides: &[String]) -> Result<MotionParams> {
    load(None::<&Path>, overrides)
}

/// The detections of a run, one entry per row.
#[derive(Debug, Default)]
struct DetectionRows {
    frame: Vec<i64>,
    x: Vec<f64>,
    y: Vec<f64>,
    signal: Vec<f64>,
    class: Vec<i64>,
    boxes: Vec<Option<BoundingBox>>,
}

//! The bedload trackers (MMPF+ and the baselines of its Table 1) on a detections table.

use std::collections::BTreeMap;

use numpy::ndarray::ArrayView1;
use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sillage::bedload::{BeadFrame, track_beads};
use sillage::core::{Detection, Error, FrameIndex, Point2, Result, TrackPoint};
use sillage::toml_config::set_key;
use sillage::track::bedload::BedloadTrackerParams;

use crate::errors::to_py;
use crate::track_columns;

/// One table's columns: frame, x, y, class, score.
type Columns<'py> = (
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, f64>,
    PyReadonlyArray1<'py, f64>,
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, f64>,
);

/// Tracks the beads of `detections` (and the confidence candidates of Eq. (1), when given)
/// with the bedload tracker of `overrides` (`key=value`, keys of `BedloadTrackerParams`);
/// returns the track columns plus `state` (motion-state names) and `class`.
#[pyfunction]
#[pyo3(signature = (detections, overrides, candidates=None))]
pub fn track_bedload<'py>(
    py: Python<'py>,
    detections: Columns<'py>,
    overrides: Vec<String>,
    candidates: Option<Columns<'py>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut params = BedloadTrackerParams::default();
    for assignment in &overrides {
        set_key(&mut params, assignment).map_err(to_py)?;
    }
    params.validate().map_err(to_py)?;
    let found = views(&detections);
    let candidates = candidates.as_ref().map(views);
    let points = py
        .detach(|| {
            let mut frames: BTreeMap<FrameIndex, BeadFrame> = BTreeMap::new();
            add_rows("detections", found, &mut frames, |frame| {
                &mut frame.detections
            })?;
            if let Some(candidates) = candidates {
                add_rows("candidates", candidates, &mut frames, |frame| {
                    &mut frame.candidates
                })?;
            }
            let (Some(&first), Some(&last)) = (frames.keys().next(), frames.keys().last()) else {
                return Err(Error::input("the detections table has no row"));
            };
            let all: Vec<BeadFrame> = (first..=last)
                .map(|frame| {
                    frames.remove(&frame).unwrap_or(BeadFrame {
                        frame,
                        ..BeadFrame::default()
                    })
                })
                .collect();
            track_beads(&params, &all)
        })
        .map_err(to_py)?;
    let columns = track_columns(py, &points)?;
    add_state_and_class(&columns, &points)?;
    Ok(columns)
}

/// Adds to `columns` the columns `state` (motion-state names) and `class` of `points`: shared
/// by tracked beads and the synthetic bedload truth.
pub(crate) fn add_state_and_class(
    columns: &Bound<'_, PyDict>,
    points: &[TrackPoint],
) -> PyResult<()> {
    let states: Vec<&str> = points.iter().map(|p| p.motion_state.name()).collect();
    let classes: Vec<i64> = points.iter().map(|p| i64::from(p.class)).collect();
    columns.set_item("state", states)?;
    columns.set_item("class", classes.into_pyarray(columns.py()))?;
    Ok(())
}

/// Read-only views of one table's columns.
type Views<'a> = (
    ArrayView1<'a, i64>,
    ArrayView1<'a, f64>,
    ArrayView1<'a, f64>,
    ArrayView1<'a, i64>,
    ArrayView1<'a, f64>,
);

fn views<'a>(columns: &'a Columns<'_>) -> Views<'a> {
    (
        columns.0.as_array(),
        columns.1.as_array(),
        columns.2.as_array(),
        columns.3.as_array(),
        columns.4.as_array(),
    )
}

/// Adds every row of a table to its frame's list chosen by `list`; negative frames or classes
/// are errors naming the table and the row.
fn add_rows(
    table: &str,
    (frame, x, y, class, score): Views<'_>,
    frames: &mut BTreeMap<FrameIndex, BeadFrame>,
    list: impl Fn(&mut BeadFrame) -> &mut Vec<Detection>,
) -> Result<()> {
    for row in 0..frame.len() {
        let (Ok(f), Ok(c)) = (u64::try_from(frame[row]), u32::try_from(class[row])) else {
            return Err(Error::input(format!(
                "{table} row {row}: frame {} and class {} must be ≥ 0",
                frame[row], class[row]
            )));
        };
        let bead = frames.entry(f).or_insert_with(|| BeadFrame {
            frame: f,
            ..BeadFrame::default()
        });
        let detection = Detection::of_class(Point2::new(x[row], y[row]), score[row] as f32, c);
        list(bead).push(detection);
    }
    Ok(())
}

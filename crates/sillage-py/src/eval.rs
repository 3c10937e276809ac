//! CLEAR MOT, IDF1 and HOTA of point tracks against their truth.

use numpy::PyReadonlyArray1;
use numpy::ndarray::ArrayView1;
use pyo3::prelude::*;
use sillage::core::{Error, Point2, Result};
use sillage::eval::evaluate_mot;
use sillage::eval::mot::{MotData, MotEstimate, MotParams, MotTruth, Shape, Similarity, TruthRole};

use crate::errors::to_py;

/// One table's columns: frame, id, x, y.
type Columns<'py> = (
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, f64>,
    PyReadonlyArray1<'py, f64>,
);

/// Scores the estimated points against the true ones (TrackEval's conventions, points
/// matched within `match_px`); returns the metrics as JSON (`clear`, `identity`, `hota`).
#[pyfunction]
pub fn evaluate(
    py: Python<'_>,
    truth: Columns<'_>,
    tracks: Columns<'_>,
    match_px: f64,
) -> PyResult<String> {
    let truth_views = (
        truth.0.as_array(),
        truth.1.as_array(),
        truth.2.as_array(),
        truth.3.as_array(),
    );
    let track_views = (
        tracks.0.as_array(),
        tracks.1.as_array(),
        tracks.2.as_array(),
        tracks.3.as_array(),
    );
    py.detach(|| {
        let truth = objects("truth", truth_views, |frame, id, centre| MotTruth {
            frame,
            id,
            shape: Shape::Point(centre),
            role: TruthRole::Scored,
        })?;
        let estimates = objects("tracks", track_views, |frame, id, centre| MotEstimate {
            frame,
            id,
            shape: Shape::Point(centre),
        })?;
        let similarity = Similarity::Distance {
            zero_distance_px: 2.0 * match_px,
        };
        let data = MotData::new(&truth, &estimates, similarity, None)
            .map_err(|e| e.in_section("match_px"))?;
        let metrics = evaluate_mot(&data, &MotParams::default())?;
        serde_json::to_string(&metrics)
            .map_err(|e| Error::input(format!("cannot write the metrics: {e}")))
    })
    .map_err(to_py)
}

/// The rows of one table as objects made by `make(frame, id, centre)`; negative frames or
/// ids are errors naming the table and the row.
fn objects<T>(
    table: &str,
    (frame, id, x, y): (
        ArrayView1<'_, i64>,
        ArrayView1<'_, i64>,
        ArrayView1<'_, f64>,
        ArrayView1<'_, f64>,
    ),
    make: impl Fn(u64, u64, Point2) -> T,
) -> Result<Vec<T>> {
    (0..frame.len())
        .map(|row| {
            let (Ok(f), Ok(i)) = (u64::try_from(frame[row]), u64::try_from(id[row])) else {
                return Err(Error::input(format!(
                    "{table} row {row}: frame {} and particle {} must be ≥ 0",
                    frame[row], id[row]
                )));
            };
            Ok(make(f, i, Point2::new(x[row], y[row])))
        })
        .collect()
}

//! CLEAR MOT, IDF1 and HOTA (and the papers' own scores) of tracks against their truth, for
//! points, bead discs and boxes, scored by `sillage::evaluate::evaluate_rows` exactly as
//! `sillage eval mot` scores files.

use numpy::PyReadonlyArray1;
use numpy::ndarray::ArrayView1;
use pyo3::prelude::*;
use sillage::core::{BoundingBox, Error, Point2, Result};
use sillage::eval::mot::{MatchRule, Shape};
use sillage::evaluate::{EvalOptions, ObjectRow, evaluate_rows};

use crate::errors::to_py;

/// One table's columns: frame, id, x, y, the box (`bb_left`, `bb_top`, `bb_width`,
/// `bb_height`) and the disc radius, NaN where a table has none.
type Columns<'py> = (
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, i64>,
    [PyReadonlyArray1<'py, f64>; 7],
);

/// Read-only views of a table's columns.
struct Table<'a> {
    frame: ArrayView1<'a, i64>,
    id: ArrayView1<'a, i64>,
    values: [ArrayView1<'a, f64>; 7],
}

impl<'a> Table<'a> {
    fn of(columns: &'a Columns<'_>) -> Self {
        Self {
            frame: columns.0.as_array(),
            id: columns.1.as_array(),
            values: std::array::from_fn(|i| columns.2[i].as_array()),
        }
    }

    /// The rows as the shapes `rule` compares; a row without the shape's values, or with a
    /// negative frame or id, is an error naming the table, the row and the fix.
    fn rows(&self, name: &str, rule: MatchRule) -> Result<Vec<ObjectRow>> {
        (0..self.frame.len())
            .map(|row| {
                let (Ok(frame), Ok(id)) =
                    (u64::try_from(self.frame[row]), u64::try_from(self.id[row]))
                else {
                    return Err(Error::input(format!(
                        "{name} row {row}: frame {} and particle {} must be ≥ 0",
                        self.frame[row], self.id[row]
                    )));
                };
                let [x, y, left, top, width, height, radius] = self.values.map(|c| c[row]);
                let missing = |what: &str| {
                    Error::input(format!(
                        "{name} row {row}: --match {rule} compares {what}; give them finite"
                    ))
                };
                let shape = match rule {
                    MatchRule::Distance { .. } => Shape::Point(Point2::new(x, y)),
                    MatchRule::Iou { .. } => {
                        if ![left, top, width, height].iter().all(|v| v.is_finite()) {
                            return Err(missing("boxes (bb_left, bb_top, bb_width, bb_height)"));
                        }
                        Shape::Box(BoundingBox {
                            left_px: left,
                            top_px: top,
                            width_px: width,
                            height_px: height,
                        })
                    }
                    MatchRule::Disc { .. } => {
                        if !radius.is_finite() {
                            return Err(missing("discs (a radius per row or per class)"));
                        }
                        Shape::Disc {
                            centre_px: Point2::new(x, y),
                            radius_px: radius,
                        }
                    }
                };
                Ok(ObjectRow { frame, id, shape })
            })
            .collect()
    }
}

/// Scores `tracks` against `truth` under the match rule `rule` (`iou:0.5`, `disc:0.43`,
/// `dist:1`), with the papers' scores when `papers`; returns the combined scores as JSON
/// (`metrics` with `clear`, `identity`, `hota`; `papers` when asked).
#[pyfunction]
#[pyo3(signature = (truth, tracks, rule, papers=false))]
pub fn evaluate(
    py: Python<'_>,
    truth: Columns<'_>,
    tracks: Columns<'_>,
    rule: &str,
    papers: bool,
) -> PyResult<String> {
    let rule: MatchRule = rule.parse().map_err(to_py)?;
    let (truth, tracks) = (Table::of(&truth), Table::of(&tracks));
    py.detach(|| {
        let options = EvalOptions {
            rule,
            papers,
            ..EvalOptions::default()
        };
        let evaluation = evaluate_rows(
            "python",
            &truth.rows("truth", rule)?,
            &tracks.rows("tracks", rule)?,
            &options,
        )?;
        serde_json::to_string(&evaluation.combined)
            .map_err(|e| Error::input(format!("cannot write the scores: {e}")))
    })
    .map_err(to_py)
}

//! Charts of the image plane (trajectories, velocity arrows): pixel coordinates with `x` to
//! the right and `y` down, as on the frames, at the same scale on both axes.

use std::ops::Range;

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use sillage_core::{Error, Point2, Result};

use crate::canvas::drawing_error;
use crate::font::FAMILY;

/// A chart whose coordinates are image pixels.
pub(crate) type PlaneChart<'a, DB> =
    ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Blank space around the chart, px.
const MARGIN: u32 = 10;
/// Room for the x axis's ticks and title, px.
const X_LABELS: u32 = 40;
/// Room for the y axis's ticks and title, px.
const Y_LABELS: u32 = 56;

/// The smallest box holding every point of `points`, grown by 3 % (at least 1 px) on each
/// side; an error naming `what` when no point is finite.
pub(crate) fn bounds(points: impl Iterator<Item = Point2>, what: &str) -> Result<[Range<f64>; 2]> {
    let mut x = f64::INFINITY..f64::NEG_INFINITY;
    let mut y = x.clone();
    for p in points.filter(|p| p.is_finite()) {
        x = x.start.min(p.x)..x.end.max(p.x);
        y = y.start.min(p.y)..y.end.max(p.y);
    }
    if x.start > x.end {
        return Err(Error::input(format!(
            "{what}: no point with a finite position to draw"
        )));
    }
    let pad = |r: Range<f64>| {
        let pad = (0.03 * (r.end - r.start)).max(1.0);
        r.start - pad..r.end + pad
    };
    Ok([pad(x), pad(y)])
}

/// A chart of the image plane in `area`, titled, framing `bounds` ([x, y] in px) at the same
/// scale on both axes (the shorter side widened, centred), `y` growing downwards.
pub(crate) fn plane_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    title: &str,
    bounds: &[Range<f64>; 2],
) -> Result<PlaneChart<'a, DB>> {
    let area = area.titled(title, (FAMILY, 18)).map_err(drawing_error)?;
    let (width, height) = area.dim_in_pixel();
    let plot_w = f64::from(width.saturating_sub(Y_LABELS + 2 * MARGIN).max(1));
    let plot_h = f64::from(height.saturating_sub(X_LABELS + 2 * MARGIN).max(1));
    let [x, y] = bounds;
    let px_per_unit = (plot_w / (x.end - x.start)).min(plot_h / (y.end - y.start));
    let widen = |r: &Range<f64>, span_px: f64| {
        let centre = 0.5 * (r.start + r.end);
        let half = 0.5 * span_px / px_per_unit;
        centre - half..centre + half
    };
    let x = widen(x, plot_w);
    let y = widen(y, plot_h);
    let mut chart = ChartBuilder::on(&area)
        .margin(MARGIN)
        .x_label_area_size(X_LABELS)
        .y_label_area_size(Y_LABELS)
        // Reversed: the top of the chart is the smallest y, as on the frames.
        .build_cartesian_2d(x, y.end..y.start)
        .map_err(drawing_error)?;
    chart
        .configure_mesh()
        .light_line_style(TRANSPARENT)
        .bold_line_style(RGBColor(230, 230, 230))
        .x_desc("x (px)")
        .y_desc("y (px)")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .label_style((FAMILY, 12))
        .axis_desc_style((FAMILY, 13))
        .draw()
        .map_err(drawing_error)?;
    Ok(chart)
}

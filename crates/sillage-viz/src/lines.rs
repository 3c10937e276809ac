//! Line charts of quantities along the frames (counts of detections and of tracks per
//! frame), one curve per series with a legend.

use plotters::coord::Shift;
use plotters::prelude::*;
use sillage_core::{Error, Result};

use crate::canvas::{Plot, drawing_error};
use crate::font::FAMILY;
use crate::legend::{LegendEntry, Mark, draw_legend};
use crate::palette::series_colour;

/// Height of the legend strip, px.
const LEGEND_HEIGHT: u32 = 28;

/// One curve: its legend text and its points in x order.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Legend text.
    pub label: String,
    /// `(x, y)` points, drawn joined in this order.
    pub points: Vec<(f64, f64)>,
}

/// Curves against a shared x axis and a y axis from 0.
#[derive(Debug, Clone, PartialEq)]
pub struct LineChart {
    /// Title above the chart.
    pub title: String,
    /// Title of the x axis.
    pub x_label: String,
    /// Title of the y axis.
    pub y_label: String,
    /// The curves; curve `i` takes the `i`-th series colour.
    pub curves: Vec<Curve>,
}

impl LineChart {
    /// Every finite point of every curve.
    fn points(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.curves
            .iter()
            .flat_map(|c| c.points.iter().copied())
            .filter(|(x, y)| x.is_finite() && y.is_finite())
    }
}

impl Plot for LineChart {
    /// Checks that a curve has a finite point.
    fn validate(&self) -> Result<()> {
        if self.points().next().is_none() {
            return Err(Error::input(format!("{}: no point to draw", self.title)));
        }
        Ok(())
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let (legend, area) = root.split_vertically(LEGEND_HEIGHT);
        let entries: Vec<LegendEntry<'_>> = self
            .curves
            .iter()
            .enumerate()
            .map(|(i, c)| LegendEntry {
                label: &c.label,
                colour: series_colour(i),
                mark: Mark::Line,
            })
            .collect();
        draw_legend(&legend, 70, &entries)?;
        let (x_min, x_max, y_min, y_max) = self.points().fold(
            (f64::INFINITY, f64::NEG_INFINITY, 0.0f64, 0.0f64),
            |(a, b, c, d), (x, y)| (a.min(x), b.max(x), c.min(y), d.max(y)),
        );
        let x_range = if x_min < x_max {
            x_min..x_max
        } else {
            x_min - 0.5..x_min + 0.5
        };
        // The y axis always shows 0 (counts from 0; signed profiles such as ⟨u'v'⟩ across it).
        let y_range = if y_max > y_min {
            let pad = 0.08 * (y_max - y_min);
            (if y_min < 0.0 { y_min - pad } else { 0.0 })..(if y_max > 0.0 {
                y_max + pad
            } else {
                0.0
            })
        } else {
            0.0..1.0
        };
        let (x_span, y_span) = (x_range.end - x_range.start, y_range.end - y_range.start);
        let mut chart = ChartBuilder::on(&area)
            .caption(&self.title, (FAMILY, 18))
            .margin(10)
            .x_label_area_size(44)
            .y_label_area_size(60)
            .build_cartesian_2d(x_range, y_range)
            .map_err(drawing_error)?;
        chart
            .configure_mesh()
            .light_line_style(TRANSPARENT)
            .bold_line_style(RGBColor(230, 230, 230))
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .x_label_formatter(&|v| tick_label(*v, x_span))
            .y_label_formatter(&|v| tick_label(*v, y_span))
            .label_style((FAMILY, 12))
            .axis_desc_style((FAMILY, 13))
            .draw()
            .map_err(drawing_error)?;
        for (i, curve) in self.curves.iter().enumerate() {
            let points = curve
                .points
                .iter()
                .copied()
                .filter(|(x, y)| x.is_finite() && y.is_finite());
            chart
                .draw_series(LineSeries::new(points, series_colour(i).stroke_width(2)))
                .map_err(drawing_error)?;
        }
        Ok(())
    }
}

/// A tick value with as many decimals as an axis spanning `span` needs (whole numbers from a
/// span of 100 up; 0.0012 on a span of 0.01).
fn tick_label(value: f64, span: f64) -> String {
    let decimals = (2.0 - span.log10().floor()).clamp(0.0, 9.0) as usize;
    format!("{value:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart() -> LineChart {
        LineChart {
            title: "per frame".into(),
            x_label: "frame".into(),
            y_label: "count".into(),
            curves: vec![
                Curve {
                    label: "detections".into(),
                    points: (0..50).map(|f| (f as f64, 100.0)).collect(),
                },
                Curve {
                    label: "tracks".into(),
                    points: (0..50).map(|f| (f as f64, 50.0)).collect(),
                },
            ],
        }
    }

    /// The rows holding a long run of the `i`-th series colour.
    fn rows(picture: &sillage_core::RgbImage, i: usize) -> Vec<usize> {
        let c = series_colour(i);
        (0..picture.height())
            .filter(|&y| {
                picture
                    .row(y)
                    .iter()
                    .filter(|&&p| p == [c.0, c.1, c.2])
                    .count()
                    > 100
            })
            .collect()
    }

    #[test]
    fn curves_sit_at_their_height_from_zero() {
        let picture = chart().to_rgb(400, 300).unwrap();
        let (high, low) = (rows(&picture, 0), rows(&picture, 1));
        assert!(!high.is_empty() && !low.is_empty());
        // y = 100 near the top, y = 50 half way down to the x axis.
        let axis = (0..300)
            .rev()
            .find(|&y| {
                picture.row(y)[80..380]
                    .iter()
                    .filter(|p| **p == [0, 0, 0])
                    .count()
                    > 200
            })
            .expect("an x axis");
        let (h, l) = ((axis - high[0]) as f64, (axis - low[0]) as f64);
        assert!((l / h - 0.5).abs() < 0.03, "{h} {l}");
        let svg = chart().to_svg(400, 300).unwrap();
        for text in ["detections", "tracks", "frame", "count", "per frame"] {
            assert!(svg.contains(text), "{text} missing");
        }
        let empty = LineChart {
            curves: vec![],
            ..chart()
        };
        assert!(
            empty
                .to_rgb(400, 300)
                .unwrap_err()
                .to_string()
                .contains("no point")
        );
    }

    #[test]
    fn negative_values_lie_below_a_positive_one_and_ticks_fit_the_span() {
        let mut chart = chart();
        chart.curves[0].points = (0..50).map(|f| (f as f64, 1.0)).collect();
        chart.curves[1].points = (0..50).map(|f| (f as f64, -1.0)).collect();
        let picture = chart.to_rgb(400, 300).unwrap();
        let (positive, negative) = (rows(&picture, 0), rows(&picture, 1));
        assert!(!positive.is_empty() && !negative.is_empty());
        assert!(negative[0] > positive[0] + 100, "{positive:?} {negative:?}");
        assert_eq!(tick_label(1200.0, 1000.0), "1200");
        assert_eq!(tick_label(0.0012, 0.01), "0.0012");
        assert_eq!(tick_label(2.5, 5.0), "2.50");
    }
}

//! Grouped bar charts with optional curves on a second axis: the layout of the MMPF+ paper's
//! Fig. 6 (bars: correct tracks, left scale; curves: MOTA, right scale) and Fig. 7 (bars:
//! F-score per motion state), drawn side by side as the panels of a [`Figure`].

use plotters::coord::Shift;
use plotters::prelude::*;
use sillage_core::{Error, Result};

use crate::canvas::{Plot, drawing_error};
use crate::font::FAMILY;
use crate::legend::{LegendEntry, Mark, draw_legend};
use crate::palette::series_colour;

/// One named series of a chart: one value per category (`None`: no value there).
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// One value per category of the chart, in its order.
    pub values: Vec<Option<f64>>,
}

/// A value axis: its title and range.
#[derive(Debug, Clone, PartialEq)]
pub struct ValueAxis {
    /// Axis title (quantity and unit).
    pub label: String,
    /// Lower end; bars rise from it.
    pub min: f64,
    /// Upper end.
    pub max: f64,
}

/// Categories along x; per category, one bar per bar series against the left axis; and, when
/// `line_axis` is set, one curve per line series against the right axis. Series `i` of bars
/// and series `i` of lines share a colour, so a tracker keeps its colour in both.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupedChart {
    /// Title above the chart.
    pub title: String,
    /// Title of the category axis.
    pub x_label: String,
    /// Category names, left to right.
    pub categories: Vec<String>,
    /// The left axis, for the bars.
    pub bar_axis: ValueAxis,
    /// Bar series (may be empty).
    pub bars: Vec<Series>,
    /// The right axis, for the curves (`None`: no curves).
    pub line_axis: Option<ValueAxis>,
    /// Curve series, drawn only with a `line_axis`.
    pub lines: Vec<Series>,
}

/// Charts drawn side by side, each in a panel of the same size.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Figure {
    /// The panels, left to right.
    pub panels: Vec<GroupedChart>,
}

/// Height of the legend strip above each chart, px.
const LEGEND_HEIGHT: u32 = 28;

impl GroupedChart {
    /// Checks that every series has one value per category, that values are finite and that
    /// each axis is a finite, non-empty range.
    pub fn validate(&self) -> Result<()> {
        let what = |detail: String| Error::input(format!("chart \"{}\": {detail}", self.title));
        if self.categories.is_empty() {
            return Err(what("no category to draw".into()));
        }
        let axes = std::iter::once(&self.bar_axis).chain(&self.line_axis);
        for axis in axes {
            if !(axis.min.is_finite() && axis.max.is_finite() && axis.min < axis.max) {
                return Err(what(format!(
                    "axis \"{}\" needs finite min < max, got {} .. {}",
                    axis.label, axis.min, axis.max
                )));
            }
        }
        for series in self.bars.iter().chain(&self.lines) {
            if series.values.len() != self.categories.len() {
                return Err(what(format!(
                    "series \"{}\" has {} values for {} categories",
                    series.label,
                    series.values.len(),
                    self.categories.len()
                )));
            }
            if series.values.iter().flatten().any(|v| !v.is_finite()) {
                return Err(what(format!(
                    "series \"{}\" holds a value that is not finite",
                    series.label
                )));
            }
        }
        Ok(())
    }

    /// Draws this chart, its legend in a strip on top, into `area`.
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let (legend_area, plot_area) = area.split_vertically(LEGEND_HEIGHT);
        self.draw_legend(&legend_area)?;
        let n = self.categories.len();
        let x_range = -0.5..n as f64 - 0.5;
        let right = self.line_axis.as_ref();
        let mut builder = ChartBuilder::on(&plot_area);
        builder
            .caption(&self.title, (FAMILY, 18))
            .margin(8)
            .x_label_area_size(44)
            .y_label_area_size(58)
            .right_y_label_area_size(if right.is_some() { 58 } else { 8 });
        let bar_range = self.bar_axis.min..self.bar_axis.max;
        let line_range = right.map_or(bar_range.clone(), |a| a.min..a.max);
        let mut chart = builder
            .build_cartesian_2d(x_range.clone(), bar_range)
            .map_err(drawing_error)?
            .set_secondary_coord(x_range, line_range);
        let categories = &self.categories;
        let category_at = |x: &f64| {
            let i = x.round();
            let on_tick = (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < categories.len();
            if on_tick {
                categories[i as usize].clone()
            } else {
                String::new()
            }
        };
        let bar_ticks = |v: &f64| tick_label(&self.bar_axis, *v);
        chart
            .configure_mesh()
            .disable_x_mesh()
            .light_line_style(TRANSPARENT)
            .bold_line_style(RGBColor(225, 225, 225))
            .x_labels(n + 1)
            .x_label_formatter(&category_at)
            .y_label_formatter(&bar_ticks)
            .x_desc(&self.x_label)
            .y_desc(&self.bar_axis.label)
            .label_style((FAMILY, 13))
            .axis_desc_style((FAMILY, 14))
            .draw()
            .map_err(drawing_error)?;
        let group_width = 0.8;
        let bar_width = group_width / self.bars.len().max(1) as f64;
        let base = self.bar_axis.min;
        for (i, series) in self.bars.iter().enumerate() {
            let colour = series_colour(i);
            let bars = series.values.iter().enumerate().filter_map(|(c, v)| {
                let x0 = c as f64 - group_width / 2.0 + i as f64 * bar_width;
                v.map(|v| Rectangle::new([(x0, base), (x0 + 0.9 * bar_width, v)], colour.filled()))
            });
            chart.draw_series(bars).map_err(drawing_error)?;
        }
        if let Some(axis) = right {
            let line_ticks = |v: &f64| tick_label(axis, *v);
            chart
                .configure_secondary_axes()
                .y_label_formatter(&line_ticks)
                .y_desc(&axis.label)
                .label_style((FAMILY, 13))
                .axis_desc_style((FAMILY, 14))
                .draw()
                .map_err(drawing_error)?;
            for (i, series) in self.lines.iter().enumerate() {
                let colour = series_colour(i);
                let points: Vec<(f64, f64)> = series
                    .values
                    .iter()
                    .enumerate()
                    .filter_map(|(c, v)| v.map(|v| (c as f64, v)))
                    .collect();
                chart
                    .draw_secondary_series(LineSeries::new(
                        points.iter().copied(),
                        colour.stroke_width(2),
                    ))
                    .map_err(drawing_error)?;
                chart
                    .draw_secondary_series(
                        points.iter().map(|&p| Circle::new(p, 3, colour.filled())),
                    )
                    .map_err(drawing_error)?;
            }
        }
        Ok(())
    }

    /// The legend: one entry per bar series (a box), then per curve without a bar twin (a
    /// line), left to right.
    fn draw_legend<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let curves_only = if self.line_axis.is_some() {
            &self.lines[self.bars.len().min(self.lines.len())..]
        } else {
            &[]
        };
        let bars = self.bars.iter().map(|s| (s, Mark::Box));
        let curves = curves_only.iter().map(|s| (s, Mark::Line));
        let entries: Vec<LegendEntry<'_>> = bars
            .chain(curves)
            .enumerate()
            .map(|(i, (series, mark))| LegendEntry {
                label: &series.label,
                colour: series_colour(i),
                mark,
            })
            .collect();
        draw_legend(area, 60, &entries)
    }
}

impl Plot for Figure {
    /// Checks every panel (see [`GroupedChart::validate`]) and that there is one.
    fn validate(&self) -> Result<()> {
        if self.panels.is_empty() {
            return Err(Error::input("a figure needs at least one chart"));
        }
        self.panels.iter().try_for_each(GroupedChart::validate)
    }

    /// The panels side by side, each a same share of the width.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let areas = root.split_evenly((1, self.panels.len()));
        for (panel, area) in self.panels.iter().zip(&areas) {
            panel.draw(area)?;
        }
        Ok(())
    }
}

/// A tick value of `axis`: whole numbers on wide axes, one decimal on narrow ones (F-scores).
fn tick_label(axis: &ValueAxis, value: f64) -> String {
    if axis.max - axis.min > 10.0 {
        format!("{value:.0}")
    } else {
        format!("{value:.1}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart() -> GroupedChart {
        GroupedChart {
            title: "Fig. 6".into(),
            x_label: "τ_t".into(),
            categories: vec!["0.15".into(), "0.25".into(), "0.35".into()],
            bar_axis: ValueAxis {
                label: "correct tracks %".into(),
                min: 0.0,
                max: 100.0,
            },
            bars: vec![Series {
                label: "MMPF+".into(),
                values: vec![Some(90.0), Some(95.0), None],
            }],
            line_axis: Some(ValueAxis {
                label: "MOTA %".into(),
                min: 50.0,
                max: 100.0,
            }),
            lines: vec![Series {
                label: "MMPF+".into(),
                values: vec![Some(70.0), Some(99.0), Some(96.0)],
            }],
        }
    }

    fn count(picture: &sillage_core::RgbImage, colour: RGBColor) -> usize {
        let want = [colour.0, colour.1, colour.2];
        picture.as_slice().iter().filter(|&&p| p == want).count()
    }

    #[test]
    fn bars_are_drawn_to_their_height() {
        let mut tall = chart();
        tall.line_axis = None;
        let mut short = tall.clone();
        short.bars[0].values = vec![Some(45.0), Some(47.5), None];
        let blue = series_colour(0);
        let tall_px = count(
            &Figure { panels: vec![tall] }.to_rgb(400, 300).unwrap(),
            blue,
        );
        let short_px = count(
            &Figure {
                panels: vec![short],
            }
            .to_rgb(400, 300)
            .unwrap(),
            blue,
        );
        // Half the height, the same widths: half the pixels (legend box aside).
        let legend_box = 15 * 13;
        let ratio = (short_px - legend_box) as f64 / (tall_px - legend_box) as f64;
        assert!((ratio - 0.5).abs() < 0.05, "{short_px} vs {tall_px}");
    }

    #[test]
    fn panels_sit_side_by_side_and_svg_has_the_texts() {
        let figure = Figure {
            panels: vec![chart(), chart()],
        };
        let picture = figure.to_rgb(640, 240).unwrap();
        assert_eq!(picture.dimensions(), (640, 240));
        let svg = figure.to_svg(640, 240).unwrap();
        for text in ["Fig. 6", "MOTA %", "correct tracks %", "MMPF+", "0.25"] {
            assert!(svg.contains(text), "{text} missing");
        }
    }

    #[test]
    fn malformed_charts_are_refused_with_the_reason() {
        let mut short = chart();
        short.bars[0].values.pop();
        let e = Figure {
            panels: vec![short],
        }
        .to_rgb(100, 100)
        .unwrap_err();
        assert!(e.to_string().contains("2 values for 3 categories"), "{e}");
        let mut nan = chart();
        nan.lines[0].values[0] = Some(f64::NAN);
        assert!(
            nan.validate()
                .unwrap_err()
                .to_string()
                .contains("not finite")
        );
        let mut flat = chart();
        flat.bar_axis.max = 0.0;
        assert!(
            flat.validate()
                .unwrap_err()
                .to_string()
                .contains("min < max")
        );
        assert!(Figure::default().validate().is_err());
    }
}

//! A field on a regular grid drawn as coloured cells with a colour bar (the Eulerian maps of
//! the TracTrac paper's Fig. 6c: mean speed, turbulent kinetic energy), `y` pointing down as
//! in the image.

use plotters::coord::Shift;
use plotters::prelude::*;
use sillage_core::{Error, Result};

use crate::canvas::{Plot, drawing_error};
use crate::colormap::viridis;
use crate::font::FAMILY;

/// One cell: its top-left corner, its side and its value (NaN cells are left blank).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeatCell {
    /// Left edge.
    pub x: f64,
    /// Top edge.
    pub y: f64,
    /// Side length.
    pub size: f64,
    /// The value shown by the cell's colour.
    pub value: f64,
}

/// A heatmap: cells coloured by value on the viridis scale between the finite values'
/// minimum and maximum.
#[derive(Debug, Clone, PartialEq)]
pub struct Heatmap {
    /// Title above the map.
    pub title: String,
    /// What the colour bar measures, with its unit.
    pub value_label: String,
    /// The axes' unit, e.g. `px` or `m`.
    pub axis_unit: String,
    /// The cells.
    pub cells: Vec<HeatCell>,
}

/// Width of the colour bar's panel, px.
const BAR_PANEL: u32 = 110;

impl Heatmap {
    /// The finite values' range (a degenerate range is widened so colours stay defined).
    fn value_range(&self) -> Result<(f64, f64)> {
        let finite = self.cells.iter().map(|c| c.value).filter(|v| v.is_finite());
        let (low, high) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        if !low.is_finite() {
            return Err(Error::input(format!(
                "heatmap `{}` has no finite value to show",
                self.title
            )));
        }
        let pad = if high > low {
            0.0
        } else {
            low.abs().max(1.0) * 1e-6
        };
        Ok((low - pad, high + pad))
    }

    /// The extent of the cells, `(x0, x1, y0, y1)`.
    fn extent(&self) -> (f64, f64, f64, f64) {
        self.cells.iter().fold(
            (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ),
            |(x0, x1, y0, y1), c| {
                (
                    x0.min(c.x),
                    x1.max(c.x + c.size),
                    y0.min(c.y),
                    y1.max(c.y + c.size),
                )
            },
        )
    }
}

impl Plot for Heatmap {
    /// Checks that a cell has a finite value.
    fn validate(&self) -> Result<()> {
        self.value_range().map(drop)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let (low, high) = self.value_range()?;
        let colour = |v: f64| {
            let [r, g, b] = viridis((v - low) / (high - low));
            RGBColor(r, g, b)
        };
        let width = root.dim_in_pixel().0;
        let (map_area, bar_area) = root.split_horizontally(width.saturating_sub(BAR_PANEL));
        let (x0, x1, y0, y1) = self.extent();
        let mut chart = ChartBuilder::on(&map_area)
            .caption(&self.title, (FAMILY, 18))
            .margin(8)
            .x_label_area_size(32)
            .y_label_area_size(52)
            // y down, as in the image.
            .build_cartesian_2d(x0..x1, y1..y0)
            .map_err(drawing_error)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(format!("x ({})", self.axis_unit))
            .y_desc(format!("y ({})", self.axis_unit))
            .label_style((FAMILY, 12))
            .draw()
            .map_err(drawing_error)?;
        chart
            .draw_series(self.cells.iter().filter(|c| c.value.is_finite()).map(|c| {
                Rectangle::new(
                    [(c.x, c.y), (c.x + c.size, c.y + c.size)],
                    colour(c.value).filled(),
                )
            }))
            .map_err(drawing_error)?;
        let mut bar = ChartBuilder::on(&bar_area)
            .margin_top(34)
            .margin_bottom(40)
            .margin_right(8)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..1.0, low..high)
            .map_err(drawing_error)?;
        bar.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_desc(&self.value_label)
            .label_style((FAMILY, 12))
            .draw()
            .map_err(drawing_error)?;
        const STEPS: usize = 64;
        let step = (high - low) / STEPS as f64;
        bar.draw_series((0..STEPS).map(|k| {
            let v = low + step * k as f64;
            Rectangle::new([(0.0, v), (1.0, v + step)], colour(v + 0.5 * step).filled())
        }))
        .map_err(drawing_error)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_core::RgbImage;

    fn map() -> Heatmap {
        Heatmap {
            title: "mean speed".into(),
            value_label: "px/frame".into(),
            axis_unit: "px".into(),
            cells: vec![
                HeatCell {
                    x: 0.0,
                    y: 0.0,
                    size: 10.0,
                    value: 0.0,
                },
                HeatCell {
                    x: 10.0,
                    y: 0.0,
                    size: 10.0,
                    value: 1.0,
                },
                HeatCell {
                    x: 0.0,
                    y: 10.0,
                    size: 10.0,
                    value: f64::NAN,
                },
                HeatCell {
                    x: 10.0,
                    y: 10.0,
                    size: 10.0,
                    value: 1.0,
                },
            ],
        }
    }

    fn count(picture: &RgbImage, rgb: [u8; 3]) -> usize {
        picture.as_slice().iter().filter(|&&p| p == rgb).count()
    }

    #[test]
    fn cells_take_the_colours_of_their_values() {
        let picture = map().to_rgb(500, 400).unwrap();
        let low = count(&picture, viridis(0.0));
        let high = count(&picture, viridis(1.0));
        // One low cell, two high cells (plus a sliver of each in the colour bar).
        assert!(low > 1000, "low cell pixels {low}");
        assert!(
            high > 2 * low - 400 && high < 2 * low + 400,
            "high {high} vs low {low}"
        );
    }

    #[test]
    fn svg_has_the_title_and_a_field_without_values_is_refused() {
        assert!(map().to_svg(500, 400).unwrap().contains("mean speed"));
        let mut empty = map();
        empty.cells.iter_mut().for_each(|c| c.value = f64::NAN);
        let error = empty.to_rgb(200, 200).unwrap_err().to_string();
        assert!(error.contains("no finite value"), "{error}");
    }
}

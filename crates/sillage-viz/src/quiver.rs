//! Velocity arrows at one frame (a quiver plot): an arrow from each object's position along
//! its velocity, lengths scaled so the arrows fill the space between objects, and a key
//! arrow of a round speed.

use plotters::coord::Shift;
use plotters::prelude::*;
use sillage_core::{Error, Point2, Result, Vec2};

use crate::canvas::{Plot, drawing_error};
use crate::font::FAMILY;
use crate::image_plane::{bounds, plane_chart};
use crate::palette::series_colour;

/// Height of the strip holding the key arrow, px.
const KEY_HEIGHT: u32 = 28;

/// One arrow: where an object is and how fast it moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arrow {
    /// Position, px.
    pub pos_px: Point2,
    /// Velocity, px/frame.
    pub vel_px_per_frame: Vec2,
}

/// Velocity arrows on the image plane (`x` right, `y` down, same scale on both).
#[derive(Debug, Clone, PartialEq)]
pub struct QuiverPlot {
    /// Title above the chart.
    pub title: String,
    /// The arrows.
    pub arrows: Vec<Arrow>,
    /// Arrow length on the image plane per unit of speed, px per (px/frame); `None`: the
    /// 90th-percentile speed is drawn as long as the mean spacing of the objects.
    pub length_per_speed: Option<f64>,
}

impl QuiverPlot {
    /// The scale used: [`QuiverPlot::length_per_speed`], or the automatic one.
    pub fn scale(&self) -> f64 {
        if let Some(scale) = self.length_per_speed {
            return scale;
        }
        let mut speeds: Vec<f64> = self.finite().map(|a| a.vel_px_per_frame.norm()).collect();
        speeds.sort_by(f64::total_cmp);
        let typical = speeds
            .get(((speeds.len().max(1) - 1) as f64 * 0.9).round() as usize)
            .copied()
            .filter(|&s| s > 0.0)
            .unwrap_or(1.0);
        let spacing = bounds(self.finite().map(|a| a.pos_px), &self.title)
            .map(|[x, y]| {
                ((x.end - x.start) * (y.end - y.start) / speeds.len().max(1) as f64).sqrt()
            })
            .unwrap_or(1.0);
        spacing / typical
    }

    /// The arrows with a finite position and velocity.
    fn finite(&self) -> impl Iterator<Item = &Arrow> {
        self.arrows
            .iter()
            .filter(|a| a.pos_px.is_finite() && a.vel_px_per_frame.is_finite())
    }
}

impl Plot for QuiverPlot {
    /// Checks that there is an arrow with a finite position and velocity, and the scale.
    fn validate(&self) -> Result<()> {
        if self.finite().next().is_none() {
            return Err(Error::input(format!("{}: no velocity to draw", self.title)));
        }
        match self.length_per_speed {
            Some(s) if !(s.is_finite() && s > 0.0) => Err(Error::parameter(
                "length_per_speed",
                s,
                "give a positive arrow length per px/frame",
            )),
            _ => Ok(()),
        }
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let (key_area, plane) = root.split_vertically(KEY_HEIGHT);
        let scale = self.scale();
        let ends = self
            .finite()
            .flat_map(|a| [a.pos_px, a.pos_px + a.vel_px_per_frame * scale]);
        let mut chart = plane_chart(&plane, &self.title, &bounds(ends, &self.title)?)?;
        let colour = series_colour(0);
        let arrows = self
            .finite()
            .flat_map(|a| arrow_lines(a.pos_px, a.vel_px_per_frame * scale));
        chart
            .draw_series(arrows.map(|line| PathElement::new(line, colour.stroke_width(1))))
            .map_err(drawing_error)?;
        // The key: an arrow of a round speed near the typical one, at the chart's scale.
        let (x_range, _) = (chart.x_range(), chart.y_range());
        let (width, _) = chart.plotting_area().dim_in_pixel();
        let px_per_unit = f64::from(width) / (x_range.end - x_range.start);
        let key_speed = round_speed(f64::from(width) * 0.12 / (scale * px_per_unit));
        let key_px = (key_speed * scale * px_per_unit).round() as i32;
        let (x0, y) = (60, (KEY_HEIGHT / 2) as i32);
        for line in arrow_lines(
            Point2::new(f64::from(x0), f64::from(y)),
            Vec2::new(f64::from(key_px), 0.0),
        ) {
            let line: Vec<(i32, i32)> = line
                .iter()
                .map(|&(x, y)| (x.round() as i32, y.round() as i32))
                .collect();
            key_area
                .draw(&PathElement::new(line, colour.stroke_width(2)))
                .map_err(drawing_error)?;
        }
        let label = Text::new(
            format!("{key_speed} px/frame"),
            (x0 + key_px + 8, y - 7),
            (FAMILY, 13),
        );
        key_area.draw(&label).map_err(drawing_error)?;
        Ok(())
    }
}

/// An arrow from `from` along `along`: its shaft and its two head strokes (30 % of the
/// length, ±25°).
fn arrow_lines(from: Point2, along: Vec2) -> [Vec<(f64, f64)>; 2] {
    let tip = from + along;
    let back = along * -0.3;
    let (sin, cos) = 25f64.to_radians().sin_cos();
    let turn = |s: f64| {
        Vec2::new(
            back.x * cos - s * back.y * sin,
            s * back.x * sin + back.y * cos,
        )
    };
    let (left, right) = (tip + turn(1.0), tip + turn(-1.0));
    [
        vec![(from.x, from.y), (tip.x, tip.y)],
        vec![(left.x, left.y), (tip.x, tip.y), (right.x, right.y)],
    ]
}

/// The 1-2-5 number nearest below `speed` (at least the smallest positive one).
fn round_speed(speed: f64) -> f64 {
    if !(speed.is_finite() && speed > 0.0) {
        return 1.0;
    }
    let decade = 10f64.powf(speed.log10().floor());
    let mantissa = [5.0, 2.0, 1.0]
        .into_iter()
        .find(|&m| m * decade <= speed)
        .unwrap_or(1.0);
    mantissa * decade
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arrow(x: f64, y: f64, vx: f64, vy: f64) -> Arrow {
        Arrow {
            pos_px: Point2::new(x, y),
            vel_px_per_frame: Vec2::new(vx, vy),
        }
    }

    fn blue(picture: &sillage_core::RgbImage, x: usize, y: usize) -> bool {
        let c = series_colour(0);
        picture.get(x, y) == [c.0, c.1, c.2]
    }

    #[test]
    fn arrows_point_along_the_velocity_with_the_key_above() {
        // One arrow pointing right at the top left, one pointing down at the bottom right.
        let plot = QuiverPlot {
            title: "quiver".into(),
            arrows: vec![arrow(0.0, 0.0, 2.0, 0.0), arrow(100.0, 100.0, 0.0, 2.0)],
            length_per_speed: Some(20.0),
        };
        let picture = plot.to_rgb(400, 400).unwrap();
        let blue_at = |x: usize, y: usize| blue(&picture, x, y);
        // Find the first arrow's row: its shaft is a horizontal run of blue.
        let rows: Vec<usize> = (40..400)
            .filter(|&y| (0..400).filter(|&x| blue_at(x, y)).count() > 40)
            .collect();
        assert!(!rows.is_empty(), "no horizontal shaft");
        // The second arrow is a vertical run of blue in a column further right.
        let columns: Vec<usize> = (0..400)
            .filter(|&x| (40..400).filter(|&y| blue_at(x, y)).count() > 40)
            .collect();
        assert!(!columns.is_empty(), "no vertical shaft");
        // The horizontal arrow sits above (y down) and the vertical one is to the right.
        let first_row = rows[0];
        let column = columns[columns.len() - 1];
        assert!(
            (0..400)
                .filter(|&x| blue_at(x, first_row))
                .all(|x| x < column)
        );
        // The key arrow is drawn in the top strip, with its speed.
        assert!((0..KEY_HEIGHT as usize).any(|y| (0..400).any(|x| blue_at(x, y))));
        let svg = plot.to_svg(400, 400).unwrap();
        assert!(svg.contains("px/frame") && svg.contains("quiver"));
    }

    #[test]
    fn the_automatic_scale_follows_spacing_and_speed() {
        let arrows: Vec<Arrow> = (0..100)
            .map(|k| arrow(10.0 * (k % 10) as f64, 10.0 * (k / 10) as f64, 0.5, 0.0))
            .collect();
        let plot = QuiverPlot {
            title: "grid".into(),
            arrows,
            length_per_speed: None,
        };
        // Spacing about 10 px (the padded box is 96 px wide), speed 0.5: about 20.
        let scale = plot.scale();
        assert!((19.0..21.0).contains(&scale), "{scale}");
        assert_eq!(round_speed(0.37), 0.2);
        assert_eq!(round_speed(7.0), 5.0);
        assert_eq!(round_speed(1.0), 1.0);
        let empty = QuiverPlot {
            arrows: vec![arrow(0.0, 0.0, f64::NAN, 0.0)],
            ..plot
        };
        assert!(
            empty
                .to_rgb(200, 200)
                .unwrap_err()
                .to_string()
                .contains("no velocity")
        );
    }
}

//! Every trajectory of a track table drawn on the image plane as a polyline coloured by speed
//! (with a viridis colour bar), by motion state (with a legend) or by identity.

use plotters::coord::Shift;
use plotters::prelude::*;
use sillage_core::{Error, MotionState, Result};

use crate::canvas::{Plot, drawing_error};
use crate::colormap::viridis;
use crate::colouring::TrackColouring;
use crate::font::FAMILY;
use crate::history::TrackHistory;
use crate::image_plane::{bounds, plane_chart};
use crate::legend::{LegendEntry, Mark, draw_legend};
use crate::palette::state_rgb;

/// Width of the speed colour bar's strip, px.
const COLOUR_BAR_WIDTH: u32 = 84;
/// Height of the legend strip, px.
const LEGEND_HEIGHT: u32 = 28;

/// All the tracks of a table on the image plane (`x` right, `y` down, same scale on both).
#[derive(Debug, Clone)]
pub struct TrajectoryPlot {
    /// Title above the chart.
    pub title: String,
    /// The tracks to draw.
    pub tracks: TrackHistory,
    /// What the colours show; speeds get a colour bar, states a legend.
    pub colouring: TrackColouring,
}

impl Plot for TrajectoryPlot {
    /// Checks that there is a track and that the colouring is valid.
    fn validate(&self) -> Result<()> {
        if self.tracks.is_empty() {
            return Err(Error::input(format!("{}: no track to draw", self.title)));
        }
        self.colouring.validate()
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let area = match self.colouring {
            TrackColouring::Speed { max_px_per_frame } => {
                let (width, _) = root.dim_in_pixel();
                let (plane, bar) = root.split_horizontally(width.saturating_sub(COLOUR_BAR_WIDTH));
                draw_colour_bar(&bar, max_px_per_frame)?;
                plane
            }
            TrackColouring::State => {
                let (legend, plane) = root.split_vertically(LEGEND_HEIGHT);
                self.draw_state_legend(&legend)?;
                plane
            }
            TrackColouring::Id => root.clone(),
        };
        let points = self.tracks.tracks().flatten().map(|p| p.pos_px);
        let mut chart = plane_chart(&area, &self.title, &bounds(points, &self.title)?)?;
        for track in self.tracks.tracks() {
            // Runs of one colour are one polyline (a whole track when coloured by id or a
            // constant state), so SVG files stay small.
            let mut start = 0;
            while start + 1 < track.len() {
                let rgb = self.colouring.point_rgb(track, start + 1);
                let mut end = start + 1;
                while end + 1 < track.len() && self.colouring.point_rgb(track, end + 1) == rgb {
                    end += 1;
                }
                let line = track[start..=end].iter().map(|p| (p.pos_px.x, p.pos_px.y));
                let colour = RGBColor(rgb[0], rgb[1], rgb[2]);
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        line.collect::<Vec<_>>(),
                        colour.stroke_width(1),
                    )))
                    .map_err(drawing_error)?;
                start = end;
            }
        }
        Ok(())
    }
}

impl TrajectoryPlot {
    /// One box per motion state present in the tracks.
    fn draw_state_legend<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<()> {
        let present = |state: MotionState| {
            self.tracks
                .tracks()
                .flatten()
                .any(|p| p.motion_state == state)
        };
        let entries: Vec<LegendEntry<'_>> = MotionState::ALL
            .into_iter()
            .filter(|&s| present(s))
            .map(|state| {
                let [r, g, b] = state_rgb(state);
                LegendEntry {
                    label: state.name(),
                    colour: RGBColor(r, g, b),
                    mark: Mark::Line,
                }
            })
            .collect();
        draw_legend(area, 60, &entries)
    }
}

/// A vertical viridis bar from 0 (bottom) to `max_px_per_frame` (top), with five speed
/// ticks to its right and the unit above.
fn draw_colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    max_px_per_frame: f64,
) -> Result<()> {
    const STEPS: i32 = 64;
    let (_, height) = area.dim_in_pixel();
    let (top, bottom) = (56, height as i32 - 60);
    let (left, right) = (12, 30);
    let font = (FAMILY, 12).into_font();
    area.draw(&Text::new("px/frame", (left - 6, top - 22), font.clone()))
        .map_err(drawing_error)?;
    let y_at = |t: f64| bottom - (t * f64::from(bottom - top)).round() as i32;
    for k in 0..STEPS {
        let [r, g, b] = viridis((f64::from(k) + 0.5) / f64::from(STEPS));
        let (t0, t1) = (
            f64::from(k) / f64::from(STEPS),
            f64::from(k + 1) / f64::from(STEPS),
        );
        let cell = Rectangle::new(
            [(left, y_at(t1)), (right, y_at(t0))],
            RGBColor(r, g, b).filled(),
        );
        area.draw(&cell).map_err(drawing_error)?;
    }
    for tick in 0..=4 {
        let t = f64::from(tick) / 4.0;
        let y = y_at(t);
        area.draw(&PathElement::new([(right, y), (right + 4, y)], BLACK))
            .map_err(drawing_error)?;
        let label = format!("{:.2}", t * max_px_per_frame);
        area.draw(&Text::new(label, (right + 7, y - 6), font.clone()))
            .map_err(drawing_error)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use sillage_core::{Point2, RgbImage, TrackPoint};

    use super::*;
    use crate::palette::id_rgb;

    /// Track `id` along row `y` from x = 0 to 100, one point per 10 px.
    fn straight(id: u64, y: f64) -> Vec<TrackPoint> {
        (0..11)
            .map(|k| TrackPoint::at(k, id, Point2::new(10.0 * k as f64, y)))
            .collect()
    }

    fn plot(colouring: TrackColouring) -> TrajectoryPlot {
        let points = straight(1, 0.0).into_iter().chain(straight(2, 100.0));
        TrajectoryPlot {
            title: "tracks".into(),
            tracks: TrackHistory::new(points),
            colouring,
        }
    }

    /// The rows where `rgb` appears, and its number of pixels.
    fn rows_of(picture: &RgbImage, rgb: [u8; 3]) -> (Vec<usize>, usize) {
        let mut rows = Vec::new();
        let mut n = 0;
        for y in 0..picture.height() {
            let k = picture.row(y).iter().filter(|&&p| p == rgb).count();
            if k > 0 {
                rows.push(y);
                n += k;
            }
        }
        (rows, n)
    }

    #[test]
    fn tracks_are_lines_where_they_are_with_y_down() {
        let picture = plot(TrackColouring::Id).to_rgb(400, 400).unwrap();
        let (rows_1, n_1) = rows_of(&picture, id_rgb(1));
        let (rows_2, n_2) = rows_of(&picture, id_rgb(2));
        // Horizontal lines: a row or two each, the y = 0 track above the y = 100 one, each
        // spanning most of the plot's width.
        assert!(
            rows_1.len() <= 2 && rows_2.len() <= 2,
            "{rows_1:?} {rows_2:?}"
        );
        assert!(rows_1[0] + 200 < rows_2[0], "{rows_1:?} {rows_2:?}");
        assert!(n_1 > 250 && n_2 > 250, "{n_1} {n_2}");
    }

    #[test]
    fn speeds_take_viridis_and_get_a_colour_bar() {
        // 10 px/frame on a 20 px/frame scale: the middle of viridis.
        let picture = plot(TrackColouring::Speed {
            max_px_per_frame: 20.0,
        })
        .to_rgb(500, 400)
        .unwrap();
        let (_, on_line) = rows_of(&picture, viridis(0.5));
        assert!(on_line > 250, "{on_line}");
        // The bar, in the right strip, holds both ends of the map.
        let bar_has = |rgb| (0..400).any(|y| (416..500).any(|x| picture.get(x, y) == rgb));
        assert!(bar_has(viridis(0.5 / 64.0)) && bar_has(viridis(63.5 / 64.0)));
        let svg = plot(TrackColouring::Speed {
            max_px_per_frame: 20.0,
        })
        .to_svg(500, 400)
        .unwrap();
        for text in ["tracks", "px/frame", "20.00", "x (px)", "<polyline"] {
            assert!(svg.contains(text), "{text} missing");
        }
    }

    #[test]
    fn states_get_a_legend_and_empty_tables_are_refused() {
        let mut tracks: Vec<TrackPoint> = straight(1, 0.0);
        for p in &mut tracks {
            p.motion_state = MotionState::Rolling;
        }
        let plot = TrajectoryPlot {
            title: "states".into(),
            tracks: TrackHistory::new(tracks),
            colouring: TrackColouring::State,
        };
        let svg = plot.to_svg(300, 200).unwrap();
        assert!(svg.contains("rolling") && !svg.contains("saltating"));
        let empty = TrajectoryPlot {
            tracks: TrackHistory::default(),
            ..plot
        };
        let e = empty.to_rgb(300, 200).unwrap_err();
        assert!(e.to_string().contains("no track"), "{e}");
        assert!(empty.to_rgb(10, 10).is_err());
    }
}

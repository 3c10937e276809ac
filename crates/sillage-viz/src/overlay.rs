//! Overlays: a frame in grey with its detections circled, each track's tail coloured at every
//! step by its motion state, its speed or its identity ([`TrackColouring`]), its head marked
//! and its id written beside it — for looking at what a tracker did, frame by frame.

use plotters::prelude::*;
use sillage_core::{Detection, Error, GrayImage, Result, RgbImage, TrackPoint};

use crate::canvas::drawing_error;
use crate::colouring::TrackColouring;
use crate::font::{FAMILY, ensure_registered};
use crate::palette::series_colour;

/// How overlays are drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct OverlayStyle {
    /// Frames of history drawn behind each track's head.
    pub tail_frames: u64,
    /// Writes each track's id beside its head.
    pub show_ids: bool,
    /// Radius of the circle around a detection, px, per detection class (the last radius for
    /// classes beyond the list).
    pub detection_radius_px: Vec<f64>,
    /// What the tails' colours show.
    pub colouring: TrackColouring,
}

impl Default for OverlayStyle {
    /// Twenty frames of tail coloured by motion state, ids shown, 4 px circles.
    fn default() -> Self {
        Self {
            tail_frames: 20,
            show_ids: true,
            detection_radius_px: vec![4.0],
            colouring: TrackColouring::State,
        }
    }
}

impl OverlayStyle {
    /// Checks the tail length, the radii and the colouring.
    pub fn validate(&self) -> Result<()> {
        self.colouring.validate()?;
        if self.tail_frames == 0 {
            return Err(Error::parameter(
                "tail_frames",
                "0",
                "give at least 1 frame of tail",
            ));
        }
        let bad = |r: &f64| !(r.is_finite() && *r > 0.0);
        if self.detection_radius_px.is_empty() || self.detection_radius_px.iter().any(bad) {
            return Err(Error::parameter(
                "detection_radius_px",
                format!("{:?}", self.detection_radius_px),
                "give one positive radius per detection class",
            ));
        }
        Ok(())
    }
}

/// Draws `frame` with `detections` circled (coloured by class) and `tails` (each one track's
/// recent points, oldest first; see [`crate::TrackHistory::tails_at`]).
pub fn draw_overlay(
    frame: &GrayImage,
    detections: &[Detection],
    tails: &[&[TrackPoint]],
    style: &OverlayStyle,
) -> Result<RgbImage> {
    style.validate()?;
    let (width, height) = frame.dimensions();
    let pixels = frame
        .as_slice()
        .iter()
        .map(|&v| {
            // NaN becomes 0 through the saturating cast.
            let level = (v.clamp(0.0, 1.0) * 255.0).round() as u8;
            [level; 3]
        })
        .collect();
    let mut picture = RgbImage::from_vec(width, height, pixels)?;
    draw_on(&mut picture, |area| {
        for detection in detections {
            let radius = style
                .detection_radius_px
                .get(detection.class as usize)
                .or(style.detection_radius_px.last())
                .copied()
                .unwrap_or(4.0);
            let colour = series_colour(5 + detection.class as usize);
            let circle = Circle::new(
                pixel(detection.pos_px),
                radius.round() as i32,
                colour.stroke_width(2),
            );
            area.draw(&circle).map_err(drawing_error)?;
        }
        for tail in tails {
            draw_tail(area, frame, tail, style)?;
        }
        Ok(())
    })?;
    Ok(picture)
}

/// The drawing area of overlays: `picture`'s own pixels, in pixel coordinates.
pub(crate) type PixelArea<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// Runs `draw` on `picture`'s pixels (the built-in typeface registered, so text can be
/// written) and presents the result into `picture`.
pub(crate) fn draw_on(
    picture: &mut RgbImage,
    draw: impl FnOnce(&PixelArea<'_>) -> Result<()>,
) -> Result<()> {
    ensure_registered()?;
    let size = (
        u32::try_from(picture.width()).map_err(drawing_error)?,
        u32::try_from(picture.height()).map_err(drawing_error)?,
    );
    let backend = BitMapBackend::with_buffer(picture.as_mut_slice().as_flattened_mut(), size);
    let area = backend.into_drawing_area();
    draw(&area)?;
    area.present().map_err(drawing_error)
}

/// One track's tail (segments coloured as their end point), head and id.
fn draw_tail<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    frame: &GrayImage,
    tail: &[TrackPoint],
    style: &OverlayStyle,
) -> Result<()> {
    let Some(head) = tail.last() else {
        return Ok(());
    };
    let colour = |i: usize| {
        let [r, g, b] = style.colouring.point_rgb(tail, i);
        RGBColor(r, g, b)
    };
    for (i, pair) in tail.windows(2).enumerate() {
        let segment = PathElement::new(
            [pixel(pair[0].pos_px), pixel(pair[1].pos_px)],
            colour(i + 1).stroke_width(2),
        );
        area.draw(&segment).map_err(drawing_error)?;
    }
    let (x, y) = pixel(head.pos_px);
    area.draw(&Circle::new((x, y), 2, colour(tail.len() - 1).filled()))
        .map_err(drawing_error)?;
    if style.show_ids {
        // Dark text on bright backgrounds (backlit beads), bright text on dark ones (PTV).
        let bright = frame_level(frame, x, y) > 0.5;
        let ink = if bright { BLACK } else { WHITE };
        let label = Text::new(
            head.track_id.to_string(),
            (x + 4, y - 12),
            (FAMILY, 11).into_font().color(&ink),
        );
        area.draw(&label).map_err(drawing_error)?;
    }
    Ok(())
}

/// The nearest pixel to `p`, as plotters' integer coordinates.
pub(crate) fn pixel(p: sillage_core::Point2) -> (i32, i32) {
    (p.x.round() as i32, p.y.round() as i32)
}

/// The grey level of `frame` at `(x, y)`, clamped inside the frame.
fn frame_level(frame: &GrayImage, x: i32, y: i32) -> f32 {
    let clamp = |v: i32, n: usize| (v.max(0) as usize).min(n.saturating_sub(1));
    frame.get(clamp(x, frame.width()), clamp(y, frame.height()))
}

#[cfg(test)]
mod tests {
    use sillage_core::{MotionState, Point2};

    use super::*;
    use crate::palette::state_rgb;

    fn count(picture: &RgbImage, rgb: [u8; 3]) -> usize {
        picture.as_slice().iter().filter(|&&p| p == rgb).count()
    }

    #[test]
    fn tails_take_the_colour_of_their_state_and_detections_are_circled() {
        let frame = GrayImage::from_vec(120, 80, vec![0.9; 120 * 80]).unwrap();
        let mut tail: Vec<TrackPoint> = (0..5)
            .map(|k| TrackPoint::at(k, 7, Point2::new(20.0 + 10.0 * k as f64, 40.0)))
            .collect();
        for p in &mut tail {
            p.motion_state = MotionState::Rolling;
        }
        let detection = Detection::of_class(Point2::new(90.0, 20.0), 1.0, 1);
        let style = OverlayStyle {
            detection_radius_px: vec![3.0, 6.0],
            ..OverlayStyle::default()
        };
        let picture = draw_overlay(&frame, &[detection], &[&tail], &style).unwrap();
        assert_eq!(picture.dimensions(), (120, 80));
        let rolling = count(&picture, state_rgb(MotionState::Rolling));
        // A 40 px, 2 px wide line and the head's dot.
        assert!((70..140).contains(&rolling), "{rolling}");
        assert_eq!(count(&picture, state_rgb(MotionState::Saltating)), 0);
        // The class-1 circle (radius 6, yellow, 2 px wide, anti-aliased): about 2·2π·6 pixels
        // more yellow than grey, all within 8 px of the detection.
        let c = series_colour(6);
        assert_eq!((c.0, c.1, c.2), (240, 228, 66));
        let yellowish = |p: &[u8; 3]| p[0] > 180 && p[1] > 190 && p[2] < 160;
        let ring: Vec<(usize, usize)> = (0..80)
            .flat_map(|y| (0..120).map(move |x| (x, y)))
            .filter(|&(x, y)| yellowish(&picture.get(x, y)))
            .collect();
        assert!((40..120).contains(&ring.len()), "{}", ring.len());
        assert!(
            ring.iter()
                .all(|&(x, y)| (x as f64 - 90.0).hypot(y as f64 - 20.0) < 8.0)
        );
        // The id is written in dark ink on this bright frame, above right of the head (60, 40).
        let ink = (60..80)
            .flat_map(|x| (24..40).map(move |y| (x, y)))
            .filter(|&(x, y)| picture.get(x, y).iter().all(|&v| v < 100))
            .count();
        assert!(ink > 5, "{ink}");
        // Away from the drawing, the frame's grey is kept.
        assert_eq!(picture.get(5, 75), [230, 230, 230]);
    }

    #[test]
    fn tails_can_take_the_colour_of_their_id_or_speed() {
        let frame = GrayImage::from_vec(100, 60, vec![0.0; 100 * 60]).unwrap();
        let tail: Vec<TrackPoint> = (0..4)
            .map(|k| TrackPoint::at(k, 3, Point2::new(20.0 + 15.0 * k as f64, 30.0)))
            .collect();
        let by = |colouring| {
            let style = OverlayStyle {
                colouring,
                show_ids: false,
                ..OverlayStyle::default()
            };
            draw_overlay(&frame, &[], &[&tail], &style).unwrap()
        };
        let by_id = by(TrackColouring::Id);
        assert!(count(&by_id, crate::palette::id_rgb(3)) > 60);
        // 15 px/frame on a scale topped at 15: the yellow end of viridis.
        let fast = by(TrackColouring::Speed {
            max_px_per_frame: 15.0,
        });
        assert!(count(&fast, crate::colormap::viridis(1.0)) > 60);
        assert_eq!(fast.get(50, 30), crate::colormap::viridis(1.0));
        let slow = by(TrackColouring::Speed {
            max_px_per_frame: 150.0,
        });
        assert_eq!(count(&slow, crate::colormap::viridis(1.0)), 0);
        assert_eq!(slow.get(50, 30), crate::colormap::viridis(0.1));
    }

    #[test]
    fn a_zero_tail_or_a_bad_radius_is_refused() {
        let frame = GrayImage::new(4, 4);
        let style = OverlayStyle {
            tail_frames: 0,
            ..OverlayStyle::default()
        };
        assert!(draw_overlay(&frame, &[], &[], &style).is_err());
        let style = OverlayStyle {
            detection_radius_px: vec![f64::NAN],
            ..OverlayStyle::default()
        };
        let e = draw_overlay(&frame, &[], &[], &style).unwrap_err();
        assert!(e.to_string().contains("detection_radius_px"), "{e}");
    }
}

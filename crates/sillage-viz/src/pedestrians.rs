//! Pedestrian overlays in the manner of the IMM-PF paper (Madrigal & Hayet, Fig. 1(b) and
//! Fig. 2): each tracked person's box with, at its top-left, a small bar split into the share
//! of each motion model (the model weights πₘ), and the trajectory so far as a polyline whose
//! segments take the colour of the model with the largest weight at that time.
//!
//! Colours follow the paper ([`model_rgb`]): `CP` red, `CV` green, `CA` blue, and `MP` (the
//! learned motion prior) magenta. A legend in the top-right corner names the models in their
//! colours.

use std::collections::{HashMap, VecDeque};

use plotters::prelude::*;
use sillage_core::{Error, FrameIndex, Result, RgbImage};

use crate::canvas::drawing_error;
use crate::font::FAMILY;
use crate::overlay::{PixelArea, draw_on};
use crate::palette::model_rgb;

/// Width of the model-weight bar, px.
const BAR_WIDTH_PX: i32 = 40;
/// Height of the model-weight bar, px.
const BAR_HEIGHT_PX: i32 = 6;
/// The colour of the boxes and ids (a yellow apart from every model colour).
const BOX_RGB: [u8; 3] = [255, 215, 0];
/// The colour of a bar without any positive weight, and of trail segments without a model.
const NO_MODEL_RGB: [u8; 3] = [160, 160, 160];

/// One tracked person at one frame, as drawn on a pedestrian overlay.
#[derive(Debug, Clone, PartialEq)]
pub struct PersonOverlay {
    /// Track identity, written beside the box.
    pub track_id: u64,
    /// Left edge of the box, px.
    pub left_px: f64,
    /// Top edge of the box, px.
    pub top_px: f64,
    /// Box width, px.
    pub width_px: f64,
    /// Box height, px.
    pub height_px: f64,
    /// πₘ, the weight of each model, in the order of the `models` given to
    /// [`draw_pedestrians`] (normalised when drawn; non-finite or negative weights count 0).
    pub model_weights: Vec<f64>,
}

impl PersonOverlay {
    /// The foot point (bottom centre of the box), px.
    pub fn foot_px(&self) -> (f64, f64) {
        (
            self.left_px + 0.5 * self.width_px,
            self.top_px + self.height_px,
        )
    }

    /// The index of the model with the largest weight (the first one on ties), `None`
    /// without any finite weight.
    pub fn dominant_model(&self) -> Option<usize> {
        self.model_weights
            .iter()
            .enumerate()
            .filter(|(_, w)| w.is_finite())
            .fold(None, |best: Option<(usize, f64)>, (i, &w)| match best {
                Some((_, b)) if b >= w => best,
                _ => Some((i, w)),
            })
            .map(|(i, _)| i)
    }
}

/// One point of a trajectory: a foot point and the dominant model there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrailPoint {
    /// Frame of the point.
    pub frame: FrameIndex,
    /// Foot point x, px.
    pub x_px: f64,
    /// Foot point y, px.
    pub y_px: f64,
    /// Index of the model with the largest weight, `None` without weights.
    pub model: Option<usize>,
}

/// The trajectories of the tracked people so far, in bounded memory: the last `max_points`
/// foot points of each track, and tracks not seen for more than `forget_after_frames` frames
/// (counted from the newest frame recorded) dropped.
#[derive(Debug, Clone)]
pub struct PedestrianTrails {
    max_points: usize,
    forget_after_frames: u64,
    newest_frame: Option<FrameIndex>,
    tracks: HashMap<u64, VecDeque<TrailPoint>>,
}

impl Default for PedestrianTrails {
    /// The last 100 points of each track; tracks forgotten after 25 frames unseen.
    fn default() -> Self {
        Self {
            max_points: 100,
            forget_after_frames: 25,
            newest_frame: None,
            tracks: HashMap::new(),
        }
    }
}

impl PedestrianTrails {
    /// Keeps the last `max_points` (at least 1) points of each track and forgets tracks not
    /// seen for more than `forget_after_frames` frames.
    pub fn new(max_points: usize, forget_after_frames: u64) -> Result<Self> {
        if max_points == 0 {
            return Err(Error::parameter(
                "max_points",
                "0",
                "keep at least 1 point per track",
            ));
        }
        Ok(Self {
            max_points,
            forget_after_frames,
            ..Self::default()
        })
    }

    /// Records `person`'s foot point and dominant model at `frame`. Points may come late
    /// (a tracker's first frames are reported when it is confirmed): each trail stays in
    /// frame order, and a second point at the same frame replaces the first.
    pub fn record(&mut self, frame: FrameIndex, person: &PersonOverlay) {
        let (x_px, y_px) = person.foot_px();
        let point = TrailPoint {
            frame,
            x_px,
            y_px,
            model: person.dominant_model(),
        };
        let trail = self.tracks.entry(person.track_id).or_default();
        let at = trail.partition_point(|p| p.frame < frame);
        match trail.get_mut(at) {
            Some(p) if p.frame == frame => *p = point,
            _ => trail.insert(at, point),
        }
        while trail.len() > self.max_points {
            trail.pop_front();
        }
        if self.newest_frame.is_none_or(|newest| frame > newest) {
            self.newest_frame = Some(frame);
            let forget = self.forget_after_frames;
            self.tracks.retain(|_, trail| {
                trail
                    .back()
                    .is_some_and(|last| last.frame.saturating_add(forget) >= frame)
            });
        }
    }

    /// The trail of `track_id`, oldest point first (empty for an unknown track).
    pub fn trail(&self, track_id: u64) -> impl Iterator<Item = &TrailPoint> {
        self.tracks.get(&track_id).into_iter().flatten()
    }

    /// Number of tracks remembered.
    pub fn len(&self) -> usize {
        self.tracks.len()
    }

    /// Whether no track is remembered.
    pub fn is_empty(&self) -> bool {
        self.tracks.is_empty()
    }
}

/// Draws `frame` with each of `people`: its trail from `trails` (segments coloured by the
/// dominant model at their end), its box and id, and the bar of its model weights at the
/// box's top-left (just above the box, or inside it at the frame's top edge); plus a legend
/// of `models` (names such as `CP`, `CV`, `CA`, `MP`, coloured by [`model_rgb`]).
///
/// Fails when `models` is empty or a person's weights do not match it.
pub fn draw_pedestrians(
    frame: &RgbImage,
    people: &[PersonOverlay],
    trails: &PedestrianTrails,
    models: &[&str],
) -> Result<RgbImage> {
    if models.is_empty() {
        return Err(Error::parameter(
            "models",
            "[]",
            "name the models of the weights (CP, CV, CA, MP)",
        ));
    }
    if let Some(p) = people
        .iter()
        .find(|p| p.model_weights.len() != models.len())
    {
        return Err(Error::input(format!(
            "track {} has {} model weights for the {} models {}",
            p.track_id,
            p.model_weights.len(),
            models.len(),
            models.join("_")
        )));
    }
    let colours: Vec<RGBColor> = models
        .iter()
        .enumerate()
        .map(|(i, name)| rgb(model_rgb(name, i)))
        .collect();
    let mut picture = frame.clone();
    draw_on(&mut picture, |area| {
        for person in people {
            draw_trail(area, trails, person.track_id, &colours)?;
        }
        for person in people {
            draw_person(area, person, &colours)?;
        }
        draw_legend(area, models, &colours)
    })?;
    Ok(picture)
}

fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// The colour of an optional model index.
fn colour_of(model: Option<usize>, colours: &[RGBColor]) -> RGBColor {
    model
        .and_then(|m| colours.get(m))
        .copied()
        .unwrap_or(rgb(NO_MODEL_RGB))
}

/// One track's trajectory, each segment in the colour of the dominant model at its end.
fn draw_trail(
    area: &PixelArea<'_>,
    trails: &PedestrianTrails,
    track_id: u64,
    colours: &[RGBColor],
) -> Result<()> {
    let point = |p: &TrailPoint| (p.x_px.round() as i32, p.y_px.round() as i32);
    let mut previous: Option<&TrailPoint> = None;
    for p in trails.trail(track_id) {
        if let Some(q) = previous {
            let segment = PathElement::new(
                [point(q), point(p)],
                colour_of(p.model, colours).stroke_width(2),
            );
            area.draw(&segment).map_err(drawing_error)?;
        }
        previous = Some(p);
    }
    Ok(())
}

/// A person's box (2 px), its model-weight bar and its id.
fn draw_person(area: &PixelArea<'_>, person: &PersonOverlay, colours: &[RGBColor]) -> Result<()> {
    let x0 = person.left_px.round() as i32;
    let y0 = person.top_px.round() as i32;
    let x1 = (person.left_px + person.width_px).round() as i32;
    let y1 = (person.top_px + person.height_px).round() as i32;
    let ink = rgb(BOX_RGB);
    for inset in 0..2 {
        let outline = Rectangle::new([(x0 + inset, y0 + inset), (x1 - inset, y1 - inset)], ink);
        area.draw(&outline).map_err(drawing_error)?;
    }
    // The bar sits above the box, within a 1 px black frame; inside the box when above would
    // leave the picture.
    let bar_top = if y0 - BAR_HEIGHT_PX - 2 >= 0 {
        y0 - BAR_HEIGHT_PX - 1
    } else {
        y0 + 3
    };
    let bar_left = x0 + 1;
    let frame = Rectangle::new(
        [
            (bar_left - 1, bar_top - 1),
            (bar_left + BAR_WIDTH_PX, bar_top + BAR_HEIGHT_PX),
        ],
        BLACK,
    );
    area.draw(&frame).map_err(drawing_error)?;
    let clean: Vec<f64> = person
        .model_weights
        .iter()
        .map(|&w| if w.is_finite() && w > 0.0 { w } else { 0.0 })
        .collect();
    let total: f64 = clean.iter().sum();
    // Filled rectangles cover [x0, x1) × [y0, y1).
    let bottom = bar_top + BAR_HEIGHT_PX;
    if total > 0.0 {
        let mut cumulative = 0.0;
        let mut from = bar_left;
        for (i, w) in clean.iter().enumerate() {
            cumulative += w;
            let to = bar_left + (cumulative / total * BAR_WIDTH_PX as f64).round() as i32;
            if to > from {
                let share = Rectangle::new([(from, bar_top), (to, bottom)], colours[i].filled());
                area.draw(&share).map_err(drawing_error)?;
            }
            from = to;
        }
    } else {
        let empty = Rectangle::new(
            [(bar_left, bar_top), (bar_left + BAR_WIDTH_PX, bottom)],
            rgb(NO_MODEL_RGB).filled(),
        );
        area.draw(&empty).map_err(drawing_error)?;
    }
    let label = Text::new(
        person.track_id.to_string(),
        (bar_left + BAR_WIDTH_PX + 3, bar_top - 5),
        (FAMILY, 12).into_font().color(&ink),
    );
    area.draw(&label).map_err(drawing_error)
}

/// The model names in their colours on a black strip in the top-right corner.
fn draw_legend(area: &PixelArea<'_>, models: &[&str], colours: &[RGBColor]) -> Result<()> {
    let font = (FAMILY, 14).into_font();
    let gap = 8;
    let mut widths = Vec::with_capacity(models.len());
    let mut height = 0;
    for name in models {
        let (w, h) = area
            .estimate_text_size(name, &font.clone().into())
            .map_err(drawing_error)?;
        widths.push(w as i32);
        height = height.max(h as i32);
    }
    let total = widths.iter().sum::<i32>() + gap * (models.len() as i32 + 1);
    let (width_px, _) = area.dim_in_pixel();
    let right = width_px as i32 - 4;
    let left = right - total;
    let strip = Rectangle::new([(left, 4), (right, 4 + height + 8)], BLACK.filled());
    area.draw(&strip).map_err(drawing_error)?;
    let mut x = left + gap;
    for ((name, w), colour) in models.iter().zip(&widths).zip(colours) {
        let text = Text::new(name.to_string(), (x, 8), font.clone().color(colour));
        area.draw(&text).map_err(drawing_error)?;
        x += w + gap;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const GREY: [u8; 3] = [100, 100, 100];
    const RED: [u8; 3] = [230, 25, 25];
    const GREEN: [u8; 3] = [20, 200, 40];

    fn grey_frame(width: usize, height: usize) -> RgbImage {
        RgbImage::from_vec(width, height, vec![GREY; width * height]).unwrap()
    }

    fn person(track_id: u64, left_px: f64, top_px: f64, weights: &[f64]) -> PersonOverlay {
        PersonOverlay {
            track_id,
            left_px,
            top_px,
            width_px: 30.0,
            height_px: 80.0,
            model_weights: weights.to_vec(),
        }
    }

    /// Pixels of colour `rgb` in `x0..x1 × y0..y1`.
    fn count_in(
        picture: &RgbImage,
        rgb: [u8; 3],
        xs: std::ops::Range<usize>,
        ys: std::ops::Range<usize>,
    ) -> usize {
        ys.flat_map(|y| xs.clone().map(move |x| (x, y)))
            .filter(|&(x, y)| picture.get(x, y) == rgb)
            .count()
    }

    #[test]
    fn model_colours_follow_the_paper() {
        assert_eq!(model_rgb("CP", 0), RED);
        assert_eq!(model_rgb("cv", 0), GREEN);
        assert_eq!(model_rgb("CA", 0), [30, 90, 255]);
        let mp = model_rgb("MP", 3);
        assert!(![RED, GREEN, [30, 90, 255], BOX_RGB].contains(&mp));
    }

    #[test]
    fn the_bar_is_split_by_the_model_weights() {
        let frame = grey_frame(200, 150);
        let people = [person(7, 50.0, 40.0, &[0.25, 0.75])];
        let trails = PedestrianTrails::default();
        let picture = draw_pedestrians(&frame, &people, &trails, &["CP", "CV"]).unwrap();
        assert_eq!(picture.dimensions(), (200, 150));
        // The 40×6 bar above the box's top-left: 10 columns red, 30 green.
        let (red, green) = (
            count_in(&picture, RED, 40..110, 25..40),
            count_in(&picture, GREEN, 40..110, 25..40),
        );
        assert_eq!((red, green), (60, 180));
        // Red left of green.
        assert_eq!(picture.get(52, 36), RED);
        assert_eq!(picture.get(70, 36), GREEN);
        // The box: two nested outlines of a 31×81 rectangle.
        let boxed = count_in(&picture, BOX_RGB, 45..86, 38..125);
        assert!(
            (2 * 2 * (29 + 79)..=2 * 2 * (31 + 81)).contains(&boxed),
            "{boxed}"
        );
        // The legend, top right, has red and green ink (anti-aliased text) on black; the
        // bottom-left is untouched.
        let ink = |keep: fn(&[u8; 3]) -> bool| {
            (0..30)
                .flat_map(|y| (120..200).map(move |x| (x, y)))
                .filter(|&(x, y)| keep(&picture.get(x, y)))
                .count()
        };
        let reddish = ink(|p| p[0] > 120 && p[1] < 60 && p[2] < 60);
        let greenish = ink(|p| p[1] > 100 && p[0] < 60 && p[2] < 60);
        assert!(reddish > 10 && greenish > 10, "{reddish} {greenish}");
        assert_eq!(picture.get(194, 6), [0, 0, 0]);
        assert_eq!(picture.get(5, 145), GREY);
    }

    #[test]
    fn a_box_at_the_top_edge_has_its_bar_inside() {
        let frame = grey_frame(240, 120);
        let people = [person(1, 20.0, 0.0, &[0.0, 1.0, 0.0])];
        let picture = draw_pedestrians(
            &frame,
            &people,
            &PedestrianTrails::default(),
            &["CP", "CV", "CA"],
        )
        .unwrap();
        assert_eq!(count_in(&picture, GREEN, 0..70, 0..15), 240);
        assert_eq!(count_in(&picture, RED, 0..70, 0..15), 0);
    }

    #[test]
    fn trails_take_the_colour_of_the_dominant_model() {
        let models = ["CP", "CV"];
        let mut trails = PedestrianTrails::default();
        // Foot points along y = 120, x = 35 + 10 k: CP dominant for k ≤ 3, CV after.
        let at = |k: u64| {
            let weights = if k <= 3 { [0.9, 0.1] } else { [0.2, 0.8] };
            person(3, 20.0 + 10.0 * k as f64, 40.0, &weights)
        };
        for k in 0..9 {
            trails.record(k, &at(k));
        }
        let picture = draw_pedestrians(&grey_frame(200, 150), &[at(8)], &trails, &models).unwrap();
        // Segments ending at k = 1..=3 (x 35..65) red, k = 4..=8 (x 65..115) green, 2 px wide;
        // the box's bottom edge covers y ≤ 120 of the last one (x 100..130).
        let below = 121..124;
        let red = count_in(&picture, RED, 36..64, below.clone());
        let green = count_in(&picture, GREEN, 66..99, below.clone());
        assert!(red >= 25, "{red}");
        assert!(green >= 30, "{green}");
        assert_eq!(count_in(&picture, GREEN, 36..64, below.clone()), 0);
        assert_eq!(count_in(&picture, RED, 66..99, below), 0);
        // A person not drawn has no trail drawn.
        let picture = draw_pedestrians(&grey_frame(200, 150), &[], &trails, &models).unwrap();
        assert_eq!(count_in(&picture, GREEN, 0..200, 100..150), 0);
    }

    #[test]
    fn trails_are_bounded_ordered_and_forgotten() {
        let mut trails = PedestrianTrails::new(3, 5).unwrap();
        for k in 0..10 {
            trails.record(k, &person(1, k as f64, 0.0, &[1.0]));
        }
        let frames = |t: &PedestrianTrails, id| t.trail(id).map(|p| p.frame).collect::<Vec<_>>();
        assert_eq!(frames(&trails, 1), vec![7, 8, 9]);
        assert_eq!(trails.trail(1).last().unwrap().x_px, 9.0 + 15.0);
        assert_eq!(trails.trail(1).last().unwrap().y_px, 80.0);
        // Late points (a confirmation) go in frame order; a repeated frame replaces.
        trails.record(9, &person(2, 0.0, 0.0, &[1.0]));
        trails.record(8, &person(2, 0.0, 0.0, &[1.0]));
        trails.record(9, &person(2, 5.0, 0.0, &[1.0]));
        assert_eq!(frames(&trails, 2), vec![8, 9]);
        assert_eq!(trails.trail(2).last().unwrap().x_px, 5.0 + 15.0);
        // Track 1 is last seen at 9: kept at frame 14, forgotten at 15.
        trails.record(14, &person(2, 0.0, 0.0, &[1.0]));
        assert_eq!(trails.len(), 2);
        trails.record(15, &person(2, 0.0, 0.0, &[1.0]));
        assert_eq!(trails.len(), 1);
        assert!(frames(&trails, 1).is_empty());
        assert!(PedestrianTrails::new(0, 5).is_err());
    }

    #[test]
    fn the_dominant_model_ignores_nan_and_takes_the_first_on_ties() {
        assert_eq!(person(1, 0.0, 0.0, &[0.5, 0.5]).dominant_model(), Some(0));
        assert_eq!(
            person(1, 0.0, 0.0, &[f64::NAN, 0.1]).dominant_model(),
            Some(1)
        );
        assert_eq!(person(1, 0.0, 0.0, &[]).dominant_model(), None);
    }

    #[test]
    fn weights_that_do_not_match_the_models_are_refused() {
        let frame = grey_frame(50, 50);
        let people = [person(4, 5.0, 5.0, &[0.5, 0.5])];
        let trails = PedestrianTrails::default();
        let e = draw_pedestrians(&frame, &people, &trails, &["CP", "CV", "CA"]).unwrap_err();
        assert!(e.to_string().contains("track 4 has 2 model weights"), "{e}");
        assert!(draw_pedestrians(&frame, &[], &trails, &[]).is_err());
    }
}

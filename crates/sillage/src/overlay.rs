//! Pictures of what a tracker did: one PNG per frame with the frame's detections circled and
//! the track tails coloured by motion state (resting blue, rolling orange, saltating
//! vermillion, unknown grey), speed or id, with ids, optionally encoded as an MP4
//! (`sillage overlay`, `track bedload --overlay`, `demo bedload --overlays`); and the
//! pedestrian overlays of `track immpf --overlay` (boxes, model-weight bars, trajectories
//! coloured by the dominant model).

use std::collections::{BTreeMap, VecDeque};
use std::path::{Path, PathBuf};

use sillage_core::{Detection, Error, FrameIndex, Result, RgbImage, TrackPoint};
use sillage_io::{FrameOptions, Mp4Writer, open_frames, write_png_rgb};
use sillage_track::immpf::{ModelName, PedestrianEstimate};
use sillage_viz::{
    OverlayStyle, PedestrianTrails, PersonOverlay, TrackHistory, draw_overlay, draw_pedestrians,
};

use crate::folders::create_folder;

/// The detections of each frame, kept for drawing.
pub type DetectionsByFrame = BTreeMap<FrameIndex, Vec<Detection>>;

/// An MP4 to encode the overlays into, at `fps` frames per second.
pub struct VideoOut<'a> {
    /// The MP4 file.
    pub path: &'a Path,
    /// Frames per second.
    pub fps: f64,
}

/// The error of drawing frame `frame` (as the user counts it).
fn overlay_error(frame: FrameIndex, e: Error) -> Error {
    Error::input(format!("overlay of frame {frame}: {e}"))
}

/// Draws every frame of `input` with its `detections` and the tails of `tracks` into `dir`
/// as `overlay_NNNNN.png` (frame index, 0-based), and into `video` when given; `on_frame` is
/// called after each frame with the number of frames when the source knows it (progress
/// bars). Returns the number of frames drawn.
pub fn write_overlays(
    input: &str,
    dir: &Path,
    detections: &DetectionsByFrame,
    tracks: Vec<TrackPoint>,
    style: &OverlayStyle,
    video: Option<VideoOut<'_>>,
    on_frame: &mut dyn FnMut(Option<usize>),
) -> Result<usize> {
    style.validate()?;
    create_folder(dir)?;
    let history = TrackHistory::new(tracks);
    let frames = open_frames(input, &FrameOptions::default())?;
    let total = frames.len();
    let mut encoder = match &video {
        Some(v) => {
            let (width, height) = frames.dimensions();
            Some(Mp4Writer::create(
                v.path,
                width,
                height,
                v.fps,
                Path::new("ffmpeg"),
            )?)
        }
        None => None,
    };
    let mut written = 0;
    for frame in frames {
        let frame = frame?;
        let tails: Vec<&[TrackPoint]> = history.tails_at(frame.index, style.tail_frames).collect();
        let found = detections.get(&frame.index).map_or(&[][..], Vec::as_slice);
        let picture = draw_overlay(&frame.image, found, &tails, style)
            .map_err(|e| overlay_error(frame.index, e))?;
        write_png_rgb(
            dir.join(format!("overlay_{:05}.png", frame.index)),
            &picture,
        )?;
        if let Some(encoder) = &mut encoder {
            encoder.push(&picture)?;
        }
        written += 1;
        on_frame(total);
    }
    if let Some(encoder) = encoder {
        encoder.finish()?;
    }
    Ok(written)
}

/// `sillage track immpf --overlay DIR`: draws each frame as the tracker goes, from the
/// estimates of that frame, into `DIR/overlay_NNNNN.png` (1-based frame number). A frame is
/// drawn `lag` frames late, when the tracker smooths its boxes and so writes them that late
/// (`detection.smooth_frames`); estimates later still (those of a track's confirmation, or of
/// a gap it filled) only join the trajectories.
pub struct PedestrianOverlays {
    dir: PathBuf,
    models: Vec<&'static str>,
    trails: PedestrianTrails,
    lag: usize,
    /// Frames not drawn yet, oldest first, with the people estimated there so far.
    pending: VecDeque<PendingOverlay>,
}

/// A frame waiting for the estimates of its people.
struct PendingOverlay {
    frame: FrameIndex,
    colour: RgbImage,
    people: Vec<PersonOverlay>,
}

impl PedestrianOverlays {
    /// Creates `dir` for the overlays of a tracker with `models` that writes the boxes of a
    /// frame `lag` frames later.
    pub fn create(dir: &Path, models: &[ModelName], lag: u64) -> Result<Self> {
        create_folder(dir)?;
        Ok(Self {
            dir: dir.to_path_buf(),
            models: models.iter().map(|m| m.label()).collect(),
            trails: PedestrianTrails::default(),
            lag: usize::try_from(lag).unwrap_or(usize::MAX),
            pending: VecDeque::new(),
        })
    }

    /// Adds the `estimates` of a step at frame `frame` (0-based), whose colour picture is
    /// `colour`, and draws the frames that are `lag` frames old (a frame handed twice adds
    /// its estimates to the first).
    pub fn push(
        &mut self,
        frame: FrameIndex,
        colour: Option<&RgbImage>,
        estimates: &[PedestrianEstimate],
    ) -> Result<()> {
        let colour = colour.ok_or_else(|| Error::input("overlays need the colour frames"))?;
        if self.pending.back().is_none_or(|p| p.frame < frame) {
            self.pending.push_back(PendingOverlay {
                frame,
                colour: colour.clone(),
                people: Vec::new(),
            });
        }
        for e in estimates {
            let person = PersonOverlay {
                track_id: e.track_id,
                left_px: e.bbox.left_px,
                top_px: e.bbox.top_px,
                width_px: e.bbox.width_px,
                height_px: e.bbox.height_px,
                model_weights: e.model_weights.clone(),
            };
            match self.pending.iter_mut().find(|p| p.frame == e.frame) {
                Some(pending) => pending.people.push(person),
                None => self.trails.record(e.frame, &person),
            }
        }
        while self.pending.len() > self.lag {
            self.draw_oldest()?;
        }
        Ok(())
    }

    /// Draws the frames still waiting (after the last frame).
    pub fn finish(mut self) -> Result<()> {
        while !self.pending.is_empty() {
            self.draw_oldest()?;
        }
        Ok(())
    }

    /// Draws the oldest waiting frame with its people, who join the trajectories.
    fn draw_oldest(&mut self) -> Result<()> {
        let Some(pending) = self.pending.pop_front() else {
            return Ok(());
        };
        for person in &pending.people {
            self.trails.record(pending.frame, person);
        }
        let picture =
            draw_pedestrians(&pending.colour, &pending.people, &self.trails, &self.models)
                .map_err(|e| overlay_error(pending.frame + 1, e))?;
        write_png_rgb(
            self.dir
                .join(format!("overlay_{:05}.png", pending.frame + 1)),
            &picture,
        )
    }
}

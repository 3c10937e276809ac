//! `sillage overlay` and `--overlay DIR`: one PNG per frame with the frame's detections
//! circled and the track tails coloured by motion state (resting blue, rolling orange,
//! saltating vermillion, unknown grey), speed or id, with ids — for looking at what a tracker
//! did — and, with `--mp4`, the same pictures as a video; and the pedestrian overlays of
//! `sillage track immpf --overlay DIR` (boxes, model-weight bars, trajectories coloured by the
//! dominant model).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use sillage::core::{Detection, FrameIndex, TrackPoint};
use sillage::io::{FrameOptions, Mp4Writer, open_frames, read_detections_csv, write_png_rgb};
use sillage::track::immpf::{ModelName, PedestrianEstimate};
use sillage::viz::{
    OverlayStyle, PedestrianTrails, PersonOverlay, TrackHistory, draw_overlay, draw_pedestrians,
};

use crate::cli::OverlayArgs;
use crate::plot::colouring;
use crate::progress::FrameProgress;
use crate::track_input::read_tracks_for_drawing;

/// The detections of each frame, kept for drawing.
pub type DetectionsByFrame = BTreeMap<FrameIndex, Vec<Detection>>;

/// An MP4 to encode the overlays into, at `fps` frames per second.
pub struct VideoOut<'a> {
    /// The MP4 file.
    pub path: &'a Path,
    /// Frames per second.
    pub fps: f64,
}

/// `sillage overlay`: the frames with the tracks of a table (and the detections of a CSV).
pub fn run(args: &OverlayArgs) -> Result<()> {
    let input = &args.input;
    let tracks = read_tracks_for_drawing(&input.tracks, input.format)?;
    let history = TrackHistory::new(tracks.points.iter().copied());
    let style = OverlayStyle {
        tail_frames: args.tail,
        detection_radius_px: vec![args.radius],
        colouring: colouring(input, tracks.has_states, &history)?,
        ..OverlayStyle::default()
    };
    let detections = match &input.detections {
        Some(path) => read_detections_csv(path)?.into_iter().collect(),
        None => DetectionsByFrame::new(),
    };
    let video = args.mp4.as_deref().map(|path| VideoOut {
        path,
        fps: args.fps,
    });
    let n = write_overlays(
        &args.frames,
        &args.out,
        &detections,
        tracks.points,
        &style,
        video,
    )?;
    eprintln!("{n} overlays → {}", args.out.display());
    if let Some(path) = &args.mp4 {
        eprintln!("video → {}", path.display());
    }
    Ok(())
}

/// Draws every frame of `input` with its `detections` and the tails of `tracks` into `dir`
/// as `overlay_NNNNN.png` (frame index, 0-based), and into `video` when given; returns the
/// number of frames drawn.
pub fn write_overlays(
    input: &str,
    dir: &Path,
    detections: &DetectionsByFrame,
    tracks: Vec<TrackPoint>,
    style: &OverlayStyle,
    video: Option<VideoOut<'_>>,
) -> Result<usize> {
    style.validate()?;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    let history = TrackHistory::new(tracks);
    let frames = open_frames(input, &FrameOptions::default())?;
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
    let mut progress = FrameProgress::new(frames.len(), "drawing overlays");
    let mut written = 0;
    for frame in frames {
        let frame = frame?;
        let tails: Vec<&[TrackPoint]> = history.tails_at(frame.index, style.tail_frames).collect();
        let found = detections.get(&frame.index).map_or(&[][..], Vec::as_slice);
        let picture = draw_overlay(&frame.image, found, &tails, style)
            .with_context(|| format!("overlay of frame {}", frame.index))?;
        write_png_rgb(
            dir.join(format!("overlay_{:05}.png", frame.index)),
            &picture,
        )?;
        if let Some(encoder) = &mut encoder {
            encoder.push(&picture)?;
        }
        written += 1;
        progress.tick();
    }
    progress.finish();
    if let Some(encoder) = encoder {
        encoder.finish()?;
    }
    Ok(written)
}

/// `sillage track immpf --overlay DIR`: draws each frame as the tracker goes, from the
/// estimates of that frame (those reported late, at a track's confirmation, only join the
/// trajectories), into `DIR/overlay_NNNNN.png` (1-based frame number).
pub struct PedestrianOverlays {
    dir: PathBuf,
    models: Vec<&'static str>,
    trails: PedestrianTrails,
    people: Vec<PersonOverlay>,
}

impl PedestrianOverlays {
    /// Creates `dir` for the overlays of a tracker with `models`.
    pub fn create(dir: &Path, models: &[ModelName]) -> Result<Self> {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create the folder {}", dir.display()))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            models: models.iter().map(|m| m.label()).collect(),
            trails: PedestrianTrails::default(),
            people: Vec::new(),
        })
    }

    /// Adds the `estimates` of a step to the trajectories and draws `prepared`'s frame with
    /// the people estimated at that frame.
    pub fn push(
        &mut self,
        prepared: &sillage::pedestrian::PreparedFrame,
        estimates: &[PedestrianEstimate],
    ) -> Result<()> {
        let colour = prepared
            .colour
            .as_ref()
            .context("overlays need the colour frames")?;
        self.people.clear();
        for e in estimates {
            let person = PersonOverlay {
                track_id: e.track_id,
                left_px: e.bbox.left_px,
                top_px: e.bbox.top_px,
                width_px: e.bbox.width_px,
                height_px: e.bbox.height_px,
                model_weights: e.model_weights.clone(),
            };
            self.trails.record(e.frame, &person);
            if e.frame == prepared.frame {
                self.people.push(person);
            }
        }
        let picture = draw_pedestrians(colour, &self.people, &self.trails, &self.models)
            .with_context(|| format!("overlay of frame {}", prepared.frame + 1))?;
        write_png_rgb(
            self.dir
                .join(format!("overlay_{:05}.png", prepared.frame + 1)),
            &picture,
        )?;
        Ok(())
    }
}

//! `sillage overlay` and `--overlay DIR`: one PNG per frame with the frame's detections
//! circled and the track tails coloured, drawn by `sillage::overlay` behind a progress bar,
//! and, with `--mp4`, the same pictures as a video.

use std::path::Path;

use anyhow::Result;
use sillage::core::TrackPoint;
use sillage::io::read_detections_csv;
pub use sillage::overlay::DetectionsByFrame;
use sillage::overlay::VideoOut;
use sillage::viz::{OverlayStyle, TrackHistory};

use crate::cli::OverlayArgs;
use crate::plot::colouring;
use crate::progress::FrameProgress;
use crate::track_input::read_tracks_for_drawing;

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

/// [`sillage::overlay::write_overlays`] behind a progress bar (also for `track bedload
/// --overlay` and `demo bedload --overlays`).
pub fn write_overlays(
    input: &str,
    dir: &Path,
    detections: &DetectionsByFrame,
    tracks: Vec<TrackPoint>,
    style: &OverlayStyle,
    video: Option<VideoOut<'_>>,
) -> Result<usize> {
    let mut progress: Option<FrameProgress> = None;
    let drawn =
        sillage::overlay::write_overlays(input, dir, detections, tracks, style, video, &mut |n| {
            progress
                .get_or_insert_with(|| FrameProgress::new(n, "drawing overlays"))
                .tick()
        });
    if let Some(progress) = progress {
        progress.finish();
    }
    Ok(drawn?)
}

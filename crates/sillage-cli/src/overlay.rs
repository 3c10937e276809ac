//! `--overlay DIR`: one PNG per frame with the frame's detections circled and the track
//! tails coloured by motion state, with ids (resting blue, rolling orange, saltating
//! vermillion, unknown grey) — for looking at what a tracker did.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result};
use sillage::core::{Detection, FrameIndex, TrackPoint};
use sillage::io::{FrameOptions, open_frames, write_png_rgb};
use sillage::viz::{OverlayStyle, TrackHistory, draw_overlay};

use crate::progress::FrameProgress;

/// The detections of each frame, kept for drawing.
pub type DetectionsByFrame = BTreeMap<FrameIndex, Vec<Detection>>;

/// Draws every frame of `input` with its `detections` and the tails of `tracks` into `dir`
/// as `overlay_NNNNN.png` (frame index, 0-based); returns the number of files written.
pub fn write_overlays(
    input: &str,
    dir: &Path,
    detections: &DetectionsByFrame,
    tracks: Vec<TrackPoint>,
    style: &OverlayStyle,
) -> Result<usize> {
    style.validate()?;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    let history = TrackHistory::new(tracks);
    let frames = open_frames(input, &FrameOptions::default())?;
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
        written += 1;
        progress.tick();
    }
    progress.finish();
    Ok(written)
}

//! `sillage overlay` and `--overlay DIR`: one PNG per frame with the frame's detections
//! circled and the track tails coloured, drawn by `sillage::overlay` behind a progress bar,
//! and, with `--mp4`, the same pictures as a video.

use std::path::Path;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sillage::core::TrackPoint;
use sillage::io::read_detections_csv;
pub use sillage::overlay::DetectionsByFrame;
use sillage::overlay::VideoOut;
use sillage::viz::{OverlayStyle, TrackHistory};

use crate::plot::colouring;
use crate::progress::FrameProgress;
use crate::shared_args::TracksInputArgs;
use crate::track_input::read_tracks_for_drawing;

/// `sillage overlay`.
#[derive(Debug, Args)]
pub struct OverlayArgs {
    /// The tracks.
    #[command(flatten)]
    pub input: TracksInputArgs,
    /// The frames the tracks were made from (a folder, a quoted glob, a multi-page TIFF or a
    /// video).
    #[arg(long, value_name = "FRAMES")]
    pub frames: String,
    /// Folder for the pictures, `overlay_NNNNN.png` (0-based frame index).
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
    /// Also encode the pictures into this MP4 (through the `ffmpeg` program).
    #[arg(long, value_name = "FILE.mp4")]
    pub mp4: Option<PathBuf>,
    /// Frames per second of the MP4.
    #[arg(long, default_value_t = 10.0)]
    pub fps: f64,
    /// Frames of history in each track's tail.
    #[arg(long, value_name = "FRAMES", default_value_t = 20)]
    pub tail: u64,
    /// Circle radius of the detections, px.
    #[arg(long, value_name = "PX", default_value_t = 4.0)]
    pub radius: f64,
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

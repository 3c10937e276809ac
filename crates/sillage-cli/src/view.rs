//! `sillage view TRACKS --frames INPUT --out view.html`: one self-contained HTML page that
//! plays the sequence with track tails (`sillage::viewer`), behind a progress bar.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sillage::viewer::write_view;

use crate::progress::FrameProgress;
use crate::ptv::output_format;
use crate::shared_args::FormatArg;

/// `sillage view`.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// Track table (TracTrac _track.txt, CSV, Parquet).
    pub tracks: PathBuf,
    /// The frames the tracks were made from: a folder, a quoted glob, a multi-page TIFF or a video.
    #[arg(long, value_name = "INPUT")]
    pub frames: String,
    /// The HTML file to write; the downscaled frames go to the folder <stem>_frames beside it.
    #[arg(long, short, value_name = "FILE.html")]
    pub out: PathBuf,
    /// Longest side of the frames in the page, px (smaller frames are kept as they are).
    #[arg(long, default_value_t = 1024)]
    pub max_side: usize,
    /// Length of the track tails first shown, frames (changeable in the page).
    #[arg(long, default_value_t = 20)]
    pub tail: usize,
    /// Format of the track table (default: from its extension).
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
}

/// `sillage view`.
pub fn run(args: &ViewArgs) -> Result<()> {
    let format = output_format(args.format, &args.tracks)?;
    let mut progress: Option<FrameProgress> = None;
    let summary = write_view(
        &args.tracks,
        format,
        &args.frames,
        &args.out,
        args.tail,
        args.max_side,
        &mut |n| {
            progress
                .get_or_insert_with(|| FrameProgress::new(n, "writing frames"))
                .tick()
        },
    );
    if let Some(progress) = progress {
        progress.finish();
    }
    let summary = summary?;
    eprintln!(
        "{} tracks over {} frames → {} (frames in {})",
        summary.tracks,
        summary.frames,
        args.out.display(),
        summary.frames_dir.display()
    );
    Ok(())
}

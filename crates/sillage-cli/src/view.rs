//! `sillage view TRACKS --frames INPUT --out view.html`: one self-contained HTML page that
//! plays the sequence with track tails (`sillage::viewer`), behind a progress bar.

use anyhow::Result;
use sillage::viewer::write_view;

use crate::cli::ViewArgs;
use crate::progress::FrameProgress;
use crate::ptv::output_format;

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

//! `sillage synth walkers`: a synthetic walkers sequence written as a MOTChallenge sequence
//! folder — colour frames `img1/000001.png`..., ground truth `gt/gt.txt` (with visibility)
//! and `seqinfo.ini` — that `track immpf DIR/img1` and `eval mot` read.

use std::path::Path;

use sillage_core::{Error, Result};
use sillage_io::{MotGroundTruthWriter, MotRow, SeqInfo, write_png_rgb, write_seqinfo};
use sillage_synth::{WalkerTruth, WalkersParams, WalkersSequence};

/// Frame rate written into `seqinfo.ini`, fps: a common video rate, at which the walkers'
/// 0.5-2.5 px/frame are a walking pace for 64 px tall people.
const FRAME_RATE: f64 = 25.0;

/// Shift from the generator's boxes (pixel centres at whole numbers) to the trackers' (a
/// blob's first column `x0` is its left edge): half a pixel.
const PIXEL_EDGE_SHIFT_PX: f64 = 0.5;

/// One walker's ground-truth row (consider flag 1, class 1 = pedestrian).
fn gt_row(frame: u64, truth: &WalkerTruth) -> MotRow {
    MotRow {
        frame,
        id: Some(truth.id),
        left_px: truth.left_px + PIXEL_EDGE_SHIFT_PX,
        top_px: truth.top_px + PIXEL_EDGE_SHIFT_PX,
        width_px: truth.width_px,
        height_px: truth.height_px,
        confidence: Some(1.0),
        class: Some(1),
        visibility: Some(truth.visibility),
        world: None,
    }
}

/// Creates `path` and its parents.
fn create_dir(path: &Path) -> Result<()> {
    std::fs::create_dir_all(path)
        .map_err(|e| Error::input(format!("cannot create the folder {}: {e}", path.display())))
}

/// Renders the sequence of `params` into the folder `dir` (named in `seqinfo.ini` by its
/// last component), calling `on_frame` after each frame; the walker boxes written.
pub fn write_walkers_sequence(
    params: &WalkersParams,
    dir: &Path,
    on_frame: &mut dyn FnMut(),
) -> Result<u64> {
    let (images, gt_dir) = (dir.join("img1"), dir.join("gt"));
    create_dir(&images)?;
    create_dir(&gt_dir)?;
    let mut gt = MotGroundTruthWriter::create(gt_dir.join("gt.txt"))?;
    let mut rows = Vec::new();
    for frame in WalkersSequence::new(params.clone())? {
        write_png_rgb(
            images.join(format!("{:06}.png", frame.index + 1)),
            &frame.colour,
        )?;
        rows.clear();
        rows.extend(frame.truth.iter().map(|t| gt_row(frame.index, t)));
        gt.push(&rows)?;
        on_frame();
    }
    let written = gt.finish()?.rows;
    let name = dir.file_name().map_or_else(
        || "walkers".to_owned(),
        |n| n.to_string_lossy().into_owned(),
    );
    write_seqinfo(
        dir.join("seqinfo.ini"),
        &SeqInfo {
            name: Some(name),
            frame_count: Some(params.n_frames as u64),
            frame_rate: Some(FRAME_RATE),
            image_width: Some(params.width as u32),
            image_height: Some(params.height as u32),
            image_dir: Some("img1".to_owned()),
            image_ext: Some(".png".to_owned()),
        },
    )?;
    Ok(written)
}

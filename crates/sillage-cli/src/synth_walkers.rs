//! `sillage synth walkers`: a synthetic walkers sequence as a MOTChallenge sequence folder —
//! colour frames `img1/000001.png`..., ground truth `gt/gt.txt` (with visibility) and
//! `seqinfo.ini` — that `sillage track immpf DIR/img1` and `sillage eval mot` read.

use std::path::Path;

use anyhow::{Context, Result, bail};
use sillage::core::Error;
use sillage::io::{MotGroundTruthWriter, MotRow, SeqInfo, write_png_rgb, write_seqinfo};
use sillage::synth::{
    CrossingParams, GroupSplitParams, RandomParams, Scenario, WalkerTruth, WalkersParams,
    WalkersSequence,
};

use crate::cli::{SynthWalkersArgs, WalkersScenarioArg};
use crate::progress::FrameProgress;

/// Frame rate written into `seqinfo.ini`, fps: a common video rate, at which the walkers'
/// 0.5-2.5 px/frame are a walking pace for 64 px tall people.
const FRAME_RATE: f64 = 25.0;

/// Walkers the two-person scenarios have.
const PAIR: usize = 2;

/// Shift from the generator's boxes (pixel centres at whole numbers) to the trackers' (a
/// blob's first column `x0` is its left edge): half a pixel.
const PIXEL_EDGE_SHIFT_PX: f64 = 0.5;

/// The generator's parameters from the command line, on top of its defaults.
fn params(args: &SynthWalkersArgs) -> Result<WalkersParams> {
    let scenario = match args.scenario {
        WalkersScenarioArg::Crossing => Scenario::Crossing(CrossingParams::default()),
        WalkersScenarioArg::GroupSplit => Scenario::GroupSplit(GroupSplitParams::default()),
        WalkersScenarioArg::Random => Scenario::Random(RandomParams {
            n: args.walkers.unwrap_or(RandomParams::default().n),
            ..RandomParams::default()
        }),
    };
    if let Some(n) = args.walkers.filter(|&n| n != PAIR)
        && args.scenario != WalkersScenarioArg::Random
    {
        bail!(
            "--walkers {n}: only --scenario random takes a number of walkers; crossing and \
             group-split have {PAIR}"
        );
    }
    let defaults = WalkersParams::default();
    let params = WalkersParams {
        width: args.width,
        height: args.height,
        n_frames: args.frames.unwrap_or(defaults.n_frames),
        scenario,
        seed: args.seed,
        ..defaults
    };
    params.validate().map_err(name_the_option)?;
    Ok(params)
}

/// A parameter error with the command-line option that sets the key, when there is one.
fn name_the_option(error: Error) -> anyhow::Error {
    let option = match &error {
        Error::Parameter { key, .. } => match key.as_str() {
            "width" => Some("--width"),
            "height" => Some("--height"),
            "n_frames" => Some("--frames"),
            "scenario.n" => Some("--walkers"),
            _ => None,
        },
        _ => None,
    };
    match option {
        Some(option) => anyhow::Error::new(error).context(format!("option {option}")),
        None => error.into(),
    }
}

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
        .with_context(|| format!("cannot create the folder {}", path.display()))
}

/// `sillage synth walkers --out DIR`.
pub fn run(args: &SynthWalkersArgs) -> Result<()> {
    let params = params(args)?;
    let dir = &args.out;
    let (images, gt_dir) = (dir.join("img1"), dir.join("gt"));
    create_dir(&images)?;
    create_dir(&gt_dir)?;
    let mut gt = MotGroundTruthWriter::create(gt_dir.join("gt.txt"))?;
    let mut progress = FrameProgress::new(Some(params.n_frames), "rendering");
    let mut rows = Vec::new();
    for frame in WalkersSequence::new(params.clone())? {
        write_png_rgb(
            images.join(format!("{:06}.png", frame.index + 1)),
            &frame.colour,
        )?;
        rows.clear();
        rows.extend(frame.truth.iter().map(|t| gt_row(frame.index, t)));
        gt.push(&rows)?;
        progress.tick();
    }
    progress.finish();
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
    eprintln!(
        "{} frames, {written} walker boxes → {} (img1/, gt/gt.txt, seqinfo.ini)",
        params.n_frames,
        dir.display()
    );
    Ok(())
}

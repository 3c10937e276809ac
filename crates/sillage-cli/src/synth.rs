//! `sillage synth vortex`: frames as 16-bit PNG and the ground truth as CSV.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use sillage::io::TruthCsvWriter;
use sillage::io::write_png16;
use sillage::synth::vortex::{VortexParams, VortexSequence};

use crate::cli::VortexArgs;
use crate::progress::FrameProgress;

/// The vortex parameters of the command line, on top of the generator's defaults.
pub fn vortex_params(args: &VortexArgs) -> VortexParams {
    VortexParams {
        width: args.width,
        height: args.height,
        n_particles: args.particles,
        n_frames: args.frames,
        snr: args.snr,
        delta: args.delta,
        intermittency: args.intermittency,
        brownian: args.brownian,
        seed: args.seed,
        ..VortexParams::default()
    }
}

/// Where frame `index` of a generated sequence is written.
pub fn frame_path(dir: &Path, index: u64) -> PathBuf {
    dir.join(format!("frame_{index:05}.png"))
}

/// Writes the sequence of `params` into `dir`: `frame_NNNNN.png` and `truth.csv`.
pub fn write_vortex(params: &VortexParams, dir: &Path) -> Result<PathBuf> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    let truth_path = dir.join("truth.csv");
    let mut truth = TruthCsvWriter::create(&truth_path)?;
    let mut progress = FrameProgress::new(Some(params.n_frames), "rendering");
    for frame in VortexSequence::new(params.clone())? {
        write_png16(frame_path(dir, frame.index), &frame.image)?;
        truth.push(&frame.truth)?;
        progress.tick();
    }
    progress.finish();
    truth.finish()?;
    Ok(truth_path)
}

/// `sillage synth vortex --out DIR`.
pub fn run_vortex(args: &VortexArgs) -> Result<()> {
    let truth = write_vortex(&vortex_params(args), &args.out)?;
    eprintln!(
        "{} frames written to {}, truth in {}",
        args.frames,
        args.out.display(),
        truth.display()
    );
    Ok(())
}

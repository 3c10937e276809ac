//! `sillage synth vortex`: frames as 16-bit PNG and the ground truth as CSV.

use anyhow::Result;
use sillage::synth::vortex::VortexParams;
use sillage::vortex_files::write_vortex;

use crate::cli::VortexArgs;
use crate::progress::FrameProgress;

/// The vortex parameters of the command line, on top of the generator's defaults.
fn vortex_params(args: &VortexArgs) -> VortexParams {
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

/// Writes the sequence of `params` into `dir` with a progress bar; returns the truth file.
pub fn write_vortex_with_progress(
    params: &VortexParams,
    dir: &std::path::Path,
) -> Result<std::path::PathBuf> {
    let mut progress = FrameProgress::new(Some(params.n_frames), "rendering");
    let truth = write_vortex(params, dir, &mut || progress.tick());
    progress.finish();
    Ok(truth?)
}

/// `sillage synth vortex --out DIR`.
pub fn run_vortex(args: &VortexArgs) -> Result<()> {
    let truth = write_vortex_with_progress(&vortex_params(args), &args.out)?;
    eprintln!(
        "{} frames written to {}, truth in {}",
        args.frames,
        args.out.display(),
        truth.display()
    );
    Ok(())
}

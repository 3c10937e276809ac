//! `sillage synth vortex`: frames as 16-bit PNG and the ground truth as CSV.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sillage::synth::vortex::VortexParams;
use sillage::vortex_files::write_vortex;

use crate::progress::FrameProgress;

/// `sillage synth vortex`.
#[derive(Debug, Args)]
pub struct VortexArgs {
    /// Output folder (created): frame_00000.png ... and truth.csv.
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
    /// Number of frames.
    #[arg(long, default_value_t = 50)]
    pub frames: usize,
    /// Number of particles.
    #[arg(long, default_value_t = 1000)]
    pub particles: usize,
    /// Frame width, px.
    #[arg(long, default_value_t = 1024)]
    pub width: usize,
    /// Frame height, px.
    #[arg(long, default_value_t = 1024)]
    pub height: usize,
    /// Signal-to-noise ratio (blob peak over noise magnitude).
    #[arg(long, default_value_t = 4.0)]
    pub snr: f64,
    /// Time step δ of Eqs. 13-16 (larger = faster flow).
    #[arg(long, default_value_t = 0.01)]
    pub delta: f64,
    /// Share of particles re-seeded per frame (0-0.5).
    #[arg(long, default_value_t = 0.0)]
    pub intermittency: f64,
    /// Brownian noise added to the displacements.
    #[arg(long, default_value_t = 0.0)]
    pub brownian: f64,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

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

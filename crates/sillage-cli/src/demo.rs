//! `sillage demo`: a synthetic vortex sequence written to disk, tracked from the files,
//! written in every format, scored against its truth.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sillage::PipelineConfig;
use sillage::demo::{score_demo, track_in_every_format};
use sillage::ptv_run::PtvRun;
use sillage::synth::vortex::VortexParams;

use crate::cli::DemoKind;
use crate::progress::FrameProgress;
use crate::shared_args::JsonArg;
use crate::synth::write_vortex_with_progress;

/// `sillage demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Output folder for frames, truth and tracks.
    #[arg(long, short, default_value = "out/demo", value_name = "DIR")]
    pub out: PathBuf,
    /// Number of frames.
    #[arg(long, default_value_t = 40)]
    pub frames: usize,
    /// Number of particles.
    #[arg(long, default_value_t = 1000)]
    pub particles: usize,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
    /// Another demo than the PTV one.
    #[command(subcommand)]
    pub kind: Option<DemoKind>,
}

/// `sillage demo`.
pub fn run(args: &DemoArgs) -> Result<()> {
    let params = VortexParams {
        n_frames: args.frames,
        n_particles: args.particles,
        seed: args.seed,
        ..VortexParams::default()
    };
    let frames_dir = args.out.join("frames");
    eprintln!(
        "1/3 synthetic vortex flow (TracTrac paper Eqs. 13-16): {} particles, {} frames of {}×{}, SNR {} → {}",
        params.n_particles,
        params.n_frames,
        params.width,
        params.height,
        params.snr,
        frames_dir.display()
    );
    let truth_path = write_vortex_with_progress(&params, &frames_dir)?;

    eprintln!("2/3 tracking the PNG frames with the default PTV configuration");
    let run = PtvRun::open(
        &PipelineConfig::default(),
        &frames_dir.display().to_string(),
    )?;
    let mut progress = FrameProgress::new(run.frame_count(), "tracking");
    let tracks = track_in_every_format(run, &args.out, &mut |r| progress.frame(r));
    progress.finish();
    let tracks = tracks?;

    eprintln!("3/3 scoring against {}", truth_path.display());
    let summary = score_demo(&truth_path, tracks)?;
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        let run = &summary.run;
        println!(
            "tracked {} frames: {} detections, {} track points in {} tracks ({:.2} ms/frame detection, {:.2} ms/frame tracking)",
            run.frames,
            run.detections,
            run.points,
            run.tracks,
            run.detect_ms_per_frame,
            run.track_ms_per_frame
        );
        println!("{}", summary.accuracy);
        println!("outputs: {}", summary.outputs.join(", "));
    }
    Ok(())
}

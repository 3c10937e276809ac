//! `sillage demo`: a synthetic vortex sequence written to disk, tracked from the files,
//! written in every format, scored against its truth.

use anyhow::Result;
use sillage::PipelineConfig;
use sillage::demo::{score_demo, track_in_every_format};
use sillage::ptv_run::PtvRun;
use sillage::synth::vortex::VortexParams;

use crate::cli::DemoArgs;
use crate::progress::FrameProgress;
use crate::synth::write_vortex_with_progress;

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
    if args.json {
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

//! `sillage synth bedload`: a synthetic bedload sequence as the bedload trackers and
//! `sillage eval mot` read it — truth in BeadTracking's layout, detections and
//! detector-confidence candidates as CSV, and the bead sizes in `sequence_param.txt`
//! (written by `sillage::bedload::synth`).

use anyhow::Result;
use sillage::bedload::synth::write_synthetic_sequence;
use sillage::synth::{BedloadDetectionParams, BedloadSceneParams};

use crate::cli::SynthBedloadArgs;
use crate::progress::FrameProgress;

/// The scene and detector parameters of the command line, on top of the defaults.
fn params(args: &SynthBedloadArgs) -> (BedloadSceneParams, BedloadDetectionParams) {
    let scene = BedloadSceneParams {
        n_frames: args.frames,
        n_black: args.black,
        n_transparent: args.transparent,
        seed: args.seed,
        ..BedloadSceneParams::default()
    };
    let detection = BedloadDetectionParams {
        position_sigma_px: args.noise,
        transparent_miss_probability: args.miss,
        burst_probability: args.burst,
        false_positive_mean: args.false_positives,
        ..BedloadDetectionParams::default()
    };
    (scene, detection)
}

/// `sillage synth bedload --out DIR`.
pub fn run_bedload(args: &SynthBedloadArgs) -> Result<()> {
    let (scene, detection) = params(args);
    let mut progress = FrameProgress::new(Some(scene.n_frames), "generating");
    let rows = write_synthetic_sequence(&args.out, &scene, detection, &mut || progress.tick());
    progress.finish();
    eprintln!(
        "{} frames, {} true bead points → {} (truth.csv, detections.csv, candidates.csv, \
         sequence_param.txt)",
        scene.n_frames,
        rows?,
        args.out.display()
    );
    Ok(())
}

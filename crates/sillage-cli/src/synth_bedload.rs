//! `sillage synth bedload`: a synthetic bedload sequence as the bedload trackers and
//! `sillage eval mot` read it — truth in BeadTracking's layout, detections and
//! detector-confidence candidates as CSV, and the bead sizes in `sequence_param.txt`
//! (written by `sillage::bedload::synth`).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sillage::bedload::synth::write_synthetic_sequence;
use sillage::synth::{BedloadDetectionParams, BedloadSceneParams};

use crate::progress::FrameProgress;

/// `sillage synth bedload`.
#[derive(Debug, Args)]
pub struct SynthBedloadArgs {
    /// Output folder (created): truth.csv, detections.csv, candidates.csv, sequence_param.txt.
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
    /// Number of frames (1280×320 px each).
    #[arg(long, default_value_t = 200)]
    pub frames: usize,
    /// Black beads (a packed bed, the rest mobile).
    #[arg(long, default_value_t = 300)]
    pub black: usize,
    /// Transparent beads (all mobile).
    #[arg(long, default_value_t = 100)]
    pub transparent: usize,
    /// Probability that a transparent bead is missed in a frame.
    #[arg(long, default_value_t = 0.03)]
    pub miss: f64,
    /// Probability per transparent bead and frame that a 5-frame run of misses starts.
    #[arg(long, default_value_t = 0.01)]
    pub burst: f64,
    /// Mean number of false detections per frame.
    #[arg(long, default_value_t = 1.0)]
    pub false_positives: f64,
    /// Standard deviation of the detection position noise, px.
    #[arg(long, default_value_t = 0.5)]
    pub noise: f64,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

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

//! `sillage synth walkers`: a synthetic walkers sequence as a MOTChallenge sequence folder
//! (`sillage::pedestrian::walkers`), its generator's parameters from the command line.

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::{Args, ValueEnum};
use sillage::core::Error;
use sillage::pedestrian::walkers::write_walkers_sequence;
use sillage::synth::{CrossingParams, GroupSplitParams, RandomParams, Scenario, WalkersParams};

use crate::progress::FrameProgress;

/// The walkers scenarios of the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum WalkersScenarioArg {
    /// Two walkers crossing; the near one hides the far one for 5 frames.
    Crossing,
    /// Two walkers entering together (one blob) who then split.
    GroupSplit,
    /// Walkers entering from the borders at random times and speeds.
    Random,
}

/// `sillage synth walkers`.
#[derive(Debug, Args)]
pub struct SynthWalkersArgs {
    /// Output sequence folder (created): img1/000001.png ..., gt/gt.txt, seqinfo.ini.
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
    /// What the walkers do.
    #[arg(long, value_enum, default_value_t = WalkersScenarioArg::Crossing)]
    pub scenario: WalkersScenarioArg,
    /// Number of walkers (random scenario only; the others have two).
    #[arg(long)]
    pub walkers: Option<usize>,
    /// Number of frames, the 10 empty warm-up frames included (default 150).
    #[arg(long)]
    pub frames: Option<usize>,
    /// Frame width, px.
    #[arg(long, default_value_t = 320)]
    pub width: usize,
    /// Frame height, px.
    #[arg(long, default_value_t = 240)]
    pub height: usize,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// Walkers the two-person scenarios have.
const PAIR: usize = 2;

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

/// `sillage synth walkers --out DIR`.
pub fn run(args: &SynthWalkersArgs) -> Result<()> {
    let params = params(args)?;
    let dir = &args.out;
    let mut progress = FrameProgress::new(Some(params.n_frames), "rendering");
    let written = write_walkers_sequence(&params, dir, &mut || progress.tick());
    progress.finish();
    let written = written?;
    eprintln!(
        "{} frames, {written} walker boxes → {} (img1/, gt/gt.txt, seqinfo.ini)",
        params.n_frames,
        dir.display()
    );
    Ok(())
}

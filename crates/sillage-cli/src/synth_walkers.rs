//! `sillage synth walkers`: a synthetic walkers sequence as a MOTChallenge sequence folder
//! (`sillage::pedestrian::walkers`), its generator's parameters from the command line.

use anyhow::{Result, bail};
use sillage::core::Error;
use sillage::pedestrian::walkers::write_walkers_sequence;
use sillage::synth::{CrossingParams, GroupSplitParams, RandomParams, Scenario, WalkersParams};

use crate::cli::{SynthWalkersArgs, WalkersScenarioArg};
use crate::progress::FrameProgress;

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

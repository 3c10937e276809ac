//! `sillage eval ptv`: the TracTrac paper's accuracy indexes from files.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sillage::eval::ptv::PtvAccuracyParams;
use sillage::evaluate::ptv_accuracy_of_files;

use crate::shared_args::JsonArg;

/// `sillage eval ptv`.
#[derive(Debug, Args)]
pub struct EvalPtvArgs {
    /// Ground truth CSV (frame,track_id,x,y[,vx,vy]).
    #[arg(long, value_name = "FILE")]
    pub truth: PathBuf,
    /// Tracks (TracTrac _track.txt, CSV, Parquet).
    #[arg(long, value_name = "FILE")]
    pub tracks: PathBuf,
    /// Maximum position error d for a true recovery, px.
    #[arg(long, default_value_t = 1.0)]
    pub max_position_error: f64,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// `sillage eval ptv --truth FILE --tracks FILE`.
pub fn run_ptv(args: &EvalPtvArgs) -> Result<()> {
    let params = PtvAccuracyParams {
        max_position_error_px: args.max_position_error,
    };
    let accuracy = ptv_accuracy_of_files(&args.truth, &args.tracks, &params)?;
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&accuracy)?);
    } else {
        println!("{accuracy}");
    }
    Ok(())
}

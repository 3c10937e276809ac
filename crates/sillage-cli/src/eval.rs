//! `sillage eval ptv`: the TracTrac paper's accuracy indexes from files.

use anyhow::Result;
use sillage::eval::ptv::{PtvAccuracyParams, ptv_accuracy};
use sillage::io::read_truth_csv;
use sillage::io::{TrackFormat, read_tracks};

use crate::cli::EvalPtvArgs;

/// `sillage eval ptv --truth FILE --tracks FILE`.
pub fn run_ptv(args: &EvalPtvArgs) -> Result<()> {
    let truth = read_truth_csv(&args.truth)?;
    let tracks = read_tracks(&args.tracks, TrackFormat::from_path(&args.tracks)?)?;
    let params = PtvAccuracyParams {
        max_position_error_px: args.max_position_error,
    };
    let accuracy = ptv_accuracy(&truth, &tracks, &params)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&accuracy)?);
    } else {
        println!("{accuracy}");
    }
    Ok(())
}

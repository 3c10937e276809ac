//! `sillage eval ptv`: the TracTrac paper's accuracy indexes from files.

use anyhow::Result;
use sillage::eval::ptv::PtvAccuracyParams;
use sillage::evaluate::ptv_accuracy_of_files;

use crate::cli::EvalPtvArgs;

/// `sillage eval ptv --truth FILE --tracks FILE`.
pub fn run_ptv(args: &EvalPtvArgs) -> Result<()> {
    let params = PtvAccuracyParams {
        max_position_error_px: args.max_position_error,
    };
    let accuracy = ptv_accuracy_of_files(&args.truth, &args.tracks, &params)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&accuracy)?);
    } else {
        println!("{accuracy}");
    }
    Ok(())
}

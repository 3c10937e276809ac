//! `sillage bench eulerian`: the time and peak memory of binning track tables of growing
//! length (10⁵ to 10⁷ rows by default). The statistics stream row by row, so the peak
//! memory must stay flat while the time grows linearly.

use std::path::Path;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sillage::eulerian_bench::bench_eulerian_case;

use crate::progress::RowProgress;
use crate::ptv::output_format;
use crate::shared_args::{FormatArg, JsonArg};

/// `sillage bench eulerian`.
#[derive(Debug, Args)]
pub struct BenchEulerianArgs {
    /// Table lengths to bin, rows, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = vec![100_000, 1_000_000, 10_000_000])]
    pub rows: Vec<u64>,
    /// Format of the generated tables.
    #[arg(long, value_enum, default_value = "csv")]
    pub format: FormatArg,
    /// Folder for the generated tables (each deleted after its run).
    #[arg(long, value_name = "DIR", default_value = ".")]
    pub dir: PathBuf,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// Runs `sillage bench eulerian`.
pub fn run(args: &BenchEulerianArgs) -> Result<()> {
    let format = output_format(Some(args.format), Path::new("."))?;
    if !args.json.enabled {
        println!(
            "{:>10} {:>8} {:>9} {:>9} {:>10} {:>6} {:>14}",
            "rows", "format", "file MiB", "time s", "Mrows/s", "bins", "peak RSS MiB"
        );
    }
    for &rows in &args.rows {
        let mut progress = RowProgress::new("binning");
        let row = bench_eulerian_case(&args.dir, format, rows, &mut || progress.tick());
        progress.finish();
        let row = row?;
        if args.json.enabled {
            println!("{}", serde_json::to_string(&row)?);
        } else {
            println!(
                "{:>10} {:>8} {:>9.1} {:>9.2} {:>10.2} {:>6} {:>14}",
                row.rows,
                row.format,
                row.file_mib,
                row.seconds,
                row.million_rows_per_s,
                row.bins,
                row.peak_rss_mib.map_or("n/a".into(), |m| format!("{m:.1}")),
            );
        }
    }
    Ok(())
}

//! `sillage bench eulerian`: the time and peak memory of binning track tables of growing
//! length (10⁵ to 10⁷ rows by default). The statistics stream row by row, so the peak
//! memory must stay flat while the time grows linearly.

use std::path::Path;

use anyhow::Result;
use sillage::eulerian_bench::bench_eulerian_case;

use crate::cli::BenchEulerianArgs;
use crate::progress::RowProgress;
use crate::ptv::output_format;

/// Runs `sillage bench eulerian`.
pub fn run(args: &BenchEulerianArgs) -> Result<()> {
    let format = output_format(Some(args.format), Path::new("."))?;
    if !args.json {
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
        if args.json {
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

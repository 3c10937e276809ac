//! `sillage bench ptv`: detection and tracking time per frame on synthetic vortex frames, and
//! the process's peak memory, for a sweep of particle counts and frame sizes; with `--files`,
//! the whole path from frame files to a track file, per stage.

use anyhow::{Context, Result};
use clap::Args;
use sillage::config::PipelineConfig;
use sillage::io::TrackFormat;
use sillage::ptv_bench::{bench_ptv_case, stream_memory};
use sillage::ptv_files_bench::bench_ptv_files;

use crate::shared_args::JsonArg;

/// `sillage bench ptv`.
#[derive(Debug, Args)]
pub struct BenchPtvArgs {
    /// Particle counts to time, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = vec![1000, 5000, 25000])]
    pub particles: Vec<usize>,
    /// Frame sizes to time (square, px), comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = vec![1024, 2048])]
    pub sizes: Vec<usize>,
    /// Frames timed per case (after 3 warm-up frames).
    #[arg(long, default_value_t = 20)]
    pub frames: usize,
    /// Instead of the sweep, stream this many frames (first size and particle count) and print
    /// the resident memory every tenth of the way.
    #[arg(long, value_name = "FRAMES")]
    pub stream: Option<usize>,
    /// Instead of the sweep, time the whole path from these frame files (folder, glob, TIFF
    /// stack or video) to a track file, per stage, with the default settings.
    #[arg(long, value_name = "FRAMES")]
    pub files: Option<String>,
    /// With `--files`: the output formats to time, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = vec!["tractrac".to_string(), "csv".to_string(), "parquet".to_string()])]
    pub formats: Vec<String>,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// `sillage bench ptv --files FRAMES`: decode, detect, track, write and wall, ms per frame.
fn run_files(args: &BenchPtvArgs, input: &str) -> Result<()> {
    let formats = args
        .formats
        .iter()
        .map(|name| {
            TrackFormat::ALL
                .into_iter()
                .find(|f| f.name() == name)
                .with_context(|| {
                    format!(
                        "--formats: unknown format `{name}`; use tractrac, csv, parquet or hdf5"
                    )
                })
        })
        .collect::<Result<Vec<_>>>()?;
    let rows = bench_ptv_files(&PipelineConfig::default(), input, &formats)?;
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&rows)?);
        return Ok(());
    }
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!("sillage bench ptv --files {input}: {threads} threads, ms per frame");
    println!(
        "{:>9} {:>7} {:>10} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "format", "frames", "points", "decode", "detect", "track", "write", "wall"
    );
    for r in &rows {
        println!(
            "{:>9} {:>7} {:>10} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>9.2}",
            r.format,
            r.frames,
            r.points,
            r.decode_ms,
            r.detect_ms,
            r.track_ms,
            r.write_ms,
            r.wall_ms
        );
    }
    println!(
        "decode and write are timed alone; in the run they overlap detection and tracking on \
         their own threads"
    );
    Ok(())
}

/// `sillage bench ptv`.
pub fn run_ptv(args: &BenchPtvArgs) -> Result<()> {
    if let Some(input) = &args.files {
        return run_files(args, input);
    }
    if let Some(frames) = args.stream {
        let size = args.sizes.first().copied().unwrap_or(1024);
        let particles = args.particles.first().copied().unwrap_or(1000);
        println!("memory over a {frames}-frame stream ({size}×{size}, {particles} particles):");
        stream_memory(size, particles, frames, &mut |done, rss| {
            let rss = rss.map_or("n/a".into(), |m| format!("{m:.1}"));
            println!("  frame {done:>6}: RSS {rss} MiB");
        })?;
        return Ok(());
    }
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let mut rows = Vec::new();
    if !args.json.enabled {
        println!(
            "sillage bench ptv: {threads} threads, {} timed frames per case",
            args.frames
        );
        println!(
            "{:>6} {:>9} {:>11} {:>10} {:>11} {:>10} {:>10} {:>10}",
            "size",
            "particles",
            "detections",
            "tracked",
            "detect ms",
            "track ms",
            "total ms",
            "peak MiB"
        );
    }
    for &size in &args.sizes {
        for &particles in &args.particles {
            let row = bench_ptv_case(size, particles, args.frames)?;
            if !args.json.enabled {
                println!(
                    "{:>6} {:>9} {:>11.0} {:>10.0} {:>11.2} {:>10.2} {:>10.2} {:>10}",
                    row.size_px,
                    row.particles,
                    row.detections_per_frame,
                    row.points_per_frame,
                    row.detect_ms_per_frame,
                    row.track_ms_per_frame,
                    row.total_ms_per_frame,
                    row.peak_rss_mib.map_or("n/a".into(), |m| format!("{m:.0}"))
                );
            }
            rows.push(row);
        }
    }
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    }
    Ok(())
}

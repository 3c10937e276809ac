//! `sillage bench ptv`: detection and tracking time per frame on synthetic vortex frames, and
//! the process's peak memory, for a sweep of particle counts and frame sizes.

use anyhow::Result;
use clap::Args;
use sillage::ptv_bench::{bench_ptv_case, stream_memory};

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
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// `sillage bench ptv`.
pub fn run_ptv(args: &BenchPtvArgs) -> Result<()> {
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

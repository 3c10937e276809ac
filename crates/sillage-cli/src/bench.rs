//! `sillage bench ptv`: detection and tracking time per frame on synthetic vortex frames, and
//! the process's peak memory, for a sweep of particle counts and frame sizes.

use anyhow::Result;
use sillage::ptv_bench::{bench_ptv_case, stream_memory};

use crate::cli::BenchPtvArgs;

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
    if !args.json {
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
            if !args.json {
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
    if args.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    }
    Ok(())
}

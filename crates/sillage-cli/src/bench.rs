//! `sillage bench ptv`: detection and tracking time per frame on synthetic vortex frames, and
//! the process's peak memory, for a sweep of particle counts and frame sizes.

use std::path::PathBuf;

use anyhow::Result;
use serde::Serialize;
use sillage::io::Frame;
use sillage::synth::vortex::{VortexParams, VortexSequence};
use sillage::{Pipeline, PipelineConfig};

use crate::cli::BenchPtvArgs;

/// Frames run before timing starts (the tracker needs two frames before it links).
const WARM_UP_FRAMES: usize = 3;

/// One row of the table.
#[derive(Serialize)]
struct BenchRow {
    size_px: usize,
    particles: usize,
    frames_timed: usize,
    detections_per_frame: f64,
    points_per_frame: f64,
    detect_ms_per_frame: f64,
    track_ms_per_frame: f64,
    total_ms_per_frame: f64,
    peak_rss_mib: Option<f64>,
}

/// Peak resident memory of this process so far (Linux `VmHWM`), MiB.
pub(crate) fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// Resets the peak resident memory to the current one (Linux ≥ 4.0, `clear_refs` 5), so
/// that the next [`peak_rss_mib`] measures what ran in between; false where unsupported.
pub(crate) fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Current resident memory of this process (Linux `VmRSS`), MiB.
fn rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// Synthetic vortex frames rendered on the fly, as the pipeline's frame stream.
fn vortex_frames(
    size: usize,
    particles: usize,
    frames: usize,
) -> Result<impl Iterator<Item = sillage::core::Result<Frame>>> {
    let params = VortexParams {
        width: size,
        height: size,
        n_particles: particles,
        n_frames: frames,
        ..VortexParams::default()
    };
    Ok(VortexSequence::new(params)?.map(|f| {
        Ok(Frame {
            index: f.index,
            path: PathBuf::from(format!("synthetic:{}", f.index)),
            image: f.image,
            colour: None,
        })
    }))
}

/// Times one (size, particles) case. Frames are rendered on the fly (rendering is not timed),
/// so the peak memory is that of a streaming run. Track points are dropped, so "track"
/// times the linking itself, not the growth of an in-memory table (which cost ~5 ms per
/// frame at 25,000 particles when the points were collected into a `Vec`).
fn bench_case(size: usize, particles: usize, frames: usize) -> Result<BenchRow> {
    let mut pipeline = Pipeline::from_config(&PipelineConfig::default())?;
    let mut sink = sillage::core::DiscardSink;
    let (mut detect_ms, mut track_ms, mut detections, mut points) = (0.0, 0.0, 0usize, 0usize);
    let stream = vortex_frames(size, particles, frames + WARM_UP_FRAMES)?;
    pipeline.run(stream, &mut sink, &mut |report| {
        if report.frame as usize >= WARM_UP_FRAMES {
            detect_ms += report.detect_time.as_secs_f64() * 1e3;
            track_ms += report.track_time.as_secs_f64() * 1e3;
            detections += report.detections;
            points += report.points_emitted;
        }
    })?;
    let n = frames.max(1) as f64;
    Ok(BenchRow {
        size_px: size,
        particles,
        frames_timed: frames,
        detections_per_frame: detections as f64 / n,
        points_per_frame: points as f64 / n,
        detect_ms_per_frame: detect_ms / n,
        track_ms_per_frame: track_ms / n,
        total_ms_per_frame: (detect_ms + track_ms) / n,
        peak_rss_mib: peak_rss_mib(),
    })
}

/// A long streaming run that prints the resident memory every tenth of the way, to show it
/// stays flat whatever the sequence length. Track points go to a sink that drops them (as a
/// file writer would after writing).
fn memory_stream(size: usize, particles: usize, frames: usize) -> Result<()> {
    println!("memory over a {frames}-frame stream ({size}×{size}, {particles} particles):");
    let mut pipeline = Pipeline::from_config(&PipelineConfig::default())?;
    let step = (frames / 10).max(1);
    pipeline.run(
        vortex_frames(size, particles, frames)?,
        &mut sillage::core::DiscardSink,
        &mut |report| {
            let done = report.frame as usize + 1;
            if done.is_multiple_of(step) {
                let rss = rss_mib().map_or("n/a".into(), |m| format!("{m:.1}"));
                println!("  frame {done:>6}: RSS {rss} MiB");
            }
        },
    )?;
    Ok(())
}

/// `sillage bench ptv`.
pub fn run_ptv(args: &BenchPtvArgs) -> Result<()> {
    if let Some(frames) = args.stream {
        let size = args.sizes.first().copied().unwrap_or(1024);
        let particles = args.particles.first().copied().unwrap_or(1000);
        return memory_stream(size, particles, frames);
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
            let row = bench_case(size, particles, args.frames)?;
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

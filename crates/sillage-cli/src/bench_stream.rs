//! `sillage bench stream`: a long synthetic stream (no files) through PTV or MMPF+, the
//! resident memory and throughput sampled along the way, track ids checked never to come
//! back; a CSV of the samples and a plot of memory against frame.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, ValueEnum};
use sillage::plots::write_plot;
use sillage::stream_bench::{StreamSample, StreamTracker, stream_frames};
use sillage::viz::{Curve, LineChart};

use crate::shared_args::JsonArg;

/// The trackers `bench stream` runs.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum StreamTrackerArg {
    /// PTV, 500 particles of the paper's vortex on 512² px (positions as detections).
    Ptv,
    /// MMPF+ on the synthetic bedload scene's detections and candidates.
    Bedload,
}

/// `sillage bench stream`.
#[derive(Debug, Args)]
pub struct BenchStreamArgs {
    /// Which tracker.
    #[arg(long, value_enum, default_value_t = StreamTrackerArg::Ptv)]
    pub tracker: StreamTrackerArg,
    /// Frames to stream.
    #[arg(long, default_value_t = 1_000_000)]
    pub frames: usize,
    /// Samples of memory and throughput along the way.
    #[arg(long, default_value_t = 100)]
    pub samples: usize,
    /// Write the samples as CSV (`frames,rss_mib,frames_per_s,points,tracks`).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Plot the resident memory against the frame (PNG or SVG).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// `--json`: the samples on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// `sillage bench stream`.
pub fn run(args: &BenchStreamArgs) -> Result<()> {
    let tracker = match args.tracker {
        StreamTrackerArg::Ptv => StreamTracker::Ptv,
        StreamTrackerArg::Bedload => StreamTracker::Bedload,
    };
    let mut samples: Vec<StreamSample> = Vec::new();
    stream_frames(tracker, args.frames, args.samples, &mut |sample| {
        if !args.json.enabled {
            eprintln!(
                "frame {:>9}: RSS {:>7} MiB, {:>8.0} frames/s, {} points, {} tracks",
                sample.frames,
                sample.rss_mib.map_or("n/a".into(), |m| format!("{m:.1}")),
                sample.frames_per_s,
                sample.points,
                sample.tracks
            );
        }
        samples.push(*sample);
    })?;
    if let Some(path) = &args.csv {
        let mut text = String::from("frames,rss_mib,frames_per_s,points,tracks\n");
        for s in &samples {
            let rss = s.rss_mib.map_or(String::new(), |m| format!("{m:.2}"));
            text.push_str(&format!(
                "{},{rss},{:.1},{},{}\n",
                s.frames, s.frames_per_s, s.points, s.tracks
            ));
        }
        sillage::io::write_text(path, &text)?;
    }
    if let Some(path) = &args.plot {
        let chart = LineChart {
            title: format!(
                "Resident memory over a {}-frame {tracker:?} stream",
                args.frames
            ),
            x_label: "frame".into(),
            y_label: "RSS (MiB)".into(),
            curves: vec![Curve {
                label: "RSS".into(),
                points: samples
                    .iter()
                    .filter_map(|s| Some((s.frames as f64, s.rss_mib?)))
                    .collect(),
            }],
        };
        write_plot(path, &chart, (900, 500))?;
    }
    if args.json.enabled {
        let mut out = std::io::stdout().lock();
        writeln!(out, "{}", serde_json::to_string_pretty(&samples)?)?;
    }
    Ok(())
}

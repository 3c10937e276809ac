//! `sillage demo`: a synthetic vortex sequence written to disk, tracked from the files,
//! written in every format, scored against its truth.

use anyhow::Result;
use serde::Serialize;
use sillage::core::{Result as CoreResult, TrackPoint, TrackSink};
use sillage::eval::ptv::{PtvAccuracy, PtvAccuracyParams, ptv_accuracy};
use sillage::io::read_truth_csv;
use sillage::io::{FrameOptions, open_frames};
use sillage::io::{TrackFormat, TrackWriter, create_track_writer};
use sillage::synth::vortex::VortexParams;
use sillage::{Pipeline, PipelineConfig, RunSummary};

use crate::cli::DemoArgs;
use crate::progress::FrameProgress;
use crate::ptv::track_header;
use crate::synth::write_vortex;

/// Sends every batch to several sinks (the writers and an in-memory copy for scoring).
struct FanOut<'a> {
    writers: Vec<Box<dyn TrackWriter>>,
    collected: &'a mut Vec<TrackPoint>,
}

impl TrackSink for FanOut<'_> {
    fn accept(&mut self, points: &[TrackPoint]) -> CoreResult<()> {
        for writer in &mut self.writers {
            writer.accept(points)?;
        }
        self.collected.extend_from_slice(points);
        Ok(())
    }
}

/// The demo's JSON summary.
#[derive(Serialize)]
struct DemoSummary {
    run: RunSummary,
    accuracy: PtvAccuracy,
    outputs: Vec<String>,
}

/// The formats the demo writes (Parquet when that feature is built).
fn demo_formats() -> Vec<(TrackFormat, &'static str)> {
    let mut formats = vec![
        (TrackFormat::Tractrac, "vortex_track.txt"),
        (TrackFormat::Csv, "tracks.csv"),
    ];
    if cfg!(feature = "parquet") {
        formats.push((TrackFormat::Parquet, "tracks.parquet"));
    }
    formats
}

/// `sillage demo`.
pub fn run(args: &DemoArgs) -> Result<()> {
    let params = VortexParams {
        n_frames: args.frames,
        n_particles: args.particles,
        seed: args.seed,
        ..VortexParams::default()
    };
    let frames_dir = args.out.join("frames");
    eprintln!(
        "1/3 synthetic vortex flow (TracTrac paper Eqs. 13-16): {} particles, {} frames of {}×{}, SNR {} → {}",
        params.n_particles,
        params.n_frames,
        params.width,
        params.height,
        params.snr,
        frames_dir.display()
    );
    let truth_path = write_vortex(&params, &frames_dir)?;

    eprintln!("2/3 tracking the PNG frames with the default PTV configuration");
    let config = PipelineConfig::default();
    let header = track_header(&config)?;
    let mut outputs = Vec::new();
    let mut writers = Vec::new();
    for (format, name) in demo_formats() {
        let path = args.out.join(name);
        writers.push(create_track_writer(&path, format, &header)?);
        outputs.push(path.display().to_string());
    }
    let mut collected = Vec::new();
    let mut sink = FanOut {
        writers,
        collected: &mut collected,
    };
    let frames = open_frames(&frames_dir.display().to_string(), &FrameOptions::default())?;
    let mut progress = FrameProgress::new(frames.len(), "tracking");
    let run = Pipeline::from_config(&config)?.run(frames, &mut sink, &mut |r| progress.frame(r))?;
    progress.finish();
    for writer in sink.writers {
        writer.finish()?;
    }

    eprintln!("3/3 scoring against {}", truth_path.display());
    let truth = read_truth_csv(&truth_path)?;
    let accuracy = ptv_accuracy(&truth, &collected, &PtvAccuracyParams::default())?;
    if args.json {
        let summary = DemoSummary {
            run,
            accuracy,
            outputs,
        };
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        println!(
            "tracked {} frames: {} detections, {} track points in {} tracks ({:.2} ms/frame detection, {:.2} ms/frame tracking)",
            run.frames,
            run.detections,
            run.points,
            run.tracks,
            run.detect_ms_per_frame,
            run.track_ms_per_frame
        );
        println!("{accuracy}");
        println!("outputs: {}", outputs.join(", "));
    }
    Ok(())
}

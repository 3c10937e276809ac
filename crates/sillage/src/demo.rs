//! `sillage demo`: a synthetic vortex sequence tracked from its files, written in every track
//! format and scored against its truth (the TracTrac paper's recovery indexes).

use std::path::Path;

use serde::Serialize;
use sillage_core::{Result, TrackPoint, TrackSink};
use sillage_eval::ptv::{PtvAccuracy, PtvAccuracyParams, ptv_accuracy};
use sillage_io::{TrackFormat, TrackWriter, create_track_writer, read_truth_csv};

use crate::pipeline::{FrameReport, RunSummary};
use crate::ptv_run::PtvRun;

/// Sends every batch to several sinks (the writers and an in-memory copy for scoring).
struct FanOut<'a> {
    writers: Vec<Box<dyn TrackWriter + Send>>,
    collected: &'a mut Vec<TrackPoint>,
}

impl TrackSink for FanOut<'_> {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        for writer in &mut self.writers {
            writer.accept(points)?;
        }
        self.collected.extend_from_slice(points);
        Ok(())
    }
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

/// The tracks of the demo: in memory for scoring, and the files written.
#[derive(Debug, Clone)]
pub struct DemoTracks {
    /// Frames, detections, points and timings.
    pub run: RunSummary,
    /// Every track point, in emission order.
    pub points: Vec<TrackPoint>,
    /// The track files written, one per format.
    pub outputs: Vec<String>,
}

/// The demo's summary (its `--json` output).
#[derive(Debug, Clone, Serialize)]
pub struct DemoSummary {
    /// Frames, detections, points and timings.
    pub run: RunSummary,
    /// True and false recovery against the truth.
    pub accuracy: PtvAccuracy,
    /// The track files written.
    pub outputs: Vec<String>,
}

/// Tracks `run` into `out_dir` in every format at once (TracTrac, CSV and, when built,
/// Parquet), keeping the points for scoring; `on_frame` is called after each frame.
pub fn track_in_every_format(
    run: PtvRun,
    out_dir: &Path,
    on_frame: &mut dyn FnMut(&FrameReport),
) -> Result<DemoTracks> {
    let mut outputs = Vec::new();
    let mut writers = Vec::new();
    for (format, name) in demo_formats() {
        let path = out_dir.join(name);
        writers.push(create_track_writer(&path, format, run.header())?);
        outputs.push(path.display().to_string());
    }
    let mut points = Vec::new();
    let mut sink = FanOut {
        writers,
        collected: &mut points,
    };
    let summary = run.run(&mut sink, on_frame)?;
    for writer in sink.writers {
        writer.finish()?;
    }
    Ok(DemoTracks {
        run: summary,
        points,
        outputs,
    })
}

/// Scores the demo's `tracks` against the truth CSV at `truth_path`.
pub fn score_demo(truth_path: &Path, tracks: DemoTracks) -> Result<DemoSummary> {
    let truth = read_truth_csv(truth_path)?;
    let accuracy = ptv_accuracy(&truth, &tracks.points, &PtvAccuracyParams::default())?;
    Ok(DemoSummary {
        run: tracks.run,
        accuracy,
        outputs: tracks.outputs,
    })
}

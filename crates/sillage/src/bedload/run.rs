//! A bedload tracker's whole run into a bead track file (`sillage track bedload`): beads
//! detected in frames or read from a detections table, tracked by the [`Pipeline`], written
//! through [`crate::long_run`] (bad frames, checkpoints, resume).

use std::path::Path;

use sillage_core::{FrameIndex, Result};
use sillage_io::{FrameOptions, TrackWriter, open_frames};
use sillage_track::bedload::{BedloadStats, BedloadTrackerParams};

use super::BeadFrame;
use super::detector::BeadDetectorConfig;
use super::output::{BeadTrackKind, BeadTrackOutput};
use crate::checkpoint::RunIdentity;
use crate::config::{DetectorConfig, PipelineConfig, TrackerConfig};
use crate::long_run::{Inputs, LongRunOptions, LongRunOutcome, LongRunOutput, run_long};
use crate::pipeline::{FrameInput, FrameObserver, Pipeline};
use crate::toml_config::dotted_keys;

/// Where the beads come from.
pub enum BeadSource {
    /// Frames (a folder, a glob, a TIFF stack or a video) to detect the beads in.
    Frames {
        /// The frames as given.
        input: String,
        /// The bead detector.
        detector: Box<BeadDetectorConfig>,
    },
    /// Detections (with their candidates) made elsewhere.
    Detections {
        /// The table's name, for messages and the run's identity.
        name: String,
        /// Its frames.
        frames: Vec<BeadFrame>,
    },
}

/// A bedload run ready to track: its pipeline built, its frames counted when known.
pub struct BedloadRun {
    pipeline: Pipeline,
    config: PipelineConfig,
    params: BedloadTrackerParams,
    source: BeadSource,
    frame_count: Option<usize>,
}

impl BedloadRun {
    /// Builds the run of `params` over `source`; a frame source is opened once to count its
    /// frames (under `options`' bad-frame policy) and the sequence length checked against
    /// the parameters.
    pub fn open(
        params: &BedloadTrackerParams,
        source: BeadSource,
        options: &LongRunOptions,
    ) -> Result<Self> {
        let mut config = PipelineConfig {
            tracker: TrackerConfig::Bedload(Box::new(params.clone())),
            ..PipelineConfig::default()
        };
        let frame_count = match &source {
            BeadSource::Frames { input, detector } => {
                config.detector = DetectorConfig::Bead((**detector).clone());
                let frame_options = FrameOptions {
                    on_bad_frame: options.on_bad_frame,
                    ..FrameOptions::default()
                };
                open_frames(input, &frame_options)?.len()
            }
            BeadSource::Detections { .. } => None,
        };
        if let Some(total) = frame_count {
            params.check_sequence_length(total)?;
        }
        Ok(Self {
            pipeline: Pipeline::from_config(&config)?,
            config,
            params: params.clone(),
            source,
            frame_count,
        })
    }

    /// Number of frames to track, when known (frame sources that know their length).
    pub fn frame_count(&self) -> Option<usize> {
        self.frame_count
    }

    /// The input's name: the frames as given, or the detections table.
    pub fn source_name(&self) -> &str {
        match &self.source {
            BeadSource::Frames { input, .. } => input,
            BeadSource::Detections { name, .. } => name,
        }
    }

    /// The tracker's counts so far (frames, confirmed tracks, predictions through misses).
    pub fn stats(&self) -> BedloadStats {
        self.pipeline.bedload_stats().unwrap_or_default()
    }

    /// Tracks every frame into the bead track file `out` of `kind` under `options`;
    /// `on_frame` sees each frame tracked by this process and what the tracker was given.
    pub fn run_long(
        &mut self,
        out: &Path,
        kind: BeadTrackKind,
        options: &LongRunOptions,
        on_frame: &mut FrameObserver<'_>,
    ) -> Result<LongRunOutcome> {
        let mut settings = dotted_keys(&self.config)?;
        settings.push(("format".to_string(), format!("{kind:?}")));
        settings.extend(options.settings());
        let identity = RunIdentity::new("track bedload", self.source_name(), out, settings);
        let params = &self.params;
        let mut create_writer = || -> Result<Box<dyn TrackWriter + Send>> {
            Ok(Box::new(BeadTrackOutput::create(out, Some(kind), params)?))
        };
        let output = LongRunOutput {
            path: out,
            create_writer: &mut create_writer,
            identity,
        };
        let on_bad_frame = options.on_bad_frame;
        let source = &self.source;
        let mut open_inputs = |start_at: FrameIndex| -> Result<Inputs<'_>> {
            match source {
                BeadSource::Frames { input, .. } => {
                    let frames = open_frames(
                        input,
                        &FrameOptions {
                            on_bad_frame,
                            start_at,
                            ..FrameOptions::default()
                        },
                    )?;
                    let log = frames.skipped();
                    Ok((
                        Box::new(frames.map(|f| f.map(FrameInput::Image))),
                        Some(log),
                    ))
                }
                BeadSource::Detections { frames, .. } => Ok((
                    Box::new(
                        frames
                            .iter()
                            .filter(move |f| f.frame >= start_at)
                            .map(|f| Ok(f.clone().into())),
                    ),
                    None,
                )),
            }
        };
        run_long(
            &mut self.pipeline,
            &mut open_inputs,
            output,
            options,
            on_frame,
        )
    }
}

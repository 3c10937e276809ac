//! sillage: follow many moving objects through image sequences.
//!
//! This facade is the composition root: it re-exports the toolkit's crates, knows every
//! detector and tracker, and holds everything the command line computes, so that Rust users,
//! the Python package and any other runner reach the same code:
//! - [`Pipeline`] runs PTV or the bedload trackers with their detector from one
//!   [`PipelineConfig`], streaming, from frames or detection tables;
//! - [`track_source`] / [`detect_source`] run any of the four trackers (PTV, bedload, IMM-PF,
//!   SIFT-PF) or three detectors (blob, bead, motion) on a frame source ([`tracking`]);
//! - [`pedestrian`], [`bedload`]: the pedestrian and bedload runs, their inputs, settings,
//!   fits and outputs; [`experiments`]: each paper's tables, medians over seeds;
//! - [`evaluate`], [`tables`]: truth and tracks of every format, scored as TrackEval does;
//! - [`toml_config`]: every command's settings, read once and validated
//!   ([`toml_config::load`]);
//! - [`windows`]: a long run split into overlapping time windows tracked in parallel and
//!   stitched back into one set of trajectories.
//!
//! ```no_run
//! use sillage::{Pipeline, PipelineConfig};
//! use sillage::io::{open_frames, FrameOptions};
//! use sillage::core::TrackPoint;
//!
//! let config = PipelineConfig::default();
//! let mut pipeline = Pipeline::from_config(&config)?;
//! let frames = open_frames("experiment/*.tif", &FrameOptions::default())?;
//! let mut tracks: Vec<TrackPoint> = Vec::new();
//! let summary = pipeline.run(frames, &mut tracks, &mut |_| {})?;
//! println!("{} tracks over {} frames", summary.tracks, summary.frames);
//! # Ok::<(), sillage::core::Error>(())
//! ```

pub mod bedload;
pub mod checkpoint;
pub mod config;
pub mod demo;
pub mod detection_stage;
pub mod eulerian;
pub mod eulerian_bench;
mod eulerian_plots;
pub mod evaluate;
pub mod experiments;
mod folders;
pub mod long_run;
pub mod overlay;
pub mod pedestrian;
pub mod pipeline;
pub mod plots;
pub mod process_memory;
pub mod ptv_accuracy_bench;
pub mod ptv_bench;
pub mod ptv_files_bench;
pub mod ptv_run;
pub mod stream_bench;
pub mod tables;
pub mod toml_config;
pub mod tracking;
pub mod tractrac;
pub mod tune;
pub mod viewer;
pub mod vortex_files;
pub mod windows;

pub use config::{DetectorConfig, PipelineConfig, TrackerConfig};
pub use detection_stage::DetectionStage;
pub use pipeline::{
    FrameInput, FrameObserver, FrameReport, Pipeline, PipelineState, RunSummary, RunTally,
};
pub use tracking::{Detecting, Tracking, detect_source, track_source};

pub use sillage_assoc as assoc;
pub use sillage_core as core;
pub use sillage_detect as detect;
pub use sillage_eval as eval;
pub use sillage_filter as filter;
pub use sillage_image as image;
pub use sillage_io as io;
pub use sillage_synth as synth;
pub use sillage_track as track;
pub use sillage_viz as viz;

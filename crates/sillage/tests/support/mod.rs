//! Shared helpers of the facade's integration tests: a synthetic vortex run scored against
//! its truth, and points cut to a frame range.

use std::path::PathBuf;

use sillage::core::{TrackPoint, TruthPoint};
use sillage::eval::ptv::{PtvAccuracy, PtvAccuracyParams, ptv_accuracy};
use sillage::io::Frame;
use sillage::synth::vortex::{VortexParams, VortexSequence};
use sillage::{Pipeline, PipelineConfig, RunSummary};

/// Tracks the vortex sequence of `params` with `config` (frames streamed from the generator)
/// and returns the emitted points with the truth.
#[allow(dead_code)] // not every test file runs the vortex
pub fn track_vortex(
    params: &VortexParams,
    config: &PipelineConfig,
) -> (Vec<TrackPoint>, Vec<TruthPoint>, RunSummary) {
    let mut truth = Vec::new();
    let frames = VortexSequence::new(params.clone())
        .expect("valid vortex parameters")
        .map(|f| {
            truth.extend_from_slice(&f.truth);
            Ok(Frame {
                index: f.index,
                path: PathBuf::from(format!("vortex:{}", f.index)),
                image: f.image,
                colour: None,
            })
        });
    let mut tracks = Vec::new();
    let summary = Pipeline::from_config(config)
        .expect("valid configuration")
        .run(frames, &mut tracks, &mut |_| {})
        .expect("tracking succeeds");
    (tracks, truth, summary)
}

/// The TracTrac paper's accuracy indexes of a vortex run (d = 1 px).
#[allow(dead_code)] // not every test file runs the vortex
pub fn vortex_accuracy(params: &VortexParams, config: &PipelineConfig) -> PtvAccuracy {
    let (tracks, truth, _) = track_vortex(params, config);
    ptv_accuracy(&truth, &tracks, &PtvAccuracyParams::default()).expect("finite inputs")
}

/// The points of `points` in frames `range` (inclusive, 0-based).
#[allow(dead_code)] // used by the bedload tests only
pub fn in_frames(points: &[TrackPoint], range: [u64; 2]) -> Vec<TrackPoint> {
    points
        .iter()
        .filter(|p| (range[0]..=range[1]).contains(&p.frame))
        .copied()
        .collect()
}

//! The bedload scene and its detector model together, streamed frame by frame.

use serde::{Deserialize, Serialize};
use sillage_core::Result;

use super::{
    BeadDetectionModel, BedloadDetectionParams, BedloadFrame, BedloadObservation, BedloadScene,
    BedloadSceneParams,
};

/// One frame of a synthetic bedload sequence: the truth and what the detector reports.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BedloadSample {
    /// The true beads.
    pub truth: BedloadFrame,
    /// The detections and candidates made from them.
    pub observation: BedloadObservation,
}

/// A [`BedloadScene`] seen through a [`BeadDetectionModel`]: frames `0..n_frames` in
/// bounded memory. The truth does not depend on the detector's parameters.
#[derive(Debug, Clone)]
pub struct BedloadSequence {
    scene: BedloadScene,
    detector: BeadDetectionModel,
}

impl BedloadSequence {
    /// The sequence `params` and `detection` describe; fails on invalid parameters, naming
    /// the key.
    pub fn new(params: BedloadSceneParams, detection: BedloadDetectionParams) -> Result<Self> {
        let detector = BeadDetectionModel::new(detection, &params)?;
        Ok(Self {
            scene: BedloadScene::new(params)?,
            detector,
        })
    }

    /// The scene (its parameters and its bed surface).
    pub fn scene(&self) -> &BedloadScene {
        &self.scene
    }

    /// The next frame, `None` after `n_frames` frames.
    pub fn next_sample(&mut self) -> Option<BedloadSample> {
        let truth = self.scene.next_frame()?;
        let observation = self.detector.observe(&truth);
        Some(BedloadSample { truth, observation })
    }
}

impl Iterator for BedloadSequence {
    type Item = BedloadSample;

    fn next(&mut self) -> Option<BedloadSample> {
        self.next_sample()
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.scene.size_hint()
    }
}

impl ExactSizeIterator for BedloadSequence {}

/// Every frame of a short sequence at once (a long one streams through
/// [`BedloadSequence`]).
pub fn generate_bedload(
    params: BedloadSceneParams,
    detection: BedloadDetectionParams,
) -> Result<Vec<BedloadSample>> {
    Ok(BedloadSequence::new(params, detection)?.collect())
}

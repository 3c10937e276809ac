//! Synthetic bedload sequences as the bedload trackers and `sillage eval mot` read them:
//! truth in BeadTracking's layout, detections and detector-confidence candidates (Eq. (1)) as
//! CSV, and the bead sizes in `sequence_param.txt`.

use std::path::Path;

use sillage_core::{Result, TrackPoint, TrackSink};
use sillage_detect::{BeadDetector, BeadParams};
use sillage_io::{
    BeadCsvWriter, BeadSequenceParams, DetectionsCsvWriter, write_bead_sequence_params,
};
use sillage_synth::{BedloadDetectionParams, BedloadSceneParams, BedloadSequence};

use crate::bedload::create_folder;

/// Scale of the synthetic sequences (the authors' example sequence), m/px.
pub const SYNTHETIC_M_PER_PX: f64 = 2.056e-4;

/// The bead radius of each class of a generated scene (black, transparent), px.
pub fn synthetic_radii(scene: &BedloadSceneParams) -> [f64; 2] {
    [scene.black_radius_px, scene.transparent_radius_px]
}

/// The sequence parameters of a generated scene, as BeadTracking writes them.
pub fn synthetic_sequence_params(scene: &BedloadSceneParams) -> BeadSequenceParams {
    let radii = synthetic_radii(scene);
    BeadSequenceParams {
        black_diameter_m: 2.0 * radii[0] * SYNTHETIC_M_PER_PX,
        transparent_diameter_m: 2.0 * radii[1] * SYNTHETIC_M_PER_PX,
        m_per_px: SYNTHETIC_M_PER_PX,
    }
}

/// The bead detector with its default (real-frame) parameters at the scene's sizes; the
/// transparent beads and the candidates above `transparent_threshold` when given.
pub fn synthetic_detector_params(
    scene: &BedloadSceneParams,
    transparent_threshold: Option<f64>,
) -> BeadParams {
    let sequence = synthetic_sequence_params(scene);
    let mut params = BeadParams {
        m_per_px: sequence.m_per_px,
        black_diameter_m: sequence.black_diameter_m,
        transparent_diameter_m: sequence.transparent_diameter_m,
        ..BeadParams::default()
    };
    if let Some(threshold) = transparent_threshold {
        params.transparent_threshold = threshold;
        params.candidate_threshold = threshold;
    }
    params
}

/// [`synthetic_detector_params`] built into a detector.
pub fn synthetic_detector(
    scene: &BedloadSceneParams,
    transparent_threshold: Option<f64>,
) -> Result<BeadDetector> {
    BeadDetector::new(synthetic_detector_params(scene, transparent_threshold))
}

/// Writes the sequence of `scene` seen through `detection` into `dir` (created):
/// `truth.csv`, `detections.csv`, `candidates.csv` and `sequence_param.txt`. `on_frame` is
/// called after each frame. Returns the number of true bead points written.
pub fn write_synthetic_sequence(
    dir: &Path,
    scene: &BedloadSceneParams,
    detection: BedloadDetectionParams,
    on_frame: &mut dyn FnMut(),
) -> Result<u64> {
    create_folder(dir)?;
    let sequence = BedloadSequence::new(scene.clone(), detection)?;
    let mut truth = BeadCsvWriter::create(dir.join("truth.csv"))?;
    let mut detections = DetectionsCsvWriter::create(dir.join("detections.csv"))?;
    let mut candidates = DetectionsCsvWriter::create(dir.join("candidates.csv"))?;
    let mut points: Vec<TrackPoint> = Vec::new();
    for sample in sequence {
        let frame = sample.truth.index;
        points.clear();
        points.extend(sample.truth.track_points());
        truth.accept(&points)?;
        detections.push(frame, &sample.observation.detections)?;
        candidates.push(frame, &sample.observation.candidates)?;
        on_frame();
    }
    let rows = truth.finish()?.rows;
    detections.finish()?;
    candidates.finish()?;
    write_bead_sequence_params(
        dir.join("sequence_param.txt"),
        &synthetic_sequence_params(scene),
    )?;
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn synthetic_sizes_round_trip_through_the_sequence_file() {
        let scene = BedloadSceneParams::default();
        let sequence = synthetic_sequence_params(&scene);
        let radius = sequence.radius_px(sillage_io::BeadCategory::Transparent);
        assert_eq!(radius, scene.transparent_radius_px.round());
        let params = synthetic_detector_params(&scene, Some(0.2));
        assert_eq!(params.candidate_threshold, 0.2);
        assert_eq!(params.m_per_px, SYNTHETIC_M_PER_PX);
    }
}

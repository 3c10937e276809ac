//! The MMPF+ bead detector (§3.3) built from its settings and files, as `sillage detect bead`
//! and `sillage track bedload FRAMES` take them: a TOML parameter file, BeadTracking's
//! `sequence_param.txt`, `key=value` overrides, the flume-base mask and the ring template.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sillage_core::{Error, GrayImage, Result};
use sillage_detect::{BeadDetections, BeadDetector, BeadParams};
use sillage_io::{
    DetectionsCsvWriter, Frame, read_bead_sequence_params, read_image, read_matrix_csv,
};

use crate::toml_config::{load_unvalidated, set_key};

/// The bead detector of a [`crate::DetectorConfig::Bead`]: resolved parameters and the files
/// it reads when built.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BeadDetectorConfig {
    /// The detector's parameters.
    pub params: BeadParams,
    /// Image of the fixed flume base (white = base, never beads).
    pub base_mask: Option<PathBuf>,
    /// Ring template of the transparent beads: a CSV matrix or an image (default: built from
    /// the bead sizes).
    pub template: Option<PathBuf>,
}

/// Where a bead detector's settings come from, applied in this order: the defaults, the TOML
/// `config` file, the bead sizes of `sequence_params`, then each `key=value` of `overrides`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BeadDetectorSources {
    /// TOML detector parameters (`BeadParams`).
    pub config: Option<PathBuf>,
    /// BeadTracking `sequence_param.txt`: bead diameters and scale.
    pub sequence_params: Option<PathBuf>,
    /// `key=value` overrides of the parameters.
    pub overrides: Vec<String>,
    /// Image of the fixed flume base.
    pub base_mask: Option<PathBuf>,
    /// Ring template of the transparent beads.
    pub template: Option<PathBuf>,
}

impl BeadDetectorSources {
    /// Reads the files once and resolves the parameters (validated; errors name the file or
    /// the key).
    pub fn load(&self) -> Result<BeadDetectorConfig> {
        let mut params: BeadParams = load_unvalidated(self.config.as_deref(), &[])?;
        if let Some(path) = &self.sequence_params {
            let sequence = read_bead_sequence_params(path)?;
            params.m_per_px = sequence.m_per_px;
            params.black_diameter_m = sequence.black_diameter_m;
            params.transparent_diameter_m = sequence.transparent_diameter_m;
        }
        // After the sequence's sizes, which `overrides` may replace.
        for assignment in &self.overrides {
            set_key(&mut params, assignment)?;
        }
        params.validate()?;
        Ok(BeadDetectorConfig {
            params,
            base_mask: self.base_mask.clone(),
            template: self.template.clone(),
        })
    }
}

impl BeadDetectorConfig {
    /// The detector: parameters validated, base mask and ring template read.
    pub fn build(&self) -> Result<BeadDetector> {
        let mut detector = BeadDetector::new(self.params.clone())?;
        if let Some(path) = &self.base_mask {
            detector = detector.with_base_mask(&read_image(path)?);
        }
        if let Some(path) = &self.template {
            detector = detector
                .with_ring_template(&read_template(path)?)
                .map_err(|e| Error::input(format!("in {}: {e}", path.display())))?;
        }
        Ok(detector)
    }
}

/// Detects the beads of `image` into `beads`, `image` being `frame` as the detector sees it
/// (the frame itself, or its pre-processed copy); the error names the frame and its file.
pub fn detect_frame(
    detector: &mut BeadDetector,
    frame: &Frame,
    image: &GrayImage,
    beads: &mut BeadDetections,
) -> Result<()> {
    detector
        .detect_beads(image, beads)
        .map_err(|e| Error::frame(&frame.path, frame.index, e.to_string()))
}

/// What [`write_bead_detections`] found over a sequence.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct BeadCounts {
    /// Frames detected.
    pub frames: u64,
    /// Black beads over all frames.
    pub black: usize,
    /// Transparent beads over all frames.
    pub transparent: usize,
    /// Candidates of Eq. (1) over all frames.
    pub candidates: usize,
}

/// Detects the beads of every frame of `frames` and writes them (black then transparent, with
/// their class) as a detections CSV at `detections`, and the candidates of Eq. (1) at
/// `candidates` when given; `on_frame` is called after each frame. Rows written before an
/// error stay valid: the files are completed either way.
pub fn write_bead_detections(
    frames: impl Iterator<Item = Result<Frame>>,
    detector: &mut BeadDetector,
    detections: &Path,
    candidates: Option<&Path>,
    on_frame: &mut dyn FnMut(),
) -> Result<BeadCounts> {
    let mut detections = DetectionsCsvWriter::create(detections)?;
    let mut candidates = candidates.map(DetectionsCsvWriter::create).transpose()?;
    let mut beads = BeadDetections::default();
    let mut both = Vec::new();
    let mut counts = BeadCounts::default();
    let mut outcome = Ok(());
    for frame in frames {
        let step = frame.and_then(|frame| {
            detect_frame(detector, &frame, &frame.image, &mut beads)?;
            both.clear();
            both.extend_from_slice(&beads.black);
            both.extend_from_slice(&beads.transparent);
            detections.push(frame.index, &both)?;
            if let Some(writer) = &mut candidates {
                writer.push(frame.index, &beads.candidates)?;
            }
            Ok(())
        });
        if let Err(e) = step {
            outcome = Err(e);
            break;
        }
        counts.frames += 1;
        counts.black += beads.black.len();
        counts.transparent += beads.transparent.len();
        counts.candidates += beads.candidates.len();
        on_frame();
    }
    detections.finish()?;
    if let Some(writer) = candidates {
        writer.finish()?;
    }
    outcome.map(|()| counts)
}

/// A ring template from a CSV matrix (BeadTracking's exported `.mat`) or an image.
fn read_template(path: &Path) -> Result<GrayImage> {
    let is_csv = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    if is_csv {
        read_matrix_csv(path)
    } else {
        read_image(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sequence's sizes replace the file's, and overrides replace the sequence's.
    #[test]
    fn sources_apply_file_then_sequence_then_overrides() {
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("bead.toml");
        std::fs::write(&config, "m_per_px = 0.001\nblack_threshold = 0.3\n").unwrap();
        let sequence = dir.path().join("sequence_param.txt");
        std::fs::write(
            &sequence,
            "diamBlackBead\t0.006\tm\ndiamTransBead\t0.004\tm\nmByPx\t0.0002\tm/px\n",
        )
        .unwrap();
        let sources = BeadDetectorSources {
            config: Some(config),
            sequence_params: Some(sequence),
            overrides: vec!["black_diameter_m=0.005".into()],
            ..BeadDetectorSources::default()
        };
        let params = sources.load().unwrap().params;
        assert_eq!(params.m_per_px, 0.0002);
        assert_eq!(params.black_threshold, 0.3);
        assert_eq!(params.black_diameter_m, 0.005);
        assert_eq!(params.transparent_diameter_m, 0.004);
        let bad = BeadDetectorSources {
            overrides: vec!["transparent_threshold=2".into()],
            ..BeadDetectorSources::default()
        };
        let err = bad.load().unwrap_err().to_string();
        assert!(err.contains("transparent_threshold"), "{err}");
    }
}

//! Pre-processing and detection of one frame, as every run does them: `F = median(I)·mask − B`
//! (TracTrac §3.1.1, Eqs. (1)–(2)), then the configured detector. [`crate::Pipeline`] runs it
//! before its tracker; the live tuner (`sillage tune`) runs it alone, so what it shows is what
//! a tracking run sees.

use sillage_core::{Detection, Detector, Error, GrayImage, Result};
use sillage_detect::Preprocessor;
use sillage_detect::blob::{BlobDetector, Calibration};
use sillage_detect::{BeadDetections, BeadDetector, ParticleImages};
use sillage_io::Frame;

use crate::bedload::detector::detect_frame;
use crate::config::{DetectorConfig, PipelineConfig};

/// The built-in detectors, chosen by [`DetectorConfig`].
#[derive(Debug, Clone)]
enum AnyDetector {
    Blob(Box<BlobDetector>),
    /// The bead detector and the beads of the last frame (their candidates are kept).
    Bead(Box<BeadDetector>, BeadDetections),
}

/// The pre-processor, mask and detector of a [`PipelineConfig`], fed one frame at a time.
#[derive(Debug, Clone)]
pub struct DetectionStage {
    preprocessor: Preprocessor,
    mask: Option<GrayImage>,
    detector: AnyDetector,
    /// Whether any pre-processing (median, background, mask) runs before detection.
    preprocessing: bool,
    preprocessed: GrayImage,
}

impl DetectionStage {
    /// The stage of `config`'s `preprocess`, `mask` and `detector` sections; their parameters
    /// are validated and the mask image is read here.
    pub fn from_config(config: &PipelineConfig) -> Result<Self> {
        let mask = config
            .mask
            .as_deref()
            .map(sillage_io::read_image)
            .transpose()?;
        let detector = match &config.detector {
            DetectorConfig::Blob(params) => {
                AnyDetector::Blob(Box::new(BlobDetector::new(*params)?))
            }
            DetectorConfig::Bead(bead) => {
                AnyDetector::Bead(Box::new(bead.build()?), BeadDetections::default())
            }
        };
        Ok(Self {
            preprocessor: Preprocessor::new(config.preprocess)?,
            preprocessing: config.preprocess.median.is_some()
                || config.preprocess.background.is_some()
                || mask.is_some(),
            mask,
            detector,
            preprocessed: GrayImage::default(),
        })
    }

    /// How many leading frames [`DetectionStage::prime_background`] wants (0 without
    /// background subtraction).
    pub fn background_init_frames(&self) -> usize {
        self.preprocessor
            .params()
            .background
            .map_or(0, |background| background.init_frames)
    }

    /// Initialises the background model from the mean of the first frames (Eq. (2)); at most
    /// [`DetectionStage::background_init_frames`] are used. Returns how many were.
    pub fn prime_background<'a>(
        &mut self,
        frames: impl IntoIterator<Item = &'a GrayImage>,
    ) -> Result<usize> {
        self.preprocessor.prime(frames)
    }

    /// The pre-processing and its state (the background model), for checkpoints.
    pub fn preprocessor(&self) -> &Preprocessor {
        &self.preprocessor
    }

    /// Continues with the pre-processing state `preprocessor` (a resumed run).
    pub fn set_preprocessor(&mut self, preprocessor: Preprocessor) {
        self.preprocessor = preprocessor;
    }

    /// Pre-processes and detects `frame` into `out`. Errors name the frame and its file when
    /// the mask's size differs from the frame's.
    pub fn detect(&mut self, frame: &Frame, out: &mut Vec<Detection>) -> Result<()> {
        if let Some(mask) = &self.mask
            && mask.dimensions() != frame.image.dimensions()
        {
            return Err(Error::frame(
                &frame.path,
                frame.index,
                format!(
                    "the mask is {}×{} but the frame is {}×{}; use a mask of the frame's size",
                    mask.width(),
                    mask.height(),
                    frame.image.width(),
                    frame.image.height()
                ),
            ));
        }
        let image = if self.preprocessing {
            self.preprocessor
                .process(&frame.image, self.mask.as_ref(), &mut self.preprocessed)?;
            &self.preprocessed
        } else {
            // Nothing to do before detection: no copy of the frame.
            &frame.image
        };
        match &mut self.detector {
            AnyDetector::Blob(detector) => {
                detector
                    .calibrate(image)
                    .map_err(|e| Error::frame(&frame.path, frame.index, e.to_string()))?;
                detector.detect(image, out)
            }
            AnyDetector::Bead(detector, beads) => {
                detect_frame(detector, frame, image, beads)?;
                out.clear();
                out.extend_from_slice(&beads.black);
                out.extend_from_slice(&beads.transparent);
                Ok(())
            }
        }
    }

    /// Measures the particle images on `frame` for a blob detector with an `"auto"` scale or
    /// polarity, before any detection (so that a run can record them in its output header);
    /// the pre-processing state (background model) is not advanced. Nothing to do for other
    /// detectors, or once measured. Errors name the frame when it has no particles to measure.
    pub fn calibrate(&mut self, frame: &Frame) -> Result<()> {
        let AnyDetector::Blob(detector) = &mut self.detector else {
            return Ok(());
        };
        if detector.calibration().is_some() {
            return Ok(());
        }
        let mut preprocessed = GrayImage::default();
        let image = if self.preprocessing {
            self.preprocessor.clone().process(
                &frame.image,
                self.mask.as_ref(),
                &mut preprocessed,
            )?;
            &preprocessed
        } else {
            &frame.image
        };
        detector
            .calibrate(image)
            .map_err(|e| Error::frame(&frame.path, frame.index, e.to_string()))
    }

    /// Adopts particle images measured on another run's first frame (see
    /// [`BlobDetector::calibrate_with`](sillage_detect::blob::BlobDetector::calibrate_with));
    /// nothing to do for other detectors.
    pub fn calibrate_with(&mut self, measured: ParticleImages) -> Result<()> {
        match &mut self.detector {
            AnyDetector::Blob(detector) => detector.calibrate_with(measured),
            AnyDetector::Bead(..) => Ok(()),
        }
    }

    /// The blob detector's scale and polarity in use and what was measured to choose them
    /// (`None` for other detectors, or before an `"auto"` one has seen a frame).
    pub fn calibration(&self) -> Option<Calibration> {
        match &self.detector {
            AnyDetector::Blob(detector) => detector.calibration(),
            AnyDetector::Bead(..) => None,
        }
    }

    /// The image the detector saw for `frame` (its pre-processed copy, or the frame itself
    /// when nothing runs before detection); valid after [`DetectionStage::detect`] of `frame`.
    pub fn detector_input<'a>(&'a self, frame: &'a Frame) -> &'a GrayImage {
        if self.preprocessing {
            &self.preprocessed
        } else {
            &frame.image
        }
    }

    /// Takes the pre-processed copy of the last frame, leaving `spare` (a buffer to reuse) in
    /// its place; `None` (and `spare` dropped) when nothing runs before detection, where the
    /// detector saw the frame itself. For a run that tracks a frame while the next is
    /// detected.
    pub fn take_preprocessed(&mut self, spare: GrayImage) -> Option<GrayImage> {
        self.preprocessing
            .then(|| std::mem::replace(&mut self.preprocessed, spare))
    }

    /// The detector-confidence candidates of Eq. (1) of the MMPF+ paper found in the last
    /// frame (empty for detectors that make none).
    pub fn candidates(&self) -> &[Detection] {
        match &self.detector {
            AnyDetector::Blob(_) => &[],
            AnyDetector::Bead(_, beads) => &beads.candidates,
        }
    }

    /// The band-passed image of the last frame (the detector's ROI), for threshold displays;
    /// `None` for detectors without one (the bead detector).
    pub fn filtered(&self) -> Option<&GrayImage> {
        match &self.detector {
            AnyDetector::Blob(detector) => Some(detector.filtered()),
            AnyDetector::Bead(..) => None,
        }
    }

    /// The intensity threshold applied to [`DetectionStage::filtered`] on the last frame.
    pub fn last_threshold(&self) -> Option<f32> {
        match &self.detector {
            AnyDetector::Blob(detector) => detector.last_threshold(),
            AnyDetector::Bead(..) => None,
        }
    }
}

//! The sequences of the bedload evaluation: a generated one rendered to frames in memory, and
//! a real one in BeadTracking's layout, each detected once at the sweep's lowest τ_t.

use std::path::Path;

use sillage_core::{Detection, Error, FrameIndex, GrayImage, Result, TrackPoint};
use sillage_detect::BeadDetections;
use sillage_io::{
    BeadCategory, FrameOptions, open_frames, read_bead_csv, read_bead_sequence_params,
};
use sillage_synth::{BedloadRenderParams, BedloadRenderer, BedloadScene, BedloadSceneParams};

use crate::bedload::BeadFrame;
use crate::bedload::detector::{BeadDetectorSources, detect_frame};
use crate::bedload::synth::{synthetic_detector, synthetic_radii};

/// Candidates (Eq. (1)) are the maxima above this, or above τ_t when it is lower
/// (BeadTracking's `detect_trans_low`).
const CANDIDATE_CEILING: f64 = 0.2;

/// What a sweep needs of one frame: its black beads and every transparent-bead maximum above
/// the sweep's lowest τ_t, with its NCC score. Detections at any τ_t of the sweep are a filter
/// of these (the detector keeps the maxima at or above τ_t; the rest of its work does not
/// depend on τ_t), so each frame is detected once.
struct SweepFrame {
    frame: FrameIndex,
    black: Vec<Detection>,
    transparent: Vec<Detection>,
}

impl SweepFrame {
    fn new(frame: FrameIndex, beads: &BeadDetections) -> Self {
        Self {
            frame,
            black: beads.black.clone(),
            transparent: beads.candidates.clone(),
        }
    }
}

/// A sequence to score: its frames, truth and the bead radius of each class.
pub struct Sequence {
    /// `real` or `synthetic`.
    pub name: &'static str,
    frames: Vec<SweepFrame>,
    /// The true bead points.
    pub truth: Vec<TrackPoint>,
    /// The bead radius of each class, px.
    pub radii: Vec<f64>,
}

impl Sequence {
    /// The tracker's input at threshold `tau`.
    pub fn at_threshold(&self, tau: f64) -> Vec<BeadFrame> {
        let candidate_floor = tau.min(CANDIDATE_CEILING) as f32;
        self.frames
            .iter()
            .map(|f| BeadFrame {
                frame: f.frame,
                detections: f
                    .black
                    .iter()
                    .chain(f.transparent.iter().filter(|d| d.strength >= tau as f32))
                    .copied()
                    .collect(),
                candidates: f
                    .transparent
                    .iter()
                    .filter(|d| d.strength > candidate_floor)
                    .copied()
                    .collect(),
            })
            .collect()
    }

    /// The real sequence in `dir` (BeadTracking's layout: `images/`,
    /// `ground_truth/trackdatatruth.csv`, `sequence_param.txt`): truth, radii and the
    /// detections of `detector` (the sequence's own `sequence_param.txt` unless it names one)
    /// at τ_t = `lowest`.
    pub fn real(dir: &Path, detector: &BeadDetectorSources, lowest: f64) -> Result<Self> {
        let sequence = read_bead_sequence_params(dir.join("sequence_param.txt"))?;
        let radii = vec![
            sequence.radius_px(BeadCategory::Black),
            sequence.radius_px(BeadCategory::Transparent),
        ];
        let truth = read_bead_csv(dir.join("ground_truth").join("trackdatatruth.csv"))?
            .iter()
            .map(|b| b.track_point())
            .collect();
        let mut sources = detector.clone();
        if sources.sequence_params.is_none() {
            sources.sequence_params = Some(dir.join("sequence_param.txt"));
        }
        sources.overrides.extend([
            format!("candidate_threshold={lowest}"),
            format!("transparent_threshold={lowest}"),
        ]);
        let mut detector = sources.load()?.build()?;
        let mut beads = BeadDetections::default();
        let mut frames = Vec::new();
        let images = dir.join("images");
        for frame in open_frames(&images.to_string_lossy(), &FrameOptions::default())? {
            let frame = frame?;
            detect_frame(&mut detector, &frame, &frame.image, &mut beads)?;
            frames.push(SweepFrame::new(frame.index, &beads));
        }
        Ok(Self {
            name: "real",
            frames,
            truth,
            radii,
        })
    }

    /// A generated sequence of `frames` frames from `seed`, rendered in memory and detected
    /// like the real ones at τ_t = `lowest`; `on_frame` is called after each frame.
    pub fn synthetic(
        frames: usize,
        seed: u64,
        lowest: f64,
        on_frame: &mut dyn FnMut(),
    ) -> Result<Self> {
        let scene = BedloadSceneParams {
            n_frames: frames,
            seed,
            ..BedloadSceneParams::default()
        };
        let radii = synthetic_radii(&scene).to_vec();
        let mut detector = synthetic_detector(&scene, Some(lowest))?;
        let mut renderer = BedloadRenderer::new(BedloadRenderParams::default())?;
        let mut image = GrayImage::new(scene.width, scene.height);
        let mut beads = BeadDetections::default();
        let (mut sweep, mut truth) = (Vec::new(), Vec::new());
        for frame in BedloadScene::new(scene)? {
            renderer.render(&frame, &mut image);
            detector
                .detect_beads(&image, &mut beads)
                .map_err(|e| Error::input(format!("synthetic frame {}: {e}", frame.index)))?;
            sweep.push(SweepFrame::new(frame.index, &beads));
            truth.extend(frame.track_points());
            on_frame();
        }
        Ok(Self {
            name: "synthetic",
            frames: sweep,
            truth,
            radii,
        })
    }
}

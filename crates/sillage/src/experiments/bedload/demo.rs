//! The bedload demo: a synthetic sequence rendered to PNG frames with its truth, the beads
//! detected from the files and tracked with MMPF+ through [`crate::Pipeline`], the tracks
//! written in BeadTracking's layout, then scored against the truth as the MMPF+ paper scores
//! (Table 1: `sillage_eval::papers::score_bead_tracks`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use sillage_core::{Detection, FrameIndex, GrayImage, Result, TrackPoint, TrackSink};
use sillage_io::{
    BeadCsvWriter, FrameOptions, open_frames, write_bead_sequence_params, write_png16,
};
use sillage_synth::{BedloadRenderParams, BedloadRenderer, BedloadScene, BedloadSceneParams};
use sillage_track::bedload::BedloadTrackerParams;

use crate::bedload::create_folder;
use crate::bedload::detector::BeadDetectorConfig;
use crate::bedload::synth::{
    synthetic_detector_params, synthetic_radii, synthetic_sequence_params,
};
use crate::config::{DetectorConfig, PipelineConfig, TrackerConfig};
use crate::pipeline::{FrameInput, FrameReport, Pipeline, RunSummary};

/// The demo's scene: `frames` frames of the default flume from `seed`.
pub fn demo_scene(frames: usize, seed: u64) -> BedloadSceneParams {
    BedloadSceneParams {
        n_frames: frames,
        seed,
        ..BedloadSceneParams::default()
    }
}

/// The folder the frames are rendered into.
pub fn frames_dir(out: &Path) -> PathBuf {
    out.join("frames")
}

/// Renders `scene` into `out/frames/frame_NNNNN.png` (16-bit), writes `out/sequence_param.txt`
/// and the truth `out/truth.csv` (BeadTracking's layout); returns the truth. `on_frame` is
/// called after each frame.
pub fn render(
    out: &Path,
    scene: &BedloadSceneParams,
    on_frame: &mut dyn FnMut(),
) -> Result<Vec<TrackPoint>> {
    let frames = frames_dir(out);
    create_folder(&frames)?;
    write_bead_sequence_params(
        out.join("sequence_param.txt"),
        &synthetic_sequence_params(scene),
    )?;
    let mut renderer = BedloadRenderer::new(BedloadRenderParams::default())?;
    let mut image = GrayImage::new(scene.width, scene.height);
    let mut truth_writer = BeadCsvWriter::create(out.join("truth.csv"))?;
    let mut truth: Vec<TrackPoint> = Vec::new();
    for frame in BedloadScene::new(scene.clone())? {
        renderer.render(&frame, &mut image);
        write_png16(frames.join(format!("frame_{:05}.png", frame.index)), &image)?;
        let start = truth.len();
        truth.extend(frame.track_points());
        truth_writer.accept(&truth[start..])?;
        on_frame();
    }
    truth_writer.finish()?;
    Ok(truth)
}

/// What [`track`] made.
pub struct DemoTracks {
    /// Every track point, in the order written.
    pub points: Vec<TrackPoint>,
    /// The file they were written to (`out/tracks.csv`).
    pub path: PathBuf,
    /// The detections of each frame, when asked for (overlays).
    pub detections: BTreeMap<FrameIndex, Vec<Detection>>,
    /// The run's totals and timings.
    pub run: RunSummary,
}

/// Detects the beads in the rendered frames of `out` (the bead detector at the scene's
/// sizes) and tracks them with MMPF+ seeded by `seed`, writing `out/tracks.csv`; keeps each
/// frame's detections when `keep_detections`. `on_frame` sees each frame's report.
pub fn track(
    out: &Path,
    scene: &BedloadSceneParams,
    seed: u64,
    keep_detections: bool,
    on_frame: &mut dyn FnMut(&FrameReport),
) -> Result<DemoTracks> {
    let config = PipelineConfig {
        detector: DetectorConfig::Bead(BeadDetectorConfig {
            params: synthetic_detector_params(scene, None),
            ..BeadDetectorConfig::default()
        }),
        tracker: TrackerConfig::Bedload(Box::new(BedloadTrackerParams {
            radius_px: synthetic_radii(scene).to_vec(),
            seed,
            ..BedloadTrackerParams::default()
        })),
        ..PipelineConfig::default()
    };
    let path = out.join("tracks.csv");
    let mut writer = BeadCsvWriter::create(&path)?;
    let frames = open_frames(&frames_dir(out).to_string_lossy(), &FrameOptions::default())?;
    let mut points: Vec<TrackPoint> = Vec::new();
    let mut detections = BTreeMap::new();
    let run = Pipeline::from_config(&config)?.run_inputs(
        frames.map(|frame| frame.map(FrameInput::Image)),
        &mut points,
        &mut |report, observations| {
            if keep_detections {
                detections.insert(report.frame, observations.detections.to_vec());
            }
            on_frame(report);
        },
    )?;
    writer.accept(&points)?;
    writer.finish()?;
    Ok(DemoTracks {
        points,
        path,
        detections,
        run,
    })
}

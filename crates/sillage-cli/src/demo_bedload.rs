//! `sillage demo bedload`: a synthetic bedload sequence rendered to PNG frames, the beads
//! detected from the files, tracked with MMPF+, written in BeadTracking's layout and scored
//! against the truth as the MMPF+ paper scores (Table 1).

use std::time::Instant;

use anyhow::{Context, Result};
use serde::Serialize;
use sillage::core::{GrayImage, TrackPoint, TrackSink, Tracker};
use sillage::detect::{BeadDetections, BeadDetector, BeadParams};
use sillage::eval::papers::{BeadTrackScores, score_bead_tracks};
use sillage::io::{
    BeadCsvWriter, BeadSequenceParams, FrameOptions, open_frames, write_bead_sequence_params,
    write_png16,
};
use sillage::synth::{BedloadRenderParams, BedloadRenderer, BedloadScene, BedloadSceneParams};
use sillage::track::bedload::{BedloadTracker, BedloadTrackerParams};
use sillage::viz::OverlayStyle;

use crate::cli::DemoBedloadArgs;
use crate::overlay::{DetectionsByFrame, write_overlays};
use crate::progress::FrameProgress;

/// Scale of the synthetic sequence (the authors' example), m/px.
const M_PER_PX: f64 = 2.056e-4;

/// The bead radius of each class of a generated scene (black, transparent), px.
pub fn synthetic_radii(scene: &BedloadSceneParams) -> [f64; 2] {
    [scene.black_radius_px, scene.transparent_radius_px]
}

/// The sequence parameters of a generated scene, as BeadTracking writes them.
fn synthetic_sequence_params(scene: &BedloadSceneParams) -> BeadSequenceParams {
    let radii = synthetic_radii(scene);
    BeadSequenceParams {
        black_diameter_m: 2.0 * radii[0] * M_PER_PX,
        transparent_diameter_m: 2.0 * radii[1] * M_PER_PX,
        m_per_px: M_PER_PX,
    }
}

/// The bead detector with its default (real-frame) parameters at the scene's sizes; the
/// transparent beads and the candidates above `transparent_threshold` when given.
pub fn synthetic_detector(
    scene: &BedloadSceneParams,
    transparent_threshold: Option<f64>,
) -> Result<BeadDetector> {
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
    Ok(BeadDetector::new(params)?)
}

/// The demo's summary.
#[derive(Serialize)]
struct DemoBedloadSummary {
    frames: usize,
    detect_ms_per_frame: f64,
    track_ms_per_frame: f64,
    scores: BeadTrackScores,
    tracks: String,
}

/// `sillage demo bedload`.
pub fn run(args: &DemoBedloadArgs) -> Result<()> {
    let scene_params = BedloadSceneParams {
        n_frames: args.frames,
        seed: args.seed,
        ..BedloadSceneParams::default()
    };
    let frames_dir = args.out.join("frames");
    std::fs::create_dir_all(&frames_dir)
        .with_context(|| format!("cannot create the folder {}", frames_dir.display()))?;
    eprintln!(
        "1/3 synthetic bedload flume (MMPF+ paper): {} black and {} transparent beads, {} frames \
         of {}×{} → {}",
        scene_params.n_black,
        scene_params.n_transparent,
        scene_params.n_frames,
        scene_params.width,
        scene_params.height,
        frames_dir.display()
    );
    let radii = synthetic_radii(&scene_params);
    write_bead_sequence_params(
        args.out.join("sequence_param.txt"),
        &synthetic_sequence_params(&scene_params),
    )?;
    let mut renderer = BedloadRenderer::new(BedloadRenderParams::default())?;
    let mut image = GrayImage::new(scene_params.width, scene_params.height);
    let mut truth_writer = BeadCsvWriter::create(args.out.join("truth.csv"))?;
    let mut truth: Vec<TrackPoint> = Vec::new();
    let mut progress = FrameProgress::new(Some(scene_params.n_frames), "rendering");
    for frame in BedloadScene::new(scene_params.clone())? {
        renderer.render(&frame, &mut image);
        write_png16(
            frames_dir.join(format!("frame_{:05}.png", frame.index)),
            &image,
        )?;
        let start = truth.len();
        truth.extend(frame.track_points());
        truth_writer.accept(&truth[start..])?;
        progress.tick();
    }
    progress.finish();
    truth_writer.finish()?;

    eprintln!("2/3 detecting the beads in the PNG frames and tracking them with MMPF+");
    let mut detector = synthetic_detector(&scene_params, None)?;
    let params = BedloadTrackerParams {
        radius_px: radii.to_vec(),
        seed: args.seed,
        ..BedloadTrackerParams::default()
    };
    let mut tracker = BedloadTracker::new(&params)?;
    let tracks_path = args.out.join("tracks.csv");
    let mut writer = BeadCsvWriter::create(&tracks_path)?;
    let mut tracks: Vec<TrackPoint> = Vec::new();
    let frames = open_frames(&frames_dir.to_string_lossy(), &FrameOptions::default())?;
    let mut progress = FrameProgress::new(frames.len(), "tracking");
    let mut beads = BeadDetections::default();
    let mut detections = Vec::new();
    let mut kept = DetectionsByFrame::new();
    let (mut detect_s, mut track_s) = (0.0, 0.0);
    for frame in frames {
        let frame = frame?;
        let start = Instant::now();
        detector.detect_beads(&frame.image, &mut beads)?;
        detect_s += start.elapsed().as_secs_f64();
        detections.clear();
        detections.extend_from_slice(&beads.black);
        detections.extend_from_slice(&beads.transparent);
        if args.overlays {
            kept.insert(frame.index, detections.clone());
        }
        let observations = sillage::core::FrameObservations {
            candidates: &beads.candidates,
            ..sillage::core::FrameObservations::from_detections(frame.index, &detections)
        };
        let start = Instant::now();
        let before = tracks.len();
        tracker.step(&observations, &mut tracks)?;
        track_s += start.elapsed().as_secs_f64();
        writer.accept(&tracks[before..])?;
        progress.tick();
    }
    progress.finish();
    // Points the tracker held back (predictions through misses) are flushed at the end.
    let n_stepped = tracks.len();
    tracker.finish(&mut tracks)?;
    writer.accept(&tracks[n_stepped..])?;
    writer.finish()?;
    if args.overlays {
        let dir = args.out.join("overlays");
        let style = OverlayStyle {
            detection_radius_px: radii.to_vec(),
            ..OverlayStyle::default()
        };
        write_overlays(
            &frames_dir.to_string_lossy(),
            &dir,
            &kept,
            tracks.clone(),
            &style,
            None,
        )?;
    }

    eprintln!("3/3 scoring against the truth (disc IoU ≥ 0.43, MMPF+ paper §5.3)");
    let scores = score_bead_tracks(&truth, &tracks, &radii)?;
    let n = args.frames.max(1) as f64;
    let summary = DemoBedloadSummary {
        frames: args.frames,
        detect_ms_per_frame: 1e3 * detect_s / n,
        track_ms_per_frame: 1e3 * track_s / n,
        scores,
        tracks: tracks_path.display().to_string(),
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        let t = &summary.scores.table1;
        println!(
            "correct tracks {:.1} % ({}/{}), MOTA {:.2} %, FN {:.2} %, FP {:.2} %, ID switches {}, \
             HOTA {:.3} — detection {:.1} ms/frame, tracking {:.1} ms/frame → {}",
            100.0 * t.correct_track_rate,
            t.correct_tracks,
            t.truth_tracks,
            100.0 * summary.scores.mot.clear.mota,
            100.0 * t.false_negative_rate,
            100.0 * t.false_positive_rate,
            t.id_switches,
            summary.scores.mot.hota.hota,
            summary.detect_ms_per_frame,
            summary.track_ms_per_frame,
            summary.tracks
        );
    }
    Ok(())
}

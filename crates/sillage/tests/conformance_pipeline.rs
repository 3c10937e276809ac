//! The tracker suite of `conformance_trackers.rs`, run on real frames through the one entry
//! point every runner uses, `sillage::track_source`, for each of the four trackers: PTV on
//! trackpy's bulk-water movie, MMPF+ on the real bedload frames, the IMM-PF and the SIFT-PF on
//! PETS 2009 S2.L1.
//!
//! Every tracker must give the same points on 1 and 4 threads, one point per (track, frame)
//! with frames increasing along a track, nothing beyond the frames it was given, boxes for the
//! pedestrian trackers, and an error (no panic) for a source that holds no frame.

use std::collections::HashMap;
use std::path::PathBuf;

use sillage::bedload::detector::BeadDetectorSources;
use sillage::core::TrackPoint;
use sillage::io::FrameOptions;
use sillage::pedestrian::immpf::Scene;
use sillage::pedestrian::{ImmpfSettings, SiftPfSettings};
use sillage::tracking::{ImmpfSetup, SiftPfSetup};
use sillage::{DetectorConfig, PipelineConfig, TrackerConfig, Tracking, track_source};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");

/// Frames each tracker is given.
const FRAMES: usize = 12;

/// Every tracker with the frames it runs on, and whether it reports boxes.
fn cases() -> Vec<(&'static str, String, Tracking, bool)> {
    let beads = format!("{DATA}/bedload_beads_lafaye2018");
    let bead_detector = BeadDetectorSources {
        sequence_params: Some(PathBuf::from(format!("{beads}/sequence_param.txt"))),
        base_mask: Some(PathBuf::from(format!("{beads}/sequence_base_mask.tif"))),
        ..BeadDetectorSources::default()
    }
    .load()
    .unwrap();
    let bedload = PipelineConfig {
        detector: DetectorConfig::Bead(bead_detector),
        tracker: TrackerConfig::Bedload(Box::default()),
        ..PipelineConfig::default()
    };
    let pets = format!("{DATA}/pets09_s2l1/img1");
    let immpf = ImmpfSetup {
        settings: ImmpfSettings::default(),
        scene: Scene::load(None, None).unwrap(),
        seed: 1,
        detections: None,
    };
    let siftpf = SiftPfSetup {
        settings: SiftPfSettings::default(),
        homography: None,
        seed: 1,
    };
    vec![
        (
            "ptv",
            format!("{DATA}/trackpy_bulk_water/frames"),
            Tracking::Pipeline(Box::default()),
            false,
        ),
        (
            "bedload",
            format!("{beads}/images"),
            Tracking::Pipeline(Box::new(bedload)),
            false,
        ),
        (
            "immpf",
            pets.clone(),
            Tracking::Immpf(Box::new(immpf)),
            true,
        ),
        ("siftpf", pets, Tracking::Siftpf(Box::new(siftpf)), true),
    ]
}

/// The first `frames` frames of a source.
fn first(frames: usize) -> FrameOptions {
    FrameOptions {
        max_frames: Some(frames),
        ..FrameOptions::default()
    }
}

fn run(source: &str, tracking: &Tracking, threads: usize) -> Vec<TrackPoint> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| {
            let mut points = Vec::new();
            let mut frames_seen = 0;
            let frames = track_source(source, tracking, &first(FRAMES), &mut points, &mut || {
                frames_seen += 1
            })
            .unwrap();
            assert_eq!(frames, frames_seen);
            points
        })
}

#[test]
fn every_tracker_runs_from_a_source_repeatably_with_one_point_per_track_and_frame() {
    for (name, source, tracking, boxes) in cases() {
        let points = run(&source, &tracking, 4);
        assert!(!points.is_empty(), "{name}: no point");
        assert_eq!(
            points,
            run(&source, &tracking, 1),
            "{name}: threads changed the points"
        );
        let mut last = HashMap::new();
        let mut by_frame = points.clone();
        by_frame.sort_by_key(|p| (p.track_id, p.frame));
        for p in &by_frame {
            assert!(
                p.frame < FRAMES as u64,
                "{name}: frame {} beyond the input",
                p.frame
            );
            if let Some(previous) = last.insert(p.track_id, p.frame) {
                assert!(
                    p.frame > previous,
                    "{name}: track {} twice in frame {}",
                    p.track_id,
                    p.frame
                );
            }
            assert_eq!(p.bbox.is_some(), boxes, "{name}: boxes");
        }
    }
}

#[test]
fn every_tracker_refuses_a_source_without_frames() {
    let empty = tempfile::tempdir().unwrap();
    let source = empty.path().to_str().unwrap();
    for (name, _, tracking, _) in cases() {
        let mut points = Vec::new();
        let outcome = track_source(
            source,
            &tracking,
            &FrameOptions::default(),
            &mut points,
            &mut || {},
        );
        let err = outcome.expect_err(name).to_string();
        assert!(
            err.contains(source),
            "{name}: the error does not name the source: {err}"
        );
    }
}

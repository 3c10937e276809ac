//! The facade's pipeline: mask, background priming, training passes, parameter errors.

use std::path::PathBuf;

use sillage::core::{GrayImage, Point2, TrackPoint};
use sillage::io::Frame;
use sillage::synth::{Noise, NoiseKind, render_spots};
use sillage::{FrameInput, Pipeline, PipelineConfig};

const SIZE: usize = 160;

/// 36 spots on a 24-px lattice drifting by (1.2, 0.4) px per frame.
fn drifting_frames(n: usize) -> Vec<Frame> {
    (0..n)
        .map(|i| {
            let spots: Vec<_> = (0..36)
                .map(|k| {
                    let x = 20.0 + (k % 6) as f64 * 24.0 + 1.2 * i as f64;
                    let y = 20.0 + (k / 6) as f64 * 24.0 + 0.4 * i as f64;
                    (Point2::new(x, y), 0.6, 2.0)
                })
                .collect();
            Frame {
                index: i as u64,
                path: PathBuf::from(format!("frame{i}")),
                image: render_spots(
                    SIZE,
                    SIZE,
                    &spots,
                    Noise::new(NoiseKind::Uniform, 0.05),
                    i as u64,
                )
                .unwrap(),
                colour: None,
            }
        })
        .collect()
}

fn run(config: &PipelineConfig, frames: Vec<Frame>) -> Vec<TrackPoint> {
    let mut tracks = Vec::new();
    Pipeline::from_config(config)
        .unwrap()
        .run(frames.into_iter().map(Ok), &mut tracks, &mut |_| {})
        .unwrap();
    tracks
}

#[test]
fn every_lattice_spot_is_followed_with_its_drift() {
    let tracks = run(&PipelineConfig::default(), drifting_frames(10));
    // Frames 1..=8 are emitted (three-frame association), 36 spots each.
    assert_eq!(tracks.len(), 36 * 8);
    for p in &tracks {
        let v = p.vel_px_per_frame.unwrap();
        assert!((v.x - 1.2).abs() < 0.1 && (v.y - 0.4).abs() < 0.1, "{p:?}");
    }
    let ids: std::collections::BTreeSet<_> = tracks.iter().map(|p| p.track_id).collect();
    assert_eq!(ids.len(), 36, "one identity per spot");
}

#[test]
fn a_mask_hides_its_zero_region() {
    let dir = tempfile::tempdir().unwrap();
    let mut mask = GrayImage::new(SIZE, SIZE);
    for y in 0..SIZE {
        for x in SIZE / 2..SIZE {
            mask.set(x, y, 1.0);
        }
    }
    let mask_path = dir.path().join("mask.png");
    sillage::io::write_png16(&mask_path, &mask).unwrap();
    let config = PipelineConfig {
        mask: Some(mask_path),
        ..PipelineConfig::default()
    };
    let tracks = run(&config, drifting_frames(8));
    assert!(!tracks.is_empty());
    assert!(
        tracks.iter().all(|p| p.pos_px.x > SIZE as f64 / 2.0 - 3.0),
        "a point in the masked half"
    );

    let small = GrayImage::new(10, 10);
    let small_path = dir.path().join("small.png");
    sillage::io::write_png16(&small_path, &small).unwrap();
    let config = PipelineConfig {
        mask: Some(small_path),
        ..PipelineConfig::default()
    };
    let frames = drifting_frames(2);
    let err = Pipeline::from_config(&config)
        .unwrap()
        .run(frames.into_iter().map(Ok), &mut Vec::new(), &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(err.contains("mask") && err.contains("frame 0"), "{err}");
}

#[test]
fn background_subtraction_removes_a_static_spot() {
    let mut frames = drifting_frames(8);
    // A bright static spot that background subtraction must remove.
    let static_spot = render_spots(
        SIZE,
        SIZE,
        &[(Point2::new(80.0, 150.0), 0.8, 2.0)],
        Noise::none(),
        0,
    )
    .unwrap();
    for frame in &mut frames {
        for (v, s) in frame
            .image
            .as_mut_slice()
            .iter_mut()
            .zip(static_spot.as_slice())
        {
            *v += s;
        }
    }
    let mut config = PipelineConfig::default();
    config.set("preprocess.background.speed=0.01").unwrap();
    let mut pipeline = Pipeline::from_config(&config).unwrap();
    assert_eq!(pipeline.background_init_frames(), 100);
    let used = pipeline
        .prime_background(frames.clone().into_iter().map(Ok))
        .unwrap();
    assert_eq!(used, 8);
    let mut tracks = Vec::new();
    pipeline
        .run(frames.into_iter().map(Ok), &mut tracks, &mut |_| {})
        .unwrap();
    assert!(!tracks.is_empty());
    assert!(
        tracks
            .iter()
            .all(|p| p.pos_px.distance(Point2::new(80.0, 150.0)) > 3.0),
        "the static spot was tracked"
    );
}

#[test]
fn training_passes_emit_one_forward_output_pass() {
    let mut config = PipelineConfig::default();
    config.set("training_passes=2").unwrap();
    let trained = run(&config, drifting_frames(10));
    // Only the output pass writes: frames 1..=8 once each, in order, no (frame, id) twice. The
    // outlier threshold, tightened by training on near-perfect data, may drop a few tracklets.
    let frames: Vec<u64> = trained.iter().map(|p| p.frame).collect();
    assert!(
        frames.windows(2).all(|w| w[0] <= w[1]),
        "output pass runs forward"
    );
    assert!(frames.iter().all(|f| (1..=8).contains(f)));
    let keys: std::collections::BTreeSet<_> =
        trained.iter().map(|p| (p.frame, p.track_id)).collect();
    assert_eq!(keys.len(), trained.len());
    assert!(trained.len() >= 36 * 8 * 9 / 10, "{} points", trained.len());
    for p in &trained {
        let v = p.vel_px_per_frame.unwrap();
        assert!((v.x - 1.2).abs() < 0.1 && (v.y - 0.4).abs() < 0.1, "{p:?}");
    }
}

#[test]
fn out_of_range_parameters_are_refused_before_any_work() {
    let mut config = PipelineConfig::default();
    config.set("detector.scale_px=0").unwrap();
    let err = Pipeline::from_config(&config).err().unwrap().to_string();
    assert!(err.contains("scale_px"), "{err}");
    let mut config = PipelineConfig::default();
    config.set("training_passes=99").unwrap();
    let err = Pipeline::from_config(&config).err().unwrap().to_string();
    assert!(err.contains("training_passes"), "{err}");
}

#[test]
fn streaming_and_detection_runs_give_the_tracks_of_a_whole_run() {
    let config = PipelineConfig::default();
    let whole = run(&config, drifting_frames(10));

    let mut streamed = Vec::new();
    let mut pipeline = Pipeline::from_config(&config).unwrap();
    for frame in drifting_frames(10) {
        pipeline
            .step(&FrameInput::Image(frame), &mut streamed)
            .unwrap();
    }
    pipeline.finish(&mut streamed).unwrap();
    assert_eq!(streamed, whole);

    // Detections made by `locate`, then tracked on their own.
    let mut locator = Pipeline::from_config(&config).unwrap();
    let detections: Vec<_> = drifting_frames(10)
        .iter()
        .map(|frame| Ok((frame.index, locator.locate(frame).unwrap().to_vec())))
        .collect();
    let mut from_detections = Vec::new();
    Pipeline::from_config(&config)
        .unwrap()
        .run_detections(detections.into_iter(), &mut from_detections, &mut |_| {})
        .unwrap();
    assert_eq!(from_detections.len(), whole.len());
    for (a, b) in from_detections.iter().zip(&whole) {
        assert_eq!((a.frame, a.track_id), (b.frame, b.track_id));
        assert!((a.pos_px.x - b.pos_px.x).abs() < 1e-12 && (a.pos_px.y - b.pos_px.y).abs() < 1e-12);
    }

    // A streamed run has one pass: training passes are refused with the key named.
    let trained = PipelineConfig {
        training_passes: 2,
        ..PipelineConfig::default()
    };
    let error = Pipeline::from_config(&trained)
        .unwrap()
        .step(
            &FrameInput::Image(drifting_frames(1).remove(0)),
            &mut Vec::new(),
        )
        .unwrap_err();
    assert!(error.to_string().contains("training_passes"), "{error}");
}

/// A pipeline of `config` with its background model primed on `frames`.
fn primed(config: &PipelineConfig, frames: &[Frame]) -> Pipeline {
    let mut pipeline = Pipeline::from_config(config).unwrap();
    pipeline
        .prime_background(frames.iter().cloned().map(Ok))
        .unwrap();
    pipeline
}

/// The points of `frames` stepped one by one through [`Pipeline::step`] (no detection ahead
/// of tracking), the background primed on them.
fn stepped(config: &PipelineConfig, frames: Vec<Frame>) -> Vec<TrackPoint> {
    let mut points = Vec::new();
    let mut pipeline = primed(config, &frames);
    for frame in frames {
        pipeline
            .step(&FrameInput::Image(frame), &mut points)
            .unwrap();
    }
    pipeline.finish(&mut points).unwrap();
    points
}

#[test]
fn a_run_detecting_ahead_gives_the_frame_by_frame_points_for_any_thread_count() {
    // Background subtraction on: its model and the pre-processed copies travel with the
    // frames the detection thread hands over.
    let mut config = PipelineConfig::default();
    config.set("preprocess.background.speed=0.05").unwrap();
    config.set("preprocess.median=3").unwrap();
    let expected = stepped(&config, drifting_frames(14));
    assert!(expected.len() > 36 * 8, "{} points", expected.len());
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut seen = Vec::new();
        let mut points = Vec::new();
        pool.install(|| {
            let frames = drifting_frames(14);
            primed(&config, &frames).run(frames.into_iter().map(Ok), &mut points, &mut |report| {
                seen.push(report.frame)
            })
        })
        .unwrap();
        assert_eq!(points, expected, "{threads} threads");
        assert_eq!(seen, (0..14).collect::<Vec<u64>>(), "frames shown in order");
    }
}

#[test]
fn a_run_detecting_ahead_stops_at_a_bad_frame_after_tracking_the_ones_before() {
    // An input that fails (a file that does not decode) at frame 5.
    let mut inputs: Vec<sillage::core::Result<Frame>> =
        drifting_frames(9).into_iter().map(Ok).collect();
    inputs[5] = Err(sillage::core::Error::input("frame5: does not decode"));
    let mut seen = Vec::new();
    let err = Pipeline::from_config(&PipelineConfig::default())
        .unwrap()
        .run(inputs.into_iter(), &mut Vec::new(), &mut |report| {
            seen.push(report.frame)
        })
        .unwrap_err();
    assert!(err.to_string().contains("frame5"), "{err}");
    assert_eq!(seen, [0, 1, 2, 3, 4]);

    // A frame the detection refuses (another size than the mask's) at frame 3.
    let dir = tempfile::tempdir().unwrap();
    let mask_path = dir.path().join("mask.png");
    let mut mask = GrayImage::new(SIZE, SIZE);
    mask.as_mut_slice().fill(1.0);
    sillage::io::write_png16(&mask_path, &mask).unwrap();
    let config = PipelineConfig {
        mask: Some(mask_path),
        ..PipelineConfig::default()
    };
    let mut frames = drifting_frames(8);
    frames[3].image = GrayImage::new(SIZE / 2, SIZE);
    let mut seen = Vec::new();
    let err = Pipeline::from_config(&config)
        .unwrap()
        .run(frames.into_iter().map(Ok), &mut Vec::new(), &mut |report| {
            seen.push(report.frame)
        })
        .unwrap_err()
        .to_string();
    assert!(err.contains("frame 3") && err.contains("mask"), "{err}");
    assert_eq!(seen, [0, 1, 2]);
}

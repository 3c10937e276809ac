//! The bedload renderer through the MMPF+ bead detector (`sillage_detect::BeadDetector`), run
//! with the parameters of the real-frame test (`sillage-detect/tests/bead.rs`: 2.056e-4 m/px,
//! 6 and 4 mm beads), scored with `sillage_eval::detection_scores` within 2 px.
//!
//! The issue's acceptance: "the detectors, run with the parameters tuned on the real frames,
//! reach within 2 points of the same recall" on the generated frames as on the real ones.
//! - On the bead configurations of the ten real frames (their hand-made ground truth,
//!   rendered), every class's recall is within 2 points of the real frames', with the
//!   built-in ring template and with BeadTracking's.
//! - On the default synthetic scene, the mobile beads overlap one another far more than in the
//!   real flume (they all move on one surface line and pass through each other), so most
//!   transparent beads there are hidden: the recall over all beads is far lower than on the
//!   real frames, which no renderer can change. The comparison is made, within 2 points, on
//!   the beads whose neighbourhood the real frames also show (no bead closer than the real
//!   frames' closest pair of the same two classes); the recall over all beads is printed.

use rand::RngExt;
use sillage_core::{
    BLACK_BEAD_CLASS, Detection, FrameIndex, GrayImage, MotionState, Point2, TruthPoint, rng_stream,
};
use sillage_detect::{BeadDetections, BeadDetector, BeadParams};
use sillage_eval::{DetectionScores, detection_scores};
use sillage_synth::{
    BedloadFrame, BedloadRenderParams, BedloadRenderer, BedloadScene, BedloadSceneParams, TrueBead,
    render_bedload_frame,
};

const DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/bedload_beads_lafaye2018"
);

/// A detection matches a true bead strictly closer than this, px (as the real-frame test).
const MATCH_RADIUS_PX: f64 = 2.0;

/// The largest gap allowed between the synthetic and the real recall (the 2 points).
const MAX_RECALL_GAP: f64 = 0.02;

/// Recall of the detector on the ten real frames (`shared/data/bedload_beads_lafaye2018`,
/// against `ground_truth/trackdatatruth.csv`, within 2 px), measured as
/// `sillage-detect/tests/bead.rs` does (same parameters, the sequence's base mask) but with
/// the built-in ring template: black 3188 of 3188, transparent 773 of 774.
const REAL_RECALL_BUILT_IN: [f64; 2] = [1.0, 773.0 / 774.0];

/// The same with BeadTracking's template (`template_transparent_bead_rOut10_rIn6.csv`):
/// black 3188 of 3188, transparent 754 of 774 (0.9742), as `cargo test -p sillage-detect
/// --test bead -- --nocapture` prints. The 20 misses are two resting beads in all ten frames.
const REAL_RECALL_TEMPLATE: [f64; 2] = [1.0, 754.0 / 774.0];

/// The closest centres in the real frames' ground truth, px, for black–black,
/// transparent–black and transparent–transparent pairs (26.2, 20.6 and 12.5 measured).
const REAL_CLOSEST_PX: [f64; 3] = [26.0, 20.5, 12.5];

/// The detector of the real-frame test, without base mask (the synthetic frames have no
/// flume base) and with the built-in ring template unless `template` is given.
fn detector(template: Option<&GrayImage>) -> BeadDetector {
    let params = BeadParams {
        m_per_px: 2.056e-4,
        black_diameter_m: 0.006,
        transparent_diameter_m: 0.004,
        ..BeadParams::default()
    };
    let detector = BeadDetector::new(params).unwrap();
    match template {
        Some(template) => detector.with_ring_template(template).unwrap(),
        None => detector,
    }
}

/// BeadTracking's ring template (21×21 values of CSV).
fn beadtracking_template() -> GrayImage {
    let path = format!("{DATA}/template_transparent_bead_rOut10_rIn6.csv");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let values: Vec<f32> = text
        .split([',', '\n'])
        .filter(|v| !v.trim().is_empty())
        .map(|v| v.trim().parse().unwrap())
        .collect();
    GrayImage::from_vec(21, 21, values).unwrap()
}

/// The ten real frames' ground truth as bedload frames (0-based pixels). Its positions are
/// whole pixels, so each bead is moved by a uniform offset of up to half a pixel along each
/// axis (the real centres lie somewhere in that square: the black beads' centroids deviate
/// from the truth by 0.31 px rms along each axis, as a rounding does).
fn real_configurations() -> Vec<BedloadFrame> {
    let path = format!("{DATA}/ground_truth/trackdatatruth.csv");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut frames: Vec<BedloadFrame> = (0..10)
        .map(|index| BedloadFrame {
            index,
            beads: Vec::new(),
        })
        .collect();
    let mut rng = rng_stream(2018, 0);
    for line in text.lines().skip(1) {
        // frame,id,x,y,category,vx,vy,motion_state; frame and pixels 1-based.
        let v: Vec<&str> = line.split(',').collect();
        let frame = v[0].parse::<usize>().unwrap() - 1;
        let (x, y): (f64, f64) = (v[2].parse().unwrap(), v[3].parse().unwrap());
        frames[frame].beads.push(TrueBead {
            track_id: v[1].parse().unwrap(),
            class: v[4].parse().unwrap(),
            pos_px: Point2::new(
                x - 1.0 + rng.random::<f64>() - 0.5,
                y - 1.0 + rng.random::<f64>() - 0.5,
            ),
            vel_px_per_frame: None,
            motion_state: MotionState::Unknown,
            in_bed: false,
        });
    }
    frames
}

/// The beads of one class (0 black, 1 transparent), all or only `admissible` ones, as truth.
fn truth(frames: &[BedloadFrame], class: u32, admissible: bool) -> Vec<TruthPoint> {
    frames
        .iter()
        .flat_map(|frame| {
            frame
                .beads
                .iter()
                .filter(move |b| b.class == class)
                .filter(move |b| !admissible || has_a_real_neighbourhood(frame, b))
                .map(move |b| TruthPoint {
                    frame: frame.index,
                    track_id: b.track_id,
                    pos_px: b.pos_px,
                    vel_px_per_frame: None,
                })
        })
        .collect()
}

/// True when no other bead of the frame is closer to `bead` than the real frames' closest
/// pair of the same two classes.
fn has_a_real_neighbourhood(frame: &BedloadFrame, bead: &TrueBead) -> bool {
    frame.beads.iter().all(|other| {
        if other.track_id == bead.track_id {
            return true;
        }
        let black = [bead.class, other.class]
            .iter()
            .filter(|&&c| c == BLACK_BEAD_CLASS)
            .count();
        let closest = REAL_CLOSEST_PX[2 - black];
        bead.pos_px.distance(other.pos_px) >= closest
    })
}

/// Scores the detections of one class (0 black, 1 transparent) against `truth`.
fn score(
    truth: &[TruthPoint],
    per_frame: &[(FrameIndex, BeadDetections)],
    class: u32,
) -> DetectionScores {
    let detections: Vec<(FrameIndex, Vec<Detection>)> = per_frame
        .iter()
        .map(|(f, d)| {
            let list = if class == BLACK_BEAD_CLASS {
                &d.black
            } else {
                &d.transparent
            };
            (*f, list.clone())
        })
        .collect();
    detection_scores(truth, &detections, MATCH_RADIUS_PX).unwrap()
}

/// Renders `frames` and runs `detector` on them.
fn render_and_detect(
    frames: &[BedloadFrame],
    detector: &mut BeadDetector,
) -> Vec<(FrameIndex, BeadDetections)> {
    let (width, height) = (1280, 320);
    let mut renderer = BedloadRenderer::new(BedloadRenderParams::default()).unwrap();
    let mut image = GrayImage::new(width, height);
    frames
        .iter()
        .map(|frame| {
            renderer.render(frame, &mut image);
            let mut beads = BeadDetections::default();
            detector.detect_beads(&image, &mut beads).unwrap();
            (frame.index, beads)
        })
        .collect()
}

fn report(label: &str, scores: &DetectionScores) -> f64 {
    let recall = scores.recall.unwrap();
    println!(
        "{label}: recall {recall:.4}, precision {:.4} ({} true, {} matched, {} false)",
        scores.precision.unwrap_or(f64::NAN),
        scores.true_positives + scores.false_negatives,
        scores.true_positives,
        scores.false_positives
    );
    recall
}

#[test]
fn rendered_real_configurations_are_as_hard_to_detect_as_the_real_frames() {
    let frames = real_configurations();
    let template = beadtracking_template();
    for (name, template, real) in [
        ("built-in ring", None, REAL_RECALL_BUILT_IN),
        (
            "BeadTracking's template",
            Some(&template),
            REAL_RECALL_TEMPLATE,
        ),
    ] {
        let per_frame = render_and_detect(&frames, &mut detector(template));
        for (class, label) in [(0, "black"), (1, "transparent")] {
            let scores = score(&truth(&frames, class, false), &per_frame, class);
            let recall = report(&format!("real configurations, {name}, {label}"), &scores);
            assert!(
                (recall - real[class as usize]).abs() <= MAX_RECALL_GAP,
                "{name}, {label}: synthetic recall {recall:.4}, real {:.4}",
                real[class as usize]
            );
        }
    }
}

#[test]
fn default_scene_frames_through_the_detector() {
    let params = BedloadSceneParams {
        n_frames: 10,
        seed: 7,
        ..BedloadSceneParams::default()
    };
    let frames: Vec<BedloadFrame> = BedloadScene::new(params).unwrap().collect();
    let start = std::time::Instant::now();
    let per_frame = render_and_detect(&frames, &mut detector(None));
    println!(
        "{} frames rendered and detected in {:?}",
        frames.len(),
        start.elapsed()
    );
    for (class, label) in [(0, "black"), (1, "transparent")] {
        let all = score(&truth(&frames, class, false), &per_frame, class);
        report(&format!("default scene, all {label} beads"), &all);
        // Recall only: the detections of the beads left out count as false positives here.
        let comparable = truth(&frames, class, true);
        let recall = score(&comparable, &per_frame, class).recall.unwrap();
        println!(
            "default scene, {} {label} beads in real-like neighbourhoods: recall {recall:.4}",
            comparable.len()
        );
        assert!(comparable.len() >= 30, "{label}: too few beads to compare");
        let real = REAL_RECALL_BUILT_IN[class as usize];
        assert!(
            (recall - real).abs() <= MAX_RECALL_GAP,
            "{label}: synthetic recall {recall:.4}, real {real:.4}"
        );
        // Not an easy stand-in: over all beads, the detector does no better than on the real
        // frames.
        assert!(all.recall.unwrap() <= real + 1e-9);
    }
}

/// A short default scene.
fn scene_frames(n_frames: usize) -> Vec<BedloadFrame> {
    let params = BedloadSceneParams {
        n_frames,
        ..BedloadSceneParams::default()
    };
    BedloadScene::new(params).unwrap().collect()
}

#[test]
fn rendering_is_deterministic_whatever_the_threads() {
    let frames = scene_frames(2);
    let params = BedloadRenderParams::default();
    let render = |frame: &BedloadFrame, params: &BedloadRenderParams| {
        let mut image = GrayImage::new(1280, 320);
        render_bedload_frame(frame, params, &mut image).unwrap();
        image
    };
    let image = render(&frames[1], &params);
    assert_eq!(image, render(&frames[1], &params));
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| render(&frames[1], &params));
    assert_eq!(image, single);
    // A renderer kept for a sequence gives the same frames as one-off renderings.
    let mut renderer = BedloadRenderer::new(params.clone()).unwrap();
    let mut kept = GrayImage::new(1280, 320);
    renderer.render(&frames[0], &mut kept);
    renderer.render(&frames[1], &mut kept);
    assert_eq!(image, kept);
    // 8-bit levels in [0, 1], as the real frames.
    assert!(image.as_slice().iter().all(|&v| {
        let level = v * 255.0;
        (0.0..=255.0).contains(&level) && (level - level.round()).abs() < 1e-3
    }));

    // Another seed changes the frame; another frame index only changes the noise (the beads'
    // looks follow their track id).
    let other_seed = BedloadRenderParams {
        seed: 1,
        ..params.clone()
    };
    assert_ne!(image, render(&frames[1], &other_seed));
    let reindexed = BedloadFrame {
        index: 99,
        ..frames[1].clone()
    };
    let noisy = render(&reindexed, &params);
    assert_ne!(image, noisy);
    let mean_change = image
        .as_slice()
        .iter()
        .zip(noisy.as_slice())
        .map(|(a, b)| f64::from((a - b).abs()))
        .sum::<f64>()
        / image.as_slice().len() as f64;
    assert!(mean_change < 0.01, "{mean_change}");

    // An empty image gets nothing and does not panic.
    let mut empty = GrayImage::new(0, 0);
    render_bedload_frame(&frames[0], &params, &mut empty).unwrap();
    assert!(empty.is_empty());
}

#[test]
fn bad_parameters_name_their_key() {
    type Case = (&'static str, fn(&mut BedloadRenderParams));
    let cases: [Case; 18] = [
        ("background_level", |p| p.background_level = 0.0),
        ("background_gradient_x", |p| p.background_gradient_x = 1.5),
        ("background_gradient_x", |p| {
            (p.background_gradient_x, p.background_gradient_y) = (0.9, 0.9)
        }),
        ("background_gradient_y", |p| {
            p.background_gradient_y = f64::NAN
        }),
        ("illumination_sigma", |p| p.illumination_sigma = -0.1),
        ("illumination_correlated_fraction", |p| {
            p.illumination_correlated_fraction = 2.0
        }),
        ("noise_sigma", |p| p.noise_sigma = f64::INFINITY),
        ("black_radius_px", |p| p.black_radius_px = 0.0),
        ("black_level", |p| p.black_level = 1.0),
        ("edge_sigma_px", |p| p.edge_sigma_px = -1.0),
        ("transparent_radius_px", |p| p.transparent_radius_px = 1e9),
        ("centre_transmission", |p| p.centre_transmission = 1.2),
        ("ring_radius_px", |p| p.ring_radius_px = 11.0),
        ("ring_transmission", |p| p.ring_transmission = 0.99),
        ("ring_outer_sigma_px", |p| p.ring_outer_sigma_px = 0.0),
        ("ring_blur_spread", |p| p.ring_blur_spread = 3.0),
        ("transparent_opacity", |p| p.transparent_opacity = -0.5),
        ("levels", |p| p.levels = 70_000),
    ];
    let frame = &scene_frames(1)[0];
    for (key, spoil) in cases {
        let mut params = BedloadRenderParams::default();
        spoil(&mut params);
        let err = BedloadRenderer::new(params.clone())
            .unwrap_err()
            .to_string();
        assert!(err.contains(&format!("`{key}`")), "{key}: {err}");
        let mut image = GrayImage::new(8, 8);
        assert!(render_bedload_frame(frame, &params, &mut image).is_err());
    }
    // A misspelt key is refused when the parameters are read (serde's value model here).
    use serde::Deserialize;
    use serde::de::value::{Error, MapDeserializer};
    let entries = MapDeserializer::<_, Error>::new([("noise_sigmaa", 0.01f64)].into_iter());
    let err = BedloadRenderParams::deserialize(entries)
        .unwrap_err()
        .to_string();
    assert!(err.contains("unknown field `noise_sigmaa`"), "{err}");
}

//! What the bedload tests through the MMPF+ bead detector share: the real frames' ground
//! truth (`shared/data/bedload_beads_lafaye2018`), the detector run with the parameters of
//! the real-frame test (`sillage-detect/tests/bead.rs`: 2.056e-4 m/px, 6 and 4 mm beads),
//! and its scoring with `sillage_eval::detection_scores` within 2 px.

use rand::RngExt;
use sillage_core::{
    BLACK_BEAD_CLASS, Detection, FrameIndex, GrayImage, MotionState, Point2, TruthPoint, Vec2,
    rng_stream,
};
use sillage_detect::{BeadDetections, BeadDetector, BeadParams};
use sillage_eval::{DetectionScores, detection_scores};
use sillage_synth::{BedloadFrame, BedloadRenderParams, BedloadRenderer, TrueBead};

/// The real sequence's folder.
pub const DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/bedload_beads_lafaye2018"
);

/// A detection matches a true bead strictly closer than this, px (as the real-frame test).
const MATCH_RADIUS_PX: f64 = 2.0;

/// The largest gap allowed between the synthetic and the real recall (the 2 points).
pub const MAX_RECALL_GAP: f64 = 0.02;

/// Recall of the detector on the ten real frames (`shared/data/bedload_beads_lafaye2018`,
/// against `ground_truth/trackdatatruth.csv`, within 2 px), measured as
/// `sillage-detect/tests/bead.rs` does (same parameters, the sequence's base mask) but with
/// the built-in ring template: black 3188 of 3188, transparent 773 of 774.
pub const REAL_RECALL_BUILT_IN: [f64; 2] = [1.0, 773.0 / 774.0];

/// The detector of the real-frame test, without base mask (the synthetic frames have no
/// flume base) and with the built-in ring template unless `template` is given.
pub fn detector(template: Option<&GrayImage>) -> BeadDetector {
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

/// The ten real frames' ground truth as bedload frames (0-based pixels), with the truth's
/// velocities (px/frame) and motion states (its "unknown" first points included; no bead
/// is marked `in_bed`). Its positions are whole pixels, so each bead is moved by a uniform
/// offset of up to half a pixel along each axis (the real centres lie somewhere in that
/// square: the black beads' centroids deviate from the truth by 0.31 px rms along each
/// axis, as a rounding does).
pub fn real_configurations() -> Vec<BedloadFrame> {
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
        let number = |k: usize| v[k].parse::<f64>().unwrap();
        let frame = v[0].parse::<usize>().unwrap() - 1;
        let motion_state = match v[7] {
            "0" => MotionState::Resting,
            "1" => MotionState::Rolling,
            "2" => MotionState::Saltating,
            _ => MotionState::Unknown,
        };
        frames[frame].beads.push(TrueBead {
            track_id: v[1].parse().unwrap(),
            class: v[4].parse().unwrap(),
            pos_px: Point2::new(
                number(2) - 1.0 + rng.random::<f64>() - 0.5,
                number(3) - 1.0 + rng.random::<f64>() - 0.5,
            ),
            vel_px_per_frame: Some(Vec2::new(number(5), number(6))),
            motion_state,
            in_bed: false,
        });
    }
    frames
}

/// The beads of one class (0 black, 1 transparent) that `keep` accepts, as truth.
pub fn truth(
    frames: &[BedloadFrame],
    class: u32,
    keep: impl Fn(&BedloadFrame, &TrueBead) -> bool,
) -> Vec<TruthPoint> {
    frames
        .iter()
        .flat_map(|frame| {
            frame
                .beads
                .iter()
                .filter(|b| b.class == class && keep(frame, b))
                .map(move |b| TruthPoint {
                    frame: frame.index,
                    track_id: b.track_id,
                    pos_px: b.pos_px,
                    vel_px_per_frame: None,
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Scores the detections of one class (0 black, 1 transparent) against `truth`.
pub fn score(
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

/// Renders `frames` (1280×320, default rendering) and runs `detector` on them.
pub fn render_and_detect(
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

/// Prints the scores of `label` and returns the recall.
pub fn report(label: &str, scores: &DetectionScores) -> f64 {
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

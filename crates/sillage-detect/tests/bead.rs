//! The bead detector on the ten real flume frames of the MMPF+ paper's authors
//! (`shared/data/bedload_beads_lafaye2018`) against their hand-edited ground truth, with the
//! paper's acceptance targets, and bad input.
//!
//! The flume-base mask is the authors' `sequence_base_mask.tif` (white = base), a CCITT
//! modified-Huffman TIFF that `sillage_io::read_image` decodes.

use sillage_core::{Detection, Detector, FrameIndex, GrayImage, TruthPoint};
use sillage_detect::{BeadDetections, BeadDetector, BeadParams};
use sillage_eval::{DetectionScores, detection_scores};
use sillage_io::{
    BeadCategory, read_bead_csv, read_bead_sequence_params, read_image, read_matrix_csv,
};

const DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/bedload_beads_lafaye2018"
);

/// A detection matches a true bead strictly closer than this, px (the "within 2 px";
/// the strict bound is the harder one).
const MATCH_RADIUS_PX: f64 = 2.0;

/// BeadTracking's ring template, read from its CSV export (21×21 values).
fn ring_template() -> GrayImage {
    read_matrix_csv(format!("{DATA}/template_transparent_bead_rOut10_rIn6.csv")).unwrap()
}

fn base_mask() -> GrayImage {
    read_image(format!("{DATA}/sequence_base_mask.tif")).unwrap()
}

/// The ten frames, in order.
fn frames() -> Vec<GrayImage> {
    let mut paths: Vec<_> = std::fs::read_dir(format!("{DATA}/images"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    paths.sort();
    paths.iter().map(|p| read_image(p).unwrap()).collect()
}

/// The detector as configured for the shared sequence: its scale from `sequence_param.txt`,
/// its base mask and its template.
fn detector(params: BeadParams) -> BeadDetector {
    let sequence = read_bead_sequence_params(format!("{DATA}/sequence_param.txt")).unwrap();
    let params = BeadParams {
        m_per_px: sequence.m_per_px,
        black_diameter_m: sequence.black_diameter_m,
        transparent_diameter_m: sequence.transparent_diameter_m,
        ..params
    };
    BeadDetector::new(params)
        .unwrap()
        .with_base_mask(&base_mask())
        .with_ring_template(&ring_template())
        .unwrap()
}

/// True beads of one category, as truth points.
fn truth(category: BeadCategory) -> Vec<TruthPoint> {
    read_bead_csv(format!("{DATA}/ground_truth/trackdatatruth.csv"))
        .unwrap()
        .into_iter()
        .filter(|p| p.category == category)
        .map(|p| TruthPoint {
            frame: p.frame,
            track_id: p.id,
            pos_px: p.pos_px,
            vel_px_per_frame: None,
        })
        .collect()
}

fn score(
    truth: &[TruthPoint],
    per_frame: &[BeadDetections],
    pick: impl Fn(&BeadDetections) -> Vec<Detection>,
) -> DetectionScores {
    let detections: Vec<(FrameIndex, Vec<Detection>)> = per_frame
        .iter()
        .enumerate()
        .map(|(f, d)| (f as FrameIndex, pick(d)))
        .collect();
    detection_scores(truth, &detections, MATCH_RADIUS_PX).unwrap()
}

#[test]
fn beads_of_the_real_frames_match_the_hand_made_truth() {
    // Candidates down to 0.15 give the whole τ_t curve; the detections use the default τ_t.
    let mut detector = detector(BeadParams {
        candidate_threshold: 0.15,
        ..BeadParams::default()
    });
    let tau_t = detector.params().transparent_threshold as f32;
    let per_frame: Vec<BeadDetections> = frames()
        .iter()
        .map(|frame| {
            let mut beads = BeadDetections::default();
            detector.detect_beads(frame, &mut beads).unwrap();
            beads
        })
        .collect();
    assert_eq!(per_frame.len(), 10);

    let black = score(&truth(BeadCategory::Black), &per_frame, |d| d.black.clone());
    println!(
        "black: recall {:.4}, precision {:.4} ({} true, {} detected, {} matched, mean error {:.2} px)",
        black.recall.unwrap(),
        black.precision.unwrap(),
        black.true_positives + black.false_negatives,
        black.true_positives + black.false_positives,
        black.true_positives,
        black.mean_error_px.unwrap()
    );
    assert!(black.recall.unwrap() >= 0.995 && black.precision.unwrap() >= 0.995);

    let transparent_truth = truth(BeadCategory::Transparent);
    let transparent = score(&transparent_truth, &per_frame, |d| d.transparent.clone());
    println!(
        "transparent at τ_t = {tau_t}: recall {:.4}, precision {:.4}",
        transparent.recall.unwrap(),
        transparent.precision.unwrap()
    );
    assert!(transparent.recall.unwrap() >= 0.95 && transparent.precision.unwrap() >= 0.95);

    println!("τ_t   recall  precision  matched  false+  missed");
    for step in -10..=10 {
        let threshold = tau_t + 0.01 * step as f32;
        let s = score(&transparent_truth, &per_frame, |d| {
            d.candidates
                .iter()
                .filter(|c| c.strength >= threshold)
                .copied()
                .collect()
        });
        println!(
            "{threshold:.2}  {:.4}  {:.4}     {:>4}     {:>4}    {:>4}",
            s.recall.unwrap(),
            s.precision.unwrap(),
            s.true_positives,
            s.false_positives,
            s.false_negatives
        );
        if step == 0 {
            assert_eq!(s, transparent, "the detections are the candidates ≥ τ_t");
        }
    }
}

#[test]
fn the_detector_trait_gives_black_then_transparent_and_threads_do_not_matter() {
    let frame = &frames()[3];
    let run = || {
        let mut d = detector(BeadParams::default());
        let (mut beads, mut plain) = (BeadDetections::default(), Vec::new());
        d.detect_beads(frame, &mut beads).unwrap();
        d.detect(frame, &mut plain).unwrap();
        (beads, plain)
    };
    let (beads, plain) = run();
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(run);
    assert_eq!((&beads, &plain), (&single.0, &single.1));
    assert_eq!(plain.len(), beads.black.len() + beads.transparent.len());
    assert_eq!(&plain[..beads.black.len()], beads.black.as_slice());
    assert!(beads.black.len() > 250 && beads.transparent.len() > 50);
    assert!(beads.black.iter().all(|d| d.strength == 1.0));
}

#[test]
fn bad_input_is_a_clear_error() {
    // A frame of another size than the base mask.
    let mut d = detector(BeadParams::default());
    let err = d
        .detect_beads(&GrayImage::new(640, 320), &mut BeadDetections::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("640×320") && err.contains("1280×320") && err.contains("mask"),
        "{err}"
    );

    // A template that is not a ring: BeadTracking's template with its centre darkened too.
    let mut disk = ring_template();
    let low = disk.get(0, 10);
    for y in 7..14 {
        for x in 7..14 {
            disk.set(x, y, low);
        }
    }
    let err = BeadDetector::new(BeadParams::default())
        .unwrap()
        .with_ring_template(&disk)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("not a ring") && err.contains("centre"),
        "{err}"
    );

    // Degenerate frames are no error (and no panic) without a mask: nothing is found.
    let mut bare = BeadDetector::new(BeadParams::default()).unwrap();
    for (w, h) in [(0, 0), (3, 2), (40, 1)] {
        let mut beads = BeadDetections::default();
        bare.detect_beads(&GrayImage::new(w, h), &mut beads)
            .unwrap();
        assert!(beads.transparent.is_empty() && beads.candidates.is_empty());
    }

    // An m/px of 0.
    let err = BeadDetector::new(BeadParams {
        m_per_px: 0.0,
        ..BeadParams::default()
    })
    .unwrap_err()
    .to_string();
    assert!(err.contains("`m_per_px` = 0"), "{err}");
}

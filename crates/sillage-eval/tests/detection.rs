//! Detection scores on hand-made cases.

use sillage_core::{Detection, Point2, TruthPoint};
use sillage_eval::detection_scores;

fn truth(frame: u64, id: u64, x: f64, y: f64) -> TruthPoint {
    TruthPoint {
        frame,
        track_id: id,
        pos_px: Point2::new(x, y),
        vel_px_per_frame: None,
    }
}

fn detection(x: f64, y: f64) -> Detection {
    Detection::new(Point2::new(x, y), 1.0)
}

#[test]
fn counts_hits_misses_and_false_alarms_per_frame() {
    let truth = [
        truth(0, 0, 0.0, 0.0),
        truth(0, 1, 10.0, 0.0),
        truth(1, 0, 0.0, 0.0),
        truth(2, 0, 5.0, 5.0),
    ];
    let detections = vec![
        (1, vec![detection(0.0, 0.4)]),
        (0, vec![detection(0.3, 0.0), detection(50.0, 0.0)]),
        (3, vec![detection(5.0, 5.0)]), // no truth in frame 3
    ];
    let s = detection_scores(&truth, &detections, 1.0).unwrap();
    assert_eq!(
        (s.true_positives, s.false_positives, s.false_negatives),
        (2, 2, 2)
    );
    assert_eq!(s.recall, Some(0.5));
    assert_eq!(s.precision, Some(0.5));
    assert!((s.mean_error_px.unwrap() - 0.35).abs() < 1e-12);
    assert!((s.rms_error_px.unwrap() - (0.125f64).sqrt()).abs() < 1e-12);
    assert!(s.to_string().contains("recall 50.0 %"), "{s}");
    assert_eq!(serde_json::to_value(s).unwrap()["false_negatives"], 2);
}

#[test]
fn empty_inputs_and_bad_values() {
    let s = detection_scores(&[], &[], 1.0).unwrap();
    assert_eq!((s.recall, s.precision, s.mean_error_px), (None, None, None));
    let nan = vec![(6, vec![detection(0.0, 0.0), detection(f64::NAN, 1.0)])];
    let err = detection_scores(&[], &nan, 1.0).unwrap_err().to_string();
    assert!(err.contains("frame 6") && err.contains("id 1"), "{err}");
    let err = detection_scores(&[], &[], f64::INFINITY)
        .unwrap_err()
        .to_string();
    assert!(err.contains("max_distance_px"), "{err}");
}

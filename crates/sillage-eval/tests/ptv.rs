//! PTV accuracy on hand-made cases whose answer is known exactly.

use sillage_core::{Point2, TrackPoint, TruthPoint, Vec2};
use sillage_eval::{PtvAccuracyParams, ptv_accuracy};

fn truth(frame: u64, id: u64, x: f64, y: f64, v: Option<(f64, f64)>) -> TruthPoint {
    TruthPoint {
        frame,
        track_id: id,
        pos_px: Point2::new(x, y),
        vel_px_per_frame: v.map(|(vx, vy)| Vec2::new(vx, vy)),
    }
}

fn track(frame: u64, id: u64, x: f64, y: f64, v: Option<(f64, f64)>) -> TrackPoint {
    let mut p = TrackPoint::at(frame, id, Point2::new(x, y));
    p.vel_px_per_frame = v.map(|(vx, vy)| Vec2::new(vx, vy));
    p
}

/// Two particles moving right at 2 px/frame on rows 10 and 30, frames 0..=4; velocities on
/// frames 1..=3 only (central differences).
fn two_particles() -> Vec<TruthPoint> {
    let mut points = Vec::new();
    for frame in 0..5 {
        let v = (1..4).contains(&frame).then_some((2.0, 0.0));
        for (id, y) in [(0, 10.0), (1, 30.0)] {
            points.push(truth(frame, id, 5.0 + 2.0 * frame as f64, y, v));
        }
    }
    points
}

/// What a perfect three-frame tracker emits: frames 1..=3, with the true velocities.
fn perfect_tracks(truth: &[TruthPoint]) -> Vec<TrackPoint> {
    truth
        .iter()
        .filter(|p| p.vel_px_per_frame.is_some())
        .map(|p| TrackPoint {
            vel_px_per_frame: p.vel_px_per_frame,
            ..TrackPoint::at(p.frame, p.track_id + 100, p.pos_px)
        })
        .collect()
}

#[test]
fn perfect_tracks_are_all_true_recoveries() {
    let truth = two_particles();
    let mut tracks = perfect_tracks(&truth);
    tracks.reverse(); // inputs need not be sorted
    let a = ptv_accuracy(&truth, &tracks, &PtvAccuracyParams::default()).unwrap();
    assert_eq!(
        (a.n_truth, a.n_estimated, a.n_true, a.n_false),
        (6, 6, 6, 0)
    );
    assert_eq!(a.true_recovery_rate, Some(1.0));
    assert_eq!(a.false_recovery_rate, Some(0.0));
    assert_eq!(a.mean_position_error_px, Some(0.0));
    assert_eq!(a.mean_displacement_error_px, Some(0.0));
    assert_eq!(a.rms_position_error_px, Some(Vec2::ZERO));
    assert_eq!(a.n_not_evaluated, 0);
}

#[test]
fn position_and_displacement_errors_are_averaged_over_true_recoveries() {
    let truth = [
        truth(1, 0, 0.0, 0.0, Some((4.0, 0.0))),
        truth(1, 1, 50.0, 0.0, Some((4.0, 0.0))),
    ];
    let tracks = [
        track(1, 7, 0.3, 0.4, Some((4.0, 1.0))), // position error 0.5, displacement error 1
        track(1, 8, 50.0, 0.1, Some((4.0, 0.0))), // position error 0.1, displacement error 0
    ];
    let a = ptv_accuracy(&truth, &tracks, &PtvAccuracyParams::default()).unwrap();
    assert_eq!(a.n_true, 2);
    assert!((a.mean_position_error_px.unwrap() - 0.3).abs() < 1e-12);
    assert!((a.mean_displacement_error_px.unwrap() - 0.5).abs() < 1e-12);
    let rms = a.rms_position_error_px.unwrap();
    assert!((rms.x - (0.09f64 / 2.0).sqrt()).abs() < 1e-12);
    assert!((rms.y - (0.17f64 / 2.0).sqrt()).abs() < 1e-12);
}

#[test]
fn a_swapped_identity_gives_false_recoveries_around_the_swap() {
    // The tracker follows particle 0 up to frame 2 then jumps to particle 1: its central
    // differences at frames 2 and 3 span two objects.
    let truth = two_particles();
    let x = |frame: u64| 5.0 + 2.0 * frame as f64;
    let tracks = [
        track(1, 0, x(1), 10.0, Some((2.0, 0.0))),
        track(2, 0, x(2), 10.0, Some((2.0, 10.0))), // (x3, 30) - (x1, 10), halved
        track(3, 0, x(3), 30.0, Some((2.0, 10.0))), // (x4, 30) - (x2, 10), halved
    ];
    let a = ptv_accuracy(&truth, &tracks, &PtvAccuracyParams::default()).unwrap();
    assert_eq!(
        (a.n_true, a.n_false, a.n_estimated, a.n_truth),
        (1, 2, 3, 6)
    );
    assert!((a.false_recovery_rate.unwrap() - 2.0 / 3.0).abs() < 1e-12);
    assert!((a.true_recovery_rate.unwrap() - 1.0 / 6.0).abs() < 1e-12);
}

#[test]
fn a_displacement_error_of_exactly_half_the_true_one_is_false() {
    let truth = [truth(1, 0, 0.0, 0.0, Some((2.0, 0.0)))];
    let at = |vx: f64| {
        let tracks = [track(1, 0, 0.0, 0.0, Some((vx, 0.0)))];
        ptv_accuracy(&truth, &tracks, &PtvAccuracyParams::default())
            .unwrap()
            .n_true
    };
    assert_eq!(at(3.0), 0); // |Δv| = 1 = |v| / 2
    assert_eq!(at(1.0), 0);
    assert_eq!(at(2.999), 1);
    assert_eq!(at(1.001), 1);
}

#[test]
fn a_position_error_of_exactly_d_is_unmatched() {
    let truth = [truth(1, 0, 0.0, 0.0, Some((2.0, 0.0)))];
    let count = |x: f64| {
        let tracks = [track(1, 0, x, 0.0, Some((2.0, 0.0)))];
        let params = PtvAccuracyParams {
            max_position_error_px: 0.5,
        };
        let a = ptv_accuracy(&truth, &tracks, &params).unwrap();
        (a.n_true, a.n_false)
    };
    assert_eq!(count(0.5), (0, 1));
    assert_eq!(count(0.49), (1, 0));
}

#[test]
fn matching_is_one_to_one_and_a_truth_point_without_velocity_cannot_be_recovered() {
    let truth = [
        truth(1, 0, 0.0, 0.0, Some((2.0, 0.0))),
        truth(1, 1, 20.0, 0.0, None), // a particle that just appeared
    ];
    let tracks = [
        track(1, 5, 0.1, 0.0, Some((2.0, 0.0))),
        track(1, 6, 0.2, 0.0, Some((2.0, 0.0))), // a duplicate: the truth is taken
        track(1, 7, 20.0, 0.0, Some((2.0, 0.0))),
        track(1, 8, 99.0, 0.0, None), // no velocity: not evaluated
        track(0, 9, 0.0, 0.0, Some((2.0, 0.0))), // frame without truth velocities
    ];
    let a = ptv_accuracy(&truth, &tracks, &PtvAccuracyParams::default()).unwrap();
    assert_eq!((a.n_truth, a.n_estimated, a.n_not_evaluated), (1, 3, 2));
    assert_eq!((a.n_true, a.n_false), (1, 2));
}

#[test]
fn empty_inputs_give_undefined_rates() {
    let a = ptv_accuracy(&[], &[], &PtvAccuracyParams::default()).unwrap();
    assert_eq!(
        (a.n_truth, a.n_estimated, a.n_true, a.n_false),
        (0, 0, 0, 0)
    );
    assert_eq!(a.true_recovery_rate, None);
    assert_eq!(a.false_recovery_rate, None);
    assert_eq!(a.mean_position_error_px, None);
    let truth = two_particles();
    let a = ptv_accuracy(&truth, &[], &PtvAccuracyParams::default()).unwrap();
    assert_eq!(a.true_recovery_rate, Some(0.0));
    assert_eq!(a.false_recovery_rate, None);
    assert!(a.to_string().contains("n/a"));
}

#[test]
fn non_finite_inputs_and_bad_parameters_are_rejected() {
    let good = [truth(1, 0, 0.0, 0.0, Some((2.0, 0.0)))];
    let nan_track = [track(4, 17, f64::NAN, 0.0, Some((2.0, 0.0)))];
    let err = ptv_accuracy(&good, &nan_track, &PtvAccuracyParams::default()).unwrap_err();
    let message = err.to_string();
    assert!(
        message.contains("frame 4") && message.contains("id 17"),
        "{message}"
    );
    let nan_truth = [truth(2, 3, 0.0, 0.0, Some((f64::NAN, 0.0)))];
    let err = ptv_accuracy(&nan_truth, &[], &PtvAccuracyParams::default()).unwrap_err();
    assert!(err.to_string().contains("frame 2, id 3"), "{err}");
    let params = PtvAccuracyParams {
        max_position_error_px: 0.0,
    };
    let err = ptv_accuracy(&good, &[], &params).unwrap_err();
    assert!(err.to_string().contains("max_position_error_px"), "{err}");
}

#[test]
fn serialises_to_json_and_displays_percentages() {
    let truth = two_particles();
    let tracks = perfect_tracks(&truth);
    let a = ptv_accuracy(&truth, &tracks[..3], &PtvAccuracyParams::default()).unwrap();
    let json = serde_json::to_value(a).unwrap();
    assert_eq!(json["n_true"], 3);
    assert_eq!(json["true_recovery_rate"], 0.5);
    let text = a.to_string();
    assert!(text.contains("50.0 %") && text.contains("0.0 %"), "{text}");
}

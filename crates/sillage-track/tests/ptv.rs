//! PTV tracker on small seeded synthetic scenes with known truth.

use std::collections::HashMap;

use rand::RngExt;
use sillage_core::{Detection, FrameObservations, Point2, TrackPoint, Tracker, Vec2, rng_stream};
use sillage_track::ptv::{
    AUTO_VOTE_FIRST_LINK_SPACINGS, AUTO_VOTE_MIN_VALID_SHARE, PassDirection, PtvParams, PtvTracker,
    VoteSearch,
};

/// Detections per frame and the true particle id of each detection.
struct Scene {
    frames: Vec<Vec<Detection>>,
    truth: Vec<Vec<u64>>,
}

impl Scene {
    /// `n` particles whose position at frame `f` is `path(initial, f)`; each detection is
    /// kept with probability `detect_prob`, and `spurious` one-frame points are added.
    fn new(
        seed: u64,
        n: usize,
        frames: usize,
        mut initial: impl FnMut(&mut sillage_core::RngStream) -> Point2,
        path: impl Fn(Point2, f64) -> Point2,
        detect_prob: f64,
        spurious: usize,
    ) -> Self {
        let mut rng = rng_stream(seed, 0);
        let starts: Vec<Point2> = (0..n).map(|_| initial(&mut rng)).collect();
        let mut scene = Scene {
            frames: Vec::new(),
            truth: Vec::new(),
        };
        let mut next_spurious = n as u64;
        for f in 0..frames {
            let (mut dets, mut ids) = (Vec::new(), Vec::new());
            for (id, &p0) in starts.iter().enumerate() {
                if rng.random::<f64>() < detect_prob {
                    dets.push(Detection::new(path(p0, f as f64), 1.0));
                    ids.push(id as u64);
                }
            }
            for _ in 0..spurious {
                dets.push(Detection::new(initial(&mut rng), 1.0));
                ids.push(next_spurious);
                next_spurious += 1;
            }
            scene.frames.push(dets);
            scene.truth.push(ids);
        }
        scene
    }

    /// Feeds the frames in `direction` to `tracker` and returns what it emitted.
    fn feed(&self, tracker: &mut PtvTracker, direction: PassDirection) -> Vec<TrackPoint> {
        tracker.start_pass(direction);
        let mut out = Vec::new();
        let mut order: Vec<usize> = (0..self.frames.len()).collect();
        if direction == PassDirection::Backward {
            order.reverse();
        }
        for f in order {
            let obs = FrameObservations::from_detections(f as u64, &self.frames[f]);
            tracker.step(&obs, &mut out).unwrap();
        }
        tracker.finish(&mut out).unwrap();
        out
    }

    fn track(&self, params: PtvParams) -> Vec<TrackPoint> {
        self.feed(
            &mut PtvTracker::new(params).unwrap(),
            PassDirection::Forward,
        )
    }

    /// True id of an emitted point (looked up by its exact position).
    fn true_ids(&self) -> HashMap<(u64, u64, u64), u64> {
        let mut map = HashMap::new();
        for (f, (dets, ids)) in self.frames.iter().zip(&self.truth).enumerate() {
            for (d, &id) in dets.iter().zip(ids) {
                map.insert((f as u64, d.pos_px.x.to_bits(), d.pos_px.y.to_bits()), id);
            }
        }
        map
    }

    /// (recall, precision) of frame-to-frame links: a link is two points of one track in
    /// consecutive frames; it is correct when both belong to the same true particle. Recall
    /// counts against the true links between frames 1..n−2, where tracking is possible.
    fn link_scores(&self, points: &[TrackPoint]) -> (f64, f64) {
        let ids = self.true_ids();
        let mut by_track: HashMap<u64, Vec<(u64, u64)>> = HashMap::new();
        for p in points {
            let key = (p.frame, p.pos_px.x.to_bits(), p.pos_px.y.to_bits());
            by_track
                .entry(p.track_id)
                .or_default()
                .push((p.frame, ids[&key]));
        }
        let (mut links, mut correct) = (0usize, 0usize);
        for track in by_track.values_mut() {
            track.sort();
            for w in track.windows(2) {
                if w[1].0 == w[0].0 + 1 {
                    links += 1;
                    correct += usize::from(w[0].1 == w[1].1);
                }
            }
        }
        let last = self.frames.len() - 2;
        let mut possible = 0usize;
        for f in 1..last {
            let next: std::collections::HashSet<_> = self.truth[f + 1].iter().collect();
            possible += self.truth[f].iter().filter(|id| next.contains(id)).count();
        }
        (
            correct as f64 / possible.max(1) as f64,
            correct as f64 / links.max(1) as f64,
        )
    }
}

/// Points on a square lattice of `pitch` px, 20 columns wide, each jittered by up to a
/// quarter pitch: random, yet never closer than half a pitch (uniform random points have
/// close pairs that no tracker can tell apart in the first, model-free step).
fn jittered_lattice(pitch: f64) -> impl FnMut(&mut sillage_core::RngStream) -> Point2 {
    let mut next = 0usize;
    move |rng| {
        let (col, row) = ((next % 20) as f64, (next / 20) as f64);
        next += 1;
        let jitter = |rng: &mut sillage_core::RngStream| rng.random_range(-0.25..0.25) * pitch;
        Point2::new(pitch * col + jitter(rng), pitch * row + jitter(rng))
    }
}

/// Solid-body rotation about (300, 300) of particles in a disk of 250 px, spinning up
/// linearly from rest to `omega` rad/frame over `ramp` frames (0: at full speed at once).
fn rotating(
    seed: u64,
    n: usize,
    (omega, ramp): (f64, f64),
    frames: usize,
    detect_prob: f64,
    spurious: usize,
) -> Scene {
    let in_disk = |rng: &mut sillage_core::RngStream| loop {
        let p = Point2::new(
            rng.random_range(-250.0..250.0),
            rng.random_range(-250.0..250.0),
        );
        if p.x.hypot(p.y) < 250.0 {
            return Point2::new(300.0 + p.x, 300.0 + p.y);
        }
    };
    let path = move |p: Point2, t: f64| {
        let angle = if t < ramp {
            omega * t * t / (2.0 * ramp)
        } else {
            omega * (t - ramp / 2.0)
        };
        let (s, c) = angle.sin_cos();
        let (x, y) = (p.x - 300.0, p.y - 300.0);
        Point2::new(300.0 + c * x - s * y, 300.0 + s * x + c * y)
    };
    Scene::new(seed, n, frames, in_disk, path, detect_prob, spurious)
}

#[test]
fn uniform_translation_gives_one_id_per_particle_and_exact_velocities() {
    let vel = Vec2::new(1.5, -0.7);
    let scene = Scene::new(
        1,
        400,
        15,
        jittered_lattice(50.0),
        |p, t| p + vel * t,
        1.0,
        0,
    );
    let points = scene.track(PtvParams::default());
    assert_eq!(points.len(), 400 * 13, "every particle in frames 1..=13");
    let ids = scene.true_ids();
    let mut track_of: HashMap<u64, u64> = HashMap::new();
    for p in &points {
        let truth = ids[&(p.frame, p.pos_px.x.to_bits(), p.pos_px.y.to_bits())];
        assert_eq!(*track_of.entry(truth).or_insert(p.track_id), p.track_id);
        // The point names the detection it is.
        let d = p.detection.expect("PTV points are detections") as usize;
        let frame = p.frame as usize;
        assert_eq!(scene.frames[frame][d].pos_px, p.pos_px);
        assert_eq!(scene.truth[frame][d], truth);
        let v = p.vel_px_per_frame.unwrap();
        assert!((v - vel).max_abs() < 1e-9, "{v:?}");
        assert!(p.acc_px_per_frame2.unwrap().max_abs() < 1e-9);
    }
    assert_eq!(track_of.len(), 400);
    let mut sorted = points.clone();
    sorted.sort_by_key(|p| (p.frame, p.track_id));
    assert_eq!(sorted, points, "frame by frame, in track id order");
}

#[test]
fn motion_model_tracks_a_fast_rotation_far_better() {
    // 3000 particles in a disk of 250 px: spacing √(S/N) ≈ 8.1 px; displacement 0.03·r,
    // 5 px at the mean radius and 7.5 px at the edge: p⁻¹ ≈ 0.6–0.9.
    let scene = rotating(2, 3000, (0.03, 0.0), 30, 1.0, 0);
    // TracTrac's algorithm: no displacement voting.
    let tractrac = PtvParams {
        vote_search_px: VoteSearch::OFF,
        ..Default::default()
    };
    let no_model = PtvParams {
        motion: false,
        ..tractrac.clone()
    };
    let (without, _) = scene.link_scores(&scene.track(no_model));
    let (one_pass, _) = scene.link_scores(&scene.track(tractrac.clone()));
    // TracTrac's default `vid_loop = 2`: forward and backward training passes first.
    let mut tracker = PtvTracker::new(tractrac).unwrap();
    scene.feed(&mut tracker, PassDirection::Forward);
    scene.feed(&mut tracker, PassDirection::Backward);
    let (trained, precision) = scene.link_scores(&scene.feed(&mut tracker, PassDirection::Forward));
    eprintln!(
        "recall: no model {without:.3}, one pass {one_pass:.3}, trained {trained:.3} (precision {precision:.4})"
    );
    assert!(without < 0.25, "{without}");
    assert!(one_pass > 2.0 * without, "{one_pass} vs {without}");
    assert!(trained > 0.9, "{trained}");
    assert!(precision > 0.98, "{precision}");
}

#[test]
fn displacement_voting_tracks_a_rotation_faster_than_the_spacing_in_one_pass() {
    // 1000 particles in a disk of 250 px (spacing ≈ 14 px) at full speed from the first
    // frame: displacement 0.1·r, 12.5 px at the mean radius and 25 px at the edge
    // (p⁻¹ ≈ 0.9–1.8). TracTrac's predictor starts from zero motion and never recovers.
    let scene = rotating(4, 1000, (0.1, 0.0), 20, 1.0, 0);
    let off = PtvParams {
        vote_search_px: VoteSearch::OFF,
        ..Default::default()
    };
    let (tractrac, _) = scene.link_scores(&scene.track(off));
    let voting = PtvParams {
        vote_search_px: VoteSearch::Px(40.0),
        ..Default::default()
    };
    let (recall, precision) = scene.link_scores(&scene.track(voting));
    // The default measures the displacements on the first two frames and votes by itself.
    let (auto_recall, auto_precision) = scene.link_scores(&scene.track(PtvParams::default()));
    eprintln!(
        "TracTrac recall {tractrac:.3}; voting recall {recall:.3}, precision {precision:.4}; \
         automatic {auto_recall:.3}, {auto_precision:.4}"
    );
    assert!(tractrac < 0.5, "{tractrac}");
    // Measured 0.87 (the first frames and the disk's rim, where cells hold few points).
    assert!(recall > 0.85, "{recall}");
    assert!(precision > 0.98, "{precision}");
    assert!(auto_recall > 0.85, "{auto_recall}");
    assert!(auto_precision > 0.98, "{auto_precision}");
}

#[test]
fn an_automatic_vote_that_cannot_resolve_the_flow_is_not_used() {
    // A steady cellular array of vortices (u = U sin kx cos ky, v = −U cos kx sin ky) with
    // cells 70 px across, about one voting cell: displacements up to 5 px (0.36 of the 14 px
    // spacing), enough for the automatic decision to consider the vote, but the flow turns
    // within each voting cell, so most cells find no single peak.
    let (u, k) = (5.0, std::f64::consts::PI / 70.0);
    let path = move |p0: Point2, t: f64| {
        let mut p = p0;
        let steps = (20.0 * t) as usize;
        for _ in 0..steps {
            let v = Vec2::new(
                u * (k * p.x).sin() * (k * p.y).cos(),
                -u * (k * p.x).cos() * (k * p.y).sin(),
            );
            p = p + v * 0.05;
        }
        p
    };
    let scene = Scene::new(9, 400, 12, jittered_lattice(14.0), path, 1.0, 0);
    let mut auto = PtvTracker::new(PtvParams::default()).unwrap();
    let automatic = scene.feed(&mut auto, PassDirection::Forward);
    let share = auto.measured_vote_valid_share().unwrap();
    let displacement = auto.measured_displacement().unwrap();
    eprintln!("valid share {share:.3}, 95 % of displacements within {displacement:.2} px");
    assert!(share < AUTO_VOTE_MIN_VALID_SHARE, "{share}");
    assert!(
        displacement >= AUTO_VOTE_FIRST_LINK_SPACINGS * 14.0,
        "{displacement}"
    );
    assert_eq!(auto.vote_radius(), None);
    // Started from rest, as TracTrac does: the same tracks as with voting off.
    let off = scene.track(PtvParams {
        vote_search_px: VoteSearch::OFF,
        ..Default::default()
    });
    assert!(
        automatic == off,
        "the automatic run differs from the run with voting off"
    );
}

#[test]
fn intermittent_particles_are_rarely_linked_to_others() {
    // 15 % of detections missing in every frame, plus 100 spurious points per frame.
    let scene = rotating(3, 2000, (0.02, 0.0), 30, 0.85, 100);
    let (recall, precision) = scene.link_scores(&scene.track(PtvParams::default()));
    eprintln!("intermittent: recall {recall:.3}, precision {precision:.4}");
    assert!(precision > 0.97, "{precision}");
    assert!(recall > 0.5, "{recall}");
}

#[test]
fn constant_acceleration_kinematics_follow_eqs_6_and_7() {
    let (v, a) = (Vec2::new(2.0, -1.0), Vec2::new(0.1, 0.05));
    for dt in [1.0, 0.5] {
        let scene = Scene::new(
            4,
            20,
            12,
            jittered_lattice(100.0),
            |p, t| p + v * t + a * (0.5 * t * t),
            1.0,
            0,
        );
        let params = PtvParams {
            dt,
            ..Default::default()
        };
        let points = scene.track(params);
        assert_eq!(points.len(), 20 * 10);
        for p in points {
            let t = p.frame as f64;
            let vel = p.vel_px_per_frame.unwrap();
            assert!((vel - (v + a * t) / dt).max_abs() < 1e-9, "{vel:?}");
            assert!((p.acc_px_per_frame2.unwrap() - a / (dt * dt)).max_abs() < 1e-9);
            assert!(p.vel_pred_px_per_frame.is_some() && p.log10_pred_err.is_some());
        }
    }
}

/// Detections of a uniformly moving lattice with ±`noise` px of position error.
fn noisy_translation(vel: Vec2, noise: f64) -> Scene {
    let mut rng = rng_stream(9, 1);
    let mut scene = Scene::new(
        3,
        400,
        20,
        jittered_lattice(50.0),
        |p, t| p + vel * t,
        1.0,
        0,
    );
    for d in scene.frames.iter_mut().flatten() {
        d.pos_px = d.pos_px
            + Vec2::new(
                rng.random_range(-noise..noise),
                rng.random_range(-noise..noise),
            );
    }
    scene
}

#[test]
fn kinematics_fitted_along_trajectories_carry_far_less_position_noise() {
    let vel = Vec2::new(1.5, -0.7);
    let scene = noisy_translation(vel, 0.3);
    let track = |velocity_window: usize, restore_flanked: bool| {
        scene.track(PtvParams {
            velocity_window,
            restore_flanked,
            ..PtvParams::default()
        })
    };
    let window = PtvParams::default().velocity_window;
    let (eq6, fitted) = (track(3, false), track(window, false));
    assert!(eq6.len() > 7000, "{} of 7,200 points", eq6.len());
    // The mean length of `vector` over the points.
    let mean_norm = |points: &[TrackPoint], vector: &dyn Fn(&TrackPoint) -> Vec2| {
        points.iter().map(|p| vector(p).norm()).sum::<f64>() / points.len() as f64
    };
    let velocity_error = move |p: &TrackPoint| p.vel_px_per_frame.unwrap() - vel;
    let (eq6_error, fitted_error) = (
        mean_norm(&eq6, &velocity_error),
        mean_norm(&fitted, &velocity_error),
    );
    // Over seven frames the error's deviation is 2.6× smaller, less at the tracks' ends.
    assert!(
        fitted_error < 0.5 * eq6_error,
        "Eq. 6: {eq6_error:.4} px/frame, fitted: {fitted_error:.4}"
    );
    let acceleration = |p: &TrackPoint| p.acc_px_per_frame2.unwrap();
    let (eq7_error, parabola_error) = (
        mean_norm(&eq6, &acceleration),
        mean_norm(&fitted, &acceleration),
    );
    assert!(
        parabola_error < 0.25 * eq7_error,
        "Eq. 7: {eq7_error:.4} px/frame², fitted: {parabola_error:.4}"
    );
    // Only the kinematics change: the same points, ids and order.
    let key = |p: &TrackPoint| {
        (
            p.frame,
            p.track_id,
            p.pos_px.x.to_bits(),
            p.pos_px.y.to_bits(),
        )
    };
    assert!(eq6.iter().map(key).eq(fitted.iter().map(key)));
    // Restoring the rejected points a trajectory vouches for only adds points.
    let restored = track(window, true);
    let restored_keys: std::collections::HashSet<_> = restored.iter().map(key).collect();
    assert!(fitted.iter().all(|p| restored_keys.contains(&key(p))));
    let fitted_keys: std::collections::HashSet<_> = fitted.iter().map(key).collect();
    let added: Vec<TrackPoint> = restored
        .into_iter()
        .filter(|p| !fitted_keys.contains(&key(p)))
        .collect();
    // In a uniform translation every rejection is the noise's: the points restored are
    // right, their velocities as good as the others'.
    assert!(added.len() > 20, "{} points restored", added.len());
    let added_error = mean_norm(&added, &velocity_error);
    assert!(
        added_error < 0.5 * eq6_error,
        "Eq. 6: {eq6_error:.4} px/frame, restored points: {added_error:.4}"
    );
}

#[test]
fn a_missing_frame_keeps_identities_and_exact_kinematics() {
    // Frame 5 is missing (a skipped bad frame): frame 4 links to frame 6 over two steps.
    let (v, a) = (Vec2::new(2.0, -1.0), Vec2::new(0.1, 0.05));
    let scene = Scene::new(
        5,
        20,
        12,
        jittered_lattice(100.0),
        |p, t| p + v * t + a * (0.5 * t * t),
        1.0,
        0,
    );
    let mut tracker = PtvTracker::new(PtvParams::default()).unwrap();
    let mut points = Vec::new();
    for f in (0..12u64).filter(|&f| f != 5) {
        let obs = FrameObservations::from_detections(f, &scene.frames[f as usize]);
        tracker.step(&obs, &mut points).unwrap();
    }
    tracker.finish(&mut points).unwrap();
    // Every frame but the first, the last and the missing one, each particle once.
    assert_eq!(points.len(), 20 * 9);
    let ids = scene.true_ids();
    let mut track_of: HashMap<u64, u64> = HashMap::new();
    for p in &points {
        assert_ne!(p.frame, 5);
        let truth = ids[&(p.frame, p.pos_px.x.to_bits(), p.pos_px.y.to_bits())];
        assert_eq!(*track_of.entry(truth).or_insert(p.track_id), p.track_id);
        let t = p.frame as f64;
        // The three-point derivatives for unequal steps are exact on a parabola.
        assert!((p.vel_px_per_frame.unwrap() - (v + a * t)).max_abs() < 1e-9);
        assert!((p.acc_px_per_frame2.unwrap() - a).max_abs() < 1e-9);
    }
    assert_eq!(
        track_of.len(),
        20,
        "one identity per particle across the gap"
    );
}

#[test]
fn outlier_filter_rejects_an_injected_wrong_link_and_keeps_the_id() {
    let vel = Vec2::new(1.0, 0.0);
    let mut scene = Scene::new(
        5,
        200,
        12,
        jittered_lattice(50.0),
        |p, t| p + vel * t,
        1.0,
        0,
    );
    // Particle 0 is detected 5 px off its path in frame 6.
    scene.frames[6][0].pos_px = scene.frames[6][0].pos_px + Vec2::new(4.0, 3.0);
    let frames_of_0 = |points: &[TrackPoint]| {
        let ids = scene.true_ids();
        let mut seen: Vec<(u64, u64)> = points
            .iter()
            .filter(|p| ids[&(p.frame, p.pos_px.x.to_bits(), p.pos_px.y.to_bits())] == 0)
            .map(|p| (p.frame, p.track_id))
            .collect();
        seen.sort();
        seen
    };
    let filtered = frames_of_0(&scene.track(PtvParams::default()));
    let frames: Vec<u64> = filtered.iter().map(|s| s.0).collect();
    assert_eq!(
        frames,
        vec![1, 2, 3, 4, 6, 8, 9, 10],
        "frames 5 and 7 link the bad point"
    );
    assert!(
        filtered.iter().all(|s| s.1 == filtered[0].1),
        "one id throughout: {filtered:?}"
    );
    let unfiltered = PtvParams {
        filter: false,
        ..Default::default()
    };
    assert_eq!(frames_of_0(&scene.track(unfiltered)).len(), 10);
}

#[test]
fn output_does_not_depend_on_the_number_of_threads() {
    let scene = rotating(6, 3000, (0.04, 0.0), 12, 0.9, 50);
    let run = |threads: usize, vote_search_px| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let params = PtvParams {
                motion_it: 1,
                vote_search_px,
                ..Default::default()
            };
            scene.track(params)
        })
    };
    for vote_search_px in [VoteSearch::OFF, VoteSearch::Px(20.0), VoteSearch::AUTO] {
        let (one, three) = (run(1, vote_search_px), run(3, vote_search_px));
        assert!(!one.is_empty());
        assert_eq!(format!("{one:?}"), format!("{three:?}"));
    }
}

#[test]
fn empty_and_single_point_frames_do_not_panic() {
    let sizes = [0usize, 1, 0, 1, 1, 2, 0, 0, 3, 1, 1, 1];
    let with_additions = PtvParams {
        vote_search_px: VoteSearch::Px(30.0),
        ambiguity_ratio: Some(0.5),
        ..Default::default()
    };
    for params in [PtvParams::default(), with_additions] {
        let mut tracker = PtvTracker::new(params).unwrap();
        let mut out = Vec::new();
        for (f, &n) in sizes.iter().enumerate() {
            let dets: Vec<Detection> = (0..n)
                .map(|i| Detection::new(Point2::new(10.0 * i as f64 + f as f64, 5.0), 1.0))
                .collect();
            tracker
                .step(
                    &FrameObservations::from_detections(f as u64, &dets),
                    &mut out,
                )
                .unwrap();
        }
        tracker.finish(&mut out).unwrap();
        // Only frames with a point before and after can be the middle of a triplet.
        assert!(out.iter().all(|p| p.frame == 4 || p.frame >= 9), "{out:?}");
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let mut tracker = PtvTracker::new(PtvParams::default()).unwrap();
    let mut out = Vec::new();
    let det = [Detection::new(Point2::new(1.0, 1.0), 1.0)];
    tracker
        .step(&FrameObservations::from_detections(5, &det), &mut out)
        .unwrap();
    let err = tracker
        .step(&FrameObservations::from_detections(3, &det), &mut out)
        .unwrap_err();
    assert!(err.to_string().contains("increasing"), "{err}");
    let nan = [Detection::new(Point2::new(f64::NAN, 1.0), 1.0)];
    let err = tracker
        .step(&FrameObservations::from_detections(6, &nan), &mut out)
        .unwrap_err();
    assert!(err.to_string().contains("frame 6"), "{err}");
}

#[test]
fn params_deserialise_with_defaults_and_errors_name_the_key() {
    let params: PtvParams = serde_json::from_str(r#"{"motion_av": 5, "filter_std": 2.0}"#).unwrap();
    assert_eq!(params.motion_av, 5);
    assert_eq!(params.filter_time, PtvParams::default().filter_time);
    assert!(serde_json::from_str::<PtvParams>(r#"{"motion_avg": 5}"#).is_err());
    let bad = PtvParams {
        filter_time: f64::INFINITY,
        ..Default::default()
    };
    let err = PtvTracker::new(bad).unwrap_err().to_string();
    assert!(err.contains("`filter_time`"), "{err}");
}

#[test]
fn max_displacement_gate_rejects_long_links() {
    let vel = Vec2::new(6.0, 0.0);
    let scene = Scene::new(
        7,
        100,
        8,
        jittered_lattice(100.0),
        |p, t| p + vel * t,
        1.0,
        0,
    );
    let gated = |gate| {
        scene.track(PtvParams {
            max_displacement_px: Some(gate),
            ..Default::default()
        })
    };
    assert!(gated(5.0).is_empty());
    assert_eq!(gated(7.0).len(), 100 * 6);
}

#[test]
fn backward_pass_keeps_forward_velocities() {
    let vel = Vec2::new(1.5, -0.7);
    let scene = Scene::new(
        8,
        100,
        10,
        jittered_lattice(50.0),
        |p, t| p + vel * t,
        1.0,
        0,
    );
    let mut tracker = PtvTracker::new(PtvParams::default()).unwrap();
    scene.feed(&mut tracker, PassDirection::Forward);
    let backward = scene.feed(&mut tracker, PassDirection::Backward);
    assert_eq!(backward.len(), 100 * 8);
    assert!(backward.windows(2).all(|w| w[0].frame >= w[1].frame));
    for p in backward {
        assert!((p.vel_px_per_frame.unwrap() - vel).max_abs() < 1e-9);
        assert!(p.acc_px_per_frame2.unwrap().max_abs() < 1e-9);
    }
}

#[test]
fn training_passes_track_at_least_as_much_as_one_pass() {
    // Faster rotation (p⁻¹ up to ≈ 2.5 at the edge) over few frames: the model needs time.
    let scene = rotating(9, 3000, (0.08, 0.0), 12, 1.0, 0);
    let one_pass = scene.track(PtvParams::default());
    let mut tracker = PtvTracker::new(PtvParams::default()).unwrap();
    scene.feed(&mut tracker, PassDirection::Forward);
    scene.feed(&mut tracker, PassDirection::Backward);
    let trained = scene.feed(&mut tracker, PassDirection::Forward);
    let (r1, p1) = scene.link_scores(&one_pass);
    let (r3, p3) = scene.link_scores(&trained);
    eprintln!(
        "one pass: {} points, recall {r1:.3}, precision {p1:.4}; after training: {} points, recall {r3:.3}, precision {p3:.4}",
        one_pass.len(),
        trained.len()
    );
    assert!(trained.len() >= one_pass.len());
    assert!(r3 >= r1);
}

/// A uniform flow's total displacement at time `t`, px.
type Shift = fn(f64) -> Vec2;

#[test]
fn tracking_resumes_after_the_flow_suddenly_changes() {
    // 400 particles on a 20 px lattice translating uniformly; at frame 10 the flow changes at
    // once (a pump starting or stopping, a shock, the camera knocked). Every tracklet of the
    // new motion is far from the model learned before: the outlier test rejected them all,
    // the model never learned the new motion, and no particle was tracked from the change's
    // fourth frame on (recall 0.46–0.47 with the defaults in every case); now such a frame
    // restarts the test.
    let changes: [(&str, Shift); 5] = [
        ("speeds up 2 → 8 px", |t| {
            Vec2::new(2.0 * t.min(10.0) + 8.0 * (t - 10.0).max(0.0), 0.0)
        }),
        ("stops", |t| Vec2::new(4.0 * t.min(10.0), 0.0)),
        ("reverses", |t| {
            Vec2::new(3.0 * t.min(10.0) - 3.0 * (t - 10.0).max(0.0), 0.0)
        }),
        ("turns", |t| {
            Vec2::new(4.0 * t.min(10.0), 4.0 * (t - 10.0).max(0.0))
        }),
        ("slows down 8 → 2 px", |t| {
            Vec2::new(8.0 * t.min(10.0) + 2.0 * (t - 10.0).max(0.0), 0.0)
        }),
    ];
    for (name, shift) in changes {
        let tracked = track_changing_lattice(name, |p, t| p + shift(t));
        assert!(
            tracked > 390,
            "{name}: {tracked} particles tracked in the last frame"
        );
    }
}

/// Tracks 400 particles of a jittered 20 px lattice moving along `path` over 20 frames with the
/// defaults, asserts link recall > 0.95 and precision > 0.99, and returns how many particles
/// are tracked in the last frame the tracker emits (the one before the sequence's last).
fn track_changing_lattice(name: &str, path: impl Fn(Point2, f64) -> Point2) -> usize {
    let scene = Scene::new(8, 400, 20, jittered_lattice(20.0), path, 1.0, 0);
    let points = scene.track(PtvParams::default());
    let (recall, precision) = scene.link_scores(&points);
    eprintln!("{name}: recall {recall:.3}, precision {precision:.4}");
    assert!(recall > 0.95, "{name}: recall {recall}");
    assert!(precision > 0.99, "{name}: precision {precision}");
    let last = (scene.frames.len() - 2) as u64;
    points.iter().filter(|p| p.frame == last).count()
}

#[test]
fn tracking_resumes_where_a_band_of_the_flow_suddenly_changes() {
    // The same lattice moving 2 px a frame; at frame 10 the particles left of x = 120 (30 %
    // of them) speed up to 8 px a frame. Most of the frame's tracklets still agree with the
    // model, so the frame-wide restart does not fire: the band was never tracked again
    // (recall 0.83 with it alone); its tracklets, rejected together and moving together, are
    // now kept.
    let tracked = track_changing_lattice("band", |p, t| {
        let fast = if p.x < 120.0 { 8.0 } else { 2.0 };
        p + Vec2::new(2.0 * t.min(10.0) + fast * (t - 10.0).max(0.0), 0.0)
    });
    assert!(
        tracked > 360,
        "{tracked} particles tracked in the last frame"
    );
}

/// Tracks `scene` with a fresh tracker as a run does (no `start_pass`, so the warm-up runs).
fn track_fresh(scene: &Scene, params: PtvParams) -> Vec<TrackPoint> {
    let mut tracker = PtvTracker::new(params).unwrap();
    let mut out = Vec::new();
    for (f, detections) in scene.frames.iter().enumerate() {
        let obs = FrameObservations::from_detections(f as u64, detections);
        tracker.step(&obs, &mut out).unwrap();
    }
    tracker.finish(&mut out).unwrap();
    out
}

#[test]
fn a_warm_up_links_the_first_frames_with_the_flow_it_learned() {
    // The rotation of `motion_model_tracks_a_fast_rotation_far_better` (p⁻¹ ≈ 0.6–0.9), 12
    // frames, no voting: from rest the first links fail and the model needs frames to learn.
    let scene = rotating(2, 3000, (0.03, 0.0), 12, 1.0, 0);
    let params = |warm_up_frames| PtvParams {
        vote_search_px: VoteSearch::OFF,
        warm_up_frames,
        ..Default::default()
    };
    let (cold, cold_precision) = scene.link_scores(&track_fresh(&scene, params(0)));
    let warm_points = track_fresh(&scene, params(10));
    let (warm, precision) = scene.link_scores(&warm_points);
    eprintln!(
        "recall (precision): from rest {cold:.3} ({cold_precision:.3}), after a 10-frame \
         warm-up {warm:.3} ({precision:.3})"
    );
    assert!(warm > cold + 0.15, "{warm} vs {cold}");
    assert!(
        precision > cold_precision,
        "{precision} vs {cold_precision}"
    );
    let mut sorted = warm_points.clone();
    sorted.sort_by_key(|p| (p.frame, p.track_id));
    assert_eq!(sorted, warm_points, "frame by frame, in track id order");
    // A sequence shorter than the warm-up is tracked again at its end: the same points as a
    // warm-up over exactly its frames.
    assert_eq!(
        track_fresh(&scene, params(50)),
        track_fresh(&scene, params(12))
    );
    // Training passes replace it: `start_pass` drops a warm-up under way.
    let mut tracker = PtvTracker::new(params(10)).unwrap();
    let trained = scene.feed(&mut tracker, PassDirection::Forward);
    assert_eq!(trained, scene.track(params(0)));
}

/// A Taylor–Green cellular flow, cells `cell` px wide and up to `speed` px/frame: the
/// position at time `t` of the particle starting at `p` (fourth-order Runge–Kutta, 20 steps
/// per frame).
fn cellular_path(cell: f64, speed: f64) -> impl Fn(Point2, f64) -> Point2 {
    let k = std::f64::consts::PI / cell;
    let velocity = move |p: Point2| {
        Vec2::new(
            speed * (k * p.x).sin() * (k * p.y).cos(),
            -speed * (k * p.x).cos() * (k * p.y).sin(),
        )
    };
    move |p0: Point2, t: f64| {
        let steps = (20.0 * t).round() as usize;
        let h = 1.0 / 20.0;
        let mut p = p0;
        for _ in 0..steps {
            let k1 = velocity(p);
            let k2 = velocity(p + k1 * (h / 2.0));
            let k3 = velocity(p + k2 * (h / 2.0));
            let k4 = velocity(p + k3 * h);
            p = p + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        }
        p
    }
}

#[test]
fn predictions_that_follow_the_trajectory_track_small_vortex_cells() {
    // 800 particles 10 px apart in cells 40 px wide turning at up to 4 px per frame: the
    // model's ten neighbours reach across a good part of a cell, whose flow turns within it.
    let scene = Scene::new(
        3,
        800,
        20,
        jittered_lattice(10.0),
        cellular_path(40.0, 4.0),
        1.0,
        0,
    );
    let track = |own_motion: bool| {
        scene.link_scores(&scene.track(PtvParams {
            own_motion,
            ..PtvParams::default()
        }))
    };
    let (model_recall, model_precision) = track(false);
    let (own_recall, own_precision) = track(true);
    eprintln!(
        "model alone: recall {model_recall:.3}, precision {model_precision:.4}; \
         with the trajectories: {own_recall:.3}, {own_precision:.4}"
    );
    // A quarter fewer links missed (measured: 0.924 → 0.949), none more wrong.
    assert!(
        1.0 - own_recall < 0.75 * (1.0 - model_recall),
        "{own_recall} vs {model_recall}"
    );
    assert!(
        own_precision >= model_precision,
        "{own_precision} vs {model_precision}"
    );
}

//! The pedestrian IMM-PF tracker on synthetic scenes with known truth: coloured walkers on a
//! grey ground, seen through the colour / motion / foreground likelihood, and detections
//! alone.

use sillage_core::{BoundingBox, GrayImage, Image, RgbImage};
use sillage_track::immpf::{
    AppearanceParams, BoxSizing, Candidate, FrameCues, ModelName, PedestrianEstimate,
    PedestrianFrame, PedestrianParams, PedestrianTracker,
};

const W: usize = 320;
const H: usize = 200;

/// A walker: foot x at frame 0, foot y, velocity px/frame, top colour, bottom colour.
type Walker = (f64, f64, f64, [u8; 3], [u8; 3]);

/// Two walkers.
const WALKERS: [Walker; 2] = [
    (40.0, 120.0, 2.5, [200, 30, 30], [30, 30, 160]),
    (280.0, 170.0, -2.0, [30, 170, 40], [220, 200, 40]),
];

/// Walker `k`'s box at `frame`; from frame `turn_at` on, the walkers walk back the way they
/// came.
fn truth(frame: usize, k: usize, turn_at: usize) -> BoundingBox {
    let (x, y, v, _, _) = WALKERS[k];
    let out = frame.min(turn_at) as f64;
    let back = frame.saturating_sub(turn_at) as f64;
    BoundingBox::standing_on(
        sillage_core::Point2::new(x + v * (out - back), y),
        16.0,
        48.0,
    )
}

/// The frame's colour image, grey levels and foreground mask.
fn render(frame: usize, turn_at: usize) -> (RgbImage, GrayImage, Image<bool>) {
    let people: Vec<Person> = WALKERS
        .iter()
        .enumerate()
        .map(|(k, walker)| (truth(frame, k, turn_at), walker.3, walker.4))
        .collect();
    render_people(frame, &people, None)
}

/// A person's box, top colour and bottom colour.
type Person = (BoundingBox, [u8; 3], [u8; 3]);

/// The colour image, grey levels and foreground mask of `people` on a textured grey ground,
/// hidden where they stand behind `wall` (its left and right x, px; the full height).
fn render_people(
    frame: usize,
    people: &[Person],
    wall: Option<(usize, usize)>,
) -> (RgbImage, GrayImage, Image<bool>) {
    let mut rgb = RgbImage::from_vec(W, H, vec![[110, 110, 110]; W * H]).unwrap();
    let mut mask = Image::from_vec(W, H, vec![false; W * H]).unwrap();
    // A textured ground, so that a box off the walker does not match it.
    for y in 0..H {
        for x in 0..W {
            if (x / 7 + y / 5) % 4 == 0 {
                rgb.set(x, y, [90, 120, 90]);
            }
        }
    }
    let hidden = |x: usize| wall.is_some_and(|(left, right)| (left..right).contains(&x));
    for &(b, top_colour, bottom_colour) in people {
        for y in b.top_px.ceil() as usize..b.bottom_px().ceil() as usize {
            for x in b.left_px.ceil() as usize..b.right_px().ceil() as usize {
                if x < W && y < H && !hidden(x) {
                    let top = (y as f64) < b.top_px + b.height_px / 2.0;
                    // Legs swing: the lower half flickers with the frame parity.
                    let leg = top || !(x + frame).is_multiple_of(3);
                    if leg {
                        rgb.set(x, y, if top { top_colour } else { bottom_colour });
                        mask.set(x, y, true);
                    }
                }
            }
        }
    }
    let grey = GrayImage::from_vec(
        W,
        H,
        rgb.as_slice()
            .iter()
            .map(|p| {
                (0.299 * f32::from(p[0]) + 0.587 * f32::from(p[1]) + 0.114 * f32::from(p[2]))
                    / 255.0
            })
            .collect(),
    )
    .unwrap();
    (rgb, grey, mask)
}

/// Updates `cues` with a rendered frame, after `previous` (the grey levels of the frame
/// before, replaced by this one's).
fn see(
    cues: &mut FrameCues,
    params: &PedestrianParams,
    (rgb, grey, mask): (RgbImage, GrayImage, Image<bool>),
    previous: &mut Option<GrayImage>,
) {
    cues.update(
        &params.appearance,
        &rgb,
        &grey,
        previous.as_ref(),
        Some(&mask),
    )
    .unwrap();
    *previous = Some(grey);
}

/// Tracks the scene; `blobs_every_frame`: in image mode the walkers' boxes are candidates on
/// every frame (as motion blobs are), not on frame 1 only.
fn run(params: &PedestrianParams, scene: Scene, seed: u64) -> Vec<PedestrianEstimate> {
    let Scene {
        frames,
        images,
        turn_at,
        blobs_every_frame,
    } = scene;
    let mut tracker =
        PedestrianTracker::new(params, BoxSizing::FromCandidate, None, (W, H), seed).unwrap();
    let mut cues = FrameCues::default();
    let mut previous: Option<GrayImage> = None;
    let mut out = Vec::new();
    for frame in 0..frames {
        let candidates: Vec<Candidate> = (0..WALKERS.len())
            .map(|k| Candidate {
                bbox: truth(frame, k, turn_at),
                score: 1.0,
            })
            .collect();
        let cues = if images {
            see(&mut cues, params, render(frame, turn_at), &mut previous);
            Some(&cues)
        } else {
            None
        };
        let observations = PedestrianFrame {
            frame: frame as u64,
            cues,
            // Image mode: the walkers are announced at frame 1 only (births need motion), then
            // the likelihood alone follows them, unless blobs come every frame; detections
            // only: every frame.
            candidates: if images && frame != 1 && !blobs_every_frame {
                &[]
            } else {
                &candidates
            },
            candidates_are_detections: !images,
        };
        tracker.step(&observations, &mut out).unwrap();
    }
    tracker.finish(&mut out);
    out
}

/// What [`run`] tracks.
#[derive(Clone, Copy)]
struct Scene {
    frames: usize,
    images: bool,
    /// Frame from which the walkers walk back (`usize::MAX`: never).
    turn_at: usize,
    blobs_every_frame: bool,
}

impl Scene {
    /// Straight walkers, seen in images (blobs at frame 1 only) or as detections.
    fn straight(frames: usize, images: bool) -> Self {
        Self {
            frames,
            images,
            turn_at: usize::MAX,
            blobs_every_frame: false,
        }
    }
}

/// For each estimate, the walker it covers (IoU ≥ 0.5), and the largest foot error, px.
fn try_check(
    estimates: &[PedestrianEstimate],
    turn_at: usize,
) -> Result<(Vec<(u64, usize)>, f64), String> {
    let mut pairs = Vec::new();
    let mut worst: f64 = 0.0;
    for e in estimates {
        let frame = e.frame as usize;
        let (k, iou) = (0..WALKERS.len())
            .map(|k| (k, e.bbox.iou(&truth(frame, k, turn_at))))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        if iou < 0.5 {
            return Err(format!(
                "frame {frame}: track {} covers no walker (IoU {iou:.2})",
                e.track_id
            ));
        }
        pairs.push((e.track_id, k));
        worst = worst.max((e.bbox.foot() - truth(frame, k, turn_at).foot()).norm());
    }
    pairs.sort_unstable();
    pairs.dedup();
    Ok((pairs, worst))
}

/// As [`try_check`], panicking on a box that covers no walker.
fn check(estimates: &[PedestrianEstimate], turn_at: usize) -> (Vec<(u64, usize)>, f64) {
    try_check(estimates, turn_at).unwrap_or_else(|e| panic!("{e}"))
}

/// Seeds each rate test runs.
const RATE_SEEDS: u64 = 40;

/// Runs `outcome` for seeds 1 to [`RATE_SEEDS`] and asserts that at least `needed` succeed:
/// scenes whose success depends on the random draws (a particle cloud left without
/// measurements) are checked as a rate, not on one seed that happens to pass. Each `needed`
/// is the 1 % point of the binomial at the success rate measured over seeds 1-200 (below
/// it a correct engine fails once in a hundred runs of new streams).
fn assert_success_rate(needed: u64, outcome: impl Fn(u64) -> Result<(), String>) {
    let failures: Vec<String> = (1..=RATE_SEEDS)
        .filter_map(|seed| outcome(seed).err().map(|e| format!("seed {seed}: {e}")))
        .collect();
    let successes = RATE_SEEDS - failures.len() as u64;
    assert!(
        successes >= needed,
        "{successes} of {RATE_SEEDS} seeds succeed, {needed} needed: {failures:#?}"
    );
}

/// Two walkers born on frame 1 and followed for 39 frames on colour and motion alone. Over
/// seeds 1-200 the engine of 2026-11-29 (ziggurat normals) succeeded on 129, the block
/// Box–Muller engine that replaced it on 140 (rate ≈ 0.67): 20 of 40 needed (≈ 27 expected).
#[test]
fn colour_and_motion_follow_two_walkers_with_one_identity_each() {
    let mut params = PedestrianParams {
        models: ModelName::parse_combination("CV_CA").unwrap(),
        appearance: AppearanceParams {
            stride: 1,
            ..Default::default()
        },
        ..Default::default()
    };
    // Every walker is born on frame 1 and never supported by a blob again.
    params.unsupported_frames = 1000;
    assert_success_rate(20, |seed| {
        let estimates = run(&params, Scene::straight(40, true), seed);
        let (pairs, worst) = try_check(&estimates, usize::MAX)?;
        if pairs != [(1, 0), (2, 1)] {
            return Err(format!(
                "tracks and walkers {pairs:?}: one track per walker expected"
            ));
        }
        if worst >= 6.0 {
            return Err(format!("largest foot error {worst:.2} px"));
        }
        let last = estimates.iter().filter(|e| e.frame == 39).count();
        if last != 2 {
            return Err(format!(
                "{last} walkers followed at the last frame, 2 expected"
            ));
        }
        // Walkers in straight lines: constant velocity carries most of the weight.
        let cv_share: f64 = estimates
            .iter()
            .filter(|e| e.frame == 39)
            .map(|e| e.model_weights[0])
            .sum::<f64>()
            / 2.0;
        if cv_share <= 0.3 {
            return Err(format!("CV weight {cv_share:.2}"));
        }
        Ok(())
    });
}

#[test]
fn detections_alone_keep_identities_and_runs_repeat_with_the_seed() {
    let params = PedestrianParams::default();
    let scene = Scene::straight(30, false);
    let estimates = run(&params, scene, 5);
    let (pairs, worst) = check(&estimates, usize::MAX);
    assert_eq!(pairs, [(1, 0), (2, 1)]);
    assert!(worst < 4.0, "largest foot error {worst:.2} px");
    assert_eq!(estimates, run(&params, scene, 5));
    assert_ne!(estimates, run(&params, scene, 6));
}

#[test]
fn frames_out_of_order_and_bad_parameters_are_refused() {
    let mut tracker = PedestrianTracker::new(
        &PedestrianParams::default(),
        BoxSizing::FromCandidate,
        None,
        (W, H),
        1,
    )
    .unwrap();
    let frame = |frame| PedestrianFrame {
        frame,
        cues: None,
        candidates: &[],
        candidates_are_detections: true,
    };
    let mut out = Vec::new();
    tracker.step(&frame(3), &mut out).unwrap();
    let err = tracker.step(&frame(3), &mut out).unwrap_err().to_string();
    assert!(err.contains("increasing order"), "{err}");
    let bad = PedestrianParams {
        birth_overlap: 1.5,
        ..Default::default()
    };
    let err = PedestrianTracker::new(&bad, BoxSizing::FromCandidate, None, (W, H), 1)
        .unwrap_err()
        .to_string();
    assert!(err.contains("birth_overlap"), "{err}");
    for (growth, max, key) in [
        (-0.1, 1.5, "revive_gate_growth"),
        (f64::NAN, 1.5, "revive_gate_growth"),
        (0.1, 0.3, "revive_gate_max"),
    ] {
        let bad = PedestrianParams {
            revive_gate_growth: growth,
            revive_gate_max: max,
            ..Default::default()
        };
        let err = PedestrianTracker::new(&bad, BoxSizing::FromCandidate, None, (W, H), 1)
            .unwrap_err()
            .to_string();
        assert!(err.contains(key), "{growth}, {max}: {err}");
    }
    for smooth in [-1.0, f64::NAN, 1e6] {
        let mut bad = PedestrianParams::default();
        bad.detection.smooth_frames = smooth;
        let err = PedestrianTracker::new(&bad, BoxSizing::FromCandidate, None, (W, H), 1)
            .unwrap_err()
            .to_string();
        assert!(err.contains("detection.smooth_frames"), "{smooth}: {err}");
    }
    let mut bad = PedestrianParams::default();
    bad.proposal.share = f64::NAN;
    let err = PedestrianTracker::new(&bad, BoxSizing::FromCandidate, None, (W, H), 1)
        .unwrap_err()
        .to_string();
    assert!(err.contains("proposal.share"), "{err}");
    for (rate, gate) in [(1.5, -3.0), (-0.1, -3.0), (0.05, f64::NAN), (0.05, 2.0)] {
        let mut bad = PedestrianParams::default();
        bad.appearance.adapt_rate = rate;
        bad.appearance.adapt_min_log_likelihood = gate;
        let err = PedestrianTracker::new(&bad, BoxSizing::FromCandidate, None, (W, H), 1)
            .unwrap_err()
            .to_string();
        assert!(err.contains("appearance.adapt_"), "{rate}, {gate}: {err}");
    }
    let mp = PedestrianParams {
        models: vec![ModelName::Mp],
        ..Default::default()
    };
    let err = PedestrianTracker::new(&mp, BoxSizing::FromCandidate, None, (W, H), 1)
        .unwrap_err()
        .to_string();
    assert!(err.contains("motion prior"), "{err}");
}

/// Mean foot error, px, of the estimates of frames `from..`, each against the walker it
/// covers.
fn mean_foot_error(estimates: &[PedestrianEstimate], from: usize, turn_at: usize) -> f64 {
    let errors: Vec<f64> = estimates
        .iter()
        .filter(|e| e.frame as usize >= from)
        .map(|e| {
            let frame = e.frame as usize;
            (0..WALKERS.len())
                .map(|k| (e.bbox.foot() - truth(frame, k, turn_at).foot()).norm())
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    errors.iter().sum::<f64>() / errors.len().max(1) as f64
}

#[test]
fn blob_proposals_keep_boxes_on_walkers_that_turn_back() {
    let scene = Scene {
        frames: 30,
        images: true,
        turn_at: 15,
        blobs_every_frame: true,
    };
    // The box lags behind a walker that turns until the velocity particles catch up; blob
    // proposals put hypotheses where the walker is at once. With the paper's fixed colour
    // reference no seed is worse with them; with the adapted reference (the default) they
    // still help on average, but the reference learnt from a lagging box makes single seeds
    // noisier (seed 6: 1.9 px with, 1.4 px without).
    let fixed_reference = {
        let mut p = PedestrianParams::default();
        p.appearance.adapt_rate = 0.0;
        p
    };
    for (with, every_seed) in [
        (fixed_reference, true),
        (PedestrianParams::default(), false),
    ] {
        let mut without = with.clone();
        without.proposal.share = 0.0;
        let (mut sum_with, mut sum_without) = (0.0, 0.0);
        for seed in 1..=6 {
            let e_with = mean_foot_error(&run(&with, scene, seed), 15, 15);
            let e_without = mean_foot_error(&run(&without, scene, seed), 15, 15);
            assert!(
                !every_seed || e_with <= 1.1 * e_without,
                "seed {seed}: {e_with:.2} px with proposals, {e_without:.2} px without"
            );
            sum_with += e_with;
            sum_without += e_without;
        }
        assert!(
            sum_with < 0.7 * sum_without,
            "adapt_rate {}: mean foot error after the turn: {:.2} px with proposals, {:.2} px \
             without",
            with.appearance.adapt_rate,
            sum_with / 6.0,
            sum_without / 6.0
        );
    }
}

/// Two people crossing on one row, seen as detections only: through the frames where their
/// boxes overlap, the assignment on IoU with the predicted boxes keeps each detection with
/// its tracker: the scene keeps two identities.
#[test]
fn a_tracker_lost_as_a_duplicate_at_a_crossing_gives_its_identity_back() {
    let params = PedestrianParams::default();
    for seed in 1..=3 {
        let mut tracker =
            PedestrianTracker::new(&params, BoxSizing::FromCandidate, None, (W, H), seed).unwrap();
        let mut out = Vec::new();
        for frame in 0..60u64 {
            let f = frame as f64;
            let candidates = [60.0 + 3.0 * f, 240.0 - 3.0 * f].map(|x| Candidate {
                bbox: BoundingBox::standing_on(sillage_core::Point2::new(x, 150.0), 16.0, 48.0),
                score: 1.0,
            });
            let observations = PedestrianFrame {
                frame,
                cues: None,
                candidates: &candidates,
                candidates_are_detections: true,
            };
            tracker.step(&observations, &mut out).unwrap();
        }
        tracker.finish(&mut out);
        let mut ids: Vec<u64> = out.iter().map(|e| e.track_id).collect();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), 2, "seed {seed}: identities {ids:?}");
        assert!(
            out.iter().any(|e| e.frame == 59),
            "seed {seed}: tracked to the end"
        );
    }
}

/// A walker who speeds up behind a wall, seen in images: its tracker dies while it is
/// hidden, with a velocity spoilt by the partial occlusion (−1.7 to 8 px a frame over seeds
/// 1-8, against 2 then 5), and the walker comes out 36-69 px (0.8-1.4 heights) from where
/// it was heading, 12 frames later. The revival gate that widens with the time since the
/// death gives it its identity back; half a height, fixed, does not.
#[test]
fn a_walker_who_speeds_up_behind_a_wall_keeps_its_identity() {
    const WALL: (usize, usize) = (130, 180);
    const HEIGHT: f64 = 48.0;
    // 2 px a frame up to the wall, 5 px a frame from x = 140 on.
    let foot_x = |frame: usize| {
        let x = 40.0 + 2.0 * frame as f64;
        if x <= 140.0 {
            x
        } else {
            140.0 + 5.0 * (frame as f64 - 50.0)
        }
    };
    let identities = |params: &PedestrianParams, seed: u64| {
        let mut tracker =
            PedestrianTracker::new(params, BoxSizing::FromCandidate, None, (W, H), seed).unwrap();
        let mut cues = FrameCues::default();
        let mut previous: Option<GrayImage> = None;
        let mut out = Vec::new();
        for frame in 0..80 {
            let b = BoundingBox::standing_on(
                sillage_core::Point2::new(foot_x(frame), 150.0),
                16.0,
                HEIGHT,
            );
            let person = (b, [200, 30, 30], [30, 30, 160]);
            see(
                &mut cues,
                params,
                render_people(frame, &[person], Some(WALL)),
                &mut previous,
            );
            // A motion blob on the walker while at least three quarters of it shows.
            let (wall_left, wall_right) = (WALL.0 as f64, WALL.1 as f64);
            let hidden = (b.right_px().min(wall_right) - b.left_px.max(wall_left)).max(0.0);
            let candidates: Vec<Candidate> = (hidden <= 0.25 * b.width_px)
                .then_some(Candidate {
                    bbox: b,
                    score: 1.0,
                })
                .into_iter()
                .collect();
            let observations = PedestrianFrame {
                frame: frame as u64,
                cues: Some(&cues),
                candidates: &candidates,
                candidates_are_detections: false,
            };
            tracker.step(&observations, &mut out).unwrap();
        }
        let mut ids: Vec<u64> = out.iter().map(|e| e.track_id).collect();
        ids.sort_unstable();
        ids.dedup();
        let last = out.iter().filter(|e| e.frame == 79).count();
        (ids, last)
    };
    let fixed = PedestrianParams {
        revive_gate_growth: 0.0,
        ..Default::default()
    };
    for seed in 1..=3 {
        let (ids, last) = identities(&PedestrianParams::default(), seed);
        assert_eq!(
            last, 1,
            "seed {seed}: the walker is followed after the wall"
        );
        assert_eq!(ids.len(), 1, "seed {seed}: identities {ids:?}");
        let (ids, _) = identities(&fixed, seed);
        assert_eq!(ids.len(), 2, "seed {seed}, fixed gate: identities {ids:?}");
    }
}

/// Detections-only frames `0..frames`: `boxes(frame)` gives (foot x, foot y, score) of the
/// frame's detections, 16 × 48 px each. Returns every estimate reported.
fn on_detections(
    params: &PedestrianParams,
    frames: u64,
    boxes: impl Fn(u64) -> Vec<(f64, f64, f64)>,
) -> Vec<PedestrianEstimate> {
    on_detections_seeded(params, frames, boxes, 1)
}

/// [`on_detections`] with the particles' seed.
fn on_detections_seeded(
    params: &PedestrianParams,
    frames: u64,
    boxes: impl Fn(u64) -> Vec<(f64, f64, f64)>,
    seed: u64,
) -> Vec<PedestrianEstimate> {
    let sized = |frame| {
        boxes(frame)
            .into_iter()
            .map(|(x, y, score)| {
                let foot = sillage_core::Point2::new(x, y);
                Candidate {
                    bbox: BoundingBox::standing_on(foot, 16.0, 48.0),
                    score,
                }
            })
            .collect()
    };
    on_candidates(params, frames, sized, seed)
}

/// Detections-only frames `0..frames` of the candidates `candidates(frame)`, particles seeded
/// with `seed`. Returns every estimate reported.
fn on_candidates(
    params: &PedestrianParams,
    frames: u64,
    candidates: impl Fn(u64) -> Vec<Candidate>,
    seed: u64,
) -> Vec<PedestrianEstimate> {
    let (mut tracker, mut out) = stepped_on_candidates(params, frames, candidates, seed);
    tracker.finish(&mut out);
    out
}

/// [`on_candidates`] before `finish`: the tracker, and the estimates its steps wrote.
fn stepped_on_candidates(
    params: &PedestrianParams,
    frames: u64,
    candidates: impl Fn(u64) -> Vec<Candidate>,
    seed: u64,
) -> (PedestrianTracker, Vec<PedestrianEstimate>) {
    let mut tracker =
        PedestrianTracker::new(params, BoxSizing::FromCandidate, None, (W, H), seed).unwrap();
    let mut out = Vec::new();
    for frame in 0..frames {
        let candidates = candidates(frame);
        let observations = PedestrianFrame {
            frame,
            cues: None,
            candidates: &candidates,
            candidates_are_detections: true,
        };
        tracker.step(&observations, &mut out).unwrap();
    }
    (tracker, out)
}

fn identities(estimates: &[PedestrianEstimate]) -> Vec<u64> {
    let mut ids: Vec<u64> = estimates.iter().map(|e| e.track_id).collect();
    ids.sort_unstable();
    ids.dedup();
    ids
}

/// On detections alone a tracker is reported once `min_hits` (here 3) detections in a row
/// held it, from that frame on: a walker from frame 2, and false detections of one or two
/// frames never; with `report_first_hits` the walker's first two frames too.
#[test]
fn detections_alone_report_a_tracker_after_three_matches_in_a_row() {
    let walker = |f: u64| (40.0 + 2.0 * f as f64, 120.0, 0.9);
    let scene = |f: u64| {
        let mut boxes = vec![walker(f)];
        if f == 10 || f == 20 || f == 21 {
            boxes.push((250.0, 60.0, 0.9));
        }
        boxes
    };
    let mut params = PedestrianParams::default();
    params.detection.min_hits = 3;
    params.detection.report_first_hits = false;
    let out = on_detections(&params, 40, scene);
    assert_eq!(identities(&out).len(), 1, "{:?}", identities(&out));
    assert_eq!(out.iter().map(|e| e.frame).min(), Some(2));
    assert_eq!(out.len(), 38);
    params.detection.report_first_hits = true;
    let out = on_detections(&params, 40, scene);
    assert_eq!(out.iter().map(|e| e.frame).min(), Some(0));
    assert_eq!(out.len(), 40);
    // A false streak as long as `min_hits` is reported, one shorter is not.
    params.detection.min_hits = 2;
    assert_eq!(identities(&on_detections(&params, 40, scene)).len(), 2);
}

/// A walker the detector misses for 10 frames keeps its identity within `lost_frames` = 30:
/// its tracker coasts on its velocity, unreported, and takes the detection back; with
/// `lost_frames` = 5 the walker comes back under a new identity.
#[test]
fn a_walker_missed_for_ten_frames_keeps_its_identity() {
    let scene = |f: u64| {
        if (20..30).contains(&f) {
            Vec::new()
        } else {
            vec![(40.0 + 2.0 * f as f64, 120.0, 0.9)]
        }
    };
    let mut params = PedestrianParams::default();
    params.detection.lost_frames = 30;
    params.detection.fill_gaps = 0;
    let out = on_detections(&params, 60, scene);
    assert_eq!(identities(&out).len(), 1, "{:?}", identities(&out));
    // Unreported while missed; re-confirmed after `min_hits` new matches, frames 30 on then
    // reported with `report_first_hits`, from frame 29 + `min_hits` without.
    let hits = params.detection.min_hits as u64;
    let first_back = if params.detection.report_first_hits {
        30
    } else {
        29 + hits
    };
    assert!(out.iter().all(|e| !(20..first_back).contains(&e.frame)));
    assert!(out.iter().any(|e| e.frame == first_back));
    assert!(out.iter().any(|e| e.frame == 59));
    let short = PedestrianParams {
        detection: sillage_track::immpf::DetectionLikelihoodParams {
            lost_frames: 5,
            ..params.detection.clone()
        },
        ..params
    };
    assert_eq!(identities(&on_detections(&short, 60, scene)).len(), 2);
}

/// With `fill_gaps` at least as long as the 10 missed frames, the walker of
/// [`a_walker_missed_for_ten_frames_keeps_its_identity`] is reported on every frame, once, the
/// missed ones on the line between its boxes before and after the gap; a shorter `fill_gaps`
/// leaves the gap empty.
#[test]
fn a_gap_no_longer_than_fill_gaps_is_reported_interpolated() {
    let walker_x = |f: u64| 40.0 + 2.0 * f as f64;
    let scene = |f: u64| {
        if (20..30).contains(&f) {
            Vec::new()
        } else {
            vec![(walker_x(f), 120.0, 0.9)]
        }
    };
    let mut params = PedestrianParams::default();
    params.detection.lost_frames = 30;
    params.detection.fill_gaps = 10;
    // The boxes as interpolated, before any smoothing (tested on its own below).
    params.detection.smooth_frames = 0.0;
    let out = on_detections(&params, 60, scene);
    assert_eq!(identities(&out).len(), 1, "{:?}", identities(&out));
    let mut frames: Vec<u64> = out.iter().map(|e| e.frame).collect();
    frames.sort_unstable();
    assert_eq!(frames, (0..60).collect::<Vec<u64>>());
    let at = |f: u64| out.iter().find(|e| e.frame == f).unwrap();
    for f in 20..30 {
        let (before, after, filled) = (at(19), at(30), at(f));
        let s = (f - 19) as f64 / 11.0;
        let expected_left = before.bbox.left_px + s * (after.bbox.left_px - before.bbox.left_px);
        assert!(
            (filled.bbox.left_px - expected_left).abs() < 1e-9,
            "frame {f}"
        );
        let foot = filled.bbox.foot();
        assert!(
            (foot.x - walker_x(f)).abs() < 3.0,
            "frame {f}: foot {foot:?}"
        );
        assert!((foot.y - 120.0).abs() < 3.0, "frame {f}: foot {foot:?}");
        assert!((filled.vel_px_per_frame.x - 2.0).abs() < 0.5, "frame {f}");
    }
    params.detection.fill_gaps = 9;
    let out = on_detections(&params, 60, scene);
    assert!(out.iter().all(|e| !(20..30).contains(&e.frame)));
}

/// A walker at 2 px a frame whose detections jitter by up to 3 px: with `smooth_frames` the
/// reported boxes are written a few frames late, every frame exactly once (the last ones by
/// `finish`), and their foot points lie closer to the walker than without.
#[test]
fn smoothed_boxes_are_written_once_each_and_closer_to_a_jittered_walker() {
    let walker_x = |f: u64| 40.0 + 2.0 * f as f64;
    let jitter = |f: u64| 3.0 * (2.3 * f as f64).sin();
    let scene = |f: u64| vec![(walker_x(f) + jitter(f), 120.0, 0.9)];
    let error = |smooth_frames: f64| {
        let mut params = PedestrianParams::default();
        params.detection.smooth_frames = smooth_frames;
        let out = on_detections(&params, 60, scene);
        let mut frames: Vec<u64> = out.iter().map(|e| e.frame).collect();
        frames.sort_unstable();
        assert_eq!(frames, (0..60).collect::<Vec<u64>>(), "σ {smooth_frames}");
        let errors: Vec<f64> = out
            .iter()
            .filter(|e| (5..55).contains(&e.frame))
            .map(|e| (e.bbox.foot().x - walker_x(e.frame)).abs())
            .collect();
        errors.iter().sum::<f64>() / errors.len() as f64
    };
    let (raw, smoothed) = (error(0.0), error(2.0));
    assert!(
        smoothed < 0.7 * raw,
        "mean foot error {smoothed} px against {raw} px"
    );
    // Written late: at frame 30 of a walker held every frame, the last frame written is 26.
    let mut params = PedestrianParams::default();
    params.detection.smooth_frames = 2.0;
    assert_eq!(params.detection.smoothing_lag_frames(), 4);
    let candidates = |f: u64| {
        scene(f)
            .into_iter()
            .map(|(x, y, score)| Candidate {
                bbox: BoundingBox::standing_on(sillage_core::Point2::new(x, y), 16.0, 48.0),
                score,
            })
            .collect()
    };
    let (mut tracker, mut out) = stepped_on_candidates(&params, 31, candidates, 1);
    assert_eq!(out.iter().map(|e| e.frame).max(), Some(26));
    tracker.finish(&mut out);
    assert_eq!(out.iter().map(|e| e.frame).max(), Some(30));
}

/// A walker coming towards the camera, its box 3.5 px taller every frame, missed for 21 frames
/// (20-40): its tracker's box keeps growing at the detections' rate while it coasts and takes
/// the walker back (one identity on ≈ 87 % of seeds); with the size frozen (`size_rate` false) the
/// coasting box is a quarter of the returning detection's area, under the IoU gate, and the
/// walker comes back under a new identity.
#[test]
fn a_walker_coming_closer_while_missed_is_taken_back_at_its_new_size() {
    let scene = |f: u64| {
        if (20..41).contains(&f) {
            return Vec::new();
        }
        let height = 20.0 + 3.5 * f as f64;
        let foot = sillage_core::Point2::new(150.0, 60.0 + 2.5 * f as f64);
        let bbox = BoundingBox::standing_on(foot, height / 3.0, height);
        vec![Candidate { bbox, score: 0.9 }]
    };
    let params = PedestrianParams::default();
    assert!(params.detection.size_rate && params.detection.lost_frames > 21);
    let mut frozen = params.clone();
    frozen.detection.size_rate = false;
    // Over seeds 1-200 the walker came back as one identity for 177 (ziggurat engine of
    // 2026-11-29) and 174 (block Box–Muller engine) seeds (rate ≈ 0.87): 30 of 40 needed
    // (≈ 35 expected).
    assert_success_rate(30, |seed| {
        let out = on_candidates(&params, 50, scene, seed);
        if identities(&out).len() != 1 {
            return Err(format!("identities {:?}", identities(&out)));
        }
        if !out.iter().any(|e| e.frame == 49) {
            return Err("not reported again".into());
        }
        Ok(())
    });
    // Without the size rate the walker's new size is never matched: a second identity.
    for seed in 1..=3 {
        let out = on_candidates(&frozen, 50, scene, seed);
        assert_eq!(identities(&out).len(), 2, "seed {seed}, frozen size");
    }
}

/// Weak detections (score below `high_score`) hold a tracker a detection held in the
/// previous frame — a person partly hidden keeps being reported — and start no tracker.
#[test]
fn weak_detections_hold_a_tracked_walker_and_start_none() {
    let scene = |f: u64| {
        let score = if (15..25).contains(&f) { 0.3 } else { 0.9 };
        vec![(40.0 + 2.0 * f as f64, 120.0, score), (250.0, 60.0, 0.3)]
    };
    let out = on_detections(&PedestrianParams::default(), 40, scene);
    assert_eq!(identities(&out).len(), 1, "{:?}", identities(&out));
    assert!((15..25).all(|f| out.iter().any(|e| e.frame == f)));
    assert!(out.iter().all(|e| e.bbox.foot().x < 200.0));
}

/// A walker detected every frame at 8 px a frame, its box 16 px wide: the particles, born
/// at rest, take the walker's velocity from its first two detections and keep it (one
/// identity, reported from its third detection, every seed); without that proposal the predicted box
/// falls behind the detections and the walker's track breaks up (measured: 5 of 5 seeds).
#[test]
fn the_first_two_detections_give_a_fast_walker_its_velocity() {
    let scene = |f: u64| vec![(20.0 + 8.0 * f as f64, 120.0, 0.9)];
    let mut params = PedestrianParams::default();
    params.detection.min_hits = 3;
    params.detection.report_first_hits = false;
    let mut still = params.clone();
    still.detection.velocity_proposal = false;
    let mut broken = 0;
    for seed in 1..=5 {
        let out = on_detections_seeded(&params, 20, scene, seed);
        assert_eq!(
            identities(&out).len(),
            1,
            "seed {seed}: {:?}",
            identities(&out)
        );
        assert_eq!(out.len(), 18, "seed {seed}");
        let out = on_detections_seeded(&still, 20, scene, seed);
        if out.len() < 18 || identities(&out).len() > 1 {
            broken += 1;
        }
    }
    assert!(
        broken >= 3,
        "{broken} of 5 seeds broke up without the proposal"
    );
}

/// Foot x of walker `k` of a meeting: they walk face to face at 3 px a frame until frame 19,
/// 6 px apart (the second hiding most of the first), then walk back the way they came.
fn meeting_x(k: usize, frame: usize) -> f64 {
    let (start, v) = [(100.0, 3.0), (220.0, -3.0)][k];
    let t = frame.min(19) as f64 - frame.saturating_sub(19) as f64;
    start + v * t
}

/// The meeting's two walkers (red over blue, green over yellow), foot y 150, 16 × 48 px.
fn meeting_person(k: usize, frame: usize) -> Person {
    let b = BoundingBox::standing_on(
        sillage_core::Point2::new(meeting_x(k, frame), 150.0),
        16.0,
        48.0,
    );
    let (_, _, _, top, bottom) = WALKERS[k];
    (b, top, bottom)
}

/// The meeting tracked on its rendered frames with both walkers' boxes as detections on
/// every frame (`with_frames`), or on the detections alone.
fn meeting(params: &PedestrianParams, with_frames: bool, seed: u64) -> Vec<PedestrianEstimate> {
    let mut tracker =
        PedestrianTracker::new(params, BoxSizing::FromCandidate, None, (W, H), seed).unwrap();
    let (mut cues, mut previous, mut out) = (FrameCues::default(), None, Vec::new());
    for frame in 0..40 {
        let people = [meeting_person(0, frame), meeting_person(1, frame)];
        see(
            &mut cues,
            params,
            render_people(frame, &people, None),
            &mut previous,
        );
        let candidates: Vec<Candidate> = people
            .iter()
            .map(|&(bbox, _, _)| Candidate { bbox, score: 1.0 })
            .collect();
        let observations = PedestrianFrame {
            frame: frame as u64,
            cues: with_frames.then_some(&cues),
            candidates: &candidates,
            candidates_are_detections: true,
        };
        tracker.step(&observations, &mut out).unwrap();
    }
    tracker.finish(&mut out);
    out
}

/// (track, walker) pairs of the meeting's estimates away from the meeting itself (frames
/// 16-24, where the boxes overlap), each estimate's walker by IoU ≥ 0.5.
fn meeting_identities(estimates: &[PedestrianEstimate]) -> Vec<(u64, usize)> {
    let mut pairs: Vec<(u64, usize)> = estimates
        .iter()
        .filter(|e| !(16..=24).contains(&e.frame))
        .filter_map(|e| {
            (0..2)
                .find(|&k| e.bbox.iou(&meeting_person(k, e.frame as usize).0) >= 0.5)
                .map(|k| (e.track_id, k))
        })
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// Detections beside frames drive the trackers as detections alone do: with the colour
/// weight set to 0 the frames change nothing, estimate for estimate.
#[test]
fn detections_beside_frames_track_as_detections_alone_without_colour() {
    let mut params = PedestrianParams::default();
    params.detection.colour_weight = 0.0;
    assert_eq!(meeting(&params, true, 4), meeting(&params, false, 4));
}

/// Two walkers meet face to face and walk back: the predicted boxes carry on into each
/// other, and the first detections after the turn overlap both equally, so on IoU alone the
/// identities swap for some seeds; with the colour distance in the assignment (weight 1, or
/// the default) each tracker keeps its own walker for every seed.
#[test]
fn colour_in_the_assignment_keeps_identities_when_walkers_meet_and_turn_back() {
    let mut params = PedestrianParams::default();
    let default_weight = params.detection.colour_weight;
    assert!(default_weight > 0.0);
    params.detection.min_hits = 3;
    params.detection.colour_weight = 0.0;
    let own = [(1, 0), (2, 1)];
    let swapped = (1..=6)
        .filter(|&seed| meeting_identities(&meeting(&params, true, seed)) != own)
        .count();
    assert!(swapped > 0, "on IoU alone no seed of six swapped");
    for weight in [1.0, default_weight] {
        params.detection.colour_weight = weight;
        for seed in 1..=6 {
            let pairs = meeting_identities(&meeting(&params, true, seed));
            assert_eq!(pairs, own, "weight {weight}, seed {seed}");
        }
    }
}

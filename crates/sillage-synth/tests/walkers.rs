//! The walkers sequence against its own truth (crossing, group split, determinism) and
//! through the motion detector the SIFT-PF tracker starts from
//! (`sillage_detect::motion::MotionDetector`, default parameters).

use sillage_core::BoundingBox;
use sillage_detect::motion::{MotionBlob, MotionDetector, MotionParams};
use sillage_eval::mot::box_iou;
use sillage_synth::{
    CrossingParams, GroupSplitParams, RandomParams, Scenario, WalkerTruth, WalkersFrame,
    WalkersParams, WalkersSequence,
};

fn frames(params: WalkersParams) -> Vec<WalkersFrame> {
    WalkersSequence::new(params).unwrap().collect()
}

fn crossing(occlusion_frames: usize, speed: f64) -> WalkersParams {
    WalkersParams {
        scenario: Scenario::Crossing(CrossingParams {
            occlusion_frames,
            speed_px_per_frame: speed,
            ..Default::default()
        }),
        ..Default::default()
    }
}

fn group_split() -> WalkersParams {
    WalkersParams {
        scenario: Scenario::GroupSplit(GroupSplitParams::default()),
        ..Default::default()
    }
}

/// The truth of walker `id` in `frame`, if listed.
fn walker(frame: &WalkersFrame, id: u64) -> Option<&WalkerTruth> {
    frame.truth.iter().find(|t| t.id == id)
}

/// A truth box as the metrics see it.
fn truth_box(t: &WalkerTruth) -> BoundingBox {
    BoundingBox {
        left_px: t.left_px,
        top_px: t.top_px,
        width_px: t.width_px,
        height_px: t.height_px,
    }
}

/// A blob's pixel box in the truth's coordinates (pixel `k` spans `[k − 0.5, k + 0.5]`).
fn blob_box(blob: &MotionBlob) -> BoundingBox {
    BoundingBox {
        left_px: blob.bbox.x0 as f64 - 0.5,
        top_px: blob.bbox.y0 as f64 - 0.5,
        width_px: blob.bbox.width() as f64,
        height_px: blob.bbox.height() as f64,
    }
}

/// Gap between two boxes, px: the larger of the horizontal and vertical gaps (≤ 0 when
/// they touch or overlap).
fn gap(a: &BoundingBox, b: &BoundingBox) -> f64 {
    let horizontal =
        (a.left_px - (b.left_px + b.width_px)).max(b.left_px - (a.left_px + a.width_px));
    let vertical = (a.top_px - (b.top_px + b.height_px)).max(b.top_px - (a.top_px + a.height_px));
    horizontal.max(vertical)
}

/// Longest run of consecutive frames where walker `id` is listed with visibility 0.
fn longest_hidden_run(frames: &[WalkersFrame], id: u64) -> usize {
    let (mut best, mut run) = (0, 0);
    for frame in frames {
        if walker(frame, id).is_some_and(|t| t.visibility == 0.0) {
            run += 1;
            best = best.max(run);
        } else {
            run = 0;
        }
    }
    best
}

#[test]
fn crossing_hides_the_far_walker_completely_for_the_asked_frames() {
    for (occlusion, speed) in [(5, 1.0), (8, 1.5), (3, 2.0)] {
        let params = crossing(occlusion, speed);
        let frames = frames(params.clone());
        let run = longest_hidden_run(&frames, 1);
        assert!(
            run >= occlusion,
            "occlusion {occlusion}, speed {speed}: hidden {run} frames"
        );
        // Not much longer either: the near walker is sized for it (one or two frames more).
        assert!(
            run <= occlusion + 3,
            "occlusion {occlusion}: hidden {run} frames"
        );
        // Fully visible well before and after the crossing (frame warm-up + 60).
        let middle = params.warmup_frames + 60;
        for frame in &frames[params.warmup_frames..params.n_frames] {
            let far = walker(frame, 1).unwrap();
            let near = walker(frame, 2).unwrap();
            let apart = (frame.index as i64 - middle as i64).unsigned_abs() as f64 * 2.0 * speed
                > 0.5 * (far.width_px + near.width_px) + 1.0;
            let inside = |t: &WalkerTruth| {
                t.left_px >= -0.5 && t.left_px + t.width_px <= params.width as f64 - 0.5
            };
            if apart && inside(far) {
                assert_eq!(far.visibility, 1.0, "frame {}", frame.index);
            }
            if inside(near) {
                assert_eq!(near.visibility, 1.0, "the near walker is never covered");
            }
            assert!(near.depth < far.depth);
        }
    }
}

#[test]
fn crossing_walkers_move_at_the_stated_speed() {
    let params = crossing(5, 1.5);
    let frames = frames(params.clone());
    assert!(
        frames[..params.warmup_frames]
            .iter()
            .all(|f| f.truth.is_empty())
    );
    for pair in frames[params.warmup_frames..].windows(2) {
        for (id, velocity) in [(1, 1.5), (2, -1.5)] {
            let (a, b) = (walker(&pair[0], id).unwrap(), walker(&pair[1], id).unwrap());
            assert!((b.left_px - a.left_px - velocity).abs() < 1e-9);
            assert_eq!(b.top_px, a.top_px);
        }
    }
}

#[test]
fn group_split_walkers_touch_then_part() {
    let params = group_split();
    let Scenario::GroupSplit(split) = &params.scenario else {
        unreachable!()
    };
    let split_frame = params.warmup_frames + split.together_frames;
    let frames = frames(params.clone());
    let mut parted = 0;
    for frame in &frames[params.warmup_frames..] {
        let (Some(a), Some(b)) = (walker(frame, 1), walker(frame, 2)) else {
            continue;
        };
        let gap = gap(&truth_box(a), &truth_box(b));
        let index = frame.index as usize;
        if index <= split_frame {
            assert!(gap <= 0.0, "frame {index}: gap {gap} px before the split");
        } else if index >= split_frame + 10 {
            assert!(gap >= 5.0, "frame {index}: gap {gap} px after the split");
            parted += 1;
        }
    }
    assert!(parted >= 30, "{parted} frames apart after the split");
}

/// Runs the motion detector with its default parameters over the grey frames.
fn blobs_per_frame(frames: &[WalkersFrame]) -> Vec<Vec<MotionBlob>> {
    blobs_with(frames, &MotionParams::default())
}

/// Runs the motion detector with `params` over the grey frames.
fn blobs_with(frames: &[WalkersFrame], params: &MotionParams) -> Vec<Vec<MotionBlob>> {
    let (width, height) = frames[0].grey.dimensions();
    let mut detector = MotionDetector::new(params, width, height).unwrap();
    frames
        .iter()
        .map(|frame| {
            let mut blobs = Vec::new();
            detector.detect(&frame.grey, &mut blobs).unwrap();
            blobs
        })
        .collect()
}

/// Over the frames after the warm-up, the share of fully visible walkers whose box lies 8 px
/// or more from every other walker's that a blob matches with IoU ≥ 0.5, and their number.
fn isolated_walkers_found(frames: &[WalkersFrame], warmup: usize) -> (f64, usize) {
    let blobs = blobs_per_frame(frames);
    let (mut found, mut total) = (0usize, 0usize);
    for (frame, blobs) in frames.iter().zip(&blobs).skip(warmup) {
        for t in &frame.truth {
            let truth = truth_box(t);
            let isolated = frame
                .truth
                .iter()
                .filter(|o| o.id != t.id)
                .all(|o| gap(&truth, &truth_box(o)) >= 8.0);
            if t.visibility < 1.0 || !isolated {
                continue;
            }
            total += 1;
            if blobs.iter().any(|b| box_iou(&truth, &blob_box(b)) >= 0.5) {
                found += 1;
            }
        }
    }
    (found as f64 / total.max(1) as f64, total)
}

#[test]
fn the_motion_detector_finds_each_isolated_walker() {
    for (name, params) in [
        ("crossing", crossing(5, 1.0)),
        ("group split", group_split()),
        (
            "random",
            WalkersParams {
                scenario: Scenario::Random(RandomParams::default()),
                seed: 3,
                ..Default::default()
            },
        ),
    ] {
        let warmup = params.warmup_frames;
        let (share, total) = isolated_walkers_found(&frames(params), warmup);
        eprintln!(
            "{name}: {:.1} % of {total} isolated walkers found",
            100.0 * share
        );
        assert!(total >= 50, "{name}: only {total} isolated walkers");
        assert!(share >= 0.9, "{name}: {:.1} % found", 100.0 * share);
    }
}

/// The frames where walkers 1 and 2 of `frames` touch, both at least 90 % visible, with
/// their true boxes.
fn together_pairs(frames: &[WalkersFrame]) -> Vec<(usize, BoundingBox, BoundingBox)> {
    frames
        .iter()
        .enumerate()
        .filter_map(|(i, frame)| {
            let (a, b) = (walker(frame, 1)?, walker(frame, 2)?);
            let together = gap(&truth_box(a), &truth_box(b)) <= 0.0;
            (together && a.visibility >= 0.9 && b.visibility >= 0.9)
                .then(|| (i, truth_box(a), truth_box(b)))
        })
        .collect()
}

#[test]
fn the_group_is_one_blob_of_the_mask_and_the_detector_cuts_it_into_its_walkers() {
    let frames = frames(group_split());
    let pairs = together_pairs(&frames);
    assert!(pairs.len() >= 20, "{} together frames", pairs.len());
    // Uncut (`person_aspect` 0), one blob holds most of both boxes: one connected foreground.
    let uncut = blobs_with(
        &frames,
        &MotionParams {
            person_aspect: 0.0,
            ..MotionParams::default()
        },
    );
    let covers = |blob: &MotionBlob, tb: &BoundingBox| {
        let bb = blob_box(blob);
        let w =
            (tb.left_px + tb.width_px).min(bb.left_px + bb.width_px) - tb.left_px.max(bb.left_px);
        let h = (tb.top_px + tb.height_px).min(bb.top_px + bb.height_px) - tb.top_px.max(bb.top_px);
        w.max(0.0) * h.max(0.0) >= 0.8 * tb.width_px * tb.height_px
    };
    let one_blob = pairs
        .iter()
        .filter(|(i, a, b)| {
            uncut[*i]
                .iter()
                .any(|blob| covers(blob, a) && covers(blob, b))
        })
        .count();
    // Cut (the default), each walker has its own blob, and both pieces name the group blob
    // they were cut from.
    let cut = blobs_per_frame(&frames);
    let own_blob = |i: usize, t: &BoundingBox| {
        cut[i]
            .iter()
            .find(|b| box_iou(t, &blob_box(b)) >= 0.5)
            .map(|b| b.cut_from)
    };
    let both_found = pairs
        .iter()
        .filter(|(i, a, b)| match (own_blob(*i, a), own_blob(*i, b)) {
            (Some(Some(ga)), Some(Some(gb))) => ga == gb,
            _ => false,
        })
        .count();
    let total = pairs.len();
    eprintln!(
        "group: one blob uncut in {one_blob}, both walkers cut out in {both_found} of {total} together frames"
    );
    assert!(
        one_blob as f64 >= 0.9 * total as f64,
        "one blob in {one_blob} of {total}"
    );
    assert!(
        both_found as f64 >= 0.8 * total as f64,
        "both cut out in {both_found} of {total}"
    );
}

#[test]
fn same_seed_same_frames_and_another_seed_another_look() {
    let params = WalkersParams {
        n_frames: 30,
        ..crossing(5, 1.0)
    };
    let first = frames(params.clone());
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| frames(params.clone()));
    assert_eq!(first, single);
    let other = frames(WalkersParams { seed: 1, ..params });
    // Same paths, other clothes: the far walker's pixels differ.
    let frame = 25;
    let t = walker(&first[frame], 1).unwrap();
    assert_eq!(Some(t), walker(&other[frame], 1));
    let mean = |f: &WalkersFrame| {
        let mut sum = [0.0f64; 3];
        let (x0, y0) = (t.left_px.ceil() as usize, t.top_px.ceil() as usize);
        let (w, h) = (t.width_px as usize - 1, t.height_px as usize - 1);
        for y in y0..y0 + h {
            for x in x0..x0 + w {
                let p = f.colour.get(x, y);
                (0..3).for_each(|c| sum[c] += f64::from(p[c]) / (w * h) as f64);
            }
        }
        sum
    };
    let (a, b) = (mean(&first[frame]), mean(&other[frame]));
    let difference: f64 = (0..3).map(|c| (a[c] - b[c]).abs()).sum();
    assert!(difference > 10.0, "{a:?} vs {b:?}");
}

#[test]
fn bad_parameters_name_their_key() {
    let cases = [
        (
            "scenario.n",
            WalkersParams {
                scenario: Scenario::Random(RandomParams {
                    n: 0,
                    ..Default::default()
                }),
                ..Default::default()
            },
        ),
        (
            "width",
            WalkersParams {
                width: 100,
                ..Default::default()
            },
        ),
        (
            "height",
            WalkersParams {
                height: 90,
                ..Default::default()
            },
        ),
        (
            "n_frames",
            WalkersParams {
                n_frames: 10,
                ..Default::default()
            },
        ),
        ("scenario.occlusion_frames", crossing(0, 1.0)),
    ];
    for (key, params) in cases {
        let error = WalkersSequence::new(params).unwrap_err().to_string();
        assert!(error.contains(&format!("`{key}`")), "{key}: {error}");
    }
}

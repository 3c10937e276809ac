//! The SIFT-PF tracker on generated walkers with ground truth, fed by the motion detector
//! through the facade's glue (`sillage::pedestrian::siftpf::detected_objects`): two people
//! crossing with a full occlusion keep their identities; a group that enters together and
//! splits gets new identities after the split; the output does not depend on the thread
//! count; bad frames are errors.

use std::collections::{BTreeMap, BTreeSet};

use sillage::core::{BoundingBox, FrameIndex, Image};
use sillage::detect::motion::{MotionDetector, MotionParams};
use sillage::pedestrian::siftpf::detected_objects;
use sillage::synth::{
    CrossingParams, GroupSplitParams, Scenario, WalkerTruth, WalkersFrame, WalkersParams,
    WalkersSequence,
};
use sillage::track::siftpf::{SiftPfEstimate, SiftPfFrame, SiftPfParams, SiftPfTracker};

/// Runs motion detection and the tracker over `frames`; every reported box.
fn track(frames: &[WalkersFrame], seed: u64) -> Vec<SiftPfEstimate> {
    let (w, h) = frames[0].grey.dimensions();
    let mut motion = MotionDetector::new(&MotionParams::default(), w, h).unwrap();
    let mut tracker = SiftPfTracker::new(&SiftPfParams::default(), None, seed).unwrap();
    let mut blobs = Vec::new();
    let mut out = Vec::new();
    for f in frames {
        motion.detect(&f.grey, &mut blobs).unwrap();
        let detections = detected_objects(&mut blobs);
        let found = tracker
            .step(SiftPfFrame {
                frame: f.index,
                grey: &f.grey,
                colour: Some(&f.colour),
                foreground: motion.foreground(),
                detections: &detections,
            })
            .unwrap();
        out.extend(found);
    }
    out.sort_by_key(|e| (e.frame, e.id));
    out
}

fn truth_box(t: &WalkerTruth) -> BoundingBox {
    // Truth pixel k spans [k − 0.5, k + 0.5]; the tracker's boxes start at the first pixel.
    BoundingBox {
        left_px: t.left_px + 0.5,
        top_px: t.top_px + 0.5,
        width_px: t.width_px,
        height_px: t.height_px,
    }
}

/// For each frame and walker, the reported identity whose box overlaps the truth by IoU ≥ 0.5.
fn matches(
    frames: &[WalkersFrame],
    estimates: &[SiftPfEstimate],
) -> BTreeMap<(FrameIndex, u64), u64> {
    let mut found = BTreeMap::new();
    for f in frames {
        for t in &f.truth {
            let tb = truth_box(t);
            let best = estimates
                .iter()
                .filter(|e| e.frame == f.index)
                .map(|e| (e.bbox.iou(&tb), e.id))
                .filter(|&(iou, _)| iou >= 0.5)
                .max_by(|a, b| a.0.total_cmp(&b.0));
            if let Some((_, id)) = best {
                found.insert((f.index, t.id), id);
            }
        }
    }
    found
}

#[test]
fn crossing_walkers_keep_their_identities_through_a_full_occlusion() {
    let params = WalkersParams {
        scenario: Scenario::Crossing(CrossingParams {
            occlusion_frames: 5,
            ..Default::default()
        }),
        ..Default::default()
    };
    let frames: Vec<_> = WalkersSequence::new(params).unwrap().collect();
    let hidden = frames
        .iter()
        .filter(|f| f.truth.iter().any(|t| t.visibility == 0.0))
        .count();
    assert!(hidden >= 5, "the far walker is hidden {hidden} frames");
    let matched = matches(&frames, &track(&frames, 7));
    for walker in [1, 2] {
        let ids: BTreeSet<u64> = matched
            .iter()
            .filter(|((_, w), _)| *w == walker)
            .map(|(_, id)| *id)
            .collect();
        assert_eq!(ids.len(), 1, "walker {walker} was followed by {ids:?}");
        // Matched in most frames where it is fully visible, once validated (10 frames).
        let visible: Vec<FrameIndex> = frames
            .iter()
            .filter(|f| {
                f.truth
                    .iter()
                    .any(|t| t.id == walker && t.visibility == 1.0)
            })
            .map(|f| f.index)
            .collect();
        let first = visible[0];
        let judged: Vec<_> = visible.iter().filter(|&&f| f >= first + 10).collect();
        let hits = judged
            .iter()
            .filter(|&&&f| matched.contains_key(&(f, walker)))
            .count();
        assert!(
            hits as f64 >= 0.9 * judged.len() as f64,
            "walker {walker}: matched in {hits} of {} visible frames",
            judged.len()
        );
    }
    let first = |walker| {
        matched
            .iter()
            .find(|((_, w), _)| *w == walker)
            .map(|(_, id)| *id)
    };
    assert_ne!(first(1), first(2));
}

#[test]
fn a_group_that_splits_gets_new_identities() {
    let params = WalkersParams {
        scenario: Scenario::GroupSplit(GroupSplitParams::default()),
        ..Default::default()
    };
    let frames: Vec<_> = WalkersSequence::new(params).unwrap().collect();
    let matched = matches(&frames, &track(&frames, 7));
    let apart = |f: &WalkersFrame| {
        if f.truth.len() != 2 {
            return false;
        }
        let [a, b] = [&f.truth[0], &f.truth[1]];
        (a.left_px - (b.left_px + b.width_px))
            .max(b.left_px - (a.left_px + a.width_px))
            .max(a.top_px - (b.top_px + b.height_px))
            .max(b.top_px - (a.top_px + a.height_px))
            > 4.0
    };
    let split_frame = frames
        .iter()
        .position(|f| !f.truth.is_empty() && apart(f))
        .expect("the walkers part") as FrameIndex;
    // The group box (one track over both walkers) matches neither walker by IoU ≥ 0.5, so
    // identities before the split are read as the tracks covering the group's blob.
    let before: BTreeSet<u64> = track(&frames, 7)
        .iter()
        .filter(|e| e.frame < split_frame)
        .map(|e| e.id)
        .collect();
    assert!(!before.is_empty(), "the group was tracked before the split");
    let late = split_frame + 20;
    let after: BTreeMap<u64, BTreeSet<u64>> = matched.iter().filter(|((f, _), _)| *f >= late).fold(
        BTreeMap::new(),
        |mut m, ((_, w), id)| {
            m.entry(*w).or_insert_with(BTreeSet::new).insert(*id);
            m
        },
    );
    assert_eq!(
        after.len(),
        2,
        "both walkers are followed after the split: {after:?}"
    );
    let ids_after: BTreeSet<u64> = after.values().flatten().copied().collect();
    assert!(
        ids_after.is_disjoint(&before),
        "after the split {ids_after:?}, before {before:?}"
    );
    assert!(after.values().all(|ids| ids.len() == 1), "{after:?}");
    assert_ne!(
        after[&frames[late as usize].truth[0].id],
        after[&frames[late as usize].truth[1].id]
    );
}

#[test]
fn output_is_the_same_on_one_thread_and_on_several() {
    let params = WalkersParams {
        n_frames: 60,
        scenario: Scenario::Crossing(CrossingParams::default()),
        ..Default::default()
    };
    let frames: Vec<_> = WalkersSequence::new(params).unwrap().collect();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| track(&frames, 3));
    let many = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap()
        .install(|| track(&frames, 3));
    assert!(!one.is_empty());
    assert_eq!(one, many);
}

#[test]
fn frames_of_different_sizes_are_an_error_naming_the_frame() {
    let frames: Vec<_> = WalkersSequence::new(WalkersParams {
        n_frames: 12,
        ..Default::default()
    })
    .unwrap()
    .collect();
    let mut tracker = SiftPfTracker::new(&SiftPfParams::default(), None, 1).unwrap();
    let small = Image::<bool>::new(10, 10);
    let err = tracker
        .step(SiftPfFrame {
            frame: 4,
            grey: &frames[0].grey,
            colour: None,
            foreground: &small,
            detections: &[],
        })
        .unwrap_err()
        .to_string();
    assert!(err.contains("frame 4"), "{err}");
    let mut params = SiftPfParams::default();
    params.filter.particles = 0;
    assert!(SiftPfTracker::new(&params, None, 1).is_err());
}

//! Integration tests of the synthetic bedload scene: determinism, identities, counts, the
//! agreement of motion and motion state, the transition table, the bed's contacts, speed
//! (the detector model's tests are in `bedload_detections.rs`).

use std::collections::{HashMap, HashSet};

use sillage_core::{BLACK_BEAD_CLASS, MotionState, TRANSPARENT_BEAD_CLASS, TrackId};
use sillage_synth::{
    BedloadDetectionParams, BedloadFrame, BedloadScene, BedloadSceneParams, BedloadSequence,
    generate_bedload,
};

fn frames(n_frames: usize, seed: u64) -> BedloadSceneParams {
    BedloadSceneParams {
        n_frames,
        seed,
        ..Default::default()
    }
}

fn truth(params: BedloadSceneParams) -> Vec<BedloadFrame> {
    BedloadScene::new(params).unwrap().collect()
}

fn state_index(state: MotionState) -> usize {
    match state {
        MotionState::Resting => 0,
        MotionState::Rolling => 1,
        MotionState::Saltating => 2,
        MotionState::Unknown => panic!("the scene never reports an unknown state"),
    }
}

#[test]
fn same_seed_same_output_and_other_seed_other_output() {
    let detection = BedloadDetectionParams::default();
    let a = generate_bedload(frames(30, 7), detection.clone()).unwrap();
    let b = generate_bedload(frames(30, 7), detection.clone()).unwrap();
    let c = generate_bedload(frames(30, 8), detection).unwrap();
    assert_eq!(a.len(), 30);
    assert_eq!(a, b);
    for (x, y) in a.iter().zip(&c).skip(1) {
        assert_ne!(x.truth, y.truth);
        assert_ne!(x.observation.detections, y.observation.detections);
    }
}

#[test]
fn ids_are_unique_never_reused_and_the_counts_stay_constant() {
    let params = frames(1500, 2);
    let (n_black, n_transparent) = (params.n_black, params.n_transparent);
    let mut gone: HashSet<TrackId> = HashSet::new();
    let mut previous: HashSet<TrackId> = HashSet::new();
    let mut births = 0;
    for frame in BedloadScene::new(params).unwrap() {
        let ids: HashSet<TrackId> = frame.beads.iter().map(|b| b.track_id).collect();
        assert_eq!(
            ids.len(),
            frame.beads.len(),
            "frame {}: duplicate ids",
            frame.index
        );
        let count = |class| frame.beads.iter().filter(|b| b.class == class).count();
        assert_eq!(count(BLACK_BEAD_CLASS), n_black);
        assert_eq!(count(TRANSPARENT_BEAD_CLASS), n_transparent);
        assert!(
            ids.is_disjoint(&gone),
            "frame {}: an id came back",
            frame.index
        );
        for bead in &frame.beads {
            let known = previous.contains(&bead.track_id);
            // A velocity exactly when the bead was there in the previous frame.
            assert_eq!(bead.vel_px_per_frame.is_some(), known);
            if frame.index > 0 && !known {
                births += 1;
                assert_eq!(bead.motion_state, MotionState::Rolling);
                // It enters at the lowest point within 4 black diameters of its entry, at
                // most 5 px from the upstream edge, and slides into the dip there, at most a
                // diameter away.
                assert!(
                    bead.pos_px.x >= 1279.0 - 5.0 - 120.0 - 30.0,
                    "a newcomer enters upstream"
                );
            }
        }
        gone.extend(previous.difference(&ids));
        previous = ids;
    }
    // The creeping layers and the beads they carry cross the frame (the real sequence: 1
    // entry and 1 exit in its 10 frames with truth; Σ|vx| / 1280 = 0.21 per frame).
    println!("{births} beads crossed the frame in 1500 frames");
    assert!(births > 40, "only {births} beads crossed the frame");
    assert_eq!(births, gone.len());
}

#[test]
fn positions_stay_in_the_frame_and_displacements_below_the_search_radius() {
    let scene = BedloadScene::new(frames(3000, 3)).unwrap();
    let mut largest: f64 = 0.0;
    let (mut moves, mut beyond) = (0usize, 0usize);
    for frame in scene {
        for bead in &frame.beads {
            let p = bead.pos_px;
            assert!(p.is_finite());
            assert!(
                (0.0..=1279.0).contains(&p.x) && (0.0..=319.0).contains(&p.y),
                "{p:?}"
            );
            if let Some(v) = bead.vel_px_per_frame.filter(|v| v.norm() > 0.1) {
                largest = largest.max(v.norm());
                moves += 1;
                // BeadTracking's search radius vMax / mByPx / acqFreq = 31.05 px.
                beyond += usize::from(v.norm() >= 31.05);
            }
        }
    }
    println!("{beyond} of {moves} moves beyond 31.05 px, largest {largest:.2} px");
    // Beads move continuously: a bead that loses its support falls under gravity, a
    // saltation stops against a bead in its way, and no move exceeds 25 px.
    assert_eq!(
        beyond, 0,
        "{beyond} of {moves} moves beyond the search radius"
    );
    assert!(largest <= 25.0 + 1e-9, "a move of {largest} px");
    assert!(
        largest > 20.0,
        "saltations and falls should reach 20-25 px per frame: {largest}"
    );
}

#[test]
fn motion_agrees_with_the_motion_state() {
    for flow_direction in [-1, 1] {
        let params = BedloadSceneParams {
            flow_direction,
            ..frames(2000, 4)
        };
        let jitter = params.resting_jitter_px;
        let clearance = params.hop_clearance_px;
        let hop_speed = params.saltation_speed_px_per_frame[0];
        let mut scene = BedloadScene::new(params).unwrap();
        let mut frames_seen = Vec::new();
        while let Some(frame) = scene.next_frame() {
            frames_seen.push(frame);
        }
        let (mut in_flight, mut saltating, mut rolling, mut fast) = (0, 0, 0, 0);
        let (mut advancing, mut largest_roll, mut backwards) = (0, 0.0f64, 0);
        for bead in frames_seen.iter().flat_map(|f| &f.beads) {
            let surface = scene.surface_y(bead.pos_px.x, bead.class);
            if bead.in_bed {
                assert_eq!(bead.motion_state, MotionState::Resting);
            }
            let Some(v) = bead.vel_px_per_frame else {
                continue;
            };
            match bead.motion_state {
                MotionState::Resting => assert!(v.norm() <= jitter + 1e-12, "{v:?}"),
                MotionState::Rolling => {
                    rolling += 1;
                    // On the bed, on other beads or falling onto them; downstream, held back
                    // by a bead, or back into the dip behind one it was left hanging on.
                    assert!(bead.pos_px.y <= surface + 1e-9, "below the bed: {bead:?}");
                    assert!(v.norm() <= 25.0 + 1e-9, "rolling by {v:?}");
                    if v.x * f64::from(flow_direction) < -jitter {
                        backwards += 1;
                    }
                    largest_roll = largest_roll.max(v.norm());
                    if v.x * f64::from(flow_direction) >= 1.0 - jitter {
                        advancing += 1;
                    }
                }
                MotionState::Saltating => {
                    saltating += 1;
                    assert!(bead.pos_px.y <= surface + 1e-9, "below the bed: {bead:?}");
                    // Downstream; at the hop's speed unless stopped against a bead.
                    assert!(v.x * f64::from(flow_direction) >= -1e-9, "{v:?}");
                    if v.x * f64::from(flow_direction) >= hop_speed - jitter {
                        fast += 1;
                    }
                    if bead.pos_px.y <= surface - clearance + 1e-9 {
                        in_flight += 1;
                    }
                }
                MotionState::Unknown => panic!("unknown state"),
            }
        }
        assert!(
            rolling > 10_000 && saltating > 1_000,
            "{rolling} {saltating}"
        );
        println!(
            "{advancing} of {rolling} rolling steps advance by 1 px or more, {backwards} go \
             back; largest {largest_roll:.1} px"
        );
        // Many rolling beads advance at their speed; the others are held back by a bead or
        // lie under one (the real sequence's rolling beads: median speed 1 px/frame for the
        // black ones, 0 for the transparent ones). Few roll back into a dip.
        assert!(
            backwards * 100 < rolling,
            "{backwards} of {rolling} backwards"
        );
        assert!(
            advancing * 10 > rolling,
            "{advancing} of {rolling} advancing"
        );
        println!("{fast} of {saltating} saltating steps at {hop_speed} px/frame or more");
        assert!(fast * 10 > saltating * 8, "{fast} of {saltating} fast");
        // Most saltating frames are in the air, the others are contacts (take-off, rebound
        // or landing on the surface).
        assert!(
            in_flight * 2 > saltating,
            "{in_flight} of {saltating} in flight"
        );
    }
}

#[test]
fn state_transitions_follow_the_table() {
    // The table drives the mobile beads' own motion; a creeping layer carries the beads
    // lying on it, which are then reported rolling whatever their state (the motion test
    // checks that). The table's frequencies are measured without the carry: on a static bed
    // of 6 layers, all black.
    let params = BedloadSceneParams {
        bed_layers: 6,
        creeping_layers: 0,
        transparent_in_bed: 0.0,
        ..frames(4000, 5)
    };
    let table = params.transition_probabilities;
    let mut counts = [[0usize; 3]; 3];
    let mut previous: HashMap<TrackId, MotionState> = HashMap::new();
    for frame in BedloadScene::new(params).unwrap() {
        let mut current = HashMap::new();
        for bead in frame.beads.iter().filter(|b| !b.in_bed) {
            if let Some(&before) = previous.get(&bead.track_id) {
                counts[state_index(before)][state_index(bead.motion_state)] += 1;
            }
            current.insert(bead.track_id, bead.motion_state);
        }
        previous = current;
    }
    for (from, row) in counts.iter().enumerate() {
        let n: usize = row.iter().sum();
        assert!(n >= 3_000, "row {from}: {n} samples");
        for (to, &count) in row.iter().enumerate() {
            let (p, observed) = (table[from][to], count as f64 / n as f64);
            // Within 0.01, or 4 binomial standard deviations if larger.
            let tolerance = (4.0 * (p * (1.0 - p) / n as f64).sqrt()).max(0.01);
            assert!(
                (observed - p).abs() <= tolerance,
                "{from} → {to}: {observed:.4} for {p} over {n} ({counts:?})"
            );
        }
    }
}

#[test]
fn bed_beads_touch_their_neighbours() {
    let params = frames(1, 6);
    let (r_black, r_trans) = (params.black_radius_px, params.transparent_radius_px);
    let frame = &truth(params)[0];
    let radius = |class| {
        if class == BLACK_BEAD_CLASS {
            r_black
        } else {
            r_trans
        }
    };
    let bed: Vec<_> = frame.beads.iter().filter(|b| b.in_bed).collect();
    let mut contacts = Vec::new();
    for a in &bed {
        let mut n = 0;
        for b in &frame.beads {
            if a.track_id == b.track_id {
                continue;
            }
            let (d, touch) = (
                a.pos_px.distance(b.pos_px),
                radius(a.class) + radius(b.class),
            );
            if b.in_bed {
                // Roughly in contact: overlaps only from the disorder (2 × 0.5 px) and the
                // jitter (0.05 px).
                assert!(d >= touch - 1.05 - 1e-9, "bed beads overlap: {d}");
            }
            // BeadTracking's neighbour rule: centre distance ≤ 1.07 × the sum of radii.
            if d <= 1.07 * touch {
                n += 1;
            }
        }
        contacts.push(n);
    }
    // The black lattice: most of its beads touch 5 or more (a transparent bead lodged in a
    // site touches the two below it; the real frames: 62 % of the resting black beads).
    let black: Vec<usize> = contacts
        .iter()
        .zip(&bed)
        .filter(|(_, b)| b.class == BLACK_BEAD_CLASS)
        .map(|(&n, _)| n)
        .collect();
    let many = black.iter().filter(|&&n| n >= 5).count();
    println!(
        "{many} of {} black bed beads with ≥ 5 contacts",
        black.len()
    );
    assert!(
        many * 2 > black.len(),
        "{many} of {} black bed beads with ≥ 5 contacts",
        black.len()
    );
    let loose: Vec<_> = contacts
        .iter()
        .zip(&bed)
        .filter(|(n, _)| **n < 2)
        .map(|(n, b)| (n, b.class, b.pos_px))
        .collect();
    assert!(
        loose.is_empty(),
        "bed beads with fewer than 2 contacts: {loose:?}"
    );
}

#[test]
fn invalid_parameters_are_rejected_naming_their_key() {
    // Every key of both structs is checked by the unit tests of their modules; here, through
    // the constructors.
    let scene = BedloadSceneParams {
        flow_direction: 0,
        ..Default::default()
    };
    let err = BedloadScene::new(scene.clone()).unwrap_err().to_string();
    assert!(err.contains("`flow_direction`"), "{err}");
    let err = BedloadSequence::new(scene, BedloadDetectionParams::default()).unwrap_err();
    assert!(err.to_string().contains("`flow_direction`"), "{err}");
    let detection = BedloadDetectionParams {
        burst_length: 0,
        ..Default::default()
    };
    let err = BedloadSequence::new(BedloadSceneParams::default(), detection).unwrap_err();
    assert!(err.to_string().contains("`burst_length`"), "{err}");
}

#[test]
fn truth_points_mirror_the_beads_and_the_stream_ends() {
    let mut scene = BedloadScene::new(frames(3, 10)).unwrap();
    assert_eq!(scene.len(), 3);
    let frames: Vec<_> = std::iter::from_fn(|| scene.next_frame()).collect();
    assert_eq!(frames.len(), 3);
    assert!(scene.next_frame().is_none());
    for frame in &frames {
        let points = frame.truth_points();
        assert_eq!(points.len(), frame.beads.len());
        for (p, b) in points.iter().zip(&frame.beads) {
            assert_eq!(
                (p.frame, p.track_id, p.pos_px),
                (frame.index, b.track_id, b.pos_px)
            );
            assert_eq!(p.vel_px_per_frame, b.vel_px_per_frame);
        }
    }
}

/// Generation speed (release: `cargo test --release -p sillage-synth --test bedload --
/// --ignored --nocapture`).
#[test]
#[ignore]
fn generation_speed() {
    for detect in [false, true] {
        let params = frames(10_000, 11);
        let start = std::time::Instant::now();
        let n = if detect {
            BedloadSequence::new(params, BedloadDetectionParams::default())
                .unwrap()
                .count()
        } else {
            BedloadScene::new(params).unwrap().count()
        };
        let seconds = start.elapsed().as_secs_f64();
        let what = if detect {
            "truth + detections"
        } else {
            "truth only"
        };
        println!(
            "{what}: {n} frames of 400 beads in {seconds:.3} s = {:.0} frames/s",
            n as f64 / seconds
        );
    }
}

//! Generated bedload sequences (`BedloadScene` with default parameters, rendered by
//! `BedloadRenderer`) against the ten real frames of the MMPF+ paper's sequence (§4.2):
//! the distances between beads, the motion states and speeds, and the recall of the bead
//! detector run with the parameters tuned on the real frames (the acceptance: within
//! 2 points of its recall on the real frames, for each class).
//!
//! `cargo test -p sillage-synth --test bedload_generated -- --nocapture` prints the
//! distributions of both.

mod common;

use common::{
    MAX_RECALL_GAP, REAL_RECALL_BUILT_IN, detector, real_configurations, render_and_detect, report,
    score, truth,
};
use sillage_core::{BLACK_BEAD_CLASS, MotionState, TRANSPARENT_BEAD_CLASS};
use sillage_synth::{BedloadFrame, BedloadScene, BedloadSceneParams, TrueBead};

/// `q`-quantile of `values` (nearest rank), NaN when empty.
fn quantile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

/// Minimum, 5 %, median and 95 % quantiles.
fn summary(values: &[f64]) -> [f64; 4] {
    [0.0, 0.05, 0.5, 0.95].map(|q| quantile(values, q))
}

fn is_moving(bead: &TrueBead) -> bool {
    matches!(
        bead.motion_state,
        MotionState::Rolling | MotionState::Saltating
    )
}

/// The distance from `bead` to the nearest other bead of `frame` that `other` accepts.
fn nearest(frame: &BedloadFrame, bead: &TrueBead, other: impl Fn(&TrueBead) -> bool) -> f64 {
    frame
        .beads
        .iter()
        .filter(|b| b.track_id != bead.track_id && other(b))
        .map(|b| b.pos_px.distance(bead.pos_px))
        .fold(f64::INFINITY, f64::min)
}

/// What the tests compare between real and generated frames.
#[derive(Debug, Default)]
struct Distributions {
    /// Nearest-neighbour distances, px: transparent to transparent, transparent to black,
    /// black to black, and moving (rolling, saltating) beads to resting ones.
    transparent_transparent: Vec<f64>,
    transparent_black: Vec<f64>,
    black_black: Vec<f64>,
    moving_resting: Vec<f64>,
    /// Per class (black, transparent): beads resting, rolling, saltating (unknown left out).
    states: [[usize; 3]; 2],
    /// Speeds of rolling and saltating beads, px/frame.
    speeds: [Vec<f64>; 2],
}

impl Distributions {
    fn of(frames: &[BedloadFrame]) -> Self {
        let mut d = Self::default();
        let black = |b: &TrueBead| b.class == BLACK_BEAD_CLASS;
        let transparent = |b: &TrueBead| b.class == TRANSPARENT_BEAD_CLASS;
        for frame in frames {
            for bead in &frame.beads {
                if transparent(bead) {
                    d.transparent_transparent
                        .push(nearest(frame, bead, transparent));
                    d.transparent_black.push(nearest(frame, bead, black));
                } else {
                    d.black_black.push(nearest(frame, bead, black));
                }
                if is_moving(bead) {
                    let resting = |b: &TrueBead| b.motion_state == MotionState::Resting;
                    d.moving_resting.push(nearest(frame, bead, resting));
                }
                let class = usize::from(transparent(bead));
                let state = match bead.motion_state {
                    MotionState::Resting => 0,
                    MotionState::Rolling => 1,
                    MotionState::Saltating => 2,
                    MotionState::Unknown => continue,
                };
                d.states[class][state] += 1;
                if let (1 | 2, Some(v)) = (state, bead.vel_px_per_frame) {
                    d.speeds[state - 1].push(v.norm());
                }
            }
        }
        d
    }

    /// Fraction of the transparent beads with another one closer than `px`.
    fn transparent_within(&self, px: f64) -> f64 {
        let n = self.transparent_transparent.len() as f64;
        self.transparent_transparent
            .iter()
            .filter(|&&d| d < px)
            .count() as f64
            / n
    }

    fn print(&self, label: &str) {
        println!("{label} (min, 5 %, median, 95 %):");
        for (name, values) in [
            ("transparent–transparent", &self.transparent_transparent),
            ("transparent–black", &self.transparent_black),
            ("black–black", &self.black_black),
            ("moving–resting", &self.moving_resting),
        ] {
            println!("  nearest {name}: {:.1?} px", summary(values));
        }
        println!(
            "  transparent beads with another within 20 px (overlapping): {:.3}; with a black \
             centre within 10 px (hidden): {:.3}",
            self.transparent_within(20.0),
            self.transparent_black.iter().filter(|&&d| d < 10.0).count() as f64
                / self.transparent_black.len() as f64
        );
        for (class, name) in [(0, "black"), (1, "transparent")] {
            let n: usize = self.states[class].iter().sum();
            let f = self.states[class].map(|k| k as f64 / n as f64);
            println!(
                "  {name} states (resting, rolling, saltating) of {n}: {:.3} {:.3} {:.3}",
                f[0], f[1], f[2]
            );
        }
        for (state, name) in [(0, "rolling"), (1, "saltating")] {
            println!(
                "  {name} speed: {:.1?} px/frame",
                summary(&self.speeds[state])
            );
        }
    }
}

/// What the motion of a sequence looks like, as its ground truth tells (beads with a
/// velocity and a known state).
#[derive(Debug)]
struct MotionStatistics {
    /// Per class (black, transparent): fractions of the beads resting, rolling, saltating.
    states: [[f64; 3]; 2],
    /// Kinematic flux: Σ|vx| over the beads of a frame divided by the frame's width, beads
    /// crossing it per frame, averaged over the frames.
    flux: f64,
    /// Median and 95 % quantile of the rolling beads' speeds, px/frame.
    rolling: [f64; 2],
    /// Median and 5 % quantile of the saltating beads' speeds, px/frame.
    saltating: [f64; 2],
}

impl MotionStatistics {
    /// The statistics of `frames`, `width` px wide.
    fn of(frames: &[BedloadFrame], width: f64) -> Self {
        let mut counts = [[0usize; 3]; 2];
        let mut speeds: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
        let (mut flux, mut n_frames) = (0.0, 0);
        for frame in frames {
            let mut sum = 0.0;
            let mut seen = false;
            for bead in &frame.beads {
                let Some(v) = bead.vel_px_per_frame else {
                    continue;
                };
                let state = match bead.motion_state {
                    MotionState::Resting => 0,
                    MotionState::Rolling => 1,
                    MotionState::Saltating => 2,
                    MotionState::Unknown => continue,
                };
                seen = true;
                sum += v.x.abs();
                counts[usize::from(bead.class != BLACK_BEAD_CLASS)][state] += 1;
                if state > 0 {
                    speeds[state - 1].push(v.norm());
                }
            }
            if seen {
                flux += sum / width;
                n_frames += 1;
            }
        }
        let states = counts.map(|row| {
            let n: usize = row.iter().sum();
            row.map(|k| k as f64 / n.max(1) as f64)
        });
        Self {
            states,
            flux: flux / f64::from(n_frames.max(1)),
            rolling: [quantile(&speeds[0], 0.5), quantile(&speeds[0], 0.95)],
            saltating: [quantile(&speeds[1], 0.5), quantile(&speeds[1], 0.05)],
        }
    }
}

#[test]
fn generated_motion_matches_the_real_sequence() {
    // The real frames: 2-10 (frame 1 has no velocities), about 400 beads each.
    let real = MotionStatistics::of(&real_configurations(), 1280.0);
    println!("real: {real:.3?}");
    let params = BedloadSceneParams {
        n_frames: 1500,
        seed: 13,
        ..BedloadSceneParams::default()
    };
    let frames: Vec<BedloadFrame> = BedloadScene::new(params).unwrap().collect();
    let generated = MotionStatistics::of(&frames, 1280.0);
    println!("generated: {generated:.3?}");
    // The real states over 3,500 beads, to ±10 points per state and class.
    for class in 0..2 {
        for state in 0..3 {
            let (g, r) = (generated.states[class][state], real.states[class][state]);
            assert!(
                (g - r).abs() <= 0.10,
                "class {class}, state {state}: {g:.3} against {r:.3}"
            );
        }
    }
    // The flux within a factor 1.5 of the real one (one sequence of 9 steps).
    let ratio = generated.flux / real.flux;
    assert!(
        (1.0 / 1.5..=1.5).contains(&ratio),
        "flux {ratio:.2} × the real"
    );
    // Speeds: the real ones are whole pixels, hence the half-pixel tolerance of the
    // median; the quantiles of a few hundred steps within 1.5 px/frame.
    assert!((generated.rolling[0] - real.rolling[0]).abs() <= 0.5);
    assert!((generated.rolling[1] - real.rolling[1]).abs() <= 1.5);
    assert!((generated.saltating[0] - real.saltating[0]).abs() <= 3.0);
}

#[test]
fn the_contact_factors_are_the_real_frames_typical_distances() {
    let real = Distributions::of(&real_configurations());
    real.print("real frames");
    let params = BedloadSceneParams::default();
    let (b, t) = (BLACK_BEAD_CLASS, TRANSPARENT_BEAD_CLASS);
    for (values, a, c) in [
        (&real.black_black, b, b),
        (&real.transparent_black, t, b),
        (&real.transparent_transparent, t, t),
    ] {
        // The nearest neighbour of a bead in the real frames mostly touches it: the median
        // is the contact distance of the pair, within a pixel (the truth is in whole px).
        let median = quantile(values, 0.5);
        let contact = params.contact_distance_px(a, c);
        assert!((median - contact).abs() < 1.0, "{median} vs {contact}");
        assert!(summary(values)[0] < contact);
    }
}

#[test]
fn generated_frames_are_as_hard_to_detect_as_the_real_ones() {
    // Every 20th frame of 200: the dropped start and the pile the motion makes of it.
    let params = BedloadSceneParams {
        n_frames: 200,
        seed: 7,
        ..BedloadSceneParams::default()
    };
    let frames: Vec<BedloadFrame> = BedloadScene::new(params).unwrap().step_by(20).collect();
    Distributions::of(&frames).print("generated frames");
    let start = std::time::Instant::now();
    let per_frame = render_and_detect(&frames, &mut detector(None));
    println!(
        "{} frames rendered and detected in {:?}",
        frames.len(),
        start.elapsed()
    );
    for (class, label) in [(0, "black"), (1, "transparent")] {
        let scores = score(&truth(&frames, class, |_, _| true), &per_frame, class);
        let recall = report(&format!("generated frames, {label}"), &scores);
        let real = REAL_RECALL_BUILT_IN[class as usize];
        assert!(
            (recall - real).abs() <= MAX_RECALL_GAP,
            "{label}: generated recall {recall:.4}, real {real:.4}"
        );
    }
}

#[test]
fn no_two_beads_come_closer_than_their_contact_distance() {
    let params = BedloadSceneParams {
        n_frames: 1000,
        seed: 12,
        ..BedloadSceneParams::default()
    };
    // Resting beads are seen off their place by up to half the jitter each; the bed surface
    // is tabulated within 0.1 px.
    let tolerance = params.resting_jitter_px + 0.1;
    let scene = BedloadScene::new(params.clone()).unwrap();
    let last_x = params.width as f64 - 1.0;
    let mut closest = f64::INFINITY;
    for frame in scene {
        for (k, a) in frame.beads.iter().enumerate().filter(|(_, b)| !b.in_bed) {
            // Bed beads come first: pair them with every mobile bead too, but those whose
            // lattice site lies just outside the frame, seen clamped to its edge (within the
            // jitter).
            let edge = |b: &&TrueBead| b.pos_px.x < 1.0 || b.pos_px.x > last_x - 1.0;
            let bed = frame.beads.iter().take_while(|b| b.in_bed);
            for b in frame
                .beads
                .iter()
                .skip(k + 1)
                .chain(bed.filter(|b| !edge(b)))
            {
                let contact = params.contact_distance_px(a.class, b.class);
                let gap = a.pos_px.distance(b.pos_px) - contact;
                closest = closest.min(gap);
                assert!(
                    gap >= -tolerance,
                    "frame {}: {a:?} and {b:?} {gap:.3} px inside contact",
                    frame.index
                );
            }
        }
    }
    println!("closest approach to contact: {closest:.4} px");
}

//! The bedload switching of §3.5.1 / §4.3 and the kinematic switching, measured on many
//! particles with a fixed seed. Frequencies are checked to 5 binomial standard errors,
//! √(p(1 − p)/n); variances to 5 standard errors of a Gaussian sample variance, σ²·√(2/n).

use sillage_core::{Point2, Vec2, rng_stream};
use sillage_filter::{
    BedloadMode, BedloadModel, BedloadParams, Gauss2, InitialSpread, KinematicParams, MotionModel,
    Noise2, Particles, Switching, SwitchingParams, TRANSITION_EQ12,
};

const N: usize = 40_000;

fn particles_in(mode: u8, vel: Vec2) -> Particles {
    let mut particles = Particles::new(N);
    let spread = InitialSpread {
        pos_px: Point2::new(0.0, 0.0),
        pos_noise: Gauss2::ZERO,
        vel_px_per_frame: vel,
        vel_noise: Gauss2::ZERO,
        mode,
    };
    particles.initialise(&spread, &mut rng_stream(1, 1));
    particles
}

fn fraction(particles: &Particles, test: impl Fn(BedloadMode) -> bool) -> f64 {
    let hits = particles
        .modes()
        .iter()
        .filter(|&&m| test(BedloadMode::from_index(m).unwrap()))
        .count();
    hits as f64 / particles.len() as f64
}

fn assert_frequency(observed: f64, p: f64, n: usize, what: &str) {
    let bound = 5.0 * (p * (1.0 - p) / n as f64).sqrt() + 1e-12;
    assert!(
        (observed - p).abs() <= bound,
        "{what}: {observed} vs {p} ± {bound}"
    );
}

fn variance(values: impl Iterator<Item = f64> + Clone) -> f64 {
    let n = values.clone().count() as f64;
    let mean = values.clone().sum::<f64>() / n;
    values.map(|v| (v - mean).powi(2)).sum::<f64>() / n
}

#[test]
fn transitions_follow_eq12_and_the_unknown_row() {
    let model = BedloadModel::new(BedloadParams::default()).unwrap();
    let mut rng = rng_stream(7, 7);
    let states = [
        BedloadMode::Resting,
        BedloadMode::Rolling,
        BedloadMode::SaltatingRebound,
        BedloadMode::Unknown,
    ];
    for (row, from) in states.into_iter().enumerate() {
        let mut particles = particles_in(from.index(), Vec2::ZERO);
        model.propagate(&mut particles, 10, &mut rng);
        let expected = if row < 3 {
            TRANSITION_EQ12[row]
        } else {
            [1.0 / 3.0; 3]
        };
        let observed = [
            fraction(&particles, |m| m == BedloadMode::Resting),
            fraction(&particles, |m| m == BedloadMode::Rolling),
            fraction(&particles, |m| {
                matches!(
                    m,
                    BedloadMode::SaltatingConstant | BedloadMode::SaltatingRebound
                )
            }),
        ];
        for (to, (&o, &p)) in observed.iter().zip(&expected).enumerate() {
            assert_frequency(o, p, N, &format!("{from:?} → column {to}"));
        }
        assert_eq!(fraction(&particles, |m| m == BedloadMode::Unknown), 0.0);
    }
}

#[test]
fn saltation_splits_half_and_half_and_starts_at_the_flow_fraction() {
    let params = BedloadParams::default();
    let model = BedloadModel::new(params.clone()).unwrap();
    let mut particles = particles_in(BedloadMode::Unknown.index(), Vec2::new(0.7, 0.0));
    model.propagate(&mut particles, 2, &mut rng_stream(3, 3));
    let salt: Vec<usize> = (0..N)
        .filter(|&i| particles.modes()[i] >= BedloadMode::SaltatingConstant.index())
        .collect();
    let rebound = salt
        .iter()
        .filter(|&&i| particles.modes()[i] == BedloadMode::SaltatingRebound.index())
        .count();
    assert_frequency(
        rebound as f64 / salt.len() as f64,
        0.5,
        salt.len(),
        "rebound share",
    );
    // Unknown → saltating: u = 0.5 · flow (= (−15.53, 0) by default) before the step, so the
    // particle moves by it; position noise is the young-track one (1.5 · Σ_salt, track_len 2).
    let init = params.flow_vel_px_per_frame * params.salt_init_fraction;
    assert!((init.x + 15.525).abs() < 0.01);
    let var_x = 1.5 * params.salt_pos_noise.var_x;
    let mean_x = salt.iter().map(|&i| particles.pos_x()[i]).sum::<f64>() / salt.len() as f64;
    let bound = 5.0 * (var_x / salt.len() as f64).sqrt();
    assert!(
        (mean_x - init.x).abs() <= bound,
        "saltating x {mean_x} vs {} ± {bound}",
        init.x
    );
    let observed = variance(salt.iter().map(|&i| particles.pos_x()[i]));
    let bound = 5.0 * var_x * (2.0 / salt.len() as f64).sqrt();
    assert!(
        (observed - var_x).abs() <= bound,
        "young saltating var {observed} vs {var_x}"
    );
    // Particles leaving unknown for rolling keep their own velocity (0.7 px/frame here).
    let roll: Vec<usize> = (0..N)
        .filter(|&i| particles.modes()[i] == BedloadMode::Rolling.index())
        .collect();
    let mean_x = roll.iter().map(|&i| particles.pos_x()[i]).sum::<f64>() / roll.len() as f64;
    assert!((mean_x - 0.7).abs() < 5.0 * (1.5 * 3.04 / roll.len() as f64).sqrt());
}

#[test]
fn young_tracks_have_inflated_noise_for_three_frames() {
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let params = BedloadParams {
        transition: identity,
        ..Default::default()
    };
    let model = BedloadModel::new(params.clone()).unwrap();
    let rest_var = params.rest_pos_noise.var_x;
    for (track_len, factor) in [(2, 1.5), (3, 1.5), (4, 1.0), (50, 1.0)] {
        let mut particles = particles_in(BedloadMode::Resting.index(), Vec2::ZERO);
        model.propagate(
            &mut particles,
            track_len,
            &mut rng_stream(5, u64::from(track_len)),
        );
        let expected = factor * rest_var;
        let observed = variance(particles.pos_x().iter().copied());
        let bound = 5.0 * expected * (2.0 / N as f64).sqrt();
        assert!(
            (observed - expected).abs() <= bound,
            "track_len {track_len}: var {observed} vs {expected} ± {bound}"
        );
    }
}

#[test]
fn kinematic_switching_follows_its_table() {
    let noise = Noise2::diagonal(1.0, 1.0);
    let switching = Switching::new(&SwitchingParams {
        models: vec![
            KinematicParams::ConstantPosition { pos_noise: noise },
            KinematicParams::ConstantVelocity {
                pos_noise: noise,
                vel_noise: noise,
            },
        ],
        transition: vec![vec![0.7, 0.3], vec![0.2, 0.8]],
    })
    .unwrap();
    assert_eq!(switching.table().probability(1, 0), 0.2);
    let mut rng = rng_stream(8, 8);
    for (from, p_to_1) in [(0u8, 0.3), (1, 0.8)] {
        let mut particles = particles_in(from, Vec2::new(5.0, 0.0));
        switching.propagate(&mut particles, 10, &mut rng);
        let to_1 = particles.modes().iter().filter(|&&m| m == 1).count();
        assert_frequency(to_1 as f64 / N as f64, p_to_1, N, &format!("from {from}"));
        // Constant velocity moved its particles by u = 5; constant position did not.
        let moved: Vec<f64> = (0..N)
            .filter(|&i| particles.modes()[i] == 1)
            .map(|i| particles.pos_x()[i])
            .collect();
        let mean = moved.iter().sum::<f64>() / moved.len() as f64;
        assert!((mean - 5.0).abs() < 5.0 / (moved.len() as f64).sqrt());
    }
}

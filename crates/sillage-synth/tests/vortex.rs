//! Integration tests of the vortex flow, its truth and its rendered frames.

use sillage_core::Point2;
use sillage_synth::{
    Noise, NoiseKind, VortexFlow, VortexParams, VortexSequence, VortexTruth, displacement_stats,
    p_inverse, render_spots, vortex_map,
};

fn small(seed: u64) -> VortexParams {
    VortexParams {
        width: 128,
        height: 96,
        n_particles: 60,
        n_frames: 5,
        intermittency: 0.1,
        brownian: 0.2,
        seed,
        ..Default::default()
    }
}

#[test]
fn same_seed_same_frames_and_other_seed_other_frames() {
    let a: Vec<_> = VortexSequence::new(small(3)).unwrap().collect();
    let b: Vec<_> = VortexSequence::new(small(3)).unwrap().collect();
    let c: Vec<_> = VortexSequence::new(small(4)).unwrap().collect();
    assert_eq!(a.len(), 5);
    assert_eq!(a, b);
    for (x, y) in a.iter().zip(&c) {
        assert_ne!(x.image, y.image);
        assert_ne!(x.truth, y.truth);
    }
}

#[test]
fn rendering_does_not_depend_on_the_thread_count() {
    let params = VortexParams {
        width: 300,
        height: 200,
        n_particles: 400,
        ..Default::default()
    };
    let flow = VortexFlow::new(&params).unwrap();
    let spots: Vec<_> = flow.positions().iter().map(|&p| (p, 0.5, 2.0)).collect();
    let render = |threads: usize, kind: NoiseKind| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| render_spots(300, 200, &spots, Noise::new(kind, 0.1), 9).unwrap())
    };
    for kind in [NoiseKind::Uniform, NoiseKind::Gaussian] {
        let (one, two) = (render(1, kind), render(2, kind));
        assert!(
            one.as_slice()
                .iter()
                .zip(two.as_slice())
                .all(|(a, b)| a.to_bits() == b.to_bits())
        );
    }
    let frame = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| VortexSequence::new(small(1)).unwrap().nth(2).unwrap())
    };
    assert_eq!(frame(1), frame(2));
}

#[test]
fn one_step_of_the_flow_is_eqs_13_to_16_about_the_image_centre() {
    let params = VortexParams {
        width: 1024,
        height: 1024,
        ..Default::default()
    };
    let centre = Point2::new(511.5, 511.5);
    let start = [Point2::new(611.5, 471.5), Point2::new(211.5, 900.0)];
    let mut flow = VortexFlow::with_positions(&params, &start).unwrap();
    for n in 0..3 {
        let before = flow.positions().to_vec();
        flow.advance();
        for (p, q) in before.iter().zip(flow.positions()) {
            let expected = centre + vortex_map(*p - centre, n, 0.01);
            assert!(expected.distance(*q) < 1e-9, "{expected:?} vs {q:?}");
        }
    }
    assert_eq!(flow.frame(), 3);
    assert_eq!(flow.track_ids(), &[0, 1]);
}

#[test]
fn a_particle_leaving_the_image_re_enters_opposite_as_a_new_identity() {
    // Frame 0, centred x = 500: Eq. 16 moves it down by 5 px, across the bottom edge.
    let params = VortexParams {
        width: 1024,
        height: 1024,
        n_frames: 3,
        ..Default::default()
    };
    let start = Point2::new(1011.5, 1021.0);
    let flow = VortexFlow::with_positions(&params, &[start]).unwrap();
    let frames: Vec<_> = VortexTruth::from_flow(flow, 3).collect();
    let after = frames[1].truth[0];
    assert_eq!(after.track_id, 1);
    assert!(
        (after.pos_px.y - (1021.0 + 5.0 - 1024.0)).abs() < 1e-3,
        "{after:?}"
    );
    assert!((after.pos_px.x - start.x).abs() < 1e-3, "{after:?}");
    // The wrap cuts the central difference around it.
    assert!(frames.iter().all(|f| f.truth[0].vel_px_per_frame.is_none()));
}

#[test]
fn intermittency_re_seeds_the_requested_share() {
    // δ = 0: nothing moves, so every new identity comes from intermittency.
    let params = VortexParams {
        n_particles: 20_000,
        delta: 0.0,
        intermittency: 0.3,
        ..Default::default()
    };
    let mut flow = VortexFlow::new(&params).unwrap();
    let (mut changed, mut total) = (0usize, 0usize);
    for _ in 0..5 {
        let before = flow.track_ids().to_vec();
        flow.advance();
        changed += before
            .iter()
            .zip(flow.track_ids())
            .filter(|(a, b)| a != b)
            .count();
        total += before.len();
    }
    let rate = changed as f64 / total as f64;
    assert!((rate - 0.3).abs() < 0.01, "re-seeded share {rate}");
}

#[test]
fn brownian_noise_scales_with_the_local_displacement() {
    let params = VortexParams {
        n_particles: 20_000,
        brownian: 0.5,
        ..Default::default()
    };
    let mut flow = VortexFlow::new(&params).unwrap();
    let centre = Point2::new(511.5, 511.5);
    let before = flow.positions().to_vec();
    let ids = flow.track_ids().to_vec();
    flow.advance();
    let mut ratios = Vec::new();
    for (slot, p) in before.iter().enumerate() {
        let c = *p - centre;
        let deterministic = vortex_map(c, 0, 0.01) - c;
        if flow.track_ids()[slot] == ids[slot] && deterministic.norm() > 1.0 {
            let xi = (flow.positions()[slot] - centre) - vortex_map(c, 0, 0.01);
            ratios.push(xi.x / deterministic.norm());
        }
    }
    let std = (ratios.iter().map(|r| r * r).sum::<f64>() / ratios.len() as f64).sqrt();
    assert!((std - 0.5).abs() < 0.02, "ξ / |d| has std {std}");
}

#[test]
fn truth_velocities_are_central_differences_of_the_truth_positions() {
    let params = VortexParams {
        n_frames: 6,
        n_particles: 300,
        ..Default::default()
    };
    let truth = VortexTruth::new(&params).unwrap();
    assert_eq!(truth.len(), 6);
    let frames: Vec<_> = truth.collect();
    assert_eq!(frames.len(), 6);
    assert!(frames[0].truth.iter().all(|p| p.vel_px_per_frame.is_none()));
    assert!(frames[5].truth.iter().all(|p| p.vel_px_per_frame.is_none()));
    let mut checked = 0;
    for t in 1..5 {
        assert_eq!(frames[t].index, t as u64);
        for (slot, p) in frames[t].truth.iter().enumerate() {
            let (before, after) = (frames[t - 1].truth[slot], frames[t + 1].truth[slot]);
            let same = before.track_id == p.track_id && after.track_id == p.track_id;
            assert_eq!(p.vel_px_per_frame.is_some(), same);
            if let Some(v) = p.vel_px_per_frame {
                assert_eq!(v, (after.pos_px - before.pos_px) / 2.0);
                checked += 1;
            }
        }
    }
    assert!(checked > 1000);
}

#[test]
fn measured_snr_matches_the_requested_one() {
    // One blob on a pixel centre: its peak pixel is A plus noise; the uniform noise spans
    // [0, A/SNR), the Gaussian one has std A/SNR.
    let spot = [(Point2::new(100.0, 100.0), 0.5, 2.0)];
    let uniform = render_spots(512, 512, &spot, Noise::new(NoiseKind::Uniform, 0.125), 1).unwrap();
    let background = |image: &sillage_core::GrayImage| -> Vec<f64> {
        (200..512)
            .flat_map(|y| image.row(y).iter().map(|&v| f64::from(v)))
            .collect::<Vec<_>>()
    };
    let noise = background(&uniform);
    let (lo, hi) = noise
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(
        (0.0..1e-3).contains(&lo) && (0.1249..0.125).contains(&hi),
        "{lo} {hi}"
    );
    let peak = f64::from(uniform.get(100, 100));
    assert!((0.5..0.625).contains(&peak));
    let snr = (peak - noise.iter().sum::<f64>() / noise.len() as f64) / hi;
    assert!((snr - 4.0).abs() < 0.5, "measured SNR {snr}");

    let gaussian =
        render_spots(512, 512, &spot, Noise::new(NoiseKind::Gaussian, 0.125), 1).unwrap();
    let noise = background(&gaussian);
    let mean = noise.iter().sum::<f64>() / noise.len() as f64;
    let std = (noise.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / noise.len() as f64).sqrt();
    assert!(
        mean.abs() < 1e-3 && (0.5 / std - 4.0).abs() < 0.02,
        "mean {mean}, std {std}"
    );
}

#[test]
fn default_flow_displacements_and_p_inverse() {
    let params = VortexParams {
        n_frames: 50,
        ..Default::default()
    };
    let stats = displacement_stats(&params).unwrap();
    assert!(stats.count > 40_000);
    assert!(stats.min_px >= 0.0 && stats.min_px < 0.5, "{stats:?}");
    assert!(stats.mean_px > 1.0 && stats.max_px < 20.0, "{stats:?}");
    let expected = stats.mean_px * (1000.0f64 / (1024.0 * 1024.0)).sqrt();
    assert!((stats.p_inverse - expected).abs() < 1e-12);
    assert_eq!(p_inverse(2.0, 100, 400.0), 1.0);
}

#[test]
fn particles_placed_outside_the_image_are_rejected() {
    let params = VortexParams::default();
    let err = VortexFlow::with_positions(&params, &[Point2::new(1024.0, 0.0)]).unwrap_err();
    assert!(err.to_string().contains("particle 0"), "{err}");
    assert!(
        VortexSequence::new(VortexParams {
            snr: -1.0,
            ..params
        })
        .is_err()
    );
}

//! Acceptance: the TracTrac paper's synthetic vortex (§4.1, Fig. 4), frames 1024², no
//! pre-processing, default parameters. The paper reports, for SNR ≥ 4 and N = 1000, fewer than
//! 5 % false recoveries with mean position and displacement errors below 0.2 px.

mod support;

use sillage::PipelineConfig;
use sillage::synth::vortex::VortexParams;
use support::{track_vortex, vortex_accuracy};

fn paper_vortex(snr: f64, seed: u64) -> VortexParams {
    VortexParams {
        snr,
        n_frames: 24,
        seed,
        ..VortexParams::default()
    }
}

#[test]
fn snr_4_and_10_meet_the_papers_figures() {
    for snr in [4.0, 10.0] {
        let accuracy = vortex_accuracy(&paper_vortex(snr, 7), &PipelineConfig::default());
        eprintln!("SNR {snr}:\n{accuracy}");
        let false_rate = accuracy.false_recovery_rate.expect("points were tracked");
        let true_rate = accuracy.true_recovery_rate.expect("truth has velocities");
        assert!(
            false_rate < 0.05,
            "SNR {snr}: false recoveries {false_rate}"
        );
        assert!(true_rate > 0.85, "SNR {snr}: true recoveries {true_rate}");
        assert!(accuracy.mean_position_error_px.unwrap() < 0.2);
        assert!(accuracy.mean_displacement_error_px.unwrap() < 0.2);
    }
}

#[test]
fn output_is_identical_for_one_and_two_threads() {
    let params = VortexParams {
        n_frames: 8,
        n_particles: 2000,
        ..VortexParams::default()
    };
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| track_vortex(&params, &PipelineConfig::default()).0)
    };
    let one = run(1);
    assert!(!one.is_empty());
    assert_eq!(one, run(2));
}

/// The paper's fast-flow claim (§4.1.2): false recoveries below 6 % at p⁻¹ ≈ 4.5, with
/// p⁻¹ = v̄_max·√(N/S) as its text defines it (δ = 0.2 gives v_max ≈ 145 px/frame against a
/// mean spacing of 32 px; v̄·√(N/S) with the mean displacement is 1.9). TracTrac's own
/// predictor (the default) fails here; displacement voting is what makes it work.
#[test]
fn fast_vortex_with_displacement_voting_meets_the_p_inverse_claim() {
    let params = VortexParams {
        delta: 0.2,
        ..paper_vortex(4.0, 7)
    };
    let stats = sillage::synth::vortex::displacement_stats(&params).expect("valid parameters");
    let p_inverse_max = stats.max_px * (params.n_particles as f64).sqrt()
        / ((params.width * params.height) as f64).sqrt();
    assert!(
        (4.2..4.8).contains(&p_inverse_max),
        "p⁻¹(max) = {p_inverse_max}"
    );

    let mut off = PipelineConfig::default();
    off.set("tracker.vote_search_px=off").expect("known key");
    let tractrac = vortex_accuracy(&params, &off);
    let automatic = vortex_accuracy(&params, &PipelineConfig::default());
    let mut config = PipelineConfig::default();
    config.set("tracker.vote_search_px=100").expect("known key");
    let voting = vortex_accuracy(&params, &config);
    config
        .set("tracker.ambiguity_ratio=0.5")
        .expect("known key");
    let voting_ratio = vortex_accuracy(&params, &config);
    eprintln!(
        "TracTrac's predictor:\n{tractrac}\nwith displacement voting:\n{voting}\n\
         and the ambiguity test:\n{voting_ratio}\nthe defaults (voting decided by itself):\n\
         {automatic}"
    );
    assert!(tractrac.false_recovery_rate.unwrap() > 0.5);
    assert!(voting.false_recovery_rate.unwrap() < 0.06);
    assert!(voting.true_recovery_rate.unwrap() > 0.6);
    assert!(voting.mean_position_error_px.unwrap() < 0.5);
    // The defaults measure the displacements on the first two frames and vote by themselves
    // (measured 73.6 % / 4.1 % since 2026-11-30 evening, when the vote began to widen by where
    // its displacements land; 63.5 % / 5.5 % before).
    assert!(automatic.false_recovery_rate.unwrap() < 0.06);
    assert!(automatic.true_recovery_rate.unwrap() > 0.6);
    // Voting alone leaves links whose far end is a neighbour within |v|/2 (mean displacement
    // error ≈ 1.1 px); the ambiguity test removes them, at the cost of recoveries.
    assert!(voting_ratio.false_recovery_rate.unwrap() < 0.06);
    assert!(voting_ratio.true_recovery_rate.unwrap() > 0.4);
    assert!(voting_ratio.mean_position_error_px.unwrap() < 0.5);
    assert!(voting_ratio.mean_displacement_error_px.unwrap() < 0.5);
}

/// Faster still (δ = 0.3, p⁻¹ ≈ 6.75): particles move further than even the automatic
/// vote's wide search, so both of its first votes land their points about at random. The
/// narrow one is aliased, and the wide one must be taken (voting then stays on over twice
/// its displacements); keeping the narrow one tracks nothing (1 % true, 97 % false).
#[test]
fn a_vortex_faster_than_every_first_vote_still_widens_it() {
    let params = VortexParams {
        delta: 0.3,
        ..paper_vortex(4.0, 11)
    };
    let automatic = vortex_accuracy(&params, &PipelineConfig::default());
    eprintln!("the defaults:\n{automatic}");
    assert!(automatic.true_recovery_rate.unwrap() > 0.3);
    assert!(automatic.false_recovery_rate.unwrap() < 0.25);
}

/// The paper's intermittency claim (§4.1.2, Fig. 4): at 50 % of the particles re-seeded at
/// random every frame, false recoveries stay at or below 12 %. TracTrac's adaptive outlier
/// threshold is inflated by the random links themselves; the ambiguity test is what works.
#[test]
fn intermittent_vortex_with_the_ambiguity_test_meets_the_papers_figure() {
    let params = VortexParams {
        intermittency: 0.5,
        ..paper_vortex(4.0, 7)
    };
    let mut off = PipelineConfig::default();
    off.set("tracker.vote_search_px=off").expect("known key");
    let tractrac = vortex_accuracy(&params, &off);
    let mut config = PipelineConfig::default();
    config
        .set("tracker.ambiguity_ratio=0.3")
        .expect("known key");
    let ratio = vortex_accuracy(&params, &config);
    eprintln!("TracTrac's filter:\n{tractrac}\nwith the ambiguity test:\n{ratio}");
    assert!(tractrac.false_recovery_rate.unwrap() > 0.3);
    assert!(ratio.false_recovery_rate.unwrap() <= 0.12);
    assert!(ratio.true_recovery_rate.unwrap() > 0.85);
    assert!(ratio.mean_position_error_px.unwrap() < 0.2);
    assert!(ratio.mean_displacement_error_px.unwrap() < 0.2);
}

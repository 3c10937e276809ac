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

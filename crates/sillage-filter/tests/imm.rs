//! The Kalman IMM against a two-step example computed by hand (every number derived below, to
//! 1e-12), and the bedload IMM built from the model's parameters.

use sillage_core::Point2;
use sillage_filter::{
    BedloadModel, BedloadParams, Gaussian, KalmanImm, LinearGaussian, Matrix, Noise2,
    PositionMeasurement, TransitionTable, Vector,
};

fn close(actual: f64, expected: f64, what: &str) {
    assert!(
        (actual - expected).abs() < 1e-12,
        "{what}: {actual} vs hand-computed {expected}"
    );
}

/// State (x, y, u, v). Model A is constant position, model B constant velocity; both have
/// Q = diag(1, 1, 0, 0). The velocity starts known exactly (u = 1, v = 0, zero variance) and,
/// with no velocity noise, stays so in both modes, so every covariance is diag(pₓ, p_y, 0, 0)
/// and the y axis (z_y = 0, same variances in both modes) cancels from the mode probabilities.
/// π = [[0.9, 0.1], [0.2, 0.8]], μ⁰ = (0.5, 0.5), R = 2·I, x⁰ = (0, 0, 1, 0), P⁰ = diag(1, 1, 0, 0).
///
/// Step 1, z₁ = (2, 0).
/// - Mixing: c_A = 0.9·0.5 + 0.2·0.5 = 0.55, c_B = 0.45; both modes hold the same belief, so
///   the mixed beliefs are x⁰, P⁰.
/// - Predictions: A: x = 0, B: x = 0 + u = 1; both pₓ = 1 + 1 = 2, p_y = 2.
/// - Updates: S = 2·I + 2·I = 4·I, gain ½ on the position: A: ν = 2, x = 0 + ½·2 = 1;
///   B: ν = 1, x = 1 + ½·1 = 1.5; pₓ = 2·2/4 = 1 for both. y stays 0, p_y = 1.
/// - ln Λ_A = −½·(4/4) − ½·ln 16 − ln 2π, ln Λ_B = −½·(1/4) − ½·ln 16 − ln 2π.
/// - μ_A = 0.55·e^(−1/2) / (0.55·e^(−1/2) + 0.45·e^(−1/8)) = 0.45652771426364613,
///   μ_B = 0.5434722857363538; the mixture log-likelihood ln(0.55Λ_A + 0.45Λ_B) =
///   −3.537902557820567.
/// - Combination: x = μ_A·1 + μ_B·1.5 = 1.2717361428681768,
///   pₓ = 1 + μ_A·μ_B·0.5² = 1.062027540093214.
///
/// Step 2, z₂ = (2.5, 0).
/// - Mixing: c_A = 0.9μ_A + 0.2μ_B = 0.5195693999845523, c_B = 0.4804306000154477;
///   μ_{A|A} = 0.9μ_A/c_A = 0.7907989632366678, μ_{B|A} = 0.20920103676333215,
///   μ_{A|B} = 0.1μ_A/c_B = 0.09502469539803815, μ_{B|B} = 0.9049753046019617;
///   x⁰_A = μ_{A|A}·1 + μ_{B|A}·1.5 = 1.104600518381666, p⁰_A = 1 + μ_{A|A}μ_{B|A}·0.25 =
///   1.0413589907451197; x⁰_B = 1.4524876523009809, p⁰_B = 1.021498750665637.
/// - Predictions: A: x = 1.104600518381666, pₓ = 2.0413589907451195;
///   B: x = x⁰_B + 1 = 2.452487652300981, pₓ = 2.021498750665637.
/// - Updates: Sₓ = pₓ + 2 (A: 4.0413589907451195, B: 4.0214987506656374), S_y = 4;
///   ν_A = 1.395399481618334, ν_B = 0.04751234769901913;
///   ln Λ_j = −½ν_j²/Sₓ − ½ln(4Sₓ) − ln 2π: A −3.4702163589743327, B −3.227132244706061;
///   x_A = 1.104600518381666 + (pₓ/Sₓ)·ν_A = 1.8094404704883398, pₓ = 2pₓ/Sₓ =
///   1.0102339314175834; x_B = 2.476370825582798, pₓ = 1.005345954828925.
/// - μ_A = c_AΛ_A / Σ = 0.4589013099461159, μ_B = 0.5410986900538841; ln Σ = −3.346051143328478.
/// - Combination: x = 2.1703156119871228, pₓ = Σ μ_j (p_j + (x_j − x)²) = 1.1180367722012257;
///   y = 0, p_y = 1, u = 1, v = 0 with zero variance.
#[test]
fn two_step_example_computed_by_hand() {
    let q = Matrix::diagonal([1.0, 1.0, 0.0, 0.0]);
    let constant_position = LinearGaussian {
        transition: Matrix::identity(),
        noise: q,
    };
    let constant_velocity = LinearGaussian {
        transition: Matrix([
            [1.0, 0.0, 1.0, 0.0],
            [0.0, 1.0, 0.0, 1.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]),
        noise: q,
    };
    let table = TransitionTable::new("pi", &[[0.9, 0.1], [0.2, 0.8]]).unwrap();
    let initial = Gaussian {
        mean: Vector::from_array([0.0, 0.0, 1.0, 0.0]),
        cov: Matrix::diagonal([1.0, 1.0, 0.0, 0.0]),
    };
    let mut imm = KalmanImm::new(
        vec![constant_position, constant_velocity],
        table,
        initial,
        &[0.5, 0.5],
    )
    .unwrap();
    let r = PositionMeasurement::new("r", &Noise2::diagonal(2.0, 2.0)).unwrap();

    imm.predict();
    close(imm.mode_probabilities()[0], 0.55, "step 1 c_A");
    close(
        imm.mode_filters()[1].state.mean.at(0),
        1.0,
        "step 1 predicted x_B",
    );
    close(
        imm.mode_filters()[0].state.cov.0[0][0],
        2.0,
        "step 1 predicted p_A",
    );
    let ll = imm.update(Point2::new(2.0, 0.0), &r);
    close(ll, -3.537902557820567, "step 1 log-likelihood");
    close(
        imm.mode_probabilities()[0],
        0.45652771426364613,
        "step 1 μ_A",
    );
    close(
        imm.mode_probabilities()[1],
        0.5434722857363538,
        "step 1 μ_B",
    );
    close(imm.mode_filters()[0].state.mean.at(0), 1.0, "step 1 x_A");
    close(imm.mode_filters()[1].state.mean.at(0), 1.5, "step 1 x_B");
    let e = imm.estimate();
    close(e.mean.at(0), 1.2717361428681768, "step 1 x");
    close(e.cov.0[0][0], 1.062027540093214, "step 1 pₓ");
    close(e.cov.0[1][1], 1.0, "step 1 p_y");

    imm.predict();
    close(
        imm.mode_probabilities()[0],
        0.5195693999845523,
        "step 2 c_A",
    );
    close(
        imm.mode_probabilities()[1],
        0.4804306000154477,
        "step 2 c_B",
    );
    close(
        imm.mode_filters()[0].state.mean.at(0),
        1.104600518381666,
        "step 2 predicted x_A",
    );
    close(
        imm.mode_filters()[0].state.cov.0[0][0],
        2.0413589907451195,
        "step 2 predicted p_A",
    );
    close(
        imm.mode_filters()[1].state.mean.at(0),
        2.452487652300981,
        "step 2 predicted x_B",
    );
    close(
        imm.mode_filters()[1].state.cov.0[0][0],
        2.021498750665637,
        "step 2 predicted p_B",
    );
    let ll = imm.update(Point2::new(2.5, 0.0), &r);
    close(ll, -3.346051143328478, "step 2 log-likelihood");
    close(
        imm.mode_probabilities()[0],
        0.4589013099461159,
        "step 2 μ_A",
    );
    close(
        imm.mode_filters()[0].state.mean.at(0),
        1.8094404704883398,
        "step 2 x_A",
    );
    close(
        imm.mode_filters()[0].state.cov.0[0][0],
        1.0102339314175834,
        "step 2 p_A",
    );
    close(
        imm.mode_filters()[1].state.mean.at(0),
        2.476370825582798,
        "step 2 x_B",
    );
    close(
        imm.mode_filters()[1].state.cov.0[0][0],
        1.005345954828925,
        "step 2 p_B",
    );
    let e = imm.estimate();
    close(e.mean.at(0), 2.1703156119871228, "step 2 x");
    close(e.cov.0[0][0], 1.1180367722012257, "step 2 pₓ");
    close(e.mean.at(1), 0.0, "step 2 y");
    close(e.cov.0[1][1], 1.0, "step 2 p_y");
    close(e.mean.at(2), 1.0, "step 2 u");
    close(e.cov.0[2][2], 0.0, "step 2 p_u");
    close(e.cov.0[0][2], 0.0, "step 2 p_xu");
}

#[test]
fn bedload_imm_follows_a_rolling_bead() {
    let model = BedloadModel::new(BedloadParams::default()).unwrap();
    let mut imm = model.kalman_imm(Gaussian {
        mean: Vector::from_array([100.0, 50.0, 0.0, 0.0]),
        cov: Matrix::diagonal([3.0, 3.0, 25.0, 25.0]),
    });
    // The unknown row (⅓ each) is the start, as for the particles (§4.3).
    for &p in imm.mode_probabilities() {
        close(p, 1.0 / 3.0, "initial mode probability");
    }
    let r = PositionMeasurement::new("r", &Noise2::diagonal(3.0, 3.0)).unwrap();
    for t in 1..=20 {
        imm.predict();
        // Rolling at 4 px/frame along x, on the bed (constant y).
        let ll = imm.update(Point2::new(100.0 + 4.0 * t as f64, 50.0), &r);
        assert!(ll.is_finite());
    }
    let mu = imm.mode_probabilities();
    assert!((mu.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    // Rolling (index 1) explains a bed-parallel motion best: no vertical velocity noise
    // beyond its own, and the resting model cannot move 4 px/frame.
    assert!(mu[1] > mu[0] && mu[1] > mu[2], "{mu:?}");
    let e = imm.estimate();
    assert!((e.mean.at(2) - 4.0).abs() < 0.5, "u = {}", e.mean.at(2));
}

//! Resamplers preserve expected counts: over R draws with a fixed seed, the mean number of
//! copies of particle i is N·wᵢ within a stated bound, and each scheme has its own structure.

use sillage_core::rng_stream;
use sillage_filter::{ResampleScheme, Resampler};

const N: usize = 40;
const DRAWS: usize = 4_000;
const SCHEMES: [ResampleScheme; 4] = [
    ResampleScheme::Multinomial,
    ResampleScheme::Systematic,
    ResampleScheme::Stratified,
    ResampleScheme::Residual,
];

/// Normalised weights with zeros, tiny ones and one dominant particle.
fn weights() -> Vec<f64> {
    let raw: Vec<f64> = (0..N)
        .map(|i| match i {
            0 | 17 | 39 => 0.0,
            5 => 12.0,
            9 | 10 => 1e-3,
            _ => 0.5 + ((i * 7) % 11) as f64 / 10.0,
        })
        .collect();
    let total: f64 = raw.iter().sum();
    raw.iter().map(|w| w / total).collect()
}

/// `counts[d][i]`: copies of particle i in draw d.
fn counts(scheme: ResampleScheme, w: &[f64]) -> Vec<Vec<u32>> {
    let mut rng = rng_stream(2024, scheme as u64);
    let mut resampler = Resampler::default();
    (0..DRAWS)
        .map(|_| {
            let mut scratch = w.to_vec();
            let mut c = vec![0u32; N];
            for &a in resampler.draw(scheme, &mut scratch, &mut rng) {
                c[a as usize] += 1;
            }
            c
        })
        .collect()
}

/// Unbiasedness: |mean count − N·wᵢ| ≤ 5·√(N·wᵢ(1 − wᵢ)/R). The binomial variance
/// N·wᵢ(1 − wᵢ) is that of multinomial resampling and bounds the other three schemes' count
/// variance (Douc & Cappé 2005), so 5 standard errors of the mean: a false alarm has
/// probability < 3e-5 over the 40 particles, and a bias of 2 % of a count fails.
#[test]
fn every_scheme_preserves_expected_counts() {
    let w = weights();
    for scheme in SCHEMES {
        let c = counts(scheme, &w);
        for i in 0..N {
            let expected = N as f64 * w[i];
            let mean = c.iter().map(|d| f64::from(d[i])).sum::<f64>() / DRAWS as f64;
            let bound = 5.0 * (expected * (1.0 - w[i]) / DRAWS as f64).sqrt() + 1e-12;
            assert!(
                (mean - expected).abs() <= bound,
                "{scheme:?}: particle {i} mean count {mean}, expected {expected} ± {bound}"
            );
            if w[i] == 0.0 {
                assert!(c.iter().all(|d| d[i] == 0), "{scheme:?} drew a zero weight");
            }
        }
        assert!(c.iter().all(|d| d.iter().sum::<u32>() == N as u32));
    }
}

/// Structure: systematic gives ⌊N·wᵢ⌋ or ⌈N·wᵢ⌉ copies, residual at least ⌊N·wᵢ⌋.
#[test]
fn systematic_and_residual_keep_the_deterministic_part() {
    let w = weights();
    for (scheme, c) in [
        (
            ResampleScheme::Systematic,
            counts(ResampleScheme::Systematic, &w),
        ),
        (
            ResampleScheme::Residual,
            counts(ResampleScheme::Residual, &w),
        ),
    ] {
        for i in 0..N {
            let expected = N as f64 * w[i];
            for d in &c {
                let k = f64::from(d[i]);
                assert!(
                    k >= expected.floor() - 1e-9,
                    "{scheme:?}: {k} < ⌊{expected}⌋"
                );
                if scheme == ResampleScheme::Systematic {
                    assert!(
                        k <= expected.ceil() + 1e-9,
                        "{scheme:?}: {k} > ⌈{expected}⌉"
                    );
                }
            }
        }
    }
}

/// Multinomial is multinomial: Pearson's statistic Σ (nᵢ − N·wᵢ)²/(N·wᵢ) has mean k − 1 over the
/// k particles of positive weight (here all expected counts are ≥ 0.4, k = 40), with variance
/// ≈ Σ (2 + 1/(N·wᵢ)) per draw; the mean over R draws must be within 5 of its standard errors.
/// Systematic resampling, far less random, must come out well below.
#[test]
fn multinomial_counts_have_multinomial_spread() {
    let raw: Vec<f64> = (0..N).map(|i| 1.0 + (i % 7) as f64).collect();
    let total: f64 = raw.iter().sum();
    let w: Vec<f64> = raw.iter().map(|x| x / total).collect();
    let pearson = |scheme| {
        counts(scheme, &w)
            .iter()
            .map(|d| {
                (0..N)
                    .map(|i| {
                        let e = N as f64 * w[i];
                        (f64::from(d[i]) - e).powi(2) / e
                    })
                    .sum::<f64>()
            })
            .sum::<f64>()
            / DRAWS as f64
    };
    let k = N as f64;
    let per_draw_var: f64 = w.iter().map(|wi| 2.0 + 1.0 / (N as f64 * wi)).sum();
    let bound = 5.0 * (per_draw_var / DRAWS as f64).sqrt();
    let multinomial = pearson(ResampleScheme::Multinomial);
    assert!(
        (multinomial - (k - 1.0)).abs() <= bound,
        "multinomial Pearson mean {multinomial}, expected {} ± {bound}",
        k - 1.0
    );
    let systematic = pearson(ResampleScheme::Systematic);
    assert!(
        systematic < 0.5 * (k - 1.0),
        "systematic Pearson mean {systematic}"
    );
}

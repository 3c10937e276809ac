//! The block Box–Muller normals against the normal distribution: a χ² test over 34 bins
//! (probabilities from Simpson integration of the density), the moments, and the far tail.

use sillage_core::rng_stream;
use sillage_filter::Normals;

const DRAWS: usize = 1_000_000;

/// `P(a < Z < b)` for `Z ~ N(0, 1)` by composite Simpson integration (error < 1e-12 here).
fn probability(a: f64, b: f64) -> f64 {
    let steps = 2_000;
    let h = (b - a) / steps as f64;
    let f = |x: f64| (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let inner: f64 = (1..steps)
        .map(|k| f(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + f(b) + inner) * h / 3.0
}

fn draws(seed: u64) -> Vec<f64> {
    let mut rng = rng_stream(seed, 0);
    let mut normals = Normals::new(&mut rng);
    let mut out = Vec::with_capacity(DRAWS);
    while out.len() < DRAWS {
        let (a, b) = normals.pair();
        out.extend([a, b]);
    }
    out
}

/// Pearson's χ² over bins of width 0.25 on [−4, 4] plus the two tails: 33 degrees of freedom,
/// mean 33, standard deviation √66 ≈ 8.1; the bound 33 + 5·8.1 = 74 fails a sampler whose bin
/// probabilities are off by ~1 % (e.g. a missing wedge or tail).
#[test]
fn histogram_matches_the_normal_density() {
    let z = draws(1);
    let mut edges: Vec<f64> = (0..=32).map(|k| -4.0 + 0.25 * k as f64).collect();
    edges.insert(0, f64::NEG_INFINITY);
    edges.push(f64::INFINITY);
    let mut counts = vec![0usize; edges.len() - 1];
    for &x in &z {
        let bin = edges.partition_point(|&e| e <= x) - 1;
        counts[bin] += 1;
    }
    let tail = probability(-12.0, -4.0);
    let chi2: f64 = counts
        .iter()
        .enumerate()
        .map(|(k, &c)| {
            let p = match k {
                0 => tail,
                k if k == counts.len() - 1 => tail,
                k => probability(edges[k], edges[k + 1]),
            };
            let expected = p * DRAWS as f64;
            (c as f64 - expected).powi(2) / expected
        })
        .sum();
    assert!(chi2 < 74.0, "χ² = {chi2} over 33 degrees of freedom");
}

/// Mean, variance and kurtosis to 5 standard errors (√(1/n), √(2/n), √(96/n)), and the tail
/// beyond |z| > 3.5 (p = 4.65e-4, the part a truncated or too coarse radius would miss) to 5
/// binomial errors.
#[test]
fn moments_and_tail() {
    let z = draws(2);
    let n = DRAWS as f64;
    let mean = z.iter().sum::<f64>() / n;
    let var = z.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    let m4 = z.iter().map(|x| (x - mean).powi(4)).sum::<f64>() / n;
    assert!(mean.abs() < 5.0 / n.sqrt(), "mean {mean}");
    assert!((var - 1.0).abs() < 5.0 * (2.0 / n).sqrt(), "variance {var}");
    assert!(
        (m4 - 3.0).abs() < 5.0 * (96.0 / n).sqrt(),
        "fourth moment {m4}"
    );
    let p = 2.0 * probability(3.5, 12.0);
    let tail = z.iter().filter(|x| x.abs() > 3.5).count() as f64 / n;
    assert!(
        (tail - p).abs() < 5.0 * (p * (1.0 - p) / n).sqrt(),
        "tail {tail} vs {p}"
    );
    assert!(z.iter().all(|x| x.is_finite()));
}

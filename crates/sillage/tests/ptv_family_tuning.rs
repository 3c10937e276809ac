//! How the PTV defaults measured from the images were chosen: variants of the automatic blob
//! scale on the **tune** halves of both `sillage bench ptv-accuracy` families (never the
//! report halves), each case's true / false recoveries printed beside the best of the grid
//! search ("tuned"), then per variant the cases within 2 points of tuned and the mean.
//! Ignored (a few minutes in release mode):
//! `cargo test --release -p sillage --test ptv_family_tuning -- --ignored --nocapture`.
//!
//! `AUTO_VOTE_MIN_VALID_SHARE` and `AUTO_VOTE_FIRST_LINK_SPACINGS` (tracker) and
//! `FLAT_PEAK_SIGMAS` (the matched-scale re-fit, `sillage_detect::matched_refine`) are
//! constants, not configuration keys: they were tuned by editing them and running
//! `sillage bench ptv-accuracy --family moderate --half tune --no-search` (the last one also
//! with `--family main`). `AUTO_SCALE_BASE_PX` was first chosen here (δ explicit, without the
//! matched-scale second look), then again by editing the constant with the second look as it
//! runs (twins merged), on both families' tune halves the same way.

use sillage::DetectorConfig;
use sillage::PipelineConfig;
use sillage::detect::blob::Scale;
use sillage::ptv_accuracy_bench::{Half, Variant, family, moderate_family, run_case, sweep};

/// `δ = √(base · σ̂)`, given explicitly (so without the matched-scale second look).
fn geometric(base: f64) -> impl Fn(&mut PipelineConfig, f64) {
    move |config, sigma| {
        if let DetectorConfig::Blob(blob) = &mut config.detector {
            blob.scale_px = Scale::Px((base * sigma).sqrt().max(0.5));
        }
    }
}

#[test]
#[ignore]
fn blob_scale_variants_on_the_tune_halves() {
    let bases = [0.4, 0.5, 0.6, 0.7, 0.8];
    let variants: Vec<_> = bases.iter().map(|&b| geometric(b)).collect();
    let functions: Vec<Variant<'_>> = variants.iter().map(|v| v as Variant<'_>).collect();
    let mut within = vec![0usize; bases.len()];
    let mut sums = vec![(0.0, 0.0); bases.len()];
    let tune: Vec<_> = moderate_family()
        .into_iter()
        .chain(family())
        .filter(|c| c.half == Half::Tune)
        .collect();
    for case in &tune {
        let tuned = run_case(case, 512, 10, true, &PipelineConfig::default())
            .unwrap()
            .tuned
            .unwrap()
            .1;
        let results = sweep(case, 512, 10, &functions).unwrap();
        let line: Vec<String> = results
            .iter()
            .map(|r| format!("{:>5.1}/{:<5.1}", r.true_pct, r.false_pct))
            .collect();
        println!(
            "{:<24} tuned {:>5.1}/{:<5.1} {}",
            case.name,
            tuned.true_pct,
            tuned.false_pct,
            line.join(" ")
        );
        for (k, r) in results.iter().enumerate() {
            within[k] += usize::from(r.near(&tuned));
            sums[k].0 += r.true_pct;
            sums[k].1 += r.false_pct;
        }
    }
    let n = tune.len() as f64;
    for (k, base) in bases.iter().enumerate() {
        println!(
            "δ = √({base}σ̂): within 2 points of tuned in {} of {}; mean true {:.1} %, false {:.1} %",
            within[k],
            tune.len(),
            sums[k].0 / n,
            sums[k].1 / n
        );
    }
}

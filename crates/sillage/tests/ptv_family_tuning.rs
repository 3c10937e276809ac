//! How the PTV defaults measured from the images were chosen: variants of the defaults on the
//! **tune** half of the `sillage bench ptv-accuracy` family (never the report half), their
//! mean true / false recoveries printed side by side. Ignored (a minute in release mode):
//! `cargo test --release -p sillage --test ptv_family_tuning -- --ignored --nocapture`.

use sillage::PipelineConfig;
use sillage::detect::blob::Scale;
use sillage::ptv_accuracy_bench::{Half, Variant, family, sweep};
use sillage::{DetectorConfig, TrackerConfig};

fn scale(factor: f64, k: f64) -> impl Fn(&mut PipelineConfig, f64) {
    move |config, sigma| {
        if let DetectorConfig::Blob(blob) = &mut config.detector {
            blob.scale_px = Scale::Px((factor * sigma).max(0.5));
            blob.threshold = sillage::detect::Threshold::Noise { k };
        }
    }
}

fn filter_std(value: f64) -> impl Fn(&mut PipelineConfig, f64) {
    move |config, _| {
        if let TrackerConfig::Ptv(ptv) = &mut config.tracker {
            ptv.filter_std = value;
        }
    }
}

fn geometric(base: f64) -> impl Fn(&mut PipelineConfig, f64) {
    move |config, sigma| {
        if let DetectorConfig::Blob(blob) = &mut config.detector {
            blob.scale_px = Scale::Px((base * sigma).sqrt().max(0.5));
        }
    }
}

#[test]
#[ignore]
fn variants_on_the_tune_half() {
    let defaults = |_: &mut PipelineConfig, _: f64| {};
    let (g08, g10, g12, g15) = (
        geometric(0.8),
        geometric(1.0),
        geometric(1.2),
        geometric(1.5),
    );
    let f07 = scale(0.7, 4.0);
    let g12_std2 = |c: &mut PipelineConfig, s: f64| {
        g12(c, s);
        filter_std(2.0)(c, s);
    };
    let variants: [(&str, Variant<'_>); 7] = [
        ("defaults", &defaults),
        ("δ=0.7σ̂", &f07),
        ("δ=√(0.8σ̂)", &g08),
        ("δ=√(1.0σ̂)", &g10),
        ("δ=√(1.2σ̂)", &g12),
        ("δ=√(1.5σ̂)", &g15),
        ("δ=√(1.2σ̂) std2", &g12_std2),
    ];
    let functions: Vec<Variant<'_>> = variants.iter().map(|(_, v)| *v).collect();
    let mut sums = vec![(0.0, 0.0); variants.len()];
    let tune: Vec<_> = family()
        .into_iter()
        .filter(|c| c.half == Half::Tune)
        .collect();
    for case in &tune {
        let results = sweep(case, 512, 10, &functions).unwrap();
        let line: Vec<String> = results
            .iter()
            .map(|r| format!("{:>5.1}/{:<5.1}", r.true_pct, r.false_pct))
            .collect();
        println!("{:<22} {}", case.name, line.join(" "));
        for (sum, r) in sums.iter_mut().zip(&results) {
            sum.0 += r.true_pct;
            sum.1 += r.false_pct;
        }
    }
    let n = tune.len() as f64;
    for ((name, _), (t, f)) in variants.iter().zip(sums) {
        println!("{name:<18} mean true {:.1} %, false {:.1} %", t / n, f / n);
    }
}

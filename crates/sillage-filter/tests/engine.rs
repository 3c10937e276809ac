//! The SIR engine: weight underflow and its counted recovery, the ESS trigger, the phases a
//! tracker drives, and identical results for any number of threads.

use sillage_core::{Point2, Vec2};
use sillage_filter::{
    BedloadModel, BedloadParams, FilterParams, FilterSpec, Particle, ParticleFilter,
    ResampleScheme, Resampling, step_all,
};

fn bedload() -> BedloadModel {
    BedloadModel::new(BedloadParams::default()).unwrap()
}

fn spec(particles: usize, resampling: Resampling) -> FilterSpec {
    FilterSpec::new(
        &FilterParams {
            particles,
            resampling,
        },
        11,
    )
    .unwrap()
}

#[test]
fn all_zero_weights_recover_to_uniform_and_are_counted() {
    let model = bedload();
    let mut filter =
        spec(200, Resampling::default()).spawn(3, &model.initial_spread(Point2::new(50.0, 50.0)));
    // A likelihood that rules out every particle: the event is reported and counted.
    let report = filter.step(&model, |_| f64::NEG_INFINITY);
    assert!(report.recovered && report.resampled);
    assert_eq!(report.log_evidence, f64::NEG_INFINITY);
    assert_eq!(filter.weight_recoveries(), 1);
    let uniform = -(200f64).ln();
    assert!(
        filter
            .particles()
            .log_weights()
            .iter()
            .all(|&w| (w - uniform).abs() < 1e-12)
    );
    assert!(filter.particles().pos_x().iter().all(|x| x.is_finite()));
    // NaN counts as zero too.
    let report = filter.step(&model, |_| f64::NAN);
    assert!(report.recovered);
    assert_eq!(filter.weight_recoveries(), 2);
    // Likelihoods far below exp's underflow (e^-1e6 = 0 in f64) are not zero in the log
    // domain: no recovery, and the ratios survive (half the particles 1e6 + ln 4 lower).
    filter.predict(&model);
    filter.weight(|p: Particle| {
        if p.pos_px.x < 50.0 {
            -1e6
        } else {
            -1e6 - 4f64.ln()
        }
    });
    let report = filter.last_report();
    assert!(!report.recovered && report.log_evidence.is_finite());
    assert_eq!(filter.weight_recoveries(), 2);
    let particles = filter.particles();
    let weight_where = |left: bool| {
        particles
            .pos_x()
            .iter()
            .zip(particles.log_weights())
            .find(|(x, _)| (**x < 50.0) == left)
            .map(|(_, &w)| w)
            .expect("particles on both sides of x = 50")
    };
    assert!((weight_where(true) - weight_where(false) - 4f64.ln()).abs() < 1e-9);
}

#[test]
fn ess_trigger_skips_flat_weights_and_resamples_peaked_ones() {
    let model = bedload();
    let policy = Resampling {
        scheme: ResampleScheme::Systematic,
        ess_fraction: Some(0.5),
    };
    let mut filter = spec(500, policy).spawn(1, &model.initial_spread(Point2::new(0.0, 0.0)));
    let report = filter.step(&model, |_| -2.0);
    assert!((report.ess - 500.0).abs() < 1e-9 && !report.resampled);
    // Weights kept (not reset) when not resampled: one particle far more likely than the rest.
    let report = filter.step(&model, |p: Particle| {
        -(p.pos_px.x.powi(2) + p.pos_px.y.powi(2))
    });
    assert!(report.ess < 250.0 && report.resampled, "{report:?}");
}

#[test]
fn phases_track_length_and_observed_velocity() {
    let model = bedload();
    let mut filter =
        spec(100, Resampling::default()).spawn(9, &model.initial_spread(Point2::new(5.0, 5.0)));
    assert_eq!((filter.track_id(), filter.track_len()), (9, 1));
    filter.predict(&model);
    assert_eq!(filter.track_len(), 2);
    // §3.5.2: the observed velocity is set on every particle at the weighting step.
    filter.particles_mut().set_velocity(Vec2::new(-3.0, 1.0));
    filter.weight(|p: Particle| -(p.pos_px - Point2::new(5.0, 5.0)).norm());
    assert!(filter.resample());
    assert!(!filter.resample(), "one weighting is resampled once");
    let estimate = filter.estimate();
    assert!((estimate.mean.at(2) + 3.0).abs() < 1e-12 && (estimate.mean.at(3) - 1.0).abs() < 1e-12);
    assert!(estimate.cov.0[2][2].abs() < 1e-20);
    let mut probabilities = [0.0; 5];
    filter.particles().mode_probabilities(&mut probabilities);
    assert!((probabilities.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    assert_eq!(
        probabilities[0], 0.0,
        "no particle stays unknown after a prediction"
    );
    filter.reinitialise(&model.initial_spread(Point2::new(1.0, 1.0)));
    assert_eq!(filter.track_len(), 1);
}

/// Runs 12 steps of 23 bedload targets (some missed: uniform likelihood, some impossible) and
/// returns every column of every filter, bit for bit.
fn run(threads: usize) -> (Vec<Vec<u64>>, Vec<u64>) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let model = bedload();
    let spec = spec(300, Resampling::default());
    let start = |k: usize| Point2::new(30.0 * k as f64, 10.0 + k as f64);
    let mut filters: Vec<ParticleFilter> = (0..23)
        .map(|k| spec.spawn(1000 + k as u64, &model.initial_spread(start(k))))
        .collect();
    pool.install(|| {
        for t in 1..=12 {
            step_all(&mut filters, &model, |k| {
                let z = start(k) + Vec2::new(-2.0 * t as f64, 0.5);
                move |p: Particle| match k % 5 {
                    0 => 0.0,
                    4 if t == 6 => f64::NEG_INFINITY,
                    _ => -(p.pos_px - z).norm().powi(2) / 6.0,
                }
            });
        }
    });
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let columns = filters
        .iter()
        .flat_map(|f| {
            let p = f.particles();
            [
                bits(p.pos_x()),
                bits(p.pos_y()),
                bits(p.vel_x()),
                bits(p.vel_y()),
                bits(p.log_weights()),
                p.modes().iter().map(|&m| u64::from(m)).collect(),
            ]
        })
        .collect();
    let counters = filters
        .iter()
        .map(ParticleFilter::weight_recoveries)
        .collect();
    (columns, counters)
}

#[test]
fn identical_output_for_one_and_three_threads() {
    let (one, recoveries) = run(1);
    let (three, recoveries_three) = run(3);
    assert_eq!(one, three);
    assert_eq!(recoveries, recoveries_three);
    // Targets 4, 9, 14 and 19 had one impossible frame.
    assert_eq!(recoveries.iter().sum::<u64>(), 4);
}

//! CLEAR MOT + Identity + HOTA: on TUD-Stadtmitte (py-motmetrics' reference files) and on
//! synthetic sequences of 10^5 to 10^6 truth rows against as many estimates (linear time);
//! on a packed bead bed, where slightly overlapping discs make each frame's similarity graph
//! one large sparse component.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use sillage_eval::mot::{
    MotChallengeProtocol, MotData, MotEstimate, MotParams, MotTruth, Shape, Similarity, TruthRole,
    evaluate_mot,
};
use sillage_io::{MotRow, read_mot_rows};

#[path = "../tests/common/scene.rs"]
mod scene;

const TUD: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/motmetrics_tud_reference/TUD-Stadtmitte"
);

fn shape(row: &MotRow) -> Shape {
    Shape::Box(row.bbox())
}

fn tud() -> (Vec<MotTruth>, Vec<MotEstimate>) {
    let gt = read_mot_rows(format!("{TUD}/gt.txt")).expect("TUD-Stadtmitte gt.txt");
    let test = read_mot_rows(format!("{TUD}/test.txt")).expect("TUD-Stadtmitte test.txt");
    let truth = gt
        .iter()
        .map(|r| MotTruth {
            frame: r.frame,
            id: r.id.unwrap_or_default(),
            shape: shape(r),
            role: MotChallengeProtocol::Mot15.truth_role(r.confidence.unwrap_or(1.0), r.class),
        })
        .collect();
    let estimates = test
        .iter()
        .map(|r| MotEstimate {
            frame: r.frame,
            id: r.id.unwrap_or_default(),
            shape: shape(r),
        })
        .collect();
    (truth, estimates)
}

fn bench_tud(c: &mut Criterion) {
    let (truth, estimates) = tud();
    let params = MotParams::default();
    let data = MotData::new(&truth, &estimates, Similarity::BoxIou, None).unwrap();
    let mut group = c.benchmark_group("mot/TUD-Stadtmitte");
    group.throughput(Throughput::Elements(truth.len() as u64));
    group.bench_function("metrics", |b| {
        b.iter(|| evaluate_mot(&data, &params).unwrap())
    });
    group.bench_function("prepare+metrics", |b| {
        b.iter(|| {
            let data = MotData::new(&truth, &estimates, Similarity::BoxIou, None).unwrap();
            evaluate_mot(&data, &params).unwrap()
        })
    });
    group.finish();
}

fn bench_synthetic(c: &mut Criterion) {
    let params = MotParams::default();
    let mut group = c.benchmark_group("mot/synthetic");
    group.sample_size(10);
    // 20 objects per frame living ~200 frames; the tracker misses 5 %, adds one false
    // positive per frame, switches id every 150 frames, with 2 px noise.
    for rows in [100_000u64, 300_000, 1_000_000] {
        let spec = scene::SceneSpec {
            frames: rows / 20,
            objects_per_frame: 20,
            lifetime: 200,
            miss_rate: 0.05,
            false_positives: 1,
            switch_every: 150,
            noise_px: 2.0,
            seed: 7,
        };
        let (truth, estimates) = scene::scene(&spec);
        group.throughput(Throughput::Elements(rows));
        group.bench_with_input(BenchmarkId::new("prepare+metrics", rows), &rows, |b, _| {
            b.iter(|| {
                let data = MotData::new(&truth, &estimates, Similarity::BoxIou, None).unwrap();
                evaluate_mot(&data, &params).unwrap()
            })
        });
    }
    group.finish();
}

/// A packed bead bed seen over `frames` frames: 260 discs of radius 15 px on a hexagonal
/// lattice of 30 px spacing with ±0.5 px jitter per frame (neighbours overlap slightly),
/// plus 140 discs of radius 10 px drifting across it; the estimates are the truth with
/// ±1 px uniform noise per coordinate, same ids.
fn bead_bed(frames: u64) -> (Vec<MotTruth>, Vec<MotEstimate>) {
    const BED_COLUMNS: usize = 20;
    const BED_ROWS: usize = 13;
    const SPACING_PX: f64 = 30.0;
    const MOVERS: usize = 140;
    let mut rng = scene::Rng::new(11);
    let width_px = BED_COLUMNS as f64 * SPACING_PX;
    let height_px = BED_ROWS as f64 * SPACING_PX * 3f64.sqrt() / 2.0;
    let movers: Vec<(f64, f64, f64, f64)> = (0..MOVERS)
        .map(|_| {
            (
                rng.unit() * width_px,
                rng.unit() * height_px,
                1.0 + 3.0 * rng.unit(),
                rng.unit() - 0.5,
            )
        })
        .collect();
    let (mut truth, mut estimates) = (Vec::new(), Vec::new());
    for frame in 0..frames {
        let mut discs = Vec::with_capacity(BED_COLUMNS * BED_ROWS + MOVERS);
        for row in 0..BED_ROWS {
            for column in 0..BED_COLUMNS {
                let shift = if row % 2 == 1 { 0.5 } else { 0.0 };
                let x = (column as f64 + shift) * SPACING_PX + rng.unit() - 0.5;
                let y = row as f64 * SPACING_PX * 3f64.sqrt() / 2.0 + rng.unit() - 0.5;
                discs.push((x, y, 15.0));
            }
        }
        for &(x, y, vx, vy) in &movers {
            let t = frame as f64;
            let x = (x + vx * t).rem_euclid(width_px);
            let y = (y + vy * t).rem_euclid(height_px);
            discs.push((x, y, 10.0));
        }
        for (id, &(x, y, radius_px)) in discs.iter().enumerate() {
            let disc = |x: f64, y: f64| Shape::Disc {
                centre_px: sillage_core::Point2::new(x, y),
                radius_px,
            };
            truth.push(MotTruth {
                frame,
                id: id as u64,
                shape: disc(x, y),
                role: TruthRole::Scored,
            });
            let (nx, ny) = (2.0 * rng.unit() - 1.0, 2.0 * rng.unit() - 1.0);
            estimates.push(MotEstimate {
                frame,
                id: id as u64,
                shape: disc(x + nx, y + ny),
            });
        }
    }
    (truth, estimates)
}

fn bench_bead_bed(c: &mut Criterion) {
    let params = MotParams {
        threshold: 0.43,
        ..MotParams::default()
    };
    let mut group = c.benchmark_group("mot/bead-bed");
    group.sample_size(10);
    let frames = 60;
    let (truth, estimates) = bead_bed(frames);
    let data = MotData::new(&truth, &estimates, Similarity::DiscIou, None).unwrap();
    group.throughput(Throughput::Elements(truth.len() as u64));
    group.bench_with_input(BenchmarkId::new("metrics", frames), &frames, |b, _| {
        b.iter(|| evaluate_mot(&data, &params).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench_tud, bench_synthetic, bench_bead_bed);
criterion_main!(benches);

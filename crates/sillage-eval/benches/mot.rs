//! CLEAR MOT + Identity + HOTA: on TUD-Stadtmitte (py-motmetrics' reference files) and on
//! synthetic sequences of 10^5 to 10^6 truth rows against as many estimates (linear time).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use sillage_eval::mot::{
    BoundingBox, MotChallengeProtocol, MotData, MotEstimate, MotParams, MotTruth, Shape,
    Similarity, evaluate_mot,
};
use sillage_io::{MotRow, read_mot_rows};

#[path = "../tests/common/scene.rs"]
mod scene;

const TUD: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/motmetrics_tud_reference/TUD-Stadtmitte"
);

fn shape(row: &MotRow) -> Shape {
    Shape::Box(BoundingBox {
        left_px: row.left_px,
        top_px: row.top_px,
        width_px: row.width_px,
        height_px: row.height_px,
    })
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

criterion_group!(benches, bench_tud, bench_synthetic);
criterion_main!(benches);

//! Build, nearest and 10-nearest queries of the grid index for 1k–100k points, with kiddo's
//! `ImmutableKdTree` as the baseline the grid was chosen against.
//!
//! Points are uniform at the density of 25,000 particles in a 2048² frame; queries are as
//! many points drawn the same way (like the next frame of a PTV sequence).

use std::hint::black_box;
use std::num::NonZeroUsize;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rand::RngExt;
use sillage_assoc::{NeighbourIndex, PointIndex};
use sillage_core::{Point2, rng_stream};

const SIZES: [usize; 4] = [1_000, 5_000, 25_000, 100_000];

fn uniform(n: usize, stream: u64) -> Vec<Point2> {
    let side = 2048.0 * (n as f64 / 25_000.0).sqrt();
    let mut rng = rng_stream(7, stream);
    (0..n)
        .map(|_| Point2::new(rng.random::<f64>() * side, rng.random::<f64>() * side))
        .collect()
}

fn neighbours(c: &mut Criterion) {
    let mut group = c.benchmark_group("neighbours");
    for n in SIZES {
        let points = uniform(n, 1);
        let queries = uniform(n, 2);
        let arrays: Vec<[f64; 2]> = points.iter().map(|p| p.to_array()).collect();
        let query_arrays: Vec<[f64; 2]> = queries.iter().map(|p| p.to_array()).collect();

        let mut grid = PointIndex::default();
        group.bench_with_input(BenchmarkId::new("grid_build", n), &n, |b, _| {
            b.iter(|| grid.rebuild(black_box(&points)))
        });
        group.bench_with_input(BenchmarkId::new("kiddo_build", n), &n, |b, _| {
            b.iter(|| ImmutableKdTree::<f64, 2>::new_from_slice(black_box(&arrays)))
        });

        grid.rebuild(&points);
        let mut nn = Vec::new();
        group.bench_with_input(BenchmarkId::new("grid_nn_batch", n), &n, |b, _| {
            b.iter(|| grid.nearest_batch(black_box(&queries), &mut nn))
        });
        let mut knn_grid = PointIndex::with_occupancy(2.0);
        knn_grid.rebuild(&points);
        let mut knn = Vec::new();
        group.bench_with_input(BenchmarkId::new("grid_knn10_batch", n), &n, |b, _| {
            b.iter(|| knn_grid.k_nearest_batch(black_box(&queries), 10, &mut knn))
        });

        let tree = ImmutableKdTree::<f64, 2>::new_from_slice(&arrays).expect("kiddo build");
        group.bench_with_input(BenchmarkId::new("kiddo_nn_batch", n), &n, |b, _| {
            b.iter(|| {
                tree.query_batch(black_box(&query_arrays))
                    .nearest_one::<SquaredEuclidean<f64>>()
                    .execute()
            })
        });
        let ten = NonZeroUsize::new(10).expect("10 > 0");
        group.bench_with_input(BenchmarkId::new("kiddo_knn10_batch", n), &n, |b, _| {
            b.iter(|| {
                tree.query_batch(black_box(&query_arrays))
                    .nearest_n::<SquaredEuclidean<f64>>(ten)
                    .execute()
            })
        });
    }
    group.finish();
}

/// Points per cell against query time at 25,000 points: nearest (default 1) and 10-nearest,
/// queries in the raster order a detector emits them.
fn occupancy(c: &mut Criterion) {
    let mut group = c.benchmark_group("occupancy");
    let points = uniform(25_000, 1);
    let mut queries = uniform(25_000, 2);
    queries.sort_by(|a, b| {
        a.y.floor()
            .total_cmp(&b.y.floor())
            .then(a.x.total_cmp(&b.x))
    });
    let mut nn = Vec::new();
    for occupancy in [0.5, 1.0, 2.0] {
        let index = {
            let mut i = PointIndex::with_occupancy(occupancy);
            i.rebuild(&points);
            i
        };
        group.bench_with_input(BenchmarkId::new("nn", occupancy), &occupancy, |b, _| {
            b.iter(|| index.nearest_batch(black_box(&queries), &mut nn))
        });
    }
    let mut sums: Vec<u64> = Vec::new();
    for occupancy in [1.0, 2.0, 10.0 / 3.0, 5.0] {
        let index = {
            let mut i = PointIndex::with_occupancy(occupancy);
            i.rebuild(&points);
            i
        };
        group.bench_with_input(BenchmarkId::new("knn10", occupancy), &occupancy, |b, _| {
            b.iter(|| {
                index.map_k_nearest(black_box(&queries), 10, &mut sums, |ids, _| {
                    ids.iter().map(|&i| u64::from(i)).sum()
                })
            })
        });
    }
    group.finish();
}

criterion_group!(benches, neighbours, occupancy);
criterion_main!(benches);

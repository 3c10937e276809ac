//! The grid index against the brute-force reference: identical answers, ties included.

use proptest::prelude::*;
use sillage_assoc::{
    BruteForceIndex, NeighbourIndex, PointIndex, mutual_nearest_neighbours, mutual_pairs,
};
use sillage_core::Point2;

/// Points on a coarse lattice (many duplicates and equal distances) or anywhere.
fn point(lattice: bool) -> impl Strategy<Value = Point2> {
    if lattice {
        (0i32..6, 0i32..6)
            .prop_map(|(x, y)| Point2::new(x as f64 * 2.0, y as f64 * 2.0))
            .boxed()
    } else {
        (-500.0f64..500.0, -500.0f64..500.0)
            .prop_map(|(x, y)| Point2::new(x, y))
            .boxed()
    }
}

fn point_sets() -> impl Strategy<Value = (Vec<Point2>, Vec<Point2>)> {
    any::<bool>().prop_flat_map(|lattice| {
        (
            prop::collection::vec(point(lattice), 0..300),
            prop::collection::vec(point(lattice), 0..60),
        )
    })
}

fn check_same(points: &[Point2], queries: &[Point2], k: usize) {
    let grid = PointIndex::new(points);
    let brute = BruteForceIndex::new(points);
    assert_eq!(grid.len(), brute.len());
    let (mut a, mut b) = (Vec::new(), Vec::new());
    grid.nearest_batch(queries, &mut a);
    brute.nearest_batch(queries, &mut b);
    assert_eq!(a, b);
    let (mut ka, mut kb) = (Vec::new(), Vec::new());
    grid.k_nearest_batch(queries, k, &mut ka);
    brute.k_nearest_batch(queries, k, &mut kb);
    assert_eq!(ka, kb);
    // The allocation-free batch and an index over the same points given in two parts.
    let mut mapped: Vec<Vec<usize>> = Vec::new();
    let mut concat = PointIndex::with_occupancy(3.0);
    concat.rebuild_concat(&points[..points.len() / 3], &points[points.len() / 3..]);
    for index in [&grid, &concat] {
        // Each slot holds the point it is reported with.
        let slot_indexes = index.slot_indexes();
        index.map_k_nearest(queries, k, &mut mapped, |ids, slots| {
            assert!(
                ids.iter()
                    .zip(slots)
                    .all(|(&i, &s)| slot_indexes[s as usize] == i)
            );
            ids.iter().map(|&i| i as usize).collect()
        });
        let expected: Vec<Vec<usize>> =
            kb.iter().map(|r| r.iter().map(|n| n.0).collect()).collect();
        assert_eq!(mapped, expected);
    }
    for (q, row) in queries.iter().zip(&ka) {
        let finite = points.iter().filter(|p| p.is_finite()).count();
        assert_eq!(row.len(), if q.is_finite() { k.min(finite) } else { 0 });
    }
    check_counted(points, queries, k);
}

/// The counted k-nearest against the brute-force order of the points: each point stands for
/// 1 to 3 samples; the fewest nearest points holding k samples, and how many of the last
/// one's samples are taken.
fn check_counted(points: &[Point2], queries: &[Point2], k: usize) {
    let count = |i: usize| 1 + u8::from(i.is_multiple_of(3)) + u8::from(i.is_multiple_of(7));
    let mut grid = PointIndex::with_occupancy(2.0);
    grid.rebuild(points);
    let counts: Vec<u8> = grid
        .slot_indexes()
        .iter()
        .map(|&i| count(i as usize))
        .collect();
    let slot_indexes = grid.slot_indexes().to_vec();
    let mut got: Vec<(Vec<usize>, usize)> = Vec::new();
    grid.map_k_nearest_counted(queries, k, &counts, &mut got, |slots, last_taken| {
        let ids = slots
            .iter()
            .map(|&s| slot_indexes[s as usize] as usize)
            .collect();
        (ids, last_taken)
    });
    let brute = BruteForceIndex::new(points);
    let mut order = Vec::new();
    for (q, got) in queries.iter().zip(&got) {
        brute.k_nearest(*q, points.len(), &mut order);
        let (mut ids, mut samples, mut last_taken) = (Vec::new(), 0, 0);
        for &(i, _) in &order {
            if samples >= k {
                break;
            }
            let c = usize::from(count(i));
            last_taken = c.min(k - samples);
            samples += c;
            ids.push(i);
        }
        assert_eq!(*got, (ids, last_taken), "query {q:?}, k {k}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn grid_matches_brute_force((points, queries) in point_sets(), k in 0usize..15) {
        check_same(&points, &queries, k);
    }

    #[test]
    fn mutual_pairs_are_mutual((from, to) in point_sets()) {
        let pairs = mutual_nearest_neighbours(&from, &to, None);
        let (bf, bt) = (BruteForceIndex::new(&from), BruteForceIndex::new(&to));
        for (i, pair) in pairs.iter().enumerate() {
            let forward = bt.nearest(from[i]).map(|n| n.0);
            let expected = forward.filter(|&j| bf.nearest(to[j]).map(|n| n.0) == Some(i));
            prop_assert_eq!(*pair, expected);
        }
    }
}

#[test]
fn ties_go_to_the_lower_index() {
    let points = [
        Point2::new(1.0, 0.0),
        Point2::new(-1.0, 0.0),
        Point2::new(0.0, 1.0),
        Point2::new(1.0, 0.0),
    ];
    let grid = PointIndex::new(&points);
    assert_eq!(grid.nearest(Point2::new(0.0, 0.0)), Some((0, 1.0)));
    let mut out = Vec::new();
    grid.k_nearest(Point2::new(0.0, 0.0), 3, &mut out);
    assert_eq!(out, vec![(0, 1.0), (1, 1.0), (2, 1.0)]);
}

#[test]
fn empty_sets_and_non_finite_values_do_not_panic() {
    let empty = PointIndex::new(&[]);
    assert!(empty.is_empty());
    assert_eq!(empty.nearest(Point2::new(0.0, 0.0)), None);
    let mut out = vec![(9, 9.0)];
    empty.k_nearest(Point2::new(0.0, 0.0), 4, &mut out);
    assert!(out.is_empty());
    let mut batch = vec![Some((1, 1.0))];
    empty.nearest_batch(&[], &mut batch);
    assert!(batch.is_empty());

    let points = [
        Point2::new(f64::NAN, 1.0),
        Point2::new(2.0, 2.0),
        Point2::new(f64::INFINITY, 0.0),
    ];
    check_same(
        &points,
        &[Point2::new(0.0, 0.0), Point2::new(f64::NAN, 0.0)],
        3,
    );
    let mut pairs = Vec::new();
    mutual_pairs(&[Some((5, 1.0))], &[], None, &mut pairs);
    assert_eq!(pairs, vec![None]);
}

#[test]
fn large_uniform_set_matches_brute_force() {
    // A deterministic scatter dense enough to exercise many rings of the grid.
    let points: Vec<Point2> = (0..4000u64)
        .map(|i| {
            let h = i.wrapping_mul(0x9E37_79B9_7F4A_7C15);
            Point2::new(
                (h >> 40) as f64 / 16.0,
                ((h >> 16) & 0xFF_FFFF) as f64 / 8192.0,
            )
        })
        .collect();
    let queries: Vec<Point2> = points
        .iter()
        .step_by(7)
        .map(|p| Point2::new(p.y, p.x))
        .collect();
    check_same(&points, &queries, 10);
}

#[test]
fn batches_alternating_between_densities_match_brute_force() {
    // Batch k-nearest queries guess each first block's candidates from the previous
    // query's k-th distance: queries alternating between a dense and a sparse region make
    // that guess far too tight or far too loose at every step.
    let scatter = |i: u64, w: f64, x0: f64| {
        let h = i.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        Point2::new(
            x0 + (h >> 40) as f64 / (1u64 << 24) as f64 * w,
            ((h >> 16) & 0xFF_FFFF) as f64 / (1u64 << 24) as f64 * 100.0,
        )
    };
    let points: Vec<Point2> = (0..3000u64)
        .map(|i| scatter(i, 100.0, 0.0))
        .chain((3000..4000u64).map(|i| scatter(i, 900.0, 100.0)))
        .collect();
    let queries: Vec<Point2> = (0..600u64)
        .map(|i| {
            let p = scatter(i * 31 + 7, 100.0, 0.0);
            if i % 2 == 0 {
                p
            } else {
                Point2::new(p.x * 9.0 + 100.0, p.y)
            }
        })
        .collect();
    for k in [1, 4, 10, 25] {
        check_same(&points, &queries, k);
    }
}

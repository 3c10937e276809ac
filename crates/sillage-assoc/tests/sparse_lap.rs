//! The sparse assignment solver against exhaustive search on small matrices (its optimum, and
//! whether that optimum is unique) and against the dense solver on small to large ones (the
//! same pairs whenever the optimum is unique): square and rectangular, both pairings,
//! forbidden entries, many ties.

use proptest::prelude::*;
use sillage_assoc::{LapSolver, Pairing, SparseLapSolver};

/// A sparse matrix as the solver takes it, with the dense row-major view beside it
/// (`INFINITY` outside the entries).
#[derive(Debug, Clone)]
struct Sparse {
    rows: usize,
    cols: usize,
    row_start: Vec<usize>,
    col_index: Vec<u32>,
    costs: Vec<f64>,
}

impl Sparse {
    /// The entries of a dense matrix that are not `INFINITY` (NaN stays, as a forbidden
    /// entry the sparse solver must skip).
    fn from_dense(rows: usize, cols: usize, dense: &[f64]) -> Self {
        let mut sparse = Sparse {
            rows,
            cols,
            row_start: vec![0],
            col_index: Vec::new(),
            costs: Vec::new(),
        };
        for i in 0..rows {
            for j in 0..cols {
                let c = dense[i * cols + j];
                if c != f64::INFINITY {
                    sparse.col_index.push(j as u32);
                    sparse.costs.push(c);
                }
            }
            sparse.row_start.push(sparse.costs.len());
        }
        sparse
    }

    /// The cost of `(i, j)`, if allowed.
    fn cost(&self, i: usize, j: usize) -> Option<f64> {
        (self.row_start[i]..self.row_start[i + 1])
            .find(|&k| self.col_index[k] as usize == j)
            .map(|k| self.costs[k])
            .filter(|c| c.is_finite())
    }

    /// The dense matrix `LapSolver` solves for `pairing`: forbidden outside the entries for
    /// `Maximum`, 0 for `Optional` (the maximum-weight convention).
    fn dense(&self, pairing: Pairing) -> Vec<f64> {
        let fill = match pairing {
            Pairing::Maximum => f64::INFINITY,
            Pairing::Optional => 0.0,
        };
        let mut dense = vec![fill; self.rows * self.cols];
        for i in 0..self.rows {
            for k in self.row_start[i]..self.row_start[i + 1] {
                let c = self.costs[k];
                // A forbidden entry is no pair: forbidden, or the 0 of "unpaired".
                dense[i * self.cols + self.col_index[k] as usize] =
                    if c.is_finite() { c } else { fill };
            }
        }
        dense
    }

    fn solve(&self, solver: &mut SparseLapSolver, pairing: Pairing) -> (Vec<Option<usize>>, bool) {
        let assignment = solver
            .solve(
                self.rows,
                self.cols,
                &self.row_start,
                &self.col_index,
                &self.costs,
                pairing,
            )
            .to_vec();
        (assignment, solver.is_unique())
    }

    /// `LapSolver`'s answer, as the sparse solver states it (`Optional`: pairs outside the
    /// entries dropped).
    fn solve_dense(&self, pairing: Pairing) -> Vec<Option<usize>> {
        let mut assignment = LapSolver::new()
            .solve(self.rows, self.cols, &self.dense(pairing))
            .to_vec();
        for (i, col) in assignment.iter_mut().enumerate() {
            if col.is_some_and(|j| self.cost(i, j).is_none()) {
                *col = None;
            }
        }
        assignment
    }

    /// Checks that `assignment` is one-to-one over allowed entries; returns (pairs, cost).
    fn score(&self, assignment: &[Option<usize>]) -> (usize, f64) {
        assert_eq!(assignment.len(), self.rows);
        let mut used = vec![false; self.cols];
        let (mut pairs, mut cost) = (0, 0.0);
        for (i, col) in assignment.iter().enumerate() {
            if let Some(j) = *col {
                assert!(j < self.cols && !used[j], "column {j} given twice");
                used[j] = true;
                cost += self
                    .cost(i, j)
                    .unwrap_or_else(|| panic!("entry ({i}, {j}) is not allowed"));
                pairs += 1;
            }
        }
        (pairs, cost)
    }
}

/// The optimum over every one-to-one assignment (as (pairs, cost); `Optional` ignores the
/// pairs) and how many assignments reach it within `tolerance`.
fn exhaustive(m: &Sparse, pairing: Pairing, tolerance: f64) -> ((usize, f64), usize) {
    fn walk(
        m: &Sparse,
        row: usize,
        used: &mut Vec<bool>,
        pairs: usize,
        cost: f64,
        out: &mut Vec<(usize, f64)>,
    ) {
        if row == m.rows {
            out.push((pairs, cost));
            return;
        }
        walk(m, row + 1, used, pairs, cost, out);
        for k in m.row_start[row]..m.row_start[row + 1] {
            let (j, c) = (m.col_index[k] as usize, m.costs[k]);
            if c.is_finite() && !used[j] {
                used[j] = true;
                walk(m, row + 1, used, pairs + 1, cost + c, out);
                used[j] = false;
            }
        }
    }
    let mut all = Vec::new();
    walk(m, 0, &mut vec![false; m.cols], 0, 0.0, &mut all);
    let key = |&(pairs, cost): &(usize, f64)| match pairing {
        Pairing::Maximum => (usize::MAX - pairs, cost),
        Pairing::Optional => (0, cost),
    };
    let best = all
        .iter()
        .copied()
        .min_by(|a, b| key(a).partial_cmp(&key(b)).unwrap())
        .unwrap();
    let ties = all
        .iter()
        .filter(|a| key(a).0 == key(&best).0 && (a.1 - best.1).abs() <= tolerance)
        .count();
    (best, ties)
}

/// A matrix of up to 7 × 7 with entries from a small set (ties), a wide range, or negative
/// values, and a share of forbidden entries (mostly absent, some NaN).
fn matrix() -> impl Strategy<Value = (usize, usize, u8, Vec<f64>)> {
    (0usize..=7, 0usize..=7, 0u8..3, 0.2f64..0.9).prop_flat_map(|(rows, cols, kind, absent)| {
        let entry = match kind {
            0 => (0u8..4).prop_map(f64::from).boxed(),
            1 => (-1000.0f64..1000.0).boxed(),
            _ => (-3i8..=0).prop_map(f64::from).boxed(),
        };
        let cell = (entry, 0.0f64..1.0).prop_map(move |(c, u)| {
            if u < absent {
                f64::INFINITY
            } else if u < absent + 0.03 {
                f64::NAN
            } else {
                c
            }
        });
        (
            Just(rows),
            Just(cols),
            Just(kind),
            prop::collection::vec(cell, rows * cols),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn solver_equals_exhaustive_search((rows, cols, kind, dense) in matrix()) {
        let m = Sparse::from_dense(rows, cols, &dense);
        let mut solver = SparseLapSolver::new();
        for pairing in [Pairing::Maximum, Pairing::Optional] {
            let (assignment, unique) = m.solve(&mut solver, pairing);
            let (pairs, cost) = m.score(&assignment);
            let tolerance = if kind == 1 { 1e-6 } else { 0.0 };
            let ((best_pairs, best_cost), optima) = exhaustive(&m, pairing, tolerance);
            if pairing == Pairing::Maximum {
                prop_assert_eq!(pairs, best_pairs);
            }
            prop_assert!((cost - best_cost).abs() <= 1e-9 * (1.0 + best_cost.abs()),
                "{:?}: cost {} vs exhaustive {}", pairing, cost, best_cost);
            // Uniqueness is exact on integer costs, and (almost surely) true on real ones.
            prop_assert_eq!(unique, optima == 1, "{:?}: {} optima", pairing, optima);
            // A unique optimum is the dense solver's answer (`Optional`: its maximum-weight
            // convention, for negative costs only).
            let negative = m.costs.iter().all(|&c| c < 0.0 || c.is_nan());
            if unique && (pairing == Pairing::Maximum || negative) {
                prop_assert_eq!(&assignment, &m.solve_dense(pairing));
            }
        }
        // A reused solver gives the same answer as a fresh one.
        let fresh = m.solve(&mut SparseLapSolver::new(), Pairing::Maximum);
        prop_assert_eq!(m.solve(&mut solver, Pairing::Maximum), fresh);
    }
}

/// SplitMix64 (Steele et al. 2014): a tiny seeded generator.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// Costs of [`random_sparse`].
#[derive(Debug, Clone, Copy, PartialEq)]
enum Costs {
    /// Real, in `[-1, 0)`: no ties.
    Real,
    /// `{-3, …, 0}`: many ties.
    FewIntegers,
    /// Integers in `[-10⁶, 0]`: exact sums, a few ties.
    ManyIntegers,
}

/// A random sparse `rows × cols` matrix with about `per_row` entries per row near the
/// diagonal band (as objects overlap their neighbours) and some anywhere.
fn random_sparse(rng: &mut Rng, rows: usize, cols: usize, per_row: usize, costs: Costs) -> Sparse {
    let mut dense = vec![f64::INFINITY; rows * cols];
    for i in 0..rows {
        let centre = i * cols / rows.max(1);
        for _ in 0..per_row {
            let j = if rng.unit() < 0.9 {
                (centre + rng.below(2 * per_row + 1)).saturating_sub(per_row)
            } else {
                rng.below(cols)
            };
            if j < cols {
                dense[i * cols + j] = match costs {
                    Costs::Real => -rng.unit(),
                    Costs::FewIntegers => -(rng.below(4) as f64),
                    Costs::ManyIntegers => -(rng.below(1_000_001) as f64),
                };
            }
        }
    }
    Sparse::from_dense(rows, cols, &dense)
}

/// Checks the sparse solver against the dense one on `m`: the same objective, and the same
/// pairs when it reports a unique optimum. Returns whether it did.
fn check_against_dense(m: &Sparse, solver: &mut SparseLapSolver, pairing: Pairing) -> bool {
    let (assignment, unique) = m.solve(solver, pairing);
    let dense = m.solve_dense(pairing);
    let ((pairs, cost), (dense_pairs, dense_cost)) = (m.score(&assignment), m.score(&dense));
    if pairing == Pairing::Maximum {
        assert_eq!(pairs, dense_pairs);
    }
    assert!(
        (cost - dense_cost).abs() <= 1e-9 * (1.0 + dense_cost.abs()),
        "{pairing:?} {}×{}: {cost} vs dense {dense_cost}",
        m.rows,
        m.cols
    );
    if unique {
        assert_eq!(assignment, dense, "{pairing:?} {}×{}", m.rows, m.cols);
    }
    unique
}

#[test]
fn medium_and_large_sparse_matrices_equal_the_dense_solver() {
    let mut rng = Rng(42);
    let mut solver = SparseLapSolver::new();
    let medium = [(60, 60), (50, 70), (70, 45)];
    let large = [(300, 300), (300, 240), (240, 300)];
    let shapes = (0..1000)
        .map(|k| (medium[k % 3], 1 + rng.below(8)))
        .chain((0..30).map(|k| (large[k % 3], 6)))
        .collect::<Vec<_>>();
    // Instances whose optimum is unique, per kind of costs.
    let mut unique_count = [0; 3];
    for ((rows, cols), per_row) in shapes {
        for (kind, costs) in [Costs::Real, Costs::FewIntegers, Costs::ManyIntegers]
            .into_iter()
            .enumerate()
        {
            let m = random_sparse(&mut rng, rows, cols, per_row, costs);
            for pairing in [Pairing::Maximum, Pairing::Optional] {
                let unique = check_against_dense(&m, &mut solver, pairing);
                // Real costs have no ties (almost surely).
                assert!(
                    unique || costs != Costs::Real,
                    "{pairing:?}: a tie on real costs"
                );
                unique_count[kind] += usize::from(unique);
            }
        }
    }
    // Every real-cost instance, and a good share of the others, was compared pair by pair.
    assert_eq!(unique_count[0], 2 * 1030);
    assert!(
        unique_count[1] > 5 && unique_count[2] > 2000,
        "{unique_count:?}"
    );
}

#[test]
fn ties_and_degenerate_shapes() {
    let inf = f64::INFINITY;
    let mut solver = SparseLapSolver::new();
    let solve = |solver: &mut SparseLapSolver, rows, cols, dense: &[f64], pairing| {
        Sparse::from_dense(rows, cols, dense).solve(solver, pairing)
    };
    // Nothing allowed, empty shapes.
    assert_eq!(
        solve(&mut solver, 2, 2, &[inf; 4], Pairing::Maximum),
        (vec![None, None], true)
    );
    assert_eq!(
        solve(&mut solver, 0, 3, &[], Pairing::Maximum),
        (vec![], true)
    );
    assert_eq!(
        solve(&mut solver, 2, 0, &[], Pairing::Optional),
        (vec![None, None], true)
    );
    // The cheaper row gets the only column, even when it comes second.
    assert_eq!(
        solve(&mut solver, 2, 1, &[10.0, 1.0], Pairing::Maximum),
        (vec![None, Some(0)], true)
    );
    // Two pairs beat one cheap pair under `Maximum`, not under `Optional`.
    let dense = [-10.0, -1.0, -1.0, inf];
    assert_eq!(
        solve(&mut solver, 2, 2, &dense, Pairing::Maximum),
        (vec![Some(1), Some(0)], true)
    );
    assert_eq!(
        solve(&mut solver, 2, 2, &dense, Pairing::Optional),
        (vec![Some(0), None], true)
    );
    // All equal: optimal, reported as a tie.
    let (assignment, unique) = solve(&mut solver, 3, 3, &[1.0; 9], Pairing::Maximum);
    assert_eq!(assignment.iter().flatten().count(), 3);
    assert!(!unique);
    // A pair of cost 0 is as good as none under `Optional`: a tie.
    assert!(!solve(&mut solver, 1, 1, &[0.0], Pairing::Optional).1);
    assert_eq!(
        solve(&mut solver, 1, 1, &[0.5], Pairing::Optional),
        (vec![None], true)
    );
}

#[test]
#[should_panic(expected = "one offset per row")]
fn malformed_rows_are_a_bug() {
    let _ = SparseLapSolver::new().solve(2, 2, &[0, 1], &[0], &[1.0], Pairing::Maximum);
}

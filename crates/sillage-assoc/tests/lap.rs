//! The assignment solver against exhaustive search on small matrices: square and
//! rectangular, with forbidden entries and many ties.

use proptest::prelude::*;
use sillage_assoc::{LapSolver, solve_assignment};

/// The best (largest number of pairs, then least cost) over every one-to-one assignment of
/// allowed entries, by enumeration.
fn exhaustive(rows: usize, cols: usize, costs: &[f64]) -> (usize, f64) {
    let mut search = Search {
        rows,
        cols,
        costs,
        used: vec![false; cols],
        best: (0, 0.0),
    };
    search.walk(0, 0, 0.0);
    search.best
}

/// The state of [`exhaustive`]'s depth-first enumeration.
struct Search<'a> {
    rows: usize,
    cols: usize,
    costs: &'a [f64],
    used: Vec<bool>,
    best: (usize, f64),
}

impl Search<'_> {
    /// Rows before `row` are decided, with `pairs` pairs costing `cost`.
    fn walk(&mut self, row: usize, pairs: usize, cost: f64) {
        if row == self.rows {
            if pairs > self.best.0 || (pairs == self.best.0 && cost < self.best.1) {
                self.best = (pairs, cost);
            }
            return;
        }
        self.walk(row + 1, pairs, cost);
        for j in 0..self.cols {
            let c = self.costs[row * self.cols + j];
            if !self.used[j] && c.is_finite() {
                self.used[j] = true;
                self.walk(row + 1, pairs + 1, cost + c);
                self.used[j] = false;
            }
        }
    }
}

/// Checks that `assignment` is one-to-one over allowed entries and returns (pairs, cost).
fn score(rows: usize, cols: usize, costs: &[f64], assignment: &[Option<usize>]) -> (usize, f64) {
    assert_eq!(assignment.len(), rows);
    let mut used = vec![false; cols];
    let (mut pairs, mut cost) = (0, 0.0);
    for (i, col) in assignment.iter().enumerate() {
        if let Some(j) = *col {
            assert!(
                j < cols && !used[j],
                "column {j} given twice or out of range"
            );
            used[j] = true;
            let c = costs[i * cols + j];
            assert!(c.is_finite(), "forbidden entry ({i}, {j}) assigned");
            pairs += 1;
            cost += c;
        }
    }
    (pairs, cost)
}

/// A matrix of up to 6 × 6 with entries from a small set (ties), a wide range, or
/// negative values, and a share of forbidden entries (infinite or NaN).
fn matrix() -> impl Strategy<Value = (usize, usize, Vec<f64>)> {
    (0usize..=6, 0usize..=6, 0u8..3, 0.0f64..0.6).prop_flat_map(|(rows, cols, kind, forbidden)| {
        let entry = match kind {
            0 => (0u8..4).prop_map(f64::from).boxed(),
            1 => (-1000.0f64..1000.0).boxed(),
            _ => (-3i8..=0).prop_map(f64::from).boxed(),
        };
        let cell = (entry, 0.0f64..1.0, any::<bool>()).prop_map(move |(c, u, nan)| {
            if u < forbidden {
                if nan { f64::NAN } else { f64::INFINITY }
            } else {
                c
            }
        });
        (
            Just(rows),
            Just(cols),
            prop::collection::vec(cell, rows * cols),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn solver_equals_exhaustive_search((rows, cols, costs) in matrix()) {
        let assignment = solve_assignment(rows, cols, &costs);
        let (pairs, cost) = score(rows, cols, &costs, &assignment);
        let (best_pairs, best_cost) = exhaustive(rows, cols, &costs);
        prop_assert_eq!(pairs, best_pairs);
        prop_assert!((cost - best_cost).abs() <= 1e-9 * (1.0 + best_cost.abs()),
            "cost {} vs exhaustive {}", cost, best_cost);

        // The transposed problem has the same optimum.
        let transposed: Vec<f64> =
            (0..cols * rows).map(|k| costs[(k % rows) * cols + k / rows]).collect();
        let (t_pairs, t_cost) =
            score(cols, rows, &transposed, &solve_assignment(cols, rows, &transposed));
        prop_assert_eq!(t_pairs, best_pairs);
        prop_assert!((t_cost - best_cost).abs() <= 1e-9 * (1.0 + best_cost.abs()));

        // A reused solver gives the same answer as a fresh one (deterministic, buffers reset).
        let mut solver = LapSolver::new();
        let _ = solver.solve(cols, rows, &transposed);
        prop_assert_eq!(solver.solve(rows, cols, &costs), &assignment[..]);
    }
}

#[test]
fn ties_go_to_lower_indices() {
    // All equal: the identity, on square and rectangular matrices.
    assert_eq!(
        solve_assignment(3, 3, &[1.0; 9]),
        vec![Some(0), Some(1), Some(2)]
    );
    assert_eq!(solve_assignment(2, 4, &[0.0; 8]), vec![Some(0), Some(1)]);
    assert_eq!(solve_assignment(3, 1, &[5.0; 3]), vec![Some(0), None, None]);
}

#[test]
fn forbidden_entries_and_degenerate_shapes() {
    let inf = f64::INFINITY;
    // Nothing allowed: nothing assigned.
    assert_eq!(solve_assignment(2, 2, &[inf; 4]), vec![None, None]);
    assert_eq!(solve_assignment(0, 3, &[]), Vec::<Option<usize>>::new());
    assert_eq!(solve_assignment(2, 0, &[]), vec![None, None]);
    // Which row gets the only column is part of the optimum: the cheaper one, even when it
    // comes second (a row-by-row method that keeps earlier rows would pick row 0).
    assert_eq!(solve_assignment(2, 1, &[10.0, 1.0]), vec![None, Some(0)]);
    // Two pairs beat one cheap pair; then the least total cost.
    assert_eq!(
        solve_assignment(2, 2, &[0.0, 100.0, 1.0, inf]),
        vec![Some(1), Some(0)]
    );
    // Negative costs are ordinary costs.
    assert_eq!(
        solve_assignment(2, 2, &[-1.0, -5.0, -4.0, -1.0]),
        vec![Some(1), Some(0)]
    );
}

#[test]
#[should_panic(expected = "cost matrix")]
fn a_matrix_of_the_wrong_size_is_a_bug() {
    let _ = solve_assignment(2, 2, &[1.0; 3]);
}

//! Optimal one-to-one matching on the sparse candidate pairs of a frame (or of a sequence,
//! for Identity): the candidates split into connected components, each solved by the
//! dense assignment solver of `sillage-assoc`. Typical frames have many tiny components,
//! so matching costs about linear time in the number of objects.
//!
//! A large component with few candidates per object (a packed bed of discs whose
//! neighbours overlap slightly) is solved by the sparse solver instead, in time that grows
//! with its candidates rather than cubically with its objects. When its optimum is not the
//! only one (a tie, or a near tie within ~10⁻⁹ × the largest value), the component is
//! re-solved densely, so that the result, tie-breaking included, is always the dense
//! solver's.

use sillage_assoc::sparse_lap::MAX_ABS_COST;
use sillage_assoc::{LapSolver, Pairing, SparseLapSolver};

/// Components of at most this many rows × columns are solved densely (the dense solver is
/// about as fast there, and needs no tie check).
const DENSE_MAX_CELLS: usize = 256;

/// Marks "none" in index buffers.
const NONE: u32 = u32::MAX;

/// One candidate pair: `row` (a true object), `col` (an estimate) and its value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Edge {
    pub row: u32,
    pub col: u32,
    pub value: f64,
}

/// What the matching optimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Objective {
    /// Largest total value; pairing is optional (values > 0). TrackEval's
    /// `linear_sum_assignment(-score)` with unmatched pairs at score 0.
    MaxWeight,
    /// As many pairs as possible, then least total value (the cost). py-motmetrics'
    /// assignment with NaN (forbidden) outside the candidates.
    MaxPairsMinCost,
}

/// Reusable buffers of [`Matcher::solve`].
#[derive(Debug, Default)]
pub(crate) struct Matcher {
    lap: LapSolver,
    sparse: SparseLapSolver,
    /// Union-find parent over rows, then columns.
    parent: Vec<u32>,
    /// Component of each edge, then the edges sorted by component.
    component_of_edge: Vec<u32>,
    component_of_root: Vec<u32>,
    order: Vec<u32>,
    /// Local index of each row / column inside the current component.
    local: Vec<u32>,
    rows: Vec<u32>,
    cols: Vec<u32>,
    costs: Vec<f64>,
    edge_at: Vec<u32>,
    /// The component row by row for the sparse solver: offsets, local columns, edges.
    row_start: Vec<usize>,
    sparse_cols: Vec<u32>,
    sparse_edges: Vec<u32>,
    /// Tests only: solve every component densely (the reference of the sparse path).
    #[cfg(test)]
    dense_only: bool,
}

impl Matcher {
    /// Fills `matched` with the indices into `edges` of an optimal matching, in increasing
    /// order. `edges` join rows `< n_rows` and columns `< n_cols`, each pair at most once.
    /// Ties go to lower indices (deterministic).
    pub fn solve(
        &mut self,
        n_rows: usize,
        n_cols: usize,
        edges: &[Edge],
        objective: Objective,
        matched: &mut Vec<usize>,
    ) {
        matched.clear();
        if edges.is_empty() {
            return;
        }
        self.split(n_rows, n_cols, edges);
        let mut start = 0;
        while start < self.order.len() {
            let component = self.component_of_edge[self.order[start] as usize];
            let end = start
                + self.order[start..]
                    .iter()
                    .take_while(|&&e| self.component_of_edge[e as usize] == component)
                    .count();
            self.solve_component(n_rows, start..end, edges, objective, matched);
            start = end;
        }
        matched.sort_unstable();
    }

    /// Labels every edge with its connected component and sorts the edges by component
    /// (then by index).
    fn split(&mut self, n_rows: usize, n_cols: usize, edges: &[Edge]) {
        self.parent.clear();
        self.parent.extend(0..(n_rows + n_cols) as u32);
        self.local.clear();
        self.local.resize(n_rows + n_cols, NONE);
        for e in edges {
            let a = find(&mut self.parent, e.row);
            let b = find(&mut self.parent, n_rows as u32 + e.col);
            if a != b {
                // Lower root wins: components are labelled by their lowest node.
                let (low, high) = (a.min(b), a.max(b));
                self.parent[high as usize] = low;
            }
        }
        self.component_of_root.clear();
        self.component_of_root.resize(n_rows + n_cols, NONE);
        self.component_of_edge.clear();
        let mut n_components = 0u32;
        for e in edges {
            let root = find(&mut self.parent, e.row) as usize;
            if self.component_of_root[root] == NONE {
                self.component_of_root[root] = n_components;
                n_components += 1;
            }
            self.component_of_edge.push(self.component_of_root[root]);
        }
        self.order.clear();
        self.order.extend(0..edges.len() as u32);
        let component_of_edge = &self.component_of_edge;
        self.order
            .sort_by_key(|&e| (component_of_edge[e as usize], e));
    }

    fn solve_component(
        &mut self,
        n_rows: usize,
        span: std::ops::Range<usize>,
        edges: &[Edge],
        objective: Objective,
        matched: &mut Vec<usize>,
    ) {
        if span.len() == 1 {
            // One candidate pair: it is the optimum under both objectives.
            matched.push(self.order[span.start] as usize);
            return;
        }
        // Rows and columns of the component, in increasing order (ties → lower index).
        self.rows.clear();
        self.cols.clear();
        for &e in &self.order[span.clone()] {
            let edge = edges[e as usize];
            self.rows.push(edge.row);
            self.cols.push(edge.col);
        }
        for list in [&mut self.rows, &mut self.cols] {
            list.sort_unstable();
            list.dedup();
        }
        for (k, &r) in self.rows.iter().enumerate() {
            self.local[r as usize] = k as u32;
        }
        for (k, &c) in self.cols.iter().enumerate() {
            self.local[n_rows + c as usize] = k as u32;
        }
        let (r, c) = (self.rows.len(), self.cols.len());
        #[cfg(test)]
        let sparse_allowed = !self.dense_only;
        #[cfg(not(test))]
        let sparse_allowed = true;
        if sparse_allowed
            && r * c > DENSE_MAX_CELLS
            && self.solve_sparse(n_rows, span.clone(), edges, objective, matched)
        {
            return;
        }
        let fill = match objective {
            Objective::MaxWeight => 0.0,
            Objective::MaxPairsMinCost => f64::INFINITY,
        };
        self.costs.clear();
        self.costs.resize(r * c, fill);
        self.edge_at.clear();
        self.edge_at.resize(r * c, NONE);
        for &e in &self.order[span] {
            let edge = edges[e as usize];
            let cell = self.local[edge.row as usize] as usize * c
                + self.local[n_rows + edge.col as usize] as usize;
            self.costs[cell] = match objective {
                Objective::MaxWeight => -edge.value,
                Objective::MaxPairsMinCost => edge.value,
            };
            self.edge_at[cell] = e;
        }
        let assignment = self.lap.solve(r, c, &self.costs);
        for (i, col) in assignment.iter().enumerate() {
            if let Some(j) = *col {
                let e = self.edge_at[i * c + j];
                if e != NONE {
                    matched.push(e as usize);
                }
            }
        }
    }
}

impl Matcher {
    /// Solves the current component (its local indices set) with the sparse solver and
    /// appends its matches; `false`, appending nothing, when the optimum is not unique (or a
    /// value is outside the sparse solver's domain), for the dense solver to decide.
    fn solve_sparse(
        &mut self,
        n_rows: usize,
        span: std::ops::Range<usize>,
        edges: &[Edge],
        objective: Objective,
        matched: &mut Vec<usize>,
    ) -> bool {
        let component = &self.order[span];
        // Dense MaxWeight may assign a pair of value ≤ 0 where its 0-fill would do as well.
        let valid = |v: f64| match objective {
            Objective::MaxWeight => v > 0.0 && v <= MAX_ABS_COST,
            Objective::MaxPairsMinCost => v.abs() <= MAX_ABS_COST,
        };
        if !component.iter().all(|&e| valid(edges[e as usize].value)) {
            return false;
        }
        // Counting sort of the component's edges by local row (then by edge index).
        let r = self.rows.len();
        self.row_start.clear();
        self.row_start.resize(r + 1, 0);
        for &e in component {
            self.row_start[self.local[edges[e as usize].row as usize] as usize + 1] += 1;
        }
        for i in 0..r {
            self.row_start[i + 1] += self.row_start[i];
        }
        self.sparse_cols.clear();
        self.sparse_cols.resize(component.len(), 0);
        self.costs.clear();
        self.costs.resize(component.len(), 0.0);
        self.sparse_edges.clear();
        self.sparse_edges.resize(component.len(), 0);
        for &e in component {
            let edge = edges[e as usize];
            let slot = &mut self.row_start[self.local[edge.row as usize] as usize];
            let k = *slot;
            *slot += 1;
            self.sparse_cols[k] = self.local[n_rows + edge.col as usize];
            self.costs[k] = match objective {
                Objective::MaxWeight => -edge.value,
                Objective::MaxPairsMinCost => edge.value,
            };
            self.sparse_edges[k] = e;
        }
        // The fill moved every offset one row on: shift back.
        self.row_start.copy_within(0..r, 1);
        self.row_start[0] = 0;
        let pairing = match objective {
            Objective::MaxWeight => Pairing::Optional,
            Objective::MaxPairsMinCost => Pairing::Maximum,
        };
        let _ = self.sparse.solve(
            r,
            self.cols.len(),
            &self.row_start,
            &self.sparse_cols,
            &self.costs,
            pairing,
        );
        if !self.sparse.is_unique() {
            return false;
        }
        for (i, col) in self.sparse.assignment().iter().enumerate() {
            if let Some(j) = *col {
                let k = (self.row_start[i]..self.row_start[i + 1])
                    .find(|&k| self.sparse_cols[k] as usize == j)
                    .expect("the sparse solver assigns listed entries only");
                matched.push(self.sparse_edges[k] as usize);
            }
        }
        true
    }
}

/// Union-find root of `node`, with path halving.
fn find(parent: &mut [u32], mut node: u32) -> u32 {
    while parent[node as usize] != node {
        let grand = parent[parent[node as usize] as usize];
        parent[node as usize] = grand;
        node = grand;
    }
    node
}

#[cfg(test)]
mod tests {
    use super::*;

    fn edge(row: u32, col: u32, value: f64) -> Edge {
        Edge { row, col, value }
    }

    /// Every matching of `edges` by enumeration: the best value under `objective`.
    fn best(edges: &[Edge], objective: Objective) -> (usize, f64) {
        fn walk(
            k: usize,
            edges: &[Edge],
            used: &mut Vec<Edge>,
            objective: Objective,
            best: &mut (usize, f64),
        ) {
            if k == edges.len() {
                let total: f64 = used.iter().map(|e| e.value).sum();
                let better = match objective {
                    Objective::MaxWeight => total > best.1 + 1e-12,
                    Objective::MaxPairsMinCost => {
                        used.len() > best.0 || (used.len() == best.0 && total < best.1 - 1e-12)
                    }
                };
                if better {
                    *best = (used.len(), total);
                }
                return;
            }
            walk(k + 1, edges, used, objective, best);
            let e = edges[k];
            if used.iter().all(|u| u.row != e.row && u.col != e.col) {
                used.push(e);
                walk(k + 1, edges, used, objective, best);
                used.pop();
            }
        }
        let start = match objective {
            Objective::MaxWeight => (0, 0.0),
            Objective::MaxPairsMinCost => (0, f64::INFINITY),
        };
        let mut out = start;
        walk(0, edges, &mut Vec::new(), objective, &mut out);
        if out.0 == 0 {
            out.1 = 0.0;
        }
        out
    }

    #[test]
    fn components_give_the_global_optimum() {
        let mut matcher = Matcher::default();
        let mut matched = Vec::new();
        // A deterministic scatter of sparse edges over 7 rows × 6 columns, many instances.
        for seed in 0u64..400 {
            let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                state
            };
            let mut edges: Vec<Edge> = Vec::new();
            for row in 0..7 {
                for col in 0..6 {
                    if next() % 4 == 0 {
                        edges.push(edge(row, col, (next() % 5 + 1) as f64 / 4.0));
                    }
                }
            }
            edges.truncate(12);
            for objective in [Objective::MaxWeight, Objective::MaxPairsMinCost] {
                matcher.solve(7, 6, &edges, objective, &mut matched);
                let chosen: Vec<Edge> = matched.iter().map(|&e| edges[e]).collect();
                for (k, a) in chosen.iter().enumerate() {
                    assert!(
                        chosen[k + 1..]
                            .iter()
                            .all(|b| a.row != b.row && a.col != b.col)
                    );
                }
                let total: f64 = chosen.iter().map(|e| e.value).sum();
                let (pairs, value) = best(&edges, objective);
                if objective == Objective::MaxPairsMinCost {
                    assert_eq!(chosen.len(), pairs, "seed {seed}");
                }
                assert!(
                    (total - value).abs() < 1e-9,
                    "seed {seed}: {total} vs {value}"
                );
            }
        }
    }

    /// Edges of a jittered lattice of `side × side` discs seen twice (truth, estimates),
    /// each object a candidate of the nearby ones: one large sparse component. Values are
    /// real (`levels == 0`) or among `levels` values (ties); a few objects are missing.
    fn lattice(seed: u64, side: u32, levels: u64) -> (usize, usize, Vec<Edge>) {
        let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut unit = move || (next() >> 11) as f64 / (1u64 << 53) as f64;
        let n = (side * side) as usize;
        let place = |k: u32, unit: &mut dyn FnMut() -> f64| {
            let (x, y) = (f64::from(k % side), f64::from(k / side));
            (x + 0.3 * unit(), y + 0.3 * unit())
        };
        let truth: Vec<_> = (0..side * side).map(|k| place(k, &mut unit)).collect();
        let estimates: Vec<_> = (0..side * side).map(|k| place(k, &mut unit)).collect();
        let mut edges = Vec::new();
        for (i, a) in truth.iter().enumerate() {
            for (j, b) in estimates.iter().enumerate() {
                let d = ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt();
                if d < 1.25 && unit() > 0.03 {
                    let value = if levels == 0 {
                        (1.3 - d) * (0.5 + unit())
                    } else {
                        (1 + (unit() * levels as f64) as u64) as f64 / levels as f64
                    };
                    edges.push(edge(i as u32, j as u32, value));
                }
            }
        }
        (n, n, edges)
    }

    #[test]
    fn large_components_match_the_dense_solver_exactly() {
        let (mut sparse, mut dense) = (Matcher::default(), Matcher::default());
        dense.dense_only = true;
        let (mut got, mut want) = (Vec::new(), Vec::new());
        for seed in 0..80 {
            let side = [6, 9, 12, 17][seed as usize % 4];
            let levels = [0, 0, 3, 1000][seed as usize / 4 % 4];
            let (rows, cols, edges) = lattice(seed, side, levels);
            // Rectangular too: drop the last row and two columns' edges.
            let shapes = [
                (rows, cols, edges.clone()),
                (
                    rows - 1,
                    cols - 2,
                    edges
                        .iter()
                        .copied()
                        .filter(|e| (e.row as usize) < rows - 1 && (e.col as usize) < cols - 2)
                        .collect(),
                ),
            ];
            for (rows, cols, edges) in &shapes {
                for objective in [Objective::MaxWeight, Objective::MaxPairsMinCost] {
                    sparse.solve(*rows, *cols, edges, objective, &mut got);
                    dense.solve(*rows, *cols, edges, objective, &mut want);
                    assert_eq!(got, want, "seed {seed}, {rows}×{cols}, {objective:?}");
                }
            }
        }
    }

    #[test]
    fn objectives_differ_where_they_should() {
        // Row 0 – col 0 is worth 1.0; the two pairs (0,1) and (1,0) are worth 0.4 each.
        let edges = [edge(0, 0, 1.0), edge(0, 1, 0.4), edge(1, 0, 0.4)];
        let mut matcher = Matcher::default();
        let mut matched = Vec::new();
        matcher.solve(2, 2, &edges, Objective::MaxWeight, &mut matched);
        assert_eq!(matched, vec![0]);
        matcher.solve(2, 2, &edges, Objective::MaxPairsMinCost, &mut matched);
        assert_eq!(matched, vec![1, 2]);
    }
}

//! Optimal one-to-one matching on the sparse candidate pairs of a frame (or of a sequence,
//! for Identity): the candidates split into connected components, each solved by the
//! dense assignment solver of `sillage-assoc`. Typical frames have many tiny components,
//! so matching costs about linear time in the number of objects.

use sillage_assoc::LapSolver;

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

//! Optimal one-to-one assignment on a sparse rectangular cost matrix: the linear assignment
//! problem of [`crate::lap`] when each row allows only a few columns, in time that grows
//! with the allowed entries rather than with `rows × cols`.
//!
//! Every row gets a private "unpaired" column, so that pairing every row is always possible
//! and the problem is a rectangular assignment in which every row is assigned. Rows are then
//! inserted one at a time by successive shortest augmenting paths (Jonker & Volgenant,
//! Computing 38, 1987; the Hungarian method in its shortest-path form): Dijkstra from the new
//! row over the reduced costs `c(i, j) − u(i) − v(j) ≥ 0` of its adjacency lists, with a
//! binary heap, stopped at the first free column; the potentials of the scanned nodes are
//! then updated so that the path becomes tight (Ahuja, Magnanti & Orlin, *Network Flows*,
//! §9.7). A search only visits the rows and columns that compete for the new row's columns,
//! so a large but sparse problem costs far less than the dense solver's `O((r + c) · c)` per
//! row. Ties in the search go to the lower column, so the result is deterministic.
//!
//! The unpaired column of a row costs 0 for [`Pairing::Optional`] (a maximum-weight matching
//! when pair costs are minus the weights) and, for [`Pairing::Maximum`], a constant larger
//! than anything one more pair can cost: `(2 · min(r, c) + 2) · max |cost|`, since an
//! augmenting path adding one pair has at most `2 · min(r, c) − 1` edges. The optima are
//! then exactly those of the dense solver: as many pairs as possible, then least cost.
//!
//! Which of several equal-cost optima is returned differs from [`crate::LapSolver`]'s
//! tie-breaking, so the solver also says whether its optimum is the only one with a margin
//! ([`SparseLapSolver::is_unique`]): it checks, from the final potentials, that no
//! alternating cycle or path made of near-tight entries exists (every optimum uses only tight
//! entries, by complementary slackness). A caller that must reproduce the dense solver's
//! choice re-solves densely when it is not.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Marks "no row" / "no column" in the solver's index buffers.
const NONE: u32 = u32::MAX;

/// Largest |cost| [`SparseLapSolver::solve`] accepts (the unpaired cost of
/// [`Pairing::Maximum`] and the potentials must stay finite).
pub const MAX_ABS_COST: f64 = 1e150;

/// Relative size of the near-tie margin: alternatives whose cost is within
/// `TIE_MARGIN · max |cost|` of the optimum count as ties.
const TIE_MARGIN: f64 = 1e-9;

/// What the assignment optimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pairing {
    /// As many pairs as the allowed entries permit, then least total cost: the objective of
    /// [`crate::LapSolver`] on the matrix whose other entries are forbidden.
    Maximum,
    /// Least total cost, a row staying unpaired at cost 0: pairs of non-negative cost are
    /// never needed. With costs `−weight`, a maximum-weight matching.
    Optional,
}

/// One entry of the Dijkstra heap: a column at a tentative distance, nearest first, lower
/// column on ties.
#[derive(Debug, Clone, Copy)]
struct Reached {
    distance: f64,
    col: u32,
}

impl PartialEq for Reached {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Reached {}

impl PartialOrd for Reached {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Reached {
    /// Reversed, so that `BinaryHeap` (a max-heap) pops the nearest column first.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .distance
            .total_cmp(&self.distance)
            .then(other.col.cmp(&self.col))
    }
}

/// A reusable sparse linear assignment solver: see [`SparseLapSolver::solve`].
#[derive(Debug, Clone, Default)]
pub struct SparseLapSolver {
    /// Problem size of the last `solve`.
    rows: usize,
    cols: usize,
    /// Cost of leaving a row unpaired (its private column `cols + row`).
    unpaired_cost: f64,
    /// Largest |cost| among the allowed entries.
    cost_scale: f64,
    /// Column of each row (`cols + row`: unpaired).
    col_of_row: Vec<u32>,
    /// Row of each column, the private ones included, or `NONE`.
    row_of_col: Vec<u32>,
    /// Potentials of rows and columns: reduced cost `c(i, j) − u(i) − v(j)`.
    row_potential: Vec<f64>,
    col_potential: Vec<f64>,
    /// Tentative distance of each column in the current search (`INFINITY`: not reached).
    col_distance: Vec<f64>,
    /// The row through which each column was last reached.
    came_from: Vec<u32>,
    /// Columns whose distance is final in the current search.
    scanned: Vec<bool>,
    /// Columns reached in the current search, to reset them.
    touched: Vec<u32>,
    /// Columns scanned in the current search, in order.
    scanned_list: Vec<u32>,
    heap: BinaryHeap<Reached>,
    /// DFS state of the uniqueness check: 0 unvisited, 1 on the stack, 2 done.
    visit: Vec<u8>,
    stack: Vec<(u32, u32)>,
    /// Whether the last optimum is the only one (with a margin).
    unique: bool,
    /// The answer of the last `solve`.
    output: Vec<Option<usize>>,
}

impl SparseLapSolver {
    /// An empty solver; buffers grow on first use.
    pub fn new() -> Self {
        Self::default()
    }

    /// Solves the assignment problem on the sparse `rows × cols` matrix given row by row:
    /// the allowed entries of row `i` are the columns `col_index[k]` at cost `costs[k]` for
    /// `k` in `row_start[i]..row_start[i + 1]`, each column at most once per row; a
    /// non-finite cost is forbidden, as is every entry not listed. Returns, for each row, the
    /// column it is paired with or `None`.
    ///
    /// The optimum follows `pairing`; when several assignments reach it, which one is
    /// returned is deterministic but need not be [`crate::LapSolver`]'s:
    /// [`is_unique`](Self::is_unique) tells whether there was a choice.
    ///
    /// # Panics
    /// When `row_start` does not have `rows + 1` non-decreasing offsets into `col_index` and
    /// `costs` (of equal length), a column index is `≥ cols`, or a finite cost exceeds
    /// [`MAX_ABS_COST`] in magnitude (bugs in the caller).
    pub fn solve(
        &mut self,
        rows: usize,
        cols: usize,
        row_start: &[usize],
        col_index: &[u32],
        costs: &[f64],
        pairing: Pairing,
    ) -> &[Option<usize>] {
        assert_eq!(
            row_start.len(),
            rows + 1,
            "one offset per row, plus the end"
        );
        assert_eq!(col_index.len(), costs.len(), "one cost per entry");
        assert!(
            row_start.windows(2).all(|w| w[0] <= w[1]) && row_start[rows] <= costs.len(),
            "non-decreasing row offsets within the entries"
        );
        assert!(
            col_index[row_start[0]..row_start[rows]]
                .iter()
                .all(|&j| (j as usize) < cols),
            "column indices below {cols}"
        );
        assert!(
            cols + rows < NONE as usize,
            "at most 2^32 − 1 rows and columns"
        );
        self.reset(rows, cols, row_start, costs, pairing);
        assert!(
            self.cost_scale <= MAX_ABS_COST,
            "costs of magnitude at most {MAX_ABS_COST}"
        );
        for source in 0..rows {
            self.insert_row(source, row_start, col_index, costs);
        }
        self.unique = self.check_unique(row_start, col_index, costs);
        self.output.clear();
        self.output.extend(
            self.col_of_row
                .iter()
                .map(|&j| ((j as usize) < cols).then_some(j as usize)),
        );
        &self.output
    }

    /// The answer of the last [`solve`](Self::solve) (empty before the first).
    pub fn assignment(&self) -> &[Option<usize>] {
        &self.output
    }

    /// Whether the last [`solve`](Self::solve)'s optimum was the only one: every other
    /// assignment costs more by at least about `10⁻⁹ · max |cost|` (more when rounding in the
    /// potentials is larger), far beyond the rounding of either solver, so that
    /// [`crate::LapSolver`] returns the same pairs. `false` when there was a tie or a near
    /// tie (or `Pairing::Optional` met a pair of cost ≥ 0 that an optimum could drop).
    pub fn is_unique(&self) -> bool {
        self.unique
    }

    /// Empties the assignment and sets feasible potentials: columns 0, each row its least
    /// cost (its unpaired column included).
    fn reset(
        &mut self,
        rows: usize,
        cols: usize,
        row_start: &[usize],
        costs: &[f64],
        pairing: Pairing,
    ) {
        self.rows = rows;
        self.cols = cols;
        let entries = &costs[row_start[0]..row_start[rows]];
        self.cost_scale = entries
            .iter()
            .filter(|c| c.is_finite())
            .fold(0.0, |m: f64, c| m.max(c.abs()));
        self.unpaired_cost = match pairing {
            Pairing::Optional => 0.0,
            Pairing::Maximum if self.cost_scale > 0.0 => {
                (2 * rows.min(cols) + 2) as f64 * self.cost_scale
            }
            Pairing::Maximum => 1.0,
        };
        let all_cols = cols + rows;
        self.col_of_row.clear();
        self.col_of_row.resize(rows, NONE);
        self.row_of_col.clear();
        self.row_of_col.resize(all_cols, NONE);
        self.col_potential.clear();
        self.col_potential.resize(all_cols, 0.0);
        self.row_potential.clear();
        self.row_potential.extend((0..rows).map(|i| {
            costs[row_start[i]..row_start[i + 1]]
                .iter()
                .filter(|c| c.is_finite())
                .fold(self.unpaired_cost, |m, &c| m.min(c))
        }));
        self.col_distance.clear();
        self.col_distance.resize(all_cols, f64::INFINITY);
        self.came_from.clear();
        self.came_from.resize(all_cols, NONE);
        self.scanned.clear();
        self.scanned.resize(all_cols, false);
    }

    /// Assigns the free row `source` by a shortest augmenting path (Dijkstra over reduced
    /// costs, stopped at the first free column), then makes the path tight.
    fn insert_row(&mut self, source: usize, row_start: &[usize], col_index: &[u32], costs: &[f64]) {
        self.heap.clear();
        self.relax(source, 0.0, row_start, col_index, costs);
        let (end, end_distance) = loop {
            let Some(Reached { distance, col }) = self.heap.pop() else {
                unreachable!("the source's unpaired column is always free");
            };
            let j = col as usize;
            if self.scanned[j] || distance > self.col_distance[j] {
                continue;
            }
            self.scanned[j] = true;
            self.scanned_list.push(col);
            match self.row_of_col[j] {
                NONE => break (j, distance),
                row => self.relax(row as usize, distance, row_start, col_index, costs),
            }
        };
        // Nodes scanned at distance d move by D − d, the source by D (Ahuja et al., §9.7):
        // reduced costs stay ≥ 0 and the path's entries become tight.
        self.row_potential[source] += end_distance;
        for &col in &self.scanned_list {
            let j = col as usize;
            let shift = end_distance - self.col_distance[j];
            self.col_potential[j] -= shift;
            let row = self.row_of_col[j];
            if row != NONE {
                self.row_potential[row as usize] += shift;
            }
        }
        // Flip the pairs along the path.
        let mut j = end as u32;
        loop {
            let row = self.came_from[j as usize];
            let previous = self.col_of_row[row as usize];
            self.col_of_row[row as usize] = j;
            self.row_of_col[j as usize] = row;
            if previous == NONE {
                break;
            }
            j = previous;
        }
        for &col in &self.touched {
            let j = col as usize;
            self.col_distance[j] = f64::INFINITY;
            self.came_from[j] = NONE;
            self.scanned[j] = false;
        }
        self.touched.clear();
        self.scanned_list.clear();
    }

    /// Relaxes the entries of `row`, reached at distance `distance`, to unscanned columns
    /// (its private unpaired column included).
    fn relax(
        &mut self,
        row: usize,
        distance: f64,
        row_start: &[usize],
        col_index: &[u32],
        costs: &[f64],
    ) {
        let base = distance - self.row_potential[row];
        let span = row_start[row]..row_start[row + 1];
        let unpaired = (self.cols + row) as u32;
        let entries = col_index[span.clone()]
            .iter()
            .zip(&costs[span])
            .map(|(&j, &c)| (j, c))
            .chain(std::iter::once((unpaired, self.unpaired_cost)));
        for (col, c) in entries {
            let j = col as usize;
            if !c.is_finite() || self.scanned[j] {
                continue;
            }
            let d = base + c - self.col_potential[j];
            if d < self.col_distance[j] {
                if self.col_distance[j] == f64::INFINITY {
                    self.touched.push(col);
                }
                self.col_distance[j] = d;
                self.came_from[j] = row as u32;
                self.heap.push(Reached { distance: d, col });
            }
        }
    }

    /// Whether the assignment is the only optimum with a margin: from the final potentials,
    /// every other assignment differs by alternating cycles and paths whose cost change is
    /// the sum of the reduced costs of the entries they add and of `−v(j)` for the columns
    /// they free; no such cycle or path may consist of near-zero terms only. Searched as a
    /// directed cycle (DFS) over rows → near-tight unassigned entries, columns → their row,
    /// free columns → a hub node, hub → assigned columns with `v ≈ 0`.
    fn check_unique(&mut self, row_start: &[usize], col_index: &[u32], costs: &[f64]) -> bool {
        let (rows, cols) = (self.rows, self.cols);
        let all_cols = cols + rows;
        // How far the potentials are from exact optimality (rounding), and the margin.
        let potential_scale = self
            .row_potential
            .iter()
            .chain(&self.col_potential)
            .fold(0.0, |m: f64, p| m.max(p.abs()));
        let mut slack =
            4.0 * f64::EPSILON * (self.cost_scale + self.unpaired_cost + 2.0 * potential_scale);
        let mut worst = 0.0f64;
        for i in 0..rows {
            let span = row_start[i]..row_start[i + 1];
            for (&col, &c) in col_index[span.clone()].iter().zip(&costs[span]) {
                if !c.is_finite() {
                    continue;
                }
                let reduced = self.reduced(i, col as usize, c);
                worst = worst.max(-reduced);
                if self.col_of_row[i] == col {
                    worst = worst.max(reduced.abs());
                }
            }
            let reduced = self.reduced(i, cols + i, self.unpaired_cost);
            worst = worst.max(-reduced);
            if self.col_of_row[i] as usize == cols + i {
                worst = worst.max(reduced.abs());
            }
        }
        for j in 0..all_cols {
            let v = self.col_potential[j];
            worst = worst.max(if self.row_of_col[j] == NONE {
                v.abs()
            } else {
                v
            });
        }
        slack += worst;
        let nodes = rows + all_cols;
        let margin = (TIE_MARGIN * self.cost_scale).max(16.0 * nodes as f64 * slack);

        // Nodes: rows 0..rows, columns rows..rows + all_cols, the hub last.
        let hub = nodes;
        self.visit.clear();
        self.visit.resize(nodes + 1, 0);
        let roots = std::iter::once(hub).chain(0..rows);
        for root in roots {
            if self.visit[root] != 0 {
                continue;
            }
            self.visit[root] = 1;
            self.stack.clear();
            self.stack.push((root as u32, 0));
            while let Some(&(node, arc)) = self.stack.last() {
                let mut arc = arc;
                let next = self.arc(node as usize, &mut arc, margin, row_start, col_index, costs);
                let top = self.stack.len() - 1;
                self.stack[top].1 = arc;
                match next {
                    None => {
                        self.visit[node as usize] = 2;
                        self.stack.pop();
                    }
                    Some(to) => match self.visit[to] {
                        0 => {
                            self.visit[to] = 1;
                            self.stack.push((to as u32, 0));
                        }
                        1 => return false,
                        _ => {}
                    },
                }
            }
        }
        true
    }

    /// Reduced cost of row `i` and column `j` at cost `c`.
    fn reduced(&self, i: usize, j: usize, c: f64) -> f64 {
        c - self.row_potential[i] - self.col_potential[j]
    }

    /// The next arc out of `node` at or after position `*arc` in the uniqueness graph (see
    /// [`check_unique`](Self::check_unique)), advancing `*arc` past it.
    fn arc(
        &self,
        node: usize,
        arc: &mut u32,
        margin: f64,
        row_start: &[usize],
        col_index: &[u32],
        costs: &[f64],
    ) -> Option<usize> {
        let (rows, cols) = (self.rows, self.cols);
        let all_cols = cols + rows;
        let hub = rows + all_cols;
        if node < rows {
            // Row: its near-tight entries other than its own, the unpaired column last.
            let i = node;
            let degree = (row_start[i + 1] - row_start[i]) as u32;
            while *arc <= degree {
                let k = *arc;
                *arc += 1;
                let (j, c) = if k < degree {
                    let e = row_start[i] + k as usize;
                    (col_index[e] as usize, costs[e])
                } else {
                    (cols + i, self.unpaired_cost)
                };
                if c.is_finite()
                    && self.col_of_row[i] as usize != j
                    && self.reduced(i, j, c) <= margin
                {
                    return Some(rows + j);
                }
            }
            None
        } else if node < hub {
            // Column: to its row, or (free) to the hub.
            if *arc > 0 {
                return None;
            }
            *arc = 1;
            match self.row_of_col[node - rows] {
                NONE => Some(hub),
                row => Some(row as usize),
            }
        } else {
            // Hub: the assigned columns that could be freed at no cost.
            while (*arc as usize) < all_cols {
                let j = *arc as usize;
                *arc += 1;
                if self.row_of_col[j] != NONE && -self.col_potential[j] <= margin {
                    return Some(rows + j);
                }
            }
            None
        }
    }
}

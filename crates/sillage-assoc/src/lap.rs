//! Optimal one-to-one assignment on a dense rectangular cost matrix (the linear assignment
//! problem), with forbidden pairs.
//!
//! The solver is the shortest augmenting path method of Jonker & Volgenant (Computing 38,
//! 1987), in the rectangular form of Crouse (IEEE TAES 52(4), 2016) that SciPy's
//! `linear_sum_assignment` uses, extended to forbidden entries: it is successive shortest
//! paths on the min-cost flow network source → rows → columns → sink (Ahuja, Magnanti &
//! Orlin, *Network Flows*, §9.7), with Johnson potentials keeping reduced costs
//! non-negative so that each search is a dense Dijkstra. All free rows are sources at once,
//! so which rows end up paired is part of the optimisation (a row-by-row Hungarian method
//! that skips rows it cannot pair is not optimal with forbidden entries).
//!
//! Cost: `O((r + c) · c)` per augmentation and at most `min(r, c)` augmentations on an
//! `r × c` matrix, with no allocation once the solver's buffers have grown.

/// Marks "no row" / "no column" in the solver's index buffers.
const NONE: usize = usize::MAX;

/// A reusable linear assignment solver: see [`LapSolver::solve`].
///
/// Keeping one solver and calling `solve` repeatedly (one call per frame, say) reuses its
/// buffers; [`solve_assignment`] is the one-shot form.
#[derive(Debug, Clone, Default)]
pub struct LapSolver {
    /// Column of each row, or `NONE`.
    col_of_row: Vec<usize>,
    /// Row of each column, or `NONE`.
    row_of_col: Vec<usize>,
    /// Potentials (dual variables) of rows and columns.
    row_potential: Vec<f64>,
    col_potential: Vec<f64>,
    /// Tentative shortest distance of each column in the current search.
    col_distance: Vec<f64>,
    /// Shortest distance of each row reached in the current search (`INFINITY`: not reached).
    row_distance: Vec<f64>,
    /// The row through which each column was last reached.
    came_from: Vec<usize>,
    /// Columns whose distance is final in the current search.
    scanned: Vec<bool>,
    /// The answer of the last `solve`.
    output: Vec<Option<usize>>,
}

impl LapSolver {
    /// An empty solver; buffers grow on first use.
    pub fn new() -> Self {
        Self::default()
    }

    /// Solves the assignment problem on the `rows × cols` matrix `costs` (row-major): returns,
    /// for each row, the column it is paired with or `None`.
    ///
    /// Every finite entry is an allowed pair; a non-finite entry (`±∞`, NaN) is forbidden and
    /// never assigned. Among the assignments that pair as many rows as the allowed entries
    /// permit (a maximum matching), the one returned has the least total cost. Without
    /// forbidden entries this is exactly SciPy's `linear_sum_assignment`: `min(rows, cols)`
    /// pairs of least total cost. To make pairing optional instead (a maximum-weight
    /// matching), give the non-pairs cost 0 and the pairs `-weight`, then drop the pairs
    /// assigned at cost 0.
    ///
    /// Ties are broken deterministically, toward lower indices: an all-equal square matrix
    /// gives the identity.
    ///
    /// # Panics
    /// When `costs.len() != rows * cols` (a bug in the caller).
    pub fn solve(&mut self, rows: usize, cols: usize, costs: &[f64]) -> &[Option<usize>] {
        assert_eq!(
            Some(costs.len()),
            rows.checked_mul(cols),
            "a cost matrix of {rows} × {cols} entries"
        );
        // Potential of the sink (every free column leads to it at zero cost).
        let Some(mut sink_potential) = self.reset(rows, cols, costs) else {
            return self.finish();
        };
        while let Some((sink_col, sink_distance)) =
            self.shortest_path(rows, cols, costs, sink_potential)
        {
            self.update_potentials(sink_distance);
            sink_potential += sink_distance;
            self.augment(sink_col);
        }
        self.finish()
    }

    /// Empties the pairing and sets the initial potentials: rows 0, each column its least
    /// allowed cost (its distance from the source while nothing is paired), the sink the
    /// least of those, which is returned; `None` when no entry is allowed.
    fn reset(&mut self, rows: usize, cols: usize, costs: &[f64]) -> Option<f64> {
        self.col_of_row.clear();
        self.col_of_row.resize(rows, NONE);
        self.row_of_col.clear();
        self.row_of_col.resize(cols, NONE);
        self.row_potential.clear();
        self.row_potential.resize(rows, 0.0);
        self.col_potential.clear();
        self.col_potential.resize(cols, f64::INFINITY);
        for row in costs.chunks_exact(cols.max(1)) {
            for (j, &c) in row.iter().enumerate() {
                if c.is_finite() {
                    self.col_potential[j] = self.col_potential[j].min(c);
                }
            }
        }
        let mut sink = f64::INFINITY;
        for p in &mut self.col_potential {
            if p.is_finite() {
                sink = sink.min(*p);
            } else {
                // No allowed entry: the column is never reached, any potential will do.
                *p = 0.0;
            }
        }
        sink.is_finite().then_some(sink)
    }

    /// Dijkstra from every free row at once over reduced costs; returns the free column that
    /// ends a shortest augmenting path and that path's reduced length, or `None` when no free
    /// column can be reached (the matching is maximum).
    fn shortest_path(
        &mut self,
        rows: usize,
        cols: usize,
        costs: &[f64],
        sink_potential: f64,
    ) -> Option<(usize, f64)> {
        self.col_distance.clear();
        self.col_distance.resize(cols, f64::INFINITY);
        self.came_from.clear();
        self.came_from.resize(cols, NONE);
        self.scanned.clear();
        self.scanned.resize(cols, false);
        self.row_distance.clear();
        self.row_distance.resize(rows, f64::INFINITY);
        for i in 0..rows {
            if self.col_of_row[i] == NONE {
                self.row_distance[i] = 0.0;
                self.relax(i, 0.0, cols, costs);
            }
        }
        let mut sink_distance = f64::INFINITY;
        let mut sink_col = NONE;
        loop {
            // The unscanned column nearest the sources; lower index on ties.
            let mut nearest = NONE;
            let mut nearest_distance = f64::INFINITY;
            for j in 0..cols {
                if !self.scanned[j] && self.col_distance[j] < nearest_distance {
                    nearest = j;
                    nearest_distance = self.col_distance[j];
                }
            }
            // The sink is final once no column is nearer (ties end the search).
            if nearest == NONE || sink_distance <= nearest_distance {
                break;
            }
            self.scanned[nearest] = true;
            match self.row_of_col[nearest] {
                NONE => {
                    // Free column → sink, reduced cost potential(col) − potential(sink) ≥ 0.
                    let d = nearest_distance + self.col_potential[nearest] - sink_potential;
                    if d < sink_distance {
                        sink_distance = d;
                        sink_col = nearest;
                    }
                }
                row => {
                    // The paired edge column → row is tight (reduced cost 0).
                    self.row_distance[row] = nearest_distance;
                    self.relax(row, nearest_distance, cols, costs);
                }
            }
        }
        (sink_col != NONE).then_some((sink_col, sink_distance))
    }

    /// Relaxes the edges from `row`, reached at reduced distance `distance`, to the unscanned
    /// columns (its own column, if paired, is already scanned).
    fn relax(&mut self, row: usize, distance: f64, cols: usize, costs: &[f64]) {
        let base = distance + self.row_potential[row];
        for (j, &c) in costs[row * cols..(row + 1) * cols].iter().enumerate() {
            if !c.is_finite() || self.scanned[j] {
                continue;
            }
            let d = base + c - self.col_potential[j];
            if d < self.col_distance[j] {
                self.col_distance[j] = d;
                self.came_from[j] = row;
            }
        }
    }

    /// Johnson's update capped at the sink's distance: every reduced cost stays ≥ 0 and the
    /// edges of the shortest path (and every pair) become tight.
    fn update_potentials(&mut self, sink_distance: f64) {
        for (p, &d) in self.col_potential.iter_mut().zip(&self.col_distance) {
            *p += d.min(sink_distance);
        }
        for (p, &d) in self.row_potential.iter_mut().zip(&self.row_distance) {
            *p += d.min(sink_distance);
        }
    }

    /// Flips the pairs along the path ending at the free column `col`.
    fn augment(&mut self, mut col: usize) {
        loop {
            let row = self.came_from[col];
            let previous = self.col_of_row[row];
            self.col_of_row[row] = col;
            self.row_of_col[col] = row;
            if previous == NONE {
                return;
            }
            col = previous;
        }
    }

    /// The pairing as `Option`s, in the reused output buffer.
    fn finish(&mut self) -> &[Option<usize>] {
        self.output.clear();
        self.output
            .extend(self.col_of_row.iter().map(|&j| (j != NONE).then_some(j)));
        &self.output
    }
}

/// Solves one assignment problem with a fresh [`LapSolver`]: for each row of the
/// `rows × cols` row-major `costs`, its column or `None`. Non-finite entries are forbidden;
/// see [`LapSolver::solve`] for the objective and the tie-breaking.
///
/// # Panics
/// When `costs.len() != rows * cols`.
pub fn solve_assignment(rows: usize, cols: usize, costs: &[f64]) -> Vec<Option<usize>> {
    LapSolver::new().solve(rows, cols, costs).to_vec()
}

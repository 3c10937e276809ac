//! Neighbour search for particle tracking.
//!
//! - [`NeighbourIndex`]: nearest and k-nearest queries, one at a time or in parallel
//!   batches (rayon; results do not depend on the number of threads).
//! - [`PointIndex`]: the fast index, a uniform grid hash built once per frame in O(n)
//!   (see its docs for why a grid rather than a k-d tree), rebuilt in place to reuse memory.
//! - [`BruteForceIndex`]: the obviously-correct O(n) reference the grid is tested against.
//! - [`mutual_nearest_neighbours`] / [`mutual_pairs_from_forward`] / [`mutual_pairs`]: the
//!   unequivocal forward-backward association of TracTrac (§3.1.2 of the TracTrac paper).
//! - [`LapSolver`] / [`solve_assignment`]: optimal one-to-one assignment on a dense
//!   rectangular cost matrix with forbidden pairs (Jonker–Volgenant shortest augmenting
//!   paths), checked against exhaustive search.
//! - [`SparseLapSolver`]: the same problem on a sparse matrix (adjacency lists), in time
//!   that grows with the allowed entries; it says whether its optimum is the only one, so
//!   that callers needing [`LapSolver`]'s tie-breaking can fall back to it on ties.
//!
//! Ties are broken deterministically: among points at the same distance the lower index wins.
//! Points with a non-finite coordinate are never returned, and a non-finite query finds nothing.
//!
//! ```
//! use sillage_assoc::{NeighbourIndex, PointIndex, mutual_nearest_neighbours};
//! use sillage_core::Point2;
//!
//! let frame = [Point2::new(0.0, 0.0), Point2::new(10.0, 0.0), Point2::new(10.0, 10.0)];
//! let index = PointIndex::new(&frame);
//! assert_eq!(index.nearest(Point2::new(9.0, 1.0)), Some((1, 2f64.sqrt())));
//!
//! let mut knn = Vec::new();
//! index.k_nearest(Point2::new(1.0, 0.0), 2, &mut knn);
//! assert_eq!(knn, vec![(0, 1.0), (1, 9.0)]);
//!
//! let next = [Point2::new(11.0, 0.5), Point2::new(0.5, 0.5)];
//! assert_eq!(mutual_nearest_neighbours(&frame, &next, None), vec![Some(1), Some(0), None]);
//!
//! // Row 1 may only take column 0: row 0 yields it, as two pairs beat one cheaper pair.
//! let costs = [1.0, 2.0, 1.0, f64::INFINITY];
//! assert_eq!(sillage_assoc::solve_assignment(2, 2, &costs), vec![Some(1), Some(0)]);
//!
//! // The same problem given sparsely, row by row (row 1 lists only column 0).
//! use sillage_assoc::{Pairing, SparseLapSolver};
//! let mut sparse = SparseLapSolver::new();
//! let pairs = sparse.solve(2, 2, &[0, 2, 3], &[0, 1, 0], &[1.0, 2.0, 1.0], Pairing::Maximum);
//! assert_eq!(pairs, &[Some(1), Some(0)]);
//! assert!(sparse.is_unique());
//! ```

mod brute;
mod grid;
mod index;
pub mod lap;
mod mutual;
pub mod sparse_lap;

pub use brute::BruteForceIndex;
pub use grid::PointIndex;
pub use index::{Neighbour, NeighbourIndex};
pub use lap::{LapSolver, solve_assignment};
pub use mutual::{mutual_nearest_neighbours, mutual_pairs, mutual_pairs_from_forward};
pub use sparse_lap::{Pairing, SparseLapSolver};

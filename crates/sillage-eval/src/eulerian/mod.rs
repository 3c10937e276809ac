//! Eulerian statistics of tracks: the rows of a track table binned on a regular grid, in
//! one pass with memory independent of the number of rows (Welford's update), giving per
//! bin the count, concentration, mean velocity, the Reynolds-stress terms ⟨u'²⟩, ⟨v'²⟩,
//! ⟨u'v'⟩, the turbulent kinetic energy, the mean speed and the mean log prediction error —
//! the time-averaged fields of the TracTrac paper (§5.1, Fig. 6c-d) — and profiles along
//! `x` or `y`.
//!
//! ```
//! use sillage_core::{Point2, TrackPoint, Vec2};
//! use sillage_eval::eulerian::{EulerianGrid, GridParams};
//!
//! let mut grid = EulerianGrid::new(GridParams { bin_size: 10.0, ..GridParams::default() })?;
//! for (frame, u) in [(0, 1.0), (1, 3.0)] {
//!     let mut point = TrackPoint::at(frame, 7, Point2::new(4.0, 5.0));
//!     point.vel_px_per_frame = Some(Vec2::new(u, 0.0));
//!     grid.push(&point)?;
//! }
//! let bins = grid.bins();
//! assert_eq!(bins.len(), 1);
//! assert_eq!(bins[0].mean_velocity.x, 2.0);
//! assert_eq!(bins[0].stresses[0], 1.0); // ⟨u'²⟩ of {1, 3}
//! # Ok::<(), sillage_core::Error>(())
//! ```

mod grid;
mod moments;
mod profile;

pub use grid::{BinAccumulator, BinStats, EulerianGrid, GridParams};
pub use moments::{RunningMean, VelocityMoments};
pub use profile::ProfileAxis;

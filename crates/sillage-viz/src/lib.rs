//! Pictures of the results, as pixels or SVG text (files are written by `sillage-io`):
//!
//! - [`Figure`] of [`GroupedChart`]s: categories along x, grouped bars on a left scale and
//!   curves on a right scale — the MMPF+ paper's Fig. 6 and Fig. 7 — as PNG pixels or SVG;
//! - [`Heatmap`]: a field on a grid as coloured cells with a colour bar (Eulerian maps);
//! - [`TrajectoryPlot`] (tracks coloured by speed, motion state or id, [`TrackColouring`]),
//!   [`QuiverPlot`] (velocity arrows at one frame), [`Histogram`] (displacements, log10
//!   prediction errors) and [`LineChart`] (counts per frame): every chart is a [`Plot`], drawn
//!   into PNG pixels or SVG by the same code;
//! - [`draw_overlay`]: a frame with its detections circled and track tails coloured by motion
//!   state, speed or id, with ids, from a [`TrackHistory`];
//! - [`draw_pedestrians`]: tracked people's boxes with the bar of their motion-model weights
//!   and their trajectories coloured by the dominant model (the IMM-PF paper's Fig. 1(b) and
//!   Fig. 2), from [`PersonOverlay`]s and [`PedestrianTrails`].
//!
//! Text uses a built-in typeface (DejaVu Sans), so nothing depends on the system's fonts.
//!
//! ```
//! use sillage_viz::{Figure, GroupedChart, Plot, Series, ValueAxis};
//!
//! let chart = GroupedChart {
//!     title: "Motion-state F-score".into(),
//!     x_label: "state".into(),
//!     categories: vec!["resting".into(), "rolling".into(), "saltating".into()],
//!     bar_axis: ValueAxis { label: "F-score".into(), min: 0.0, max: 1.0 },
//!     bars: vec![Series { label: "MMPF+".into(), values: vec![Some(0.87), Some(0.57), Some(0.9)] }],
//!     line_axis: None,
//!     lines: vec![],
//! };
//! let picture = Figure { panels: vec![chart] }.to_rgb(480, 320)?;
//! assert_eq!(picture.dimensions(), (480, 320));
//! # Ok::<(), sillage_core::Error>(())
//! ```

mod canvas;
mod chart;
mod colormap;
mod colouring;
mod font;
mod heatmap;
mod histogram;
mod history;
mod image_plane;
mod legend;
mod lines;
mod overlay;
mod palette;
mod pedestrians;
mod quiver;
mod trajectories;

pub use canvas::Plot;
pub use chart::{Figure, GroupedChart, Series, ValueAxis};
pub use colormap::viridis;
pub use colouring::{TrackColouring, speed_scale};
pub use heatmap::{HeatCell, Heatmap};
pub use histogram::{Bins, Histogram};
pub use history::{TrackHistory, velocity_px_per_frame};
pub use lines::{Curve, LineChart};
pub use overlay::{OverlayStyle, draw_overlay};
pub use palette::{id_rgb, model_rgb, state_rgb};
pub use pedestrians::{PedestrianTrails, PersonOverlay, TrailPoint, draw_pedestrians};
pub use quiver::{Arrow, QuiverPlot};
pub use trajectories::TrajectoryPlot;

//! `sillage plot`: charts of a track table as PNG or SVG — trajectories coloured by speed,
//! motion state or id, velocity arrows at one frame, histograms of the displacements and of
//! the log10 prediction errors, and counts of tracks and detections per frame.

use std::path::Path;
use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::{Args, ValueEnum};
use sillage::plots::{
    ColourBy, counts_chart, displacement_histogram, file_name, prediction_error_histogram,
    quiver_plot, track_colouring, write_plot,
};
use sillage::viz::{Plot, TrackColouring, TrackHistory, TrajectoryPlot};

use crate::shared_args::{ColourArg, FrameSize, TracksInputArgs};
use crate::track_input::read_tracks_for_drawing;

/// The charts of `sillage plot`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PlotKind {
    /// Every track as a line on the image plane (`--colour speed|state|id`).
    Trajectories,
    /// Velocity arrows at one frame (`--frame`).
    Quiver,
    /// Histogram of the displacement per frame (speed, px/frame).
    Displacements,
    /// Histogram of log10 of the prediction error (PTV tables).
    PredictionError,
    /// Tracks (and, with `--detections`, detections) per frame.
    Counts,
}

/// `sillage plot`.
#[derive(Debug, Args)]
pub struct PlotArgs {
    /// Which chart.
    #[arg(value_enum)]
    pub kind: PlotKind,
    /// The tracks.
    #[command(flatten)]
    pub input: TracksInputArgs,
    /// Picture to write: `.png` or `.svg`.
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Frame of the velocity arrows (0-based; default: the frame with most tracks).
    #[arg(long, value_name = "N")]
    pub frame: Option<u64>,
    /// Leave out tracks of fewer points.
    #[arg(long, value_name = "L", default_value_t = 1)]
    pub min_length: usize,
    /// Picture size `WxH`, px.
    #[arg(long, value_name = "WxH", default_value = "800x600")]
    pub size: FrameSize,
    /// Histogram bins.
    #[arg(long, default_value_t = 50)]
    pub bins: usize,
    /// Histogram counts on a log scale.
    #[arg(long)]
    pub log_y: bool,
}

/// Runs `sillage plot`.
pub fn run(args: &PlotArgs) -> Result<()> {
    let input = &args.input;
    let tracks = read_tracks_for_drawing(&input.tracks, input.format)?;
    let has_velocities = tracks.has_velocities;
    let has_states = tracks.has_states;
    let history = TrackHistory::new(tracks.points).with_min_points(args.min_length);
    if history.is_empty() {
        bail!(
            "{}: no track has {} points or more; lower --min-length",
            input.tracks.display(),
            args.min_length
        );
    }
    let name = file_name(&input.tracks);
    let uses_velocities = matches!(args.kind, PlotKind::Quiver | PlotKind::Displacements);
    if uses_velocities && !has_velocities {
        eprintln!("note: {name} has no velocities; using finite differences of the positions");
    }
    let (width, height) = args.size.0;
    let size = (width as u32, height as u32);
    let out = &args.out;
    let (bins, log_y) = (args.bins, args.log_y);
    match args.kind {
        PlotKind::Trajectories => {
            let colouring = colouring(input, has_states, &history)?;
            let title = format!("{} tracks ({name})", history.len());
            let plot = TrajectoryPlot {
                title,
                tracks: history,
                colouring,
            };
            write(out, &plot, size)
        }
        PlotKind::Quiver => write(out, &quiver_plot(&history, args.frame, &name)?, size),
        PlotKind::Displacements => write(
            out,
            &displacement_histogram(&history, &name, bins, log_y),
            size,
        ),
        PlotKind::PredictionError => {
            let histogram =
                prediction_error_histogram(&input.tracks, &history, &name, bins, log_y)?;
            write(out, &histogram, size)
        }
        PlotKind::Counts => {
            let chart = counts_chart(&history, input.detections.as_deref(), &name)?;
            write(out, &chart, size)
        }
    }
}

/// The colouring asked by `--colour` (default: state for tables with motion states, else
/// speed, scaled to the tracks' speeds).
pub fn colouring(
    input: &TracksInputArgs,
    has_states: bool,
    history: &TrackHistory,
) -> Result<TrackColouring> {
    let requested = input.colour.map(|colour| match colour {
        ColourArg::Speed => ColourBy::Speed,
        ColourArg::State => ColourBy::State,
        ColourArg::Id => ColourBy::Id,
    });
    Ok(track_colouring(
        &input.tracks,
        requested,
        has_states,
        history,
    )?)
}

/// Writes `plot` at `path` (PNG or SVG, after the extension) and names the file.
fn write(path: &Path, plot: &impl Plot, size: (u32, u32)) -> Result<()> {
    write_plot(path, plot, size)?;
    eprintln!("{}", path.display());
    Ok(())
}

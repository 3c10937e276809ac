//! `sillage plot`: charts of a track table as PNG or SVG — trajectories coloured by speed,
//! motion state or id, velocity arrows at one frame, histograms of the displacements and of
//! the log10 prediction errors, and counts of tracks and detections per frame.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Result, bail};
use sillage::core::FrameIndex;
use sillage::io::{read_detections_csv, write_png_rgb, write_text};
use sillage::viz::{
    Arrow, Curve, Histogram, LineChart, Plot, QuiverPlot, TrackColouring, TrackHistory,
    TrajectoryPlot, speed_scale, velocity_px_per_frame,
};

use crate::cli::{ColourArg, PlotArgs, PlotKind, TracksInputArgs};
use crate::track_input::read_tracks_for_drawing;

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
    match args.kind {
        PlotKind::Trajectories => {
            let colouring = colouring(input, has_states, &history)?;
            let title = format!("{} tracks ({name})", history.len());
            write_plot(
                out,
                &TrajectoryPlot {
                    title,
                    tracks: history,
                    colouring,
                },
                size,
            )
        }
        PlotKind::Quiver => write_plot(out, &quiver(&history, args.frame, &name)?, size),
        PlotKind::Displacements => {
            let values = history
                .tracks()
                .flat_map(|t| (0..t.len()).filter_map(move |i| velocity_px_per_frame(t, i)))
                .map(|v| v.norm())
                .collect();
            let histogram = Histogram {
                title: format!("Displacement per frame ({name})"),
                x_label: "displacement (px/frame)".into(),
                values,
                bins: args.bins,
                log_y: args.log_y,
            };
            write_plot(out, &histogram, size)
        }
        PlotKind::PredictionError => {
            let values: Vec<f64> = history
                .tracks()
                .flatten()
                .filter_map(|p| p.log10_pred_err)
                .collect();
            if values.is_empty() {
                bail!(
                    "{}: no prediction error (log_err column) in this table; only `sillage ptv` \
                     writes them",
                    input.tracks.display()
                );
            }
            let histogram = Histogram {
                title: format!("Prediction error ({name})"),
                x_label: "log10 prediction error (px)".into(),
                values,
                bins: args.bins,
                log_y: args.log_y,
            };
            write_plot(out, &histogram, size)
        }
        PlotKind::Counts => write_plot(
            out,
            &counts(&history, input.detections.as_deref(), &name)?,
            size,
        ),
    }
}

/// The colouring asked by `--colour` (default: state for tables with motion states, else
/// speed, scaled to the tracks' speeds).
pub fn colouring(
    input: &TracksInputArgs,
    has_states: bool,
    history: &TrackHistory,
) -> Result<TrackColouring> {
    let default = if has_states {
        ColourArg::State
    } else {
        ColourArg::Speed
    };
    Ok(match input.colour.unwrap_or(default) {
        ColourArg::Speed => TrackColouring::Speed {
            max_px_per_frame: speed_scale(history.tracks()),
        },
        ColourArg::State if !has_states => bail!(
            "{}: the table has no motion states (a motion_state column: bedload tables); use \
             --colour speed or --colour id",
            input.tracks.display()
        ),
        ColourArg::State => TrackColouring::State,
        ColourArg::Id => TrackColouring::Id,
    })
}

/// Writes `plot` at `path` as PNG or SVG, after the extension.
pub fn write_plot(path: &Path, plot: &impl Plot, (width, height): (u32, u32)) -> Result<()> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("png") => write_png_rgb(path, &plot.to_rgb(width, height)?)?,
        Some("svg") => write_text(path, &plot.to_svg(width, height)?)?,
        _ => bail!(
            "{}: give a picture file ending in .png or .svg",
            path.display()
        ),
    }
    eprintln!("{}", path.display());
    Ok(())
}

/// Velocity arrows at `frame`, or at the frame with the most tracks.
fn quiver(history: &TrackHistory, frame: Option<FrameIndex>, name: &str) -> Result<QuiverPlot> {
    let per_frame = points_per_frame(history);
    let frame = match frame {
        Some(frame) => frame,
        // The first of the busiest frames.
        None => per_frame
            .iter()
            .max_by_key(|&(f, n)| (*n, std::cmp::Reverse(*f)))
            .map_or(0, |(f, _)| *f),
    };
    let arrows: Vec<Arrow> = history
        .tracks()
        .filter_map(|t| {
            let i = t.iter().position(|p| p.frame == frame)?;
            Some(Arrow {
                pos_px: t[i].pos_px,
                vel_px_per_frame: velocity_px_per_frame(t, i)?,
            })
        })
        .collect();
    if arrows.is_empty() {
        let (first, last) = (per_frame.keys().next(), per_frame.keys().next_back());
        bail!(
            "{name}: no track with a velocity at frame {frame}; the tracks span frames {} to {} \
             (0-based), give --frame in that range",
            first.copied().unwrap_or(0),
            last.copied().unwrap_or(0)
        );
    }
    Ok(QuiverPlot {
        title: format!("Velocities at frame {frame} ({name})"),
        arrows,
        length_per_speed: None,
    })
}

/// Tracks per frame and, with `detections`, detections per frame, over every frame from the
/// first to the last (zeros included).
fn counts(history: &TrackHistory, detections: Option<&Path>, name: &str) -> Result<LineChart> {
    let tracks = points_per_frame(history);
    let detections: Option<BTreeMap<FrameIndex, usize>> = detections
        .map(|path| {
            let rows = read_detections_csv(path)?;
            Ok::<_, anyhow::Error>(rows.into_iter().map(|(f, d)| (f, d.len())).collect())
        })
        .transpose()?;
    let frames = tracks
        .keys()
        .chain(detections.iter().flat_map(|d| d.keys()));
    let (first, last) = frames.fold((u64::MAX, 0), |(a, b), &f| (a.min(f), b.max(f)));
    let curve = |label: &str, counts: &BTreeMap<FrameIndex, usize>| Curve {
        label: label.into(),
        points: (first..=last)
            .map(|f| (f as f64, counts.get(&f).copied().unwrap_or(0) as f64))
            .collect(),
    };
    let mut curves = Vec::new();
    if let Some(d) = &detections {
        curves.push(curve("detections", d));
    }
    curves.push(curve("tracks", &tracks));
    Ok(LineChart {
        title: format!("Per frame ({name})"),
        x_label: "frame (0-based)".into(),
        y_label: "count".into(),
        curves,
    })
}

/// Number of tracks with a point at each frame.
fn points_per_frame(history: &TrackHistory) -> BTreeMap<FrameIndex, usize> {
    let mut counts = BTreeMap::new();
    for p in history.tracks().flatten() {
        *counts.entry(p.frame).or_insert(0) += 1;
    }
    counts
}

/// The file name of `path`, for titles.
pub fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

//! The charts of `sillage plot` built from a track table, and picture files written after
//! their extension: trajectories coloured by speed, motion state or id, velocity arrows at one
//! frame, histograms of the displacements and of the log10 prediction errors, and counts of
//! tracks and detections per frame.

use std::collections::BTreeMap;
use std::path::Path;

use sillage_core::{Error, FrameIndex, Result};
use sillage_io::{read_detections_csv, write_png_rgb, write_text};
use sillage_viz::{
    Arrow, Curve, Histogram, LineChart, Plot, QuiverPlot, TrackColouring, TrackHistory,
    speed_scale, velocity_px_per_frame,
};

/// What the track tails are coloured by (`--colour`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColourBy {
    /// Speed, on the viridis map.
    Speed,
    /// Motion state (tables with a `motion_state` column).
    State,
    /// Track identity.
    Id,
}

/// The colouring `requested` for the tracks of the table `tracks` (default: state for tables
/// with motion states, else speed, scaled to the tracks' speeds).
pub fn track_colouring(
    tracks: &Path,
    requested: Option<ColourBy>,
    has_states: bool,
    history: &TrackHistory,
) -> Result<TrackColouring> {
    let default = if has_states {
        ColourBy::State
    } else {
        ColourBy::Speed
    };
    Ok(match requested.unwrap_or(default) {
        ColourBy::Speed => TrackColouring::Speed {
            max_px_per_frame: speed_scale(history.tracks()),
        },
        ColourBy::State if !has_states => {
            return Err(Error::input(format!(
                "{}: the table has no motion states (a motion_state column: bedload tables); \
                 use --colour speed or --colour id",
                tracks.display()
            )));
        }
        ColourBy::State => TrackColouring::State,
        ColourBy::Id => TrackColouring::Id,
    })
}

/// Writes `plot` at `path` as PNG or SVG, after the extension.
pub fn write_plot(path: &Path, plot: &impl Plot, (width, height): (u32, u32)) -> Result<()> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("png") => write_png_rgb(path, &plot.to_rgb(width, height)?),
        Some("svg") => write_text(path, &plot.to_svg(width, height)?),
        _ => Err(Error::input(format!(
            "{}: give a picture file ending in .png or .svg",
            path.display()
        ))),
    }
}

/// Histogram of the displacement per frame of every point with a velocity (else a finite
/// difference of the positions), px/frame; `name` titles it.
pub fn displacement_histogram(
    history: &TrackHistory,
    name: &str,
    bins: usize,
    log_y: bool,
) -> Histogram {
    let values = history
        .tracks()
        .flat_map(|t| (0..t.len()).filter_map(move |i| velocity_px_per_frame(t, i)))
        .map(|v| v.norm())
        .collect();
    Histogram {
        title: format!("Displacement per frame ({name})"),
        x_label: "displacement (px/frame)".into(),
        values,
        bins,
        log_y,
    }
}

/// Histogram of the log10 prediction errors of the table `tracks` (only PTV writes them).
pub fn prediction_error_histogram(
    tracks: &Path,
    history: &TrackHistory,
    name: &str,
    bins: usize,
    log_y: bool,
) -> Result<Histogram> {
    let values: Vec<f64> = history
        .tracks()
        .flatten()
        .filter_map(|p| p.log10_pred_err)
        .collect();
    if values.is_empty() {
        return Err(Error::input(format!(
            "{}: no prediction error (log_err column) in this table; only `sillage ptv` writes \
             them",
            tracks.display()
        )));
    }
    Ok(Histogram {
        title: format!("Prediction error ({name})"),
        x_label: "log10 prediction error (px)".into(),
        values,
        bins,
        log_y,
    })
}

/// Velocity arrows at `frame`, or at the first of the frames with the most tracks.
pub fn quiver_plot(
    history: &TrackHistory,
    frame: Option<FrameIndex>,
    name: &str,
) -> Result<QuiverPlot> {
    let per_frame = points_per_frame(history);
    let frame = match frame {
        Some(frame) => frame,
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
        return Err(Error::input(format!(
            "{name}: no track with a velocity at frame {frame}; the tracks span frames {} to {} \
             (0-based), give --frame in that range",
            first.copied().unwrap_or(0),
            last.copied().unwrap_or(0)
        )));
    }
    Ok(QuiverPlot {
        title: format!("Velocities at frame {frame} ({name})"),
        arrows,
        length_per_speed: None,
    })
}

/// Tracks per frame and, with the detections CSV `detections`, detections per frame, over
/// every frame from the first to the last (zeros included).
pub fn counts_chart(
    history: &TrackHistory,
    detections: Option<&Path>,
    name: &str,
) -> Result<LineChart> {
    let tracks = points_per_frame(history);
    let detections: Option<BTreeMap<FrameIndex, usize>> = detections
        .map(|path| {
            let rows = read_detections_csv(path)?;
            Ok::<_, Error>(rows.into_iter().map(|(f, d)| (f, d.len())).collect())
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

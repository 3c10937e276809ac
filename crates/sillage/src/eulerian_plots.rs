//! The plots of `sillage eulerian --plots DIR`: the per-bin fields as PNG heatmaps (the TracTrac paper's
//! Fig. 6c: mean speed and turbulent kinetic energy; also the count, both mean velocity
//! components and the Reynolds shear stress), and the profiles as line charts (Fig. 6d: mean
//! velocity, and the Reynolds stresses, against the position across the flow).

use std::path::{Path, PathBuf};

use sillage_core::Result;
use sillage_eval::eulerian::{BinStats, EulerianGrid, ProfileAxis};
use sillage_io::write_png_rgb;
use sillage_viz::{Curve, HeatCell, Heatmap, LineChart, Plot};

use crate::folders::create_folder;

/// The value a heatmap shows for a bin.
type Field = fn(&BinStats) -> f64;

/// Picture size of each heatmap, px.
const SIZE: (u32, u32) = (720, 600);

/// Writes one heatmap per field into `dir`, and two line charts per profile (mean velocity;
/// Reynolds stresses); returns the files written.
pub fn write_eulerian_plots(
    dir: &Path,
    grid: &EulerianGrid,
    bins: &[BinStats],
    profiles: &[(ProfileAxis, Vec<BinStats>)],
) -> Result<Vec<PathBuf>> {
    create_folder(dir)?;
    let calibrated = grid.params().calibration.is_some();
    let (length, velocity, stress) = if calibrated {
        ("m", "m/s", "m²/s²")
    } else {
        ("px", "px/frame", "px²/frame²")
    };
    let fields: [(&str, String, Field); 6] = [
        ("points", "points per bin".into(), |b| b.points as f64),
        ("speed", format!("mean speed ({velocity})"), |b| {
            b.mean_speed
        }),
        ("u", format!("mean u ({velocity})"), |b| b.mean_velocity.x),
        ("v", format!("mean v ({velocity})"), |b| b.mean_velocity.y),
        ("tke", format!("turbulent kinetic energy ({stress})"), |b| {
            b.turbulent_kinetic_energy
        }),
        ("uv", format!("<u'v'> ({stress})"), |b| b.stresses[2]),
    ];
    let size = grid.params().bin_size;
    let mut written = Vec::new();
    for (name, label, value) in fields {
        let map = Heatmap {
            title: label.clone(),
            value_label: label,
            axis_unit: length.into(),
            cells: bins
                .iter()
                .map(|b| HeatCell {
                    x: b.centre.x - 0.5 * size,
                    y: b.centre.y - 0.5 * size,
                    size,
                    value: value(b),
                })
                .collect(),
        };
        if bins.iter().all(|b| !value(b).is_finite()) {
            continue; // e.g. a table without velocities: no velocity maps.
        }
        let path = dir.join(format!("eulerian_{name}.png"));
        write_png_rgb(&path, &map.to_rgb(SIZE.0, SIZE.1)?)?;
        written.push(path);
    }
    for (axis, profile) in profiles {
        let (name, along): (&str, fn(&BinStats) -> f64) = match axis {
            ProfileAxis::X => ("x", |b| b.centre.x),
            ProfileAxis::Y => ("y", |b| b.centre.y),
        };
        let curve = |label: &str, value: Field| Curve {
            label: label.into(),
            points: profile.iter().map(|b| (along(b), value(b))).collect(),
        };
        let charts = [
            (
                "velocity",
                velocity,
                vec![
                    curve("<u>", |b| b.mean_velocity.x),
                    curve("<v>", |b| b.mean_velocity.y),
                ],
            ),
            (
                "stresses",
                stress,
                vec![
                    curve("<u'u'>", |b| b.stresses[0]),
                    curve("<v'v'>", |b| b.stresses[1]),
                    curve("<u'v'>", |b| b.stresses[2]),
                ],
            ),
        ];
        for (what, unit, curves) in charts {
            let chart = LineChart {
                title: format!("profile along {name}: {what}"),
                x_label: format!("{name} ({length})"),
                y_label: format!("{what} ({unit})"),
                curves,
            };
            if chart.validate().is_err() {
                continue; // no velocities: nothing to draw.
            }
            let path = dir.join(format!("eulerian_profile_{name}_{what}.png"));
            write_png_rgb(&path, &chart.to_rgb(SIZE.0, SIZE.1)?)?;
            written.push(path);
        }
    }
    Ok(written)
}

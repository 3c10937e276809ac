//! `sillage eulerian --plots DIR`: the per-bin fields as PNG heatmaps (the TracTrac paper's
//! Fig. 6c: mean speed and turbulent kinetic energy; also the count, both mean velocity
//! components and the Reynolds shear stress).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use sillage::eval::eulerian::{BinStats, EulerianGrid};
use sillage::io::write_png_rgb;
use sillage::viz::{HeatCell, Heatmap, Plot};

/// The value a heatmap shows for a bin.
type Field = fn(&BinStats) -> f64;

/// Picture size of each heatmap, px.
const SIZE: (u32, u32) = (720, 600);

/// Writes one heatmap per field into `dir`; returns the files written.
pub fn write(dir: &Path, grid: &EulerianGrid, bins: &[BinStats]) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the folder {}", dir.display()))?;
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
    Ok(written)
}

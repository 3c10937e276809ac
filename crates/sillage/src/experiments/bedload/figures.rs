//! The figures of the bedload evaluation (`sillage bench bedload --plots DIR`): the MMPF+
//! paper's Fig. 6 (per
//! sequence, correct tracks of transparent beads as bars and MOTA as curves, against τ_t) and
//! Fig. 7 (per sequence, the motion-state F-scores of MMPF+ and MMPF), as PNG and SVG.

use std::path::Path;

use sillage_core::Result;
use sillage_io::{write_png_rgb, write_text};
use sillage_track::bedload::BedloadTrackerKind;
use sillage_viz::{Figure, GroupedChart, Plot, Series, ValueAxis};

use super::{Row, Scope, TABLE_THRESHOLD};
use crate::bedload::create_folder;

/// Size of one panel, px.
const PANEL: (u32, u32) = (760, 460);

/// The sequences present in `rows`, real first (the paper's ExpSeq is its left panel).
fn sequences(rows: &[Row]) -> Vec<&'static str> {
    let mut names: Vec<&'static str> = Vec::new();
    for row in rows {
        if !names.contains(&row.sequence) {
            names.push(row.sequence);
        }
    }
    names.sort_by_key(|name| *name != "real");
    names
}

/// The τ_t values of the sweep, in increasing order.
fn thresholds(rows: &[Row]) -> Vec<f64> {
    let mut values: Vec<f64> = rows
        .iter()
        .filter(|r| r.scope == Scope::Transparent)
        .map(|r| r.transparent_threshold)
        .collect();
    values.sort_by(f64::total_cmp);
    values.dedup();
    values
}

/// The sweep's value of `metric` for `kind` on `sequence` at each of `taus` (percent).
fn sweep_series(
    rows: &[Row],
    taus: &[f64],
    sequence: &str,
    kind: BedloadTrackerKind,
    metric: impl Fn(&Row) -> f64,
) -> Series {
    let values = taus
        .iter()
        .map(|&tau| {
            rows.iter()
                .find(|r| {
                    r.scope == Scope::Transparent
                        && r.sequence == sequence
                        && r.tracker == kind
                        && (r.transparent_threshold - tau).abs() < 1e-9
                })
                .map(|r| 100.0 * metric(r))
        })
        .collect();
    Series {
        label: kind.paper_name().to_string(),
        values,
    }
}

/// Fig. 6: one panel per sequence.
fn fig6(rows: &[Row]) -> Figure {
    let taus = thresholds(rows);
    let panels = sequences(rows)
        .into_iter()
        .map(|sequence| {
            let series = |metric: fn(&Row) -> f64| -> Vec<Series> {
                BedloadTrackerKind::ALL
                    .iter()
                    .map(|&kind| sweep_series(rows, &taus, sequence, kind, metric))
                    .collect()
            };
            let bars = series(|r| r.scores.table1.correct_track_rate);
            let lines = series(|r| r.scores.mot.clear.mota);
            let lowest = lines
                .iter()
                .flat_map(|s| s.values.iter().flatten())
                .fold(100.0_f64, |m, &v| m.min(v));
            GroupedChart {
                title: format!("Transparent beads, {sequence} sequence"),
                x_label: "transparent-bead threshold τ_t".into(),
                categories: taus.iter().map(|t| format!("{t:.2}")).collect(),
                bar_axis: ValueAxis {
                    label: "correct tracks % (bars)".into(),
                    min: 0.0,
                    max: 100.0,
                },
                bars,
                line_axis: Some(ValueAxis {
                    label: "MOTA % (curves)".into(),
                    min: (lowest / 10.0).floor().min(9.0) * 10.0,
                    max: 100.0,
                }),
                lines,
            }
        })
        .collect();
    Figure { panels }
}

/// Fig. 7: one panel per sequence, MMPF+ and MMPF at the Table 1 threshold.
fn fig7(rows: &[Row]) -> Figure {
    let panels = sequences(rows)
        .into_iter()
        .map(|sequence| {
            let bars = [BedloadTrackerKind::MmpfPlus, BedloadTrackerKind::Mmpf]
                .into_iter()
                .map(|kind| {
                    let row = rows.iter().find(|r| {
                        r.scope == Scope::AllBeads && r.sequence == sequence && r.tracker == kind
                    });
                    let values = (0..3)
                        .map(|i| row.and_then(|r| r.scores.states.by_state()[i].1.f_score))
                        .collect();
                    Series {
                        label: kind.paper_name().to_string(),
                        values,
                    }
                })
                .collect();
            GroupedChart {
                title: format!("Motion states, {sequence} sequence (τ_t = {TABLE_THRESHOLD})"),
                x_label: "motion state".into(),
                categories: vec!["resting".into(), "rolling".into(), "saltating".into()],
                bar_axis: ValueAxis {
                    label: "F-score".into(),
                    min: 0.0,
                    max: 1.0,
                },
                bars,
                line_axis: None,
                lines: Vec::new(),
            }
        })
        .collect();
    Figure { panels }
}

/// Draws both figures into `dir` (created when missing); returns the files written.
pub fn write_figures(dir: &Path, rows: &[Row]) -> Result<Vec<String>> {
    create_folder(dir)?;
    let mut written = Vec::new();
    for (name, figure) in [
        ("fig6_tau_sweep", fig6(rows)),
        ("fig7_state_f_scores", fig7(rows)),
    ] {
        let width = PANEL.0 * figure.panels.len() as u32;
        let png = dir.join(format!("{name}.png"));
        write_png_rgb(&png, &figure.to_rgb(width, PANEL.1)?)?;
        let svg = dir.join(format!("{name}.svg"));
        write_text(&svg, &figure.to_svg(width, PANEL.1)?)?;
        written.extend([png, svg].map(|p| p.display().to_string()));
    }
    Ok(written)
}

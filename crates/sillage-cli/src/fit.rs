//! `sillage fit bedload`: learns the bedload particle filter's motion parameters (the
//! transition table of the MMPF+ paper's Eqs. (11)-(12) and the process noises of Eq. (3),
//! §4.3) from BeadTracking ground truth, and writes them atomically as the `[motion]` table of
//! a TOML config the trackers read.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result, bail};
use serde::Serialize;
use sillage::core::{MotionState, Vec2};
use sillage::filter::fit::STATE_NAMES;
use sillage::filter::{
    BedloadFit, BedloadParams, FitOptions, FitReport, StatePoint, StateTrack, fit_bedload,
};
use sillage::io::read_bead_csv;

use crate::cli::FitBedloadArgs;

/// The config file: the fitted parameters under `[motion]`.
#[derive(Serialize)]
struct ConfigFile<'a> {
    motion: &'a BedloadParams,
}

/// `--json`: what was read, the options, the fitted parameters and the report.
#[derive(Serialize)]
struct JsonSummary<'a> {
    truth: &'a Path,
    out: &'a Path,
    tracks: usize,
    tracks_without_state: usize,
    train_fraction: f64,
    min_probability: f64,
    min_samples: u64,
    motion: &'a BedloadParams,
    report: &'a FitReport,
}

/// `sillage fit bedload --truth FILE --out FILE`.
pub fn run_bedload(args: &FitBedloadArgs) -> Result<()> {
    let options = FitOptions {
        train_fraction: args.train_fraction,
        min_probability: args.min_probability,
        min_samples: args.min_samples,
    };
    options
        .validate()
        .context("invalid option (--train-fraction, --min-probability, --min-samples)")?;
    let tracks = read_tracks(&args.truth).context(
        "cannot read the ground truth given by --truth (a BeadTracking CSV: \
         frame,id,x,y,category,vx,vy,motion_state)",
    )?;
    let tracks_without_state = tracks
        .iter()
        .filter(|t| {
            t.points
                .iter()
                .all(|p| p.motion_state == MotionState::Unknown)
        })
        .count();
    let fit = fit_bedload(&tracks, &BedloadParams::default(), &options).with_context(|| {
        format!(
            "cannot fit the bedload motion parameters to {}",
            args.truth.display()
        )
    })?;
    let text = config_text(args, &fit, tracks.len(), tracks_without_state)?;
    write_config(&args.out, &text)?;
    if args.json {
        let summary = JsonSummary {
            truth: &args.truth,
            out: &args.out,
            tracks: tracks.len(),
            tracks_without_state,
            train_fraction: options.train_fraction,
            min_probability: options.min_probability,
            min_samples: options.min_samples,
            motion: &fit.params,
            report: &fit.report,
        };
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print!("{}", human_summary(args, &fit, tracks.len()));
    }
    Ok(())
}

/// Reads the BeadTracking CSV and groups its points by bead id, frames increasing; an id
/// given twice in one frame is an error naming the file.
fn read_tracks(path: &Path) -> Result<Vec<StateTrack>> {
    let points = read_bead_csv(path)?;
    let mut by_id: BTreeMap<u64, Vec<StatePoint>> = BTreeMap::new();
    for p in points {
        by_id.entry(p.id).or_default().push(StatePoint {
            frame: p.frame,
            pos_px: p.pos_px,
            motion_state: p.motion_state,
        });
    }
    by_id
        .into_iter()
        .map(|(track_id, mut points)| {
            points.sort_by_key(|p| p.frame);
            if let Some(pair) = points.windows(2).find(|w| w[0].frame == w[1].frame) {
                bail!(
                    "{}: bead id {track_id} appears twice in frame {} (the file's numbering); \
                     keep one row per id and frame",
                    path.display(),
                    pair[0].frame + 1
                );
            }
            Ok(StateTrack { track_id, points })
        })
        .collect()
}

/// The TOML file: comment lines saying where the values come from, then `[motion]`.
fn config_text(
    args: &FitBedloadArgs,
    fit: &BedloadFit,
    tracks: usize,
    tracks_without_state: usize,
) -> Result<String> {
    let r = &fit.report;
    let mut text = String::new();
    let mut line = |s: String| {
        text.push_str("# ");
        text.push_str(&s);
        text.push('\n');
    };
    line(format!(
        "Bedload motion parameters (MMPF+ Eq. (3) process noises, Eqs. (11)-(12) transition \
         table), by `sillage fit bedload` (sillage {}).",
        env!("CARGO_PKG_VERSION")
    ));
    line(format!("source: {}", args.truth.display()));
    line(format!(
        "{tracks} tracks ({tracks_without_state} without any motion state); frames {}..={} \
         (0-based), trained on {}..={} (--train-fraction {})",
        r.frame_range[0],
        r.frame_range[1],
        r.training_frames[0],
        r.training_frames[1],
        args.train_fraction
    ));
    line(format!(
        "--min-probability {} (each fitted row floored, then renormalised); --min-samples {}",
        args.min_probability, args.min_samples
    ));
    line(format!(
        "residuals per state (step t-1 -> t, by the state at t): {} (saltating: {} rebound)",
        per_state(|s| r.samples[s].to_string()),
        r.rebound_samples
    ));
    line(format!(
        "mean residual, px (zero-mean noises expected): {}",
        per_state(|s| r.mean_residual_px[s].map_or("none".into(), show_vec))
    ));
    line("transition counts, rows from / columns to (resting, rolling, saltating):".into());
    for (s, row) in r.transition_counts.iter().enumerate() {
        line(format!("  {:<9} {row:?}", STATE_NAMES[s]));
    }
    line(if r.kept.is_empty() {
        "kept from the defaults: none".into()
    } else {
        format!(
            "kept from the defaults (fewer than {} samples): {}",
            args.min_samples,
            r.kept.join(", ")
        )
    });
    line(
        "velocity noises equal the position noises (finite-difference velocities); the other \
         keys are the defaults: set flow_vel_px_per_frame for your sequence"
            .into(),
    );
    let body = toml::to_string(&ConfigFile {
        motion: &fit.params,
    })
    .context("cannot write the fitted parameters as TOML")?;
    Ok(format!("{text}\n{body}"))
}

/// `resting A, rolling B, saltating C`.
fn per_state(value: impl Fn(usize) -> String) -> String {
    (0..3)
        .map(|s| format!("{} {}", STATE_NAMES[s], value(s)))
        .collect::<Vec<_>>()
        .join(", ")
}

fn show_vec(v: Vec2) -> String {
    format!("({:.3}, {:.3})", v.x, v.y)
}

/// A few lines for a person: the table, the noises and what was kept.
fn human_summary(args: &FitBedloadArgs, fit: &BedloadFit, tracks: usize) -> String {
    let (r, p) = (&fit.report, &fit.params);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "fitted on frames {}..={} of {}..={} of {} ({tracks} tracks) → {}",
        r.training_frames[0],
        r.training_frames[1],
        r.frame_range[0],
        r.frame_range[1],
        args.truth.display(),
        args.out.display()
    );
    let _ = writeln!(
        s,
        "{:<10}{:>12}{:>8}{:>8}{:>8}{:>11}{:>9}{:>9}{:>9}",
        "state", "transitions", "π→rest", "→roll", "→salt", "residuals", "var_x", "var_y", "cov_xy"
    );
    let noises = [p.rest_pos_noise, p.roll_pos_noise, p.salt_pos_noise];
    let from = r.transitions_from();
    for state in 0..3 {
        let row = p.transition[state];
        let n = noises[state];
        let _ = writeln!(
            s,
            "{:<10}{:>12}{:>8.3}{:>8.3}{:>8.3}{:>11}{:>9.4}{:>9.4}{:>9.4}",
            STATE_NAMES[state],
            from[state],
            row[0],
            row[1],
            row[2],
            r.samples[state],
            n.var_x,
            n.var_y,
            n.cov_xy
        );
    }
    let _ = writeln!(
        s,
        "noises in px² (position; velocity noises equal), π rows floored at {}",
        args.min_probability
    );
    if !r.kept.is_empty() {
        let _ = writeln!(
            s,
            "kept from the defaults (fewer than {} samples): {}",
            args.min_samples,
            r.kept.join(", ")
        );
    }
    s
}

/// Writes a config with `sillage_io::write_text` (a partial file renamed when complete),
/// naming the final path on error.
pub(crate) fn write_config(path: &Path, text: &str) -> Result<()> {
    sillage::io::write_text(path, text).with_context(|| {
        format!(
            "{}: cannot write the config; check that its folder exists and is writable",
            path.display()
        )
    })
}

//! `sillage fit bedload`: learns the bedload particle filter's motion parameters (the
//! transition table of the MMPF+ paper's Eqs. (11)-(12) and the process noises of Eq. (3),
//! §4.3) from BeadTracking ground truth, and writes them atomically as the `[motion]` table of
//! a TOML config the trackers read (the text from `sillage::bedload::fit`).

use std::fmt::Write as _;
use std::path::Path;
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use serde::Serialize;
use sillage::bedload::fit::fit_bedload_files;
use sillage::filter::fit::STATE_NAMES;
use sillage::filter::{BedloadFit, BedloadParams, FitOptions, FitReport};
use sillage::track::bedload::{EmissionParams, EmissionReport, STRETCH_POINTS, SmootherParams};

use crate::shared_args::JsonArg;

/// `sillage fit bedload`.
#[derive(Debug, Args)]
pub struct FitBedloadArgs {
    /// Ground truth with motion states: a BeadTracking CSV
    /// (frame,id,x,y,category,vx,vy,motion_state).
    #[arg(long, value_name = "FILE")]
    pub truth: PathBuf,
    /// TOML file to write; its `[motion]` table holds the fitted parameters.
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Share of the frame range to train on, from the first frame, in (0, 1].
    #[arg(long, value_name = "F", default_value_t = FitOptions::default().train_fraction)]
    pub train_fraction: f64,
    /// Minimal transition probability imposed on each fitted row, in [0, 1/3]; 0 keeps the raw
    /// estimate.
    #[arg(long, value_name = "P", default_value_t = FitOptions::default().min_probability)]
    pub min_probability: f64,
    /// `sillage track bedload`'s output (BeadTracking CSV) on the frames of `--truth`: the
    /// motion-state smoother's evidence model (`[smoother.emission]`) is then learnt from its
    /// points paired with the truth, on the same training frames.
    #[arg(long, value_name = "FILE")]
    pub tracks: Option<PathBuf>,
    /// Fewest samples for a state's row or noises to be fitted; below, the default is kept.
    #[arg(long, value_name = "N", default_value_t = FitOptions::default().min_samples)]
    pub min_samples: u64,
    /// With `--tracks`: points on each side over which the evidence is averaged
    /// (`smoother.half_window`, written beside the model; track with the same).
    #[arg(long, value_name = "N", default_value_t = SmootherParams::default().half_window)]
    pub half_window: u32,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
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
    /// The smoother's evidence model and its samples, with `--tracks`.
    #[serde(skip_serializing_if = "Option::is_none")]
    emission: Option<(&'a EmissionParams, &'a EmissionReport)>,
    /// The window the evidence was averaged over, with `--tracks`.
    #[serde(skip_serializing_if = "Option::is_none")]
    half_window: Option<u32>,
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
    let fitted = fit_bedload_files(
        &args.truth,
        args.tracks.as_deref(),
        &options,
        args.half_window,
    )
    .with_context(|| {
        format!(
            "cannot fit the bedload parameters to --truth {} (a BeadTracking CSV: \
                 frame,id,x,y,category,vx,vy,motion_state){}",
            args.truth.display(),
            args.tracks
                .as_ref()
                .map(|t| format!(" and --tracks {}", t.display()))
                .unwrap_or_default()
        )
    })?;
    let (fit, text) = (&fitted.fit, &fitted.text);
    let emission = args.tracks.as_deref().zip(fitted.emission.as_ref());
    write_config(&args.out, text)?;
    if args.json.enabled {
        let summary = JsonSummary {
            truth: &args.truth,
            out: &args.out,
            tracks: fitted.tracks,
            tracks_without_state: fitted.tracks_without_state,
            train_fraction: options.train_fraction,
            min_probability: options.min_probability,
            min_samples: options.min_samples,
            motion: &fit.params,
            report: &fit.report,
            emission: fitted.emission.as_ref().map(|(m, r)| (m, r)),
            half_window: args.tracks.as_ref().map(|_| args.half_window),
        };
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print!("{}", human_summary(args, fit, fitted.tracks));
        if let Some((path, (model, report))) = emission {
            print!(
                "{}",
                emission_summary(path, model, report, args.half_window)
            );
        }
    }
    Ok(())
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

/// The smoother's evidence model, one line per state.
fn emission_summary(
    path: &Path,
    model: &EmissionParams,
    report: &EmissionReport,
    half_window: u32,
) -> String {
    let mut s = format!(
        "motion-state evidence from {} ({} points unpaired), over ±{half_window} frames: \
         ln(mean velocity's speed + {:.4} m/s) and ln(mean contact ratio), mean ± sd\n",
        path.display(),
        report.unpaired,
        model.speed_floor_m_per_s
    );
    for (state, m) in [&model.resting, &model.rolling, &model.saltating]
        .into_iter()
        .enumerate()
    {
        let _ = writeln!(
            s,
            "{:<10}{:>8} samples   speed {:>7.3} ± {:.3}   contact {:>7.3} ± {:.3}",
            STATE_NAMES[state],
            report.samples[state],
            m.log_speed.mean,
            m.log_speed.sd,
            m.log_contact.mean,
            m.log_contact.sd
        );
    }
    let _ = writeln!(
        s,
        "saltating at or above {:.3} m/s over the steadiest stretch of {STRETCH_POINTS} points",
        model.saltation_speed_m_per_s
    );
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

//! `sillage ptv` and `sillage config`: configuration assembly and a tracking run.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use serde::Serialize;
use sillage::io::{SkippedFrame, TrackFormat};
use sillage::ptv_run::{PtvRun, load_ptv_config};
use sillage::track::ptv::AUTO_VOTE_MIN_VALID_SHARE;
use sillage::windows::WindowPlan;
use sillage::{PipelineConfig, RunSummary, Tracking};

use crate::progress::FrameProgress;
use crate::shared_args::{ConfigArgs, FormatArg, JsonArg, LongRunArgs, WindowArgs};

/// `sillage ptv`.
#[derive(Debug, Args)]
pub struct PtvArgs {
    /// Frames: a folder, a quoted glob pattern, a multi-page TIFF or a video file.
    pub input: String,
    /// Trajectory file to write (format from the extension unless --format is given).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Output format (default: from the extension of --out).
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
    /// Configuration sources.
    #[command(flatten)]
    pub config: ConfigArgs,
    /// Bad frames, checkpoints and resume.
    #[command(flatten)]
    pub long_run: LongRunArgs,
    /// Time windows tracked at once.
    #[command(flatten)]
    pub windows: WindowArgs,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// Assembles the configuration: defaults, then `--config`, then `--tractrac-par`, then `--set`.
pub fn load_config(args: &ConfigArgs) -> Result<PipelineConfig> {
    Ok(load_ptv_config(
        args.params.config.as_deref(),
        args.tractrac_par.as_deref(),
        &args.params.overrides,
    )?)
}

/// `sillage config`: prints the assembled configuration as TOML.
pub fn print_config(args: &ConfigArgs) -> Result<()> {
    print!("{}", load_config(args)?.to_toml_string()?);
    Ok(())
}

/// The track format chosen by `--format`, or else by the file's extension.
pub fn output_format(format: Option<FormatArg>, path: &std::path::Path) -> Result<TrackFormat> {
    Ok(match format {
        Some(FormatArg::Tractrac) => TrackFormat::Tractrac,
        Some(FormatArg::Csv) => TrackFormat::Csv,
        Some(FormatArg::Parquet) => TrackFormat::Parquet,
        Some(FormatArg::Hdf5) => TrackFormat::Hdf5,
        None => TrackFormat::from_path(path)?,
    })
}

/// The `--json` summary of `sillage ptv`: the run's totals, the frames skipped and the
/// checkpoint resumed from.
#[derive(Serialize)]
struct PtvJson<'a> {
    #[serde(flatten)]
    summary: &'a RunSummary,
    skipped_frames: &'a [SkippedFrame],
    resumed_after_frame: Option<u64>,
}

/// Tells what a long run skipped and where it resumed (stderr).
pub fn report_long_run(skipped: &[SkippedFrame], resumed_after: Option<u64>) {
    if let Some(frame) = resumed_after {
        eprintln!("resumed after frame {frame} from the checkpoint");
    }
    for frame in skipped {
        eprintln!(
            "skipped frame {} ({}): {}",
            frame.index,
            frame.path.display(),
            frame.reason
        );
    }
}

/// `sillage ptv INPUT --out FILE`.
pub fn run(args: &PtvArgs) -> Result<()> {
    let config = load_config(&args.config)?;
    let format = output_format(args.format, &args.out)?;
    let options = args.long_run.options()?;
    let run = PtvRun::open_with(&config, &args.input, options.on_bad_frame)?;
    if let Some(used) = run.background_frames() {
        eprintln!("background initialised from the mean of the first {used} frames");
    }
    if let Some(calibration) = run.calibration()
        && let Some(measured) = &calibration.measured
    {
        eprintln!("{calibration}");
        if let Some(warning) = measured.density_warning() {
            eprintln!("warning: {warning}");
        }
    }
    if let Some(warning) = run.too_few_frames_warning() {
        eprintln!("warning: {warning}");
    }
    if let Some(window) = args.windows.window {
        return run_windowed(args, run, format, window);
    }
    let mut progress = FrameProgress::new(run.frame_count(), "tracking");
    let outcome = run.run_long(&args.out, format, &options, &mut |report| {
        progress.frame(report)
    });
    progress.finish();
    let tracked = outcome?;
    report_long_run(&tracked.skipped, tracked.resumed_after);
    let summary = tracked.summary;
    if let Some(displacement) = summary.measured_displacement_px {
        let voting = summary.vote_search_px.map_or("off".to_string(), |r| {
            format!("on, search radius {r:.1} px")
        });
        let resolved = summary.vote_valid_share.map_or(String::new(), |share| {
            format!(
                ", {:.0} % of the points in cells the vote resolved{}",
                100.0 * share,
                if share < AUTO_VOTE_MIN_VALID_SHARE {
                    " (under half: the flow varies within a voting cell, so the vote is used \
                     only for displacements of a spacing or more)"
                } else {
                    ""
                }
            )
        });
        eprintln!(
            "displacements measured on the first two frames: 95 % within {displacement:.2} px\
             {resolved} → displacement voting {voting}"
        );
    }
    if args.json.enabled {
        let json = PtvJson {
            summary: &summary,
            skipped_frames: &tracked.skipped,
            resumed_after_frame: tracked.resumed_after,
        };
        println!("{}", serde_json::to_string_pretty(&json)?);
    } else {
        let restored = summary
            .restored_points
            .filter(|&n| n > 0)
            .map_or(String::new(), |n| format!(" ({n} restored)"));
        eprintln!(
            "{} frames, {} detections, {} track points{restored} in {} tracks → {} ({:.2} ms/frame detection, {:.2} ms/frame tracking)",
            summary.frames,
            summary.detections,
            summary.points,
            summary.tracks,
            tracked.written.path.display(),
            summary.detect_ms_per_frame,
            summary.track_ms_per_frame
        );
    }
    Ok(())
}

/// `sillage ptv … --window W`: the windows tracked `--jobs` at once, stitched into `--out`.
fn run_windowed(args: &PtvArgs, run: PtvRun, format: TrackFormat, window: usize) -> Result<()> {
    let tracking = Tracking::Pipeline(Box::new(load_config(&args.config)?));
    let plan = WindowPlan::for_source(&args.input, window, args.windows.overlap, &tracking)?;
    let jobs = args.windows.jobs();
    let mut progress = FrameProgress::new(Some(plan.windows().len()), "windows");
    let outcome = run.run_windowed(&args.out, format, plan, jobs, &mut |_| progress.tick());
    progress.finish();
    let (summary, written) = outcome?;
    if args.json.enabled {
        let json = serde_json::json!({ "windows": summary, "rows": written.rows });
        println!("{}", serde_json::to_string_pretty(&json)?);
    } else {
        let joined: usize = summary.seams.iter().map(|s| s.joined).sum();
        eprintln!(
            "{} windows of {window} frames overlapping by {} ({} at once): {} track points in \
             {} tracks → {}; {joined} tracks joined across {} seams",
            summary.windows,
            plan.overlap,
            summary.jobs,
            summary.points,
            summary.tracks,
            written.path.display(),
            summary.seams.len()
        );
    }
    Ok(())
}

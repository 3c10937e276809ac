//! `sillage ptv` and `sillage config`: configuration assembly and a tracking run.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sillage::PipelineConfig;
use sillage::io::TrackFormat;
use sillage::ptv_run::{PtvRun, load_ptv_config};

use crate::progress::FrameProgress;
use crate::shared_args::{ConfigArgs, FormatArg, JsonArg};

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

/// `sillage ptv INPUT --out FILE`.
pub fn run(args: &PtvArgs) -> Result<()> {
    let config = load_config(&args.config)?;
    let format = output_format(args.format, &args.out)?;
    let run = PtvRun::open(&config, &args.input)?;
    if let Some(used) = run.background_frames() {
        eprintln!("background initialised from the mean of the first {used} frames");
    }
    if let Some(calibration) = run.calibration()
        && calibration.measured.is_some()
    {
        eprintln!("{calibration}");
    }
    let mut progress = FrameProgress::new(run.frame_count(), "tracking");
    let outcome = run.run_to_file(&args.out, format, &mut |report| progress.frame(report));
    progress.finish();
    let tracked = outcome?;
    let summary = tracked.summary;
    if let Some(displacement) = summary.measured_displacement_px {
        let voting = summary.vote_search_px.map_or("off".to_string(), |r| {
            format!("on, search radius {r:.1} px")
        });
        eprintln!(
            "displacements measured on the first two frames: 95 % within {displacement:.2} px \
             → displacement voting {voting}"
        );
    }
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        eprintln!(
            "{} frames, {} detections, {} track points in {} tracks → {} ({:.2} ms/frame detection, {:.2} ms/frame tracking)",
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

//! `sillage ptv` and `sillage config`: configuration assembly and a tracking run.

use anyhow::{Context, Result};
use sillage::io::{FrameOptions, open_frames};
use sillage::io::{TrackFileHeader, TrackFormat, create_track_writer};
use sillage::{Pipeline, PipelineConfig};

use crate::cli::{ConfigArgs, FormatArg, PtvArgs};
use crate::progress::FrameProgress;

/// Assembles the configuration: defaults, then `--config`, then `--tractrac-par`, then `--set`.
pub fn load_config(args: &ConfigArgs) -> Result<PipelineConfig> {
    let mut config = match &args.config {
        Some(path) => PipelineConfig::from_toml_file(path)?,
        None => PipelineConfig::default(),
    };
    if let Some(path) = &args.tractrac_par {
        let par = sillage::io::read_tractrac_par(path)?;
        sillage::tractrac::apply_par(&mut config, &par)
            .with_context(|| format!("in {}", path.display()))?;
    }
    for assignment in &args.overrides {
        config.set(assignment)?;
    }
    config.validate()?;
    Ok(config)
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

/// The header written into track files: our version and every parameter.
pub fn track_header(config: &PipelineConfig) -> Result<TrackFileHeader> {
    let toml = config.to_toml_string()?;
    let parameters = toml
        .lines()
        .filter_map(|line| line.split_once(" = "))
        .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
        .collect();
    Ok(TrackFileHeader {
        program_version: format!("sillage {}", env!("CARGO_PKG_VERSION")),
        parameters,
        ..TrackFileHeader::default()
    })
}

/// `sillage ptv INPUT --out FILE`.
pub fn run(args: &PtvArgs) -> Result<()> {
    let config = load_config(&args.config)?;
    let format = output_format(args.format, &args.out)?;
    let mut pipeline = Pipeline::from_config(&config)?;
    if pipeline.background_init_frames() > 0 {
        let used =
            pipeline.prime_background(open_frames(&args.input, &FrameOptions::default())?)?;
        eprintln!("background initialised from the mean of the first {used} frames");
    }
    let frames = open_frames(&args.input, &FrameOptions::default())?;
    let mut progress = FrameProgress::new(frames.len(), "tracking");
    let mut writer = create_track_writer(&args.out, format, &track_header(&config)?)?;
    let outcome = pipeline.run(frames, writer.as_mut(), &mut |report| {
        progress.frame(report)
    });
    progress.finish();
    // Rows written before an error stay valid: the file is completed either way.
    let written = writer.finish()?;
    let summary = outcome?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        eprintln!(
            "{} frames, {} detections, {} track points in {} tracks → {} ({:.2} ms/frame detection, {:.2} ms/frame tracking)",
            summary.frames,
            summary.detections,
            summary.points,
            summary.tracks,
            written.path.display(),
            summary.detect_ms_per_frame,
            summary.track_ms_per_frame
        );
    }
    Ok(())
}

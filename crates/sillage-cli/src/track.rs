//! `sillage track bedload`: the bedload trackers (MMPF+ and the baselines of its Table 1) on
//! detections read from CSV, or on frames through the bead detector, run by the facade's
//! `Pipeline`; trajectories written in BeadTracking's layout or as a track table with motion
//! states.

use std::path::Path;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use serde::Serialize;
use sillage::bedload::detector::BeadDetectorSources;
use sillage::bedload::output::{BeadTrackKind, BeadTrackOutput};
use sillage::bedload::{BeadFrame, read_bead_frames};
use sillage::checkpoint::RunIdentity;
use sillage::io::{FrameOptions, SkippedFrame, TrackFormat, TrackWriter, open_frames};
use sillage::long_run::{Inputs, LongRunOutput, OpenInputs, run_long};
use sillage::toml_config::{dotted_keys, load_unvalidated};
use sillage::track::bedload::BedloadTrackerParams;
use sillage::viz::OverlayStyle;
use sillage::{DetectorConfig, FrameInput, Pipeline, PipelineConfig, TrackerConfig};

use crate::overlay::{DetectionsByFrame, write_overlays};
use crate::progress::FrameProgress;
use crate::ptv::report_long_run;
use crate::shared_args::{BeadDetectorArgs, ConfigFileArgs, JsonArg, LongRunArgs};

/// The trackers of `sillage track bedload --tracker`.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum BedloadTrackerArg {
    /// Multi-model particle filter with the motion-state cue (the paper's method).
    MmpfPlus,
    /// Multi-model particle filter without the cue, one saltating state.
    Mmpf,
    /// One constant-velocity particle filter.
    Pf,
    /// Kalman IMM of the three linear motions.
    Imm,
    /// Deterministic association of the detections.
    Det,
}

impl From<BedloadTrackerArg> for sillage::track::bedload::BedloadTrackerKind {
    fn from(arg: BedloadTrackerArg) -> Self {
        match arg {
            BedloadTrackerArg::MmpfPlus => Self::MmpfPlus,
            BedloadTrackerArg::Mmpf => Self::Mmpf,
            BedloadTrackerArg::Pf => Self::Pf,
            BedloadTrackerArg::Imm => Self::Imm,
            BedloadTrackerArg::Det => Self::Det,
        }
    }
}

/// Output formats of bead trajectories.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BeadFormatArg {
    /// CSV in the layout of BeadTracking's ground truth,
    /// `frame,id,x,y,category,vx,vy,motion_state,spread_px` (1-based frames and pixels,
    /// motion-state codes 0-3): what `sillage eval mot` compares with bead truth.
    Beads,
    /// CSV with trackpy column names then `class,motion_state,spread_px` (0-based, state
    /// names).
    Csv,
    /// Apache Parquet with the CSV's columns.
    Parquet,
    /// HDF5, one dataset per column (needs the `hdf5` cargo feature).
    Hdf5,
}

/// `sillage track bedload`.
#[derive(Debug, Args)]
pub struct TrackBedloadArgs {
    /// Frames to detect the beads in (a folder, a quoted glob, a multi-page TIFF or a video),
    /// instead of `--detections`.
    #[arg(required_unless_present = "detections", conflicts_with_all = ["detections", "candidates"])]
    pub input: Option<String>,
    /// Detections CSV: `frame,x,y,class,score` (frames 0-based; class 0 black, 1 transparent).
    #[arg(long, value_name = "FILE")]
    pub detections: Option<PathBuf>,
    /// Detector-confidence candidates (Eq. (1)), same layout: every response maximum above a
    /// low threshold with its score. Without it, a missed bead is pulled towards the
    /// unclaimed detections of its class.
    #[arg(long, value_name = "FILE")]
    pub candidates: Option<PathBuf>,
    /// Trajectories to write; the format from `--format`, else from the extension: `.csv`
    /// in BeadTracking's layout, `.parquet`, `.h5`.
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Output format (default: `beads` for `.csv`, else from the extension of --out).
    #[arg(long, value_enum)]
    pub format: Option<BeadFormatArg>,
    /// `--config FILE` and `--set KEY=VALUE`: the parameters.
    #[command(flatten)]
    pub params: ConfigFileArgs,
    /// Which tracker (overrides the config's `tracker`).
    #[arg(long, value_enum)]
    pub tracker: Option<BedloadTrackerArg>,
    /// Random seed of the particles (overrides the config's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// The detector, when tracking frames.
    #[command(flatten)]
    pub detector: BeadDetectorArgs,
    /// Also draw every frame with its detections and track tails (coloured by motion state,
    /// with ids) into this folder, as `overlay_NNNNN.png`.
    #[arg(long, value_name = "DIR", requires = "input")]
    pub overlay: Option<PathBuf>,
    /// Frames of history in each overlay tail.
    #[arg(long, value_name = "FRAMES", default_value_t = 20)]
    pub overlay_tail: u64,
    /// Bad frames, checkpoints and resume.
    #[command(flatten)]
    pub long_run: LongRunArgs,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// Defaults, then `--config`, then `--set`, then `--tracker` and `--seed`; validated.
pub fn load_bedload_params(args: &TrackBedloadArgs) -> Result<BedloadTrackerParams> {
    let mut params: BedloadTrackerParams =
        load_unvalidated(args.params.config.as_deref(), &args.params.overrides)?;
    if let Some(kind) = args.tracker {
        params.tracker = kind.into();
    }
    if let Some(seed) = args.seed {
        params.seed = seed;
    }
    params.validate()?;
    Ok(params)
}

/// What a run did, printed at the end (`--json`: as JSON).
#[derive(Debug, Serialize)]
struct TrackSummary {
    tracker: &'static str,
    frames: u64,
    detections: u64,
    candidates: u64,
    skipped_frames: Vec<SkippedFrame>,
    tracks: u64,
    points: u64,
    coasted_points: u64,
    weight_recoveries: u64,
    ms_per_frame: f64,
    out: String,
}

/// The frames of `--detections` (with `--candidates`), refusing an `--out` that would
/// overwrite one of them.
fn read_inputs(args: &TrackBedloadArgs, detections: &Path) -> Result<Vec<BeadFrame>> {
    let inputs = std::iter::once(detections).chain(args.candidates.as_deref());
    for input in inputs {
        let same = match (input.canonicalize(), args.out.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        };
        anyhow::ensure!(
            !same,
            "--out {} would overwrite the input {}; write the tracks to another file",
            args.out.display(),
            input.display()
        );
    }
    Ok(read_bead_frames(detections, args.candidates.as_deref())?)
}

/// The track file kind of `--format` (`None`: from the extension of `--out`).
fn output_kind(format: Option<BeadFormatArg>) -> Option<BeadTrackKind> {
    format.map(|format| match format {
        BeadFormatArg::Beads => BeadTrackKind::Beads,
        BeadFormatArg::Csv => BeadTrackKind::Table(TrackFormat::Csv),
        BeadFormatArg::Parquet => BeadTrackKind::Table(TrackFormat::Parquet),
        BeadFormatArg::Hdf5 => BeadTrackKind::Table(TrackFormat::Hdf5),
    })
}

/// `sillage track bedload [FRAMES | --detections FILE] --out FILE`.
pub fn run_bedload(args: &TrackBedloadArgs) -> Result<()> {
    let params = load_bedload_params(args)?;
    let options = args.long_run.options()?;
    let mut config = PipelineConfig {
        tracker: TrackerConfig::Bedload(Box::new(params.clone())),
        ..PipelineConfig::default()
    };
    let (total, source, mut open_inputs): (Option<usize>, String, Box<OpenInputs<'_>>) =
        match (&args.input, &args.detections) {
            (Some(input), _) => {
                let sources = BeadDetectorSources::from(&args.detector);
                config.detector = DetectorConfig::Bead(sources.load()?);
                let frame_options = FrameOptions {
                    on_bad_frame: options.on_bad_frame,
                    ..FrameOptions::default()
                };
                let total = open_frames(input, &frame_options)?.len();
                let source = input.clone();
                let input = input.clone();
                let open = move |start_at| -> sillage::core::Result<Inputs<'static>> {
                    let options = FrameOptions {
                        start_at,
                        ..frame_options.clone()
                    };
                    let frames = open_frames(&input, &options)?;
                    let log = frames.skipped();
                    Ok((
                        Box::new(frames.map(|f| f.map(FrameInput::Image))),
                        Some(log),
                    ))
                };
                (total, source, Box::new(open))
            }
            (None, Some(detections)) => {
                let frames = read_inputs(args, detections)?;
                let open = move |start_at| -> sillage::core::Result<Inputs<'static>> {
                    let from: Vec<BeadFrame> = frames
                        .iter()
                        .filter(|f| f.frame >= start_at)
                        .cloned()
                        .collect();
                    Ok((Box::new(from.into_iter().map(|f| Ok(f.into()))), None))
                };
                (None, detections.display().to_string(), Box::new(open))
            }
            (None, None) => anyhow::bail!("give frames to detect beads in, or --detections FILE"),
        };
    if let Some(total) = total {
        params.check_sequence_length(total)?;
    }
    let kind = match output_kind(args.format) {
        Some(kind) => kind,
        None => BeadTrackKind::from_path(&args.out)?,
    };
    let mut pipeline = Pipeline::from_config(&config)?;
    let mut create_writer = || -> sillage::core::Result<Box<dyn TrackWriter + Send>> {
        Ok(Box::new(BeadTrackOutput::create(
            &args.out,
            Some(kind),
            &params,
        )?))
    };
    let mut settings = dotted_keys(&config)?;
    settings.push(("format".to_string(), format!("{kind:?}")));
    settings.extend(options.settings());
    let output = LongRunOutput {
        path: &args.out,
        create_writer: &mut create_writer,
        identity: RunIdentity::new("track bedload", &source, &args.out, settings),
    };
    let mut progress = FrameProgress::new(total, "tracking");
    let start = Instant::now();
    let mut frames_here = 0u64;
    let mut kept = DetectionsByFrame::new();
    let outcome = run_long(
        &mut pipeline,
        &mut open_inputs,
        output,
        &options,
        &mut |report, observations| {
            frames_here += 1;
            if args.overlay.is_some() {
                kept.insert(report.frame, observations.detections.to_vec());
            }
            progress.tick();
        },
    );
    progress.finish();
    let elapsed = start.elapsed().as_secs_f64();
    let tracked = outcome.with_context(|| format!("while tracking {source}"))?;
    report_long_run(&tracked.skipped, tracked.resumed_after);
    let written = tracked.written;
    if let (Some(dir), Some(input)) = (&args.overlay, &args.input) {
        let tracks = kind.read(&written.path)?;
        let style = OverlayStyle {
            tail_frames: args.overlay_tail,
            detection_radius_px: params.radius_px.clone(),
            ..OverlayStyle::default()
        };
        let n = write_overlays(input, dir, &kept, tracks, &style, None)?;
        eprintln!("{n} overlays → {}", dir.display());
    }
    let stats = pipeline.bedload_stats().unwrap_or_default();
    let summary = TrackSummary {
        tracker: params.tracker.name(),
        frames: stats.frames,
        detections: tracked.summary.detections,
        candidates: tracked.summary.candidates,
        skipped_frames: tracked.skipped,
        tracks: stats.tracks,
        points: written.rows,
        coasted_points: stats.coasted,
        weight_recoveries: stats.weight_recoveries,
        ms_per_frame: 1e3 * elapsed / frames_here.max(1) as f64,
        out: written.path.display().to_string(),
    };
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        eprintln!(
            "{}: {} frames, {} detections → {} tracks, {} points ({} predicted through misses) \
             → {} ({:.2} ms/frame)",
            summary.tracker,
            summary.frames,
            summary.detections,
            summary.tracks,
            summary.points,
            summary.coasted_points,
            summary.out,
            summary.ms_per_frame
        );
    }
    Ok(())
}

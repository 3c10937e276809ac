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
use sillage::bedload::output::BeadTrackKind;
use sillage::bedload::run::{BeadSource, BedloadRun};
use sillage::bedload::{BeadFrame, read_bead_frames};
use sillage::io::{SkippedFrame, TrackFormat};
use sillage::toml_config::load_unvalidated;
use sillage::track::bedload::BedloadTrackerParams;
use sillage::viz::OverlayStyle;

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
    let source = match (&args.input, &args.detections) {
        (Some(input), _) => BeadSource::Frames {
            input: input.clone(),
            detector: Box::new(BeadDetectorSources::from(&args.detector).load()?),
        },
        (None, Some(detections)) => BeadSource::Detections {
            name: detections.display().to_string(),
            frames: read_inputs(args, detections)?,
        },
        (None, None) => anyhow::bail!("give frames to detect beads in, or --detections FILE"),
    };
    let kind = match output_kind(args.format) {
        Some(kind) => kind,
        None => BeadTrackKind::from_path(&args.out)?,
    };
    let mut run = BedloadRun::open(&params, source, &options)?;
    let total = run.frame_count();
    let mut progress = FrameProgress::new(total, "tracking");
    let start = Instant::now();
    let mut frames_here = 0u64;
    let mut kept = DetectionsByFrame::new();
    let outcome = run.run_long(&args.out, kind, &options, &mut |report, observations| {
        frames_here += 1;
        if args.overlay.is_some() {
            kept.insert(report.frame, observations.detections.to_vec());
        }
        progress.tick();
    });
    progress.finish();
    let elapsed = start.elapsed().as_secs_f64();
    let tracked = outcome.with_context(|| format!("while tracking {}", run.source_name()))?;
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
    let stats = run.stats();
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

//! `sillage track immpf`: pedestrians with one IMM particle filter each (Madrigal & Hayet),
//! on colour frames (motion blobs as births), on detections beside the frames, or on
//! detections alone;
//! writes MOTChallenge results and, with `--model-weights`, the model weights πₘ per row.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use serde::Serialize;
use sillage::io::{FrameOptions, MotResultsWriter};
use sillage::pedestrian::immpf::{ImmpfRun, ModelWeightsWriter, Scene, mot_rows};
use sillage::pedestrian::input::frame_size_beside;
use sillage::pedestrian::{ImmpfSettings, PedestrianInput};
use sillage::track::immpf::ModelName;

use crate::progress::FrameProgress;
use crate::shared_args::{ConfigFileArgs, FrameSize, JsonArg};
use sillage::overlay::PedestrianOverlays;

/// `sillage track immpf`.
#[derive(Debug, Args)]
pub struct TrackImmpfArgs {
    /// Colour frames (a folder, a quoted glob, a multi-page TIFF or a video); without them,
    /// `--detections` alone are tracked.
    #[arg(required_unless_present = "detections")]
    pub input: Option<String>,
    /// MOTChallenge detections (`frame,-1,left,top,width,height,score,...`): the
    /// measurements that drive the trackers, alone or beside the frames (which then add
    /// colour: `tracker.detection.colour_weight`); with `--set
    /// tracker.detection.with_frames=births`, only the birth candidates instead of motion
    /// blobs.
    #[arg(long, value_name = "FILE")]
    pub detections: Option<PathBuf>,
    /// Frame size `WxH` for detections alone (default: the `seqinfo.ini` of a MOTChallenge
    /// sequence folder `SEQ/det/det.txt`).
    #[arg(long, value_name = "WxH")]
    pub size: Option<FrameSize>,
    /// Ground plane (TOML: `[homography]` and `adult_height_m`, `adult_width_m`; written by
    /// `sillage fit homography`): boxes sized by an adult's size at the foot point (§4).
    /// Without it each tracker keeps the size of the blob or detection it was born on.
    #[arg(long, value_name = "FILE")]
    pub ground_plane: Option<PathBuf>,
    /// Learned motion prior (JSON from `sillage fit motion-prior`), needed by MP.
    #[arg(long, value_name = "FILE")]
    pub motion_prior: Option<PathBuf>,
    /// The competing models as the paper writes them: CA, CV, MP, CV_CA, CV_CA_MP,
    /// CP_CV_CA, CP_CV_CA_MP, ... (default CV_CA).
    #[arg(long, value_name = "MODELS")]
    pub models: Option<String>,
    /// MOTChallenge results to write (1-based frames).
    #[arg(long, short, value_name = "FILE")]
    pub out: PathBuf,
    /// Also write `frame,id,<model weights>` for every result row.
    #[arg(long, value_name = "FILE")]
    pub model_weights: Option<PathBuf>,
    /// Also draw every frame with each person's box, the bar of its model weights and its
    /// trajectory coloured by the dominant model (CP red, CV green, CA blue, MP magenta) into
    /// this folder, as `overlay_NNNNN.png` (1-based frame number).
    #[arg(long, value_name = "DIR", requires = "input")]
    pub overlay: Option<PathBuf>,
    /// `--config FILE` and `--set KEY=VALUE`: the parameters.
    #[command(flatten)]
    pub params: ConfigFileArgs,
    /// Random seed of the particles.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Stop after this many frames.
    #[arg(long, value_name = "N")]
    pub max_frames: Option<usize>,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// What a run did (`--json`: as JSON on stdout).
#[derive(Debug, Serialize)]
struct Summary {
    models: String,
    frames: u64,
    tracks: u64,
    rows: u64,
    gap_rows: u64,
    ms_per_frame: f64,
    tracking_ms_per_frame: f64,
    out: String,
}

/// `sillage track immpf [FRAMES] [--detections FILE] --out FILE`.
pub fn run(args: &TrackImmpfArgs) -> Result<()> {
    let models = args
        .models
        .as_deref()
        .map(ModelName::parse_combination)
        .transpose()?;
    let settings = ImmpfSettings::load(
        args.params.config.as_deref(),
        &args.params.overrides,
        models.as_deref(),
    )?;
    let params = &settings.tracker;
    let scene = Scene::load(args.ground_plane.as_deref(), args.motion_prior.as_deref())?;
    let size = match (args.size, &args.detections) {
        (Some(size), _) => Some(size.0),
        (None, Some(detections)) => frame_size_beside(detections),
        _ => None,
    };
    let input = PedestrianInput::open(
        args.input.as_deref(),
        args.detections.as_deref(),
        size,
        &settings.motion_params(args.ground_plane.is_some()),
        params,
        &FrameOptions {
            max_frames: args.max_frames,
            ..FrameOptions::default()
        },
        args.overlay.is_some(),
    )?;
    let tracking = ImmpfRun::new(input, params, scene, args.seed)?;
    let mut writer = MotResultsWriter::create(&args.out)?;
    let mut weights = args
        .model_weights
        .as_deref()
        .map(|path| ModelWeightsWriter::create(path, &params.models))
        .transpose()?;
    let mut overlays = args
        .overlay
        .as_deref()
        .map(|dir| {
            let lag = params.detection.smoothing_lag_frames();
            PedestrianOverlays::create(dir, &params.models, lag)
        })
        .transpose()?;
    let mut progress = FrameProgress::new(tracking.frames_expected(), "tracking");
    let run = tracking.run(&mut |prepared, estimates| -> Result<()> {
        writer.push(&mot_rows(estimates))?;
        if let Some(w) = &mut weights {
            w.push(estimates)?;
        }
        if let Some(o) = &mut overlays {
            o.push(prepared.frame, prepared.colour.as_ref(), estimates)?;
        }
        progress.tick();
        Ok(())
    });
    progress.finish();
    let run = run?;
    writer.finish()?;
    if let Some(w) = weights {
        w.finish()?;
    }
    if let Some(o) = overlays {
        o.finish()?;
    }
    let per_frame = |d: std::time::Duration| 1e3 * d.as_secs_f64() / run.frames as f64;
    let summary = Summary {
        models: ModelName::combination_label(&params.models),
        frames: run.frames,
        tracks: run.tracks,
        rows: run.rows,
        gap_rows: run.gap_rows,
        ms_per_frame: per_frame(run.total),
        tracking_ms_per_frame: per_frame(run.tracking),
        out: args.out.display().to_string(),
    };
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        eprintln!(
            "{} frames, {} tracks, {} rows ({} over filled gaps) with {} → {} ({:.1} ms/frame, \
             tracking {:.1} ms/frame)",
            summary.frames,
            summary.tracks,
            summary.rows,
            summary.gap_rows,
            summary.models,
            summary.out,
            summary.ms_per_frame,
            summary.tracking_ms_per_frame
        );
    }
    Ok(())
}

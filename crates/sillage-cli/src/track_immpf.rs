//! `sillage track immpf`: pedestrians with one IMM particle filter each (Madrigal & Hayet),
//! on colour frames (motion blobs or `--detections` as births) or on detections alone;
//! writes MOTChallenge results and, with `--model-weights`, the model weights πₘ per row.

use std::io::Write as _;
use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, ensure};
use serde::{Deserialize, Serialize};
use sillage::detect::motion::MotionParams;
use sillage::filter::MotionPrior;
use sillage::io::{MotResultsWriter, MotRow, PartialFile};
use sillage::overlay::PedestrianOverlays;
use sillage::toml_config::{read_toml_file, set_key};
use sillage::track::immpf::{
    BoxSizing, ModelName, PedestrianEstimate, PedestrianFrame, PedestrianParams, PedestrianTracker,
};

use crate::cli::TrackImmpfArgs;
use crate::fit_pedestrian::read_motion_prior;
use crate::ground_plane::GroundPlaneFile;
use crate::pedestrian_input::{PedestrianInput, PreparedFrame, seqinfo_beside};
use crate::progress::FrameProgress;

/// Start-up frames of the background model behind the pedestrian tracker's motion blobs
/// (`MixtureParams::bootstrap_frames`).
const MOTION_BOOTSTRAP_FRAMES: usize = 20;

/// With a ground plane, a blob is cut into people by the detector when wider than this × its
/// height (`MotionParams::group_aspect`), unless the configuration file or `--set` gives the
/// key.
const GROUND_GROUP_ASPECT: f64 = 1.0;

/// The motion detector's parameters the pedestrian tracker runs with by default: the
/// detector's defaults with two changes.
/// - A 20-frame start-up of the background model instead of one as long as its history. A
///   long running-mean start learns people who stop into the background within tens of
///   frames (on PETS 2009 S2.L1 two people standing for 60 frames were half absent from the
///   foreground); a short one leaves the ghosts of the first frames' people longer, which
///   this tracker does not take for births (`birth_min_motion`). The SIFT-PF tracker, whose
///   objects are the blobs themselves, keeps the detector's defaults (a 20-frame start-up
///   cost it 25-41 MOTA points on the TUD sequences).
/// - With a ground plane ([`GROUND_GROUP_ASPECT`], set in [`load_params`]), only blobs wider
///   than tall are cut into people by the detector:
///   the tracker counts the people of the others at the adult width the plane gives
///   (`BoxSizing::people_in`). On PETS 2009 S2.L1 (CV_CA_MP, 30 seeds), cutting at the
///   detector's 0.55 as well cost 5 ATA points and 4.5 IDF1 points; cutting at 1.0 gained
///   7 MOTA points over no cut.
fn pedestrian_motion_params() -> MotionParams {
    let mut params = MotionParams::default();
    params.mixture.bootstrap_frames = MOTION_BOOTSTRAP_FRAMES;
    params
}

/// Defaults, then `--config`, then the ground plane's group aspect, then `--set`, then `--models` and `--seed`; validated.
pub fn load_params(args: &TrackImmpfArgs) -> Result<(PedestrianParams, MotionParams)> {
    #[derive(Serialize, Deserialize)]
    #[serde(default, deny_unknown_fields)]
    struct ConfigFile {
        tracker: PedestrianParams,
        motion_detector: MotionParams,
    }
    impl Default for ConfigFile {
        fn default() -> Self {
            Self {
                tracker: PedestrianParams::default(),
                motion_detector: pedestrian_motion_params(),
            }
        }
    }
    let (mut config, file_sets_group_aspect) = match &args.config {
        Some(path) => {
            let keys: toml::Table = read_toml_file(path)?;
            let sets = keys
                .get("motion_detector")
                .and_then(|m| m.get("group_aspect"))
                .is_some();
            (read_toml_file::<ConfigFile>(path)?, sets)
        }
        None => (ConfigFile::default(), false),
    };
    if args.ground_plane.is_some() && !file_sets_group_aspect {
        config.motion_detector.group_aspect = GROUND_GROUP_ASPECT;
    }
    for assignment in &args.overrides {
        set_key(&mut config, assignment)?;
    }
    if let Some(models) = &args.models {
        config.tracker.models = ModelName::parse_combination(models)?;
    }
    config.tracker.validate()?;
    config.motion_detector.validate()?;
    Ok((config.tracker, config.motion_detector))
}

/// The box sizing and the motion prior of a run.
pub fn load_scene(
    ground: Option<&Path>,
    prior: Option<&Path>,
) -> Result<(BoxSizing, Option<MotionPrior>)> {
    let sizing = match ground {
        Some(path) => GroundPlaneFile::read_sizing(path)?,
        None => BoxSizing::FromCandidate,
    };
    let prior = prior.map(read_motion_prior).transpose()?;
    Ok((sizing, prior))
}

/// What a run did (`--json`: as JSON on stdout).
#[derive(Debug, Serialize)]
struct Summary {
    models: String,
    frames: u64,
    tracks: u64,
    rows: u64,
    ms_per_frame: f64,
    tracking_ms_per_frame: f64,
    out: String,
}

/// `sillage track immpf [FRAMES] [--detections FILE] --out FILE`.
pub fn run(args: &TrackImmpfArgs) -> Result<()> {
    let (params, motion) = load_params(args)?;
    let (sizing, prior) = load_scene(args.ground_plane.as_deref(), args.motion_prior.as_deref())?;
    let size = match (args.size, &args.detections) {
        (Some(size), _) => Some(size.0),
        (None, Some(detections)) => seqinfo_beside(detections)
            .and_then(|(_, info)| Some((info.image_width? as usize, info.image_height? as usize))),
        _ => None,
    };
    let mut input = PedestrianInput::open(
        args.input.as_deref(),
        args.detections.as_deref(),
        size,
        &motion,
        &params.appearance,
        args.max_frames,
        args.overlay.is_some(),
    )?;
    let mut tracker = PedestrianTracker::new(
        &params,
        sizing,
        prior.as_ref(),
        input.frame_size_px,
        args.seed,
    )?;
    let mut writer = MotResultsWriter::create(&args.out)?;
    let mut weights = args
        .model_weights
        .as_deref()
        .map(|path| ModelWeightsWriter::create(path, &params.models))
        .transpose()?;
    let mut overlays = args
        .overlay
        .as_deref()
        .map(|dir| PedestrianOverlays::create(dir, &params.models))
        .transpose()?;
    let mut progress = FrameProgress::new(input.len, "tracking");
    let (mut frames, mut rows, mut last_id) = (0u64, 0u64, 0u64);
    let mut estimates = Vec::new();
    let started = Instant::now();
    let mut tracking = std::time::Duration::ZERO;
    while let Some(prepared) = input.next_frame()? {
        estimates.clear();
        let tick = Instant::now();
        step(&mut tracker, &prepared, &mut estimates)?;
        tracking += tick.elapsed();
        writer.push(&mot_rows(&estimates))?;
        if let Some(w) = &mut weights {
            w.push(&estimates)?;
        }
        if let Some(o) = &mut overlays {
            o.push(prepared.frame, prepared.colour.as_ref(), &estimates)?;
        }
        input.recycle(prepared);
        rows += estimates.len() as u64;
        last_id = estimates.iter().map(|e| e.track_id).fold(last_id, u64::max);
        frames += 1;
        progress.tick();
    }
    progress.finish();
    ensure!(frames > 0, "the input holds no frame");
    writer.finish()?;
    if let Some(w) = weights {
        w.finish()?;
    }
    let elapsed = started.elapsed().as_secs_f64();
    let summary = Summary {
        models: ModelName::combination_label(&params.models),
        frames,
        tracks: last_id,
        rows,
        ms_per_frame: 1e3 * elapsed / frames as f64,
        tracking_ms_per_frame: 1e3 * tracking.as_secs_f64() / frames as f64,
        out: args.out.display().to_string(),
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        eprintln!(
            "{} frames, {} tracks, {} rows with {} → {} ({:.1} ms/frame, tracking {:.1} ms/frame)",
            summary.frames,
            summary.tracks,
            summary.rows,
            summary.models,
            summary.out,
            summary.ms_per_frame,
            summary.tracking_ms_per_frame
        );
    }
    Ok(())
}

/// One tracker step on a prepared frame.
pub fn step(
    tracker: &mut PedestrianTracker,
    prepared: &PreparedFrame,
    out: &mut Vec<PedestrianEstimate>,
) -> Result<()> {
    let frame = PedestrianFrame {
        frame: prepared.frame,
        cues: prepared.cues.as_ref(),
        candidates: &prepared.candidates,
    };
    tracker
        .step(&frame, out)
        .with_context(|| format!("frame {}", prepared.frame + 1))?;
    Ok(())
}

/// Estimates as MOTChallenge result rows (confidence 1).
pub fn mot_rows(estimates: &[PedestrianEstimate]) -> Vec<MotRow> {
    estimates
        .iter()
        .map(|e| MotRow {
            frame: e.frame,
            id: Some(e.track_id),
            left_px: e.bbox.left_px,
            top_px: e.bbox.top_px,
            width_px: e.bbox.width_px,
            height_px: e.bbox.height_px,
            confidence: Some(1.0),
            class: None,
            visibility: None,
            world: None,
        })
        .collect()
}

/// `--model-weights FILE`: `frame,id,<model>...` with πₘ per row (1-based frames), written to
/// a partial file renamed at the end.
struct ModelWeightsWriter {
    out: PartialFile,
}

impl ModelWeightsWriter {
    fn create(path: &Path, models: &[ModelName]) -> Result<Self> {
        let mut out = PartialFile::create(path)?;
        let header: Vec<&str> = models.iter().map(|m| m.label()).collect();
        writeln!(out, "frame,id,{}", header.join(","))?;
        Ok(Self { out })
    }

    fn push(&mut self, estimates: &[PedestrianEstimate]) -> Result<()> {
        for e in estimates {
            write!(self.out, "{},{}", e.frame + 1, e.track_id)?;
            for w in &e.model_weights {
                write!(self.out, ",{w:.4}")?;
            }
            writeln!(self.out)?;
        }
        Ok(())
    }

    fn finish(self) -> Result<()> {
        self.out.commit()?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Command {
        #[command(flatten)]
        args: TrackImmpfArgs,
    }

    fn group_aspect(extra: &[&str]) -> f64 {
        let argv = ["track", "frames", "--out", "out.txt"].iter().chain(extra);
        let command = Command::try_parse_from(argv).expect("valid arguments");
        load_params(&command.args).unwrap().1.group_aspect
    }

    #[test]
    fn a_ground_plane_leaves_narrower_groups_to_the_tracker_unless_told_otherwise() {
        let detector_default = MotionParams::default().group_aspect;
        assert_eq!(group_aspect(&[]), detector_default);
        assert_eq!(
            group_aspect(&["--ground-plane", "ground.toml"]),
            GROUND_GROUP_ASPECT
        );
        let set = [
            "--ground-plane",
            "g.toml",
            "--set",
            "motion_detector.group_aspect=0.7",
        ];
        assert_eq!(group_aspect(&set), 0.7);
        // A configuration file that gives the key, even at the detector's default, is obeyed.
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("c.toml");
        let value = MotionParams::default().group_aspect;
        std::fs::write(
            &file,
            format!("[motion_detector]\ngroup_aspect = {value}\n"),
        )
        .unwrap();
        let path = file.to_str().unwrap();
        assert_eq!(
            group_aspect(&["--ground-plane", "g.toml", "--config", path]),
            value
        );
        std::fs::write(&file, "[motion_detector]\nmin_blob_px = 150\n").unwrap();
        assert_eq!(
            group_aspect(&["--ground-plane", "g.toml", "--config", path]),
            GROUND_GROUP_ASPECT
        );
    }
}

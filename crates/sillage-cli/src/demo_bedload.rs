//! `sillage demo bedload`: a synthetic bedload sequence rendered to PNG frames, the beads
//! detected from the files, tracked with MMPF+, written in BeadTracking's layout and scored
//! against the truth as the MMPF+ paper scores (Table 1). The steps are
//! `sillage::experiments::bedload::demo`'s; this shows their progress and prints the scores.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use serde::Serialize;
use sillage::bedload::synth::synthetic_radii;
use sillage::eval::papers::{BeadTrackScores, score_bead_tracks};
use sillage::experiments::bedload::demo::{demo_scene, frames_dir, render, track};
use sillage::viz::OverlayStyle;

use crate::overlay::write_overlays;
use crate::progress::FrameProgress;
use crate::shared_args::JsonArg;

/// `sillage demo bedload`.
#[derive(Debug, Args)]
pub struct DemoBedloadArgs {
    /// Output folder for frames, truth and tracks.
    #[arg(long, short, default_value = "out/demo_bedload", value_name = "DIR")]
    pub out: PathBuf,
    /// Number of frames.
    #[arg(long, default_value_t = 100)]
    pub frames: usize,
    /// Random seed (scene and particles).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Also draw every frame with its detections and track tails into OUT/overlays.
    #[arg(long)]
    pub overlays: bool,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// The demo's summary.
#[derive(Serialize)]
struct DemoBedloadSummary {
    frames: usize,
    detect_ms_per_frame: f64,
    track_ms_per_frame: f64,
    scores: BeadTrackScores,
    tracks: String,
}

/// `sillage demo bedload`.
pub fn run(args: &DemoBedloadArgs) -> Result<()> {
    let scene = demo_scene(args.frames, args.seed);
    let frames_dir = frames_dir(&args.out);
    eprintln!(
        "1/3 synthetic bedload flume (MMPF+ paper): {} black and {} transparent beads, {} frames \
         of {}×{} → {}",
        scene.n_black,
        scene.n_transparent,
        scene.n_frames,
        scene.width,
        scene.height,
        frames_dir.display()
    );
    let mut progress = FrameProgress::new(Some(scene.n_frames), "rendering");
    let truth = render(&args.out, &scene, &mut || progress.tick());
    progress.finish();
    let truth = truth?;

    eprintln!("2/3 detecting the beads in the PNG frames and tracking them with MMPF+");
    let mut progress = FrameProgress::new(Some(scene.n_frames), "tracking");
    let tracks = track(&args.out, &scene, args.seed, args.overlays, &mut |_| {
        progress.tick()
    });
    progress.finish();
    let tracks = tracks?;
    let radii = synthetic_radii(&scene);
    if args.overlays {
        let dir = args.out.join("overlays");
        let style = OverlayStyle {
            detection_radius_px: radii.to_vec(),
            ..OverlayStyle::default()
        };
        write_overlays(
            &frames_dir.to_string_lossy(),
            &dir,
            &tracks.detections,
            tracks.points.clone(),
            &style,
            None,
        )?;
    }

    eprintln!("3/3 scoring against the truth (disc IoU ≥ 0.43, MMPF+ paper §5.3)");
    let summary = DemoBedloadSummary {
        frames: args.frames,
        detect_ms_per_frame: tracks.run.detect_ms_per_frame,
        track_ms_per_frame: tracks.run.track_ms_per_frame,
        scores: score_bead_tracks(&truth, &tracks.points, &radii)?,
        tracks: tracks.path.display().to_string(),
    };
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        let t = &summary.scores.table1;
        println!(
            "correct tracks {:.1} % ({}/{}), MOTA {:.2} %, FN {:.2} %, FP {:.2} %, ID switches {}, \
             HOTA {:.3} — detection {:.1} ms/frame, tracking {:.1} ms/frame → {}",
            100.0 * t.correct_track_rate,
            t.correct_tracks,
            t.truth_tracks,
            100.0 * summary.scores.mot.clear.mota,
            100.0 * t.false_negative_rate,
            100.0 * t.false_positive_rate,
            t.id_switches,
            summary.scores.mot.hota.hota,
            summary.detect_ms_per_frame,
            summary.track_ms_per_frame,
            summary.tracks
        );
    }
    Ok(())
}

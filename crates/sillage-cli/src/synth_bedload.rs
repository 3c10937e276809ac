//! `sillage synth bedload`: a synthetic bedload sequence as the bedload trackers and
//! `sillage eval mot` read it — truth in BeadTracking's layout, detections and
//! detector-confidence candidates as CSV, and the bead sizes in `sequence_param.txt`.

use anyhow::{Context, Result};
use sillage::core::{TrackPoint, TrackSink};
use sillage::io::{
    BeadCsvWriter, BeadSequenceParams, DetectionsCsvWriter, write_bead_sequence_params,
};
use sillage::synth::{BedloadDetectionParams, BedloadSceneParams, BedloadSequence};

use crate::cli::SynthBedloadArgs;
use crate::progress::FrameProgress;

/// Scale written into `sequence_param.txt`: the authors' example sequence, m/px.
const M_PER_PX: f64 = 2.056e-4;

/// The scene and detector parameters of the command line, on top of the defaults.
fn params(args: &SynthBedloadArgs) -> (BedloadSceneParams, BedloadDetectionParams) {
    let scene = BedloadSceneParams {
        n_frames: args.frames,
        n_black: args.black,
        n_transparent: args.transparent,
        seed: args.seed,
        ..BedloadSceneParams::default()
    };
    let detection = BedloadDetectionParams {
        position_sigma_px: args.noise,
        transparent_miss_probability: args.miss,
        burst_probability: args.burst,
        false_positive_mean: args.false_positives,
        ..BedloadDetectionParams::default()
    };
    (scene, detection)
}

/// `sillage synth bedload --out DIR`.
pub fn run_bedload(args: &SynthBedloadArgs) -> Result<()> {
    let (scene, detection) = params(args);
    let dir = &args.out;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the folder {}", dir.display()))?;
    let sequence = BedloadSequence::new(scene.clone(), detection)?;
    let mut truth = BeadCsvWriter::create(dir.join("truth.csv"))?;
    let mut detections = DetectionsCsvWriter::create(dir.join("detections.csv"))?;
    let mut candidates = DetectionsCsvWriter::create(dir.join("candidates.csv"))?;
    let mut progress = FrameProgress::new(Some(scene.n_frames), "generating");
    let mut points: Vec<TrackPoint> = Vec::new();
    for sample in sequence {
        let frame = sample.truth.index;
        points.clear();
        points.extend(sample.truth.track_points());
        truth.accept(&points)?;
        detections.push(frame, &sample.observation.detections)?;
        candidates.push(frame, &sample.observation.candidates)?;
        progress.tick();
    }
    progress.finish();
    let rows = truth.finish()?.rows;
    detections.finish()?;
    candidates.finish()?;
    let diameter = |radius_px: f64| 2.0 * radius_px * M_PER_PX;
    write_bead_sequence_params(
        dir.join("sequence_param.txt"),
        &BeadSequenceParams {
            black_diameter_m: diameter(scene.black_radius_px),
            transparent_diameter_m: diameter(scene.transparent_radius_px),
            m_per_px: M_PER_PX,
        },
    )?;
    eprintln!(
        "{} frames, {rows} true bead points → {} (truth.csv, detections.csv, candidates.csv, \
         sequence_param.txt)",
        scene.n_frames,
        dir.display()
    );
    Ok(())
}

//! `sillage bench bedload`: Table 1 of the MMPF+ paper — the five bedload trackers on the same
//! detections, scored against the truth — on a synthetic sequence, and on a real one with
//! `--real DIR` (BeadTracking's layout: `images/`, `ground_truth/trackdatatruth.csv`,
//! `sequence_param.txt`), where the τ_t sweep of Fig. 6 is also run.

use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use serde::Serialize;
use sillage::bedload::{BeadFrame, bedload_table};
use sillage::core::TrackPoint;
use sillage::detect::BeadDetections;
use sillage::eval::Table;
use sillage::eval::papers::BeadTrackScores;
use sillage::io::{
    BeadCategory, FrameOptions, open_frames, read_bead_csv, read_bead_sequence_params,
};
use sillage::synth::{BedloadDetectionParams, BedloadSceneParams, BedloadSequence};
use sillage::track::bedload::{BedloadTrackerKind, BedloadTrackerParams};

use crate::cli::BenchBedloadArgs;
use crate::detect::{build_detector, detect_frame};

/// One row of a table: the tracker (or τ_t) and its scores.
#[derive(Debug, Serialize)]
struct Row {
    sequence: String,
    tracker: &'static str,
    transparent_threshold: Option<f64>,
    scores: BeadTrackScores,
    track_ms_per_frame: f64,
}

/// The synthetic sequence's frames and truth.
fn synthetic(args: &BenchBedloadArgs) -> Result<(Vec<BeadFrame>, Vec<TrackPoint>, Vec<f64>)> {
    let scene = BedloadSceneParams {
        n_frames: args.frames,
        seed: args.seed,
        ..BedloadSceneParams::default()
    };
    let radii = vec![scene.black_radius_px, scene.transparent_radius_px];
    let (mut frames, mut truth) = (Vec::new(), Vec::new());
    for sample in BedloadSequence::new(scene, BedloadDetectionParams::default())? {
        truth.extend(sample.truth.track_points());
        frames.push(BeadFrame {
            frame: sample.truth.index,
            detections: sample.observation.detections,
            candidates: sample.observation.candidates,
        });
    }
    Ok((frames, truth, radii))
}

/// The real sequence's truth and bead radii.
fn real_truth(dir: &Path) -> Result<(Vec<TrackPoint>, Vec<f64>)> {
    let sequence = read_bead_sequence_params(dir.join("sequence_param.txt"))?;
    let radii = vec![
        sequence.radius_px(BeadCategory::Black),
        sequence.radius_px(BeadCategory::Transparent),
    ];
    let truth = read_bead_csv(dir.join("ground_truth").join("trackdatatruth.csv"))?
        .iter()
        .map(|b| b.track_point())
        .collect();
    Ok((truth, radii))
}

/// The real frames detected with the command line's detector, τ_t set to `threshold`.
fn real_frames(args: &BenchBedloadArgs, dir: &Path, threshold: f64) -> Result<Vec<BeadFrame>> {
    let mut detector_args = args.detector.clone();
    if detector_args.sequence_params.is_none() {
        detector_args.sequence_params = Some(dir.join("sequence_param.txt"));
    }
    // Candidates stay at 0.20 (the code's), or at τ_t when it is lower.
    let candidates = threshold.min(0.2);
    detector_args.detector_overrides.extend([
        format!("candidate_threshold={candidates}"),
        format!("transparent_threshold={threshold}"),
    ]);
    let mut detector = build_detector(&detector_args)?;
    let mut beads = BeadDetections::default();
    let mut frames = Vec::new();
    for frame in open_frames(
        &dir.join("images").to_string_lossy(),
        &FrameOptions::default(),
    )? {
        let frame = frame?;
        detect_frame(&mut detector, &frame, &mut beads)?;
        frames.push(BeadFrame {
            frame: frame.index,
            detections: beads
                .black
                .iter()
                .chain(&beads.transparent)
                .copied()
                .collect(),
            candidates: beads.candidates.clone(),
        });
    }
    Ok(frames)
}

/// Runs the trackers of `kinds` and appends a row each.
fn run_table(
    rows: &mut Vec<Row>,
    sequence: &str,
    threshold: Option<f64>,
    kinds: &[BedloadTrackerKind],
    frames: &[BeadFrame],
    truth: &[TrackPoint],
    radii: &[f64],
) -> Result<()> {
    let params = BedloadTrackerParams {
        radius_px: radii.to_vec(),
        ..BedloadTrackerParams::default()
    };
    for &kind in kinds {
        let start = Instant::now();
        let mut scores = bedload_table(&params, &[kind], frames, truth)?;
        let (_, scores) = scores.remove(0);
        rows.push(Row {
            sequence: sequence.to_string(),
            tracker: kind.name(),
            transparent_threshold: threshold,
            scores,
            track_ms_per_frame: 1e3 * start.elapsed().as_secs_f64() / frames.len().max(1) as f64,
        });
    }
    Ok(())
}

fn print_rows(rows: &[Row]) {
    let header = [
        "sequence",
        "tracker",
        "τ_t",
        "correct %",
        "MOTP %",
        "FN %",
        "FP %",
        "IDSW",
        "MOTA %",
        "IDF1",
        "HOTA",
        "F rest/roll/salt",
    ];
    let mut table = Table::new(header.map(String::from));
    for row in rows {
        let s = &row.scores;
        let f = |i: usize| {
            s.states.by_state()[i]
                .1
                .f_score
                .map_or("–".into(), |v| format!("{v:.2}"))
        };
        table.push([
            row.sequence.clone(),
            row.tracker.to_string(),
            row.transparent_threshold
                .map_or("–".into(), |t| format!("{t:.2}")),
            format!("{:.1}", 100.0 * s.table1.correct_track_rate),
            format!("{:.2}", 100.0 * s.mot.clear.motp),
            format!("{:.2}", 100.0 * s.table1.false_negative_rate),
            format!("{:.2}", 100.0 * s.table1.false_positive_rate),
            s.table1.id_switches.to_string(),
            format!("{:.2}", 100.0 * s.mot.clear.mota),
            format!("{:.3}", s.mot.identity.idf1),
            format!("{:.3}", s.mot.hota.hota),
            format!("{}/{}/{}", f(0), f(1), f(2)),
        ]);
    }
    println!("{table}");
}

/// `sillage bench bedload`.
pub fn run(args: &BenchBedloadArgs) -> Result<()> {
    let mut rows = Vec::new();
    let (frames, truth, radii) = synthetic(args)?;
    let name = format!("synthetic ({} frames)", args.frames);
    run_table(
        &mut rows,
        &name,
        None,
        &BedloadTrackerKind::ALL,
        &frames,
        &truth,
        &radii,
    )?;
    if let Some(dir) = &args.real {
        let (truth, radii) = real_truth(dir)?;
        let frames = real_frames(args, dir, 0.25)?;
        run_table(
            &mut rows,
            "real",
            Some(0.25),
            &BedloadTrackerKind::ALL,
            &frames,
            &truth,
            &radii,
        )?;
        // Fig. 6: correct tracks and MOTA of MMPF+ and DET against τ_t.
        for step in 0..=10 {
            let threshold = 0.15 + 0.02 * step as f64;
            let frames = real_frames(args, dir, threshold)?;
            let kinds = [BedloadTrackerKind::MmpfPlus, BedloadTrackerKind::Det];
            run_table(
                &mut rows,
                "real τ_t sweep",
                Some(threshold),
                &kinds,
                &frames,
                &truth,
                &radii,
            )?;
        }
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        print_rows(&rows);
    }
    Ok(())
}

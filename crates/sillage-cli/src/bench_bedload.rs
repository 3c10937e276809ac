//! `sillage bench bedload`: the MMPF+ paper's evaluation (§5) in one command — Table 1 (the
//! five bedload trackers on the same detections, scored against the truth) and the τ_t sweep
//! of Fig. 6 (correct tracks and MOTA of transparent beads against the detector threshold), on
//! a generated sequence rendered to frames and, with `--real DIR` (BeadTracking's layout:
//! `images/`, `ground_truth/trackdatatruth.csv`, `sequence_param.txt`), on real frames;
//! `--plots DIR` draws Figs. 6 and 7.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use serde::Serialize;
use sillage::bedload::{BeadFrame, track_beads};
use sillage::core::{Detection, FrameIndex, GrayImage, TRANSPARENT_BEAD_CLASS, TrackPoint};
use sillage::detect::BeadDetections;
use sillage::eval::Table;
use sillage::eval::papers::{BeadTrackScores, score_bead_tracks};
use sillage::io::{
    BeadCategory, FrameOptions, open_frames, read_bead_csv, read_bead_sequence_params,
};
use sillage::synth::{BedloadRenderParams, BedloadRenderer, BedloadScene, BedloadSceneParams};
use sillage::track::bedload::{BedloadTrackerKind, BedloadTrackerParams};

use crate::bench_bedload_plots::write_figures;
use crate::cli::BenchBedloadArgs;
use crate::demo_bedload::{synthetic_detector, synthetic_radii};
use crate::detect::{build_detector, detect_frame};
use crate::progress::FrameProgress;

/// τ_t of Table 1 (BeadTracking's sequence default is 0.23; 0.25 is the paper's figure's
/// middle and where both trackers reach 99 % on the real frames).
pub const TABLE_THRESHOLD: f64 = 0.25;

/// Candidates (Eq. (1)) are the maxima above this, or above τ_t when it is lower
/// (BeadTracking's `detect_trans_low`).
const CANDIDATE_CEILING: f64 = 0.2;

/// What a sweep needs of one frame: its black beads and every transparent-bead maximum above
/// the sweep's lowest τ_t, with its NCC score. Detections at any τ_t of the sweep are a filter
/// of these (the detector keeps the maxima at or above τ_t; the rest of its work does not
/// depend on τ_t), so each frame is detected once.
struct SweepFrame {
    frame: FrameIndex,
    black: Vec<Detection>,
    transparent: Vec<Detection>,
}

/// A sequence to score: its frames, truth and the bead radius of each class.
pub struct Sequence {
    /// `real` or `synthetic`.
    pub name: &'static str,
    frames: Vec<SweepFrame>,
    truth: Vec<TrackPoint>,
    radii: Vec<f64>,
}

impl Sequence {
    /// The tracker's input at threshold `tau`.
    fn at_threshold(&self, tau: f64) -> Vec<BeadFrame> {
        let candidate_floor = tau.min(CANDIDATE_CEILING) as f32;
        self.frames
            .iter()
            .map(|f| BeadFrame {
                frame: f.frame,
                detections: f
                    .black
                    .iter()
                    .chain(f.transparent.iter().filter(|d| d.strength >= tau as f32))
                    .copied()
                    .collect(),
                candidates: f
                    .transparent
                    .iter()
                    .filter(|d| d.strength > candidate_floor)
                    .copied()
                    .collect(),
            })
            .collect()
    }
}

/// Which beads a row scores.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Scope {
    /// Every bead (Table 1).
    AllBeads,
    /// Transparent beads only (Fig. 6).
    Transparent,
}

/// One scored run: a tracker on a sequence at one τ_t.
#[derive(Debug, Serialize)]
pub struct Row {
    /// The sequence's name.
    pub sequence: &'static str,
    /// The tracker.
    pub tracker: BedloadTrackerKind,
    /// The transparent-bead detection threshold.
    pub transparent_threshold: f64,
    /// Which beads are scored.
    pub scope: Scope,
    /// Every score.
    pub scores: BeadTrackScores,
    /// Tracking time (scoring excluded), ms per frame.
    pub track_ms_per_frame: f64,
}

/// The real sequence: truth, radii and detections from its images at the sweep's lowest τ_t.
fn real_sequence(args: &BenchBedloadArgs, dir: &Path) -> Result<Sequence> {
    let sequence = read_bead_sequence_params(dir.join("sequence_param.txt"))?;
    let radii = vec![
        sequence.radius_px(BeadCategory::Black),
        sequence.radius_px(BeadCategory::Transparent),
    ];
    let truth = read_bead_csv(dir.join("ground_truth").join("trackdatatruth.csv"))?
        .iter()
        .map(|b| b.track_point())
        .collect();
    let mut detector_args = args.detector.clone();
    if detector_args.sequence_params.is_none() {
        detector_args.sequence_params = Some(dir.join("sequence_param.txt"));
    }
    let lowest = lowest_threshold(args);
    detector_args.detector_overrides.extend([
        format!("candidate_threshold={lowest}"),
        format!("transparent_threshold={lowest}"),
    ]);
    let mut detector = build_detector(&detector_args)?;
    let mut beads = BeadDetections::default();
    let mut frames = Vec::new();
    let images = dir.join("images");
    for frame in open_frames(&images.to_string_lossy(), &FrameOptions::default())? {
        let frame = frame?;
        detect_frame(&mut detector, &frame, &mut beads)?;
        frames.push(sweep_frame(frame.index, &beads));
    }
    Ok(Sequence {
        name: "real",
        frames,
        truth,
        radii,
    })
}

/// A generated sequence rendered to frames in memory and detected like the real ones.
fn synthetic_sequence(args: &BenchBedloadArgs) -> Result<Sequence> {
    let scene = BedloadSceneParams {
        n_frames: args.frames,
        seed: args.seed,
        ..BedloadSceneParams::default()
    };
    let radii = synthetic_radii(&scene).to_vec();
    let lowest = lowest_threshold(args);
    let mut detector = synthetic_detector(&scene, Some(lowest))?;
    let mut renderer = BedloadRenderer::new(BedloadRenderParams::default())?;
    let mut image = GrayImage::new(scene.width, scene.height);
    let mut beads = BeadDetections::default();
    let (mut frames, mut truth) = (Vec::new(), Vec::new());
    let mut progress = FrameProgress::new(Some(scene.n_frames), "rendering and detecting");
    for frame in BedloadScene::new(scene)? {
        renderer.render(&frame, &mut image);
        detector
            .detect_beads(&image, &mut beads)
            .with_context(|| format!("synthetic frame {}", frame.index))?;
        frames.push(sweep_frame(frame.index, &beads));
        truth.extend(frame.track_points());
        progress.tick();
    }
    progress.finish();
    Ok(Sequence {
        name: "synthetic",
        frames,
        truth,
        radii,
    })
}

/// The threshold every frame is detected at: the lowest of the sweep and of Table 1.
fn lowest_threshold(args: &BenchBedloadArgs) -> f64 {
    args.thresholds
        .iter()
        .copied()
        .fold(TABLE_THRESHOLD, f64::min)
}

fn sweep_frame(frame: FrameIndex, beads: &BeadDetections) -> SweepFrame {
    SweepFrame {
        frame,
        black: beads.black.clone(),
        transparent: beads.candidates.clone(),
    }
}

/// Runs every tracker on `sequence` at τ_t = `tau` and appends a row each, scored on `scope`.
fn run_trackers(rows: &mut Vec<Row>, sequence: &Sequence, tau: f64, scope: Scope) -> Result<()> {
    let frames = sequence.at_threshold(tau);
    let truth: Vec<TrackPoint> = match scope {
        Scope::AllBeads => sequence.truth.clone(),
        Scope::Transparent => transparent_only(&sequence.truth),
    };
    let params = BedloadTrackerParams {
        radius_px: sequence.radii.clone(),
        ..BedloadTrackerParams::default()
    };
    for kind in BedloadTrackerKind::ALL {
        let params = BedloadTrackerParams {
            tracker: kind,
            ..params.clone()
        };
        let start = Instant::now();
        let points = track_beads(&params, &frames)?;
        let track_s = start.elapsed().as_secs_f64();
        let points = match scope {
            Scope::AllBeads => points,
            Scope::Transparent => transparent_only(&points),
        };
        rows.push(Row {
            sequence: sequence.name,
            tracker: kind,
            transparent_threshold: tau,
            scope,
            scores: score_bead_tracks(&truth, &points, &sequence.radii)?,
            track_ms_per_frame: 1e3 * track_s / frames.len().max(1) as f64,
        });
    }
    Ok(())
}

fn transparent_only(points: &[TrackPoint]) -> Vec<TrackPoint> {
    points
        .iter()
        .filter(|p| p.class == TRANSPARENT_BEAD_CLASS)
        .copied()
        .collect()
}

fn print_table1(rows: &[&Row]) {
    let header = [
        "sequence",
        "tracker",
        "correct %",
        "MOTP %",
        "FN %",
        "FP %",
        "IDSW",
        "MOTA %",
        "IDF1",
        "HOTA",
        "F rest/roll/salt",
        "ms/frame",
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
            row.sequence.to_string(),
            row.tracker.paper_name().to_string(),
            format!("{:.1}", 100.0 * s.table1.correct_track_rate),
            format!("{:.2}", 100.0 * s.mot.clear.motp),
            format!("{:.2}", 100.0 * s.table1.false_negative_rate),
            format!("{:.2}", 100.0 * s.table1.false_positive_rate),
            s.table1.id_switches.to_string(),
            format!("{:.2}", 100.0 * s.mot.clear.mota),
            format!("{:.3}", s.mot.identity.idf1),
            format!("{:.3}", s.mot.hota.hota),
            format!("{}/{}/{}", f(0), f(1), f(2)),
            format!("{:.2}", row.track_ms_per_frame),
        ]);
    }
    println!("Table 1 (τ_t = {TABLE_THRESHOLD}, every bead)\n{table}");
}

/// The sweep as one line per (sequence, τ_t): correct tracks / MOTA of each tracker.
fn print_sweep(rows: &[&Row]) {
    let mut header = vec!["sequence".to_string(), "τ_t".to_string()];
    header.extend(
        BedloadTrackerKind::ALL
            .iter()
            .map(|k| format!("{} correct / MOTA %", k.paper_name())),
    );
    let mut table = Table::new(header);
    for chunk in rows.chunks(BedloadTrackerKind::ALL.len()) {
        let mut line = vec![
            chunk[0].sequence.to_string(),
            format!("{:.2}", chunk[0].transparent_threshold),
        ];
        line.extend(chunk.iter().map(|r| {
            format!(
                "{:.1} / {:.2}",
                100.0 * r.scores.table1.correct_track_rate,
                100.0 * r.scores.mot.clear.mota
            )
        }));
        table.push(line);
    }
    println!("Fig. 6 (transparent beads)\n{table}");
}

/// `sillage bench bedload`.
pub fn run(args: &BenchBedloadArgs) -> Result<()> {
    if let Some(bad) = args.thresholds.iter().find(|t| !(**t > 0.0 && **t < 1.0)) {
        anyhow::bail!(
            "--thresholds: τ_t = {bad} is not an NCC threshold; give values between 0 and 1, \
             e.g. 0.15,0.25,0.35"
        );
    }
    let mut sequences = vec![synthetic_sequence(args)?];
    if let Some(dir) = &args.real {
        sequences.push(real_sequence(args, dir)?);
    }
    let mut rows = Vec::new();
    for sequence in &sequences {
        run_trackers(&mut rows, sequence, TABLE_THRESHOLD, Scope::AllBeads)?;
        for &tau in &args.thresholds {
            run_trackers(&mut rows, sequence, tau, Scope::Transparent)?;
        }
    }
    if let Some(dir) = &args.plots {
        let written = write_figures(dir, &rows)?;
        eprintln!("figures: {}", written.join(", "));
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        let (table1, sweep): (Vec<&Row>, Vec<&Row>) =
            rows.iter().partition(|r| r.scope == Scope::AllBeads);
        print_table1(&table1);
        print_sweep(&sweep);
    }
    Ok(())
}

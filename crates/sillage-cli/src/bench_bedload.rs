//! `sillage bench bedload`: the MMPF+ paper's evaluation (§5) in one command — Table 1 (the
//! five bedload trackers on the same detections, scored against the truth) and the τ_t sweep
//! of Fig. 6 (correct tracks and MOTA of transparent beads against the detector threshold), on
//! a generated sequence rendered to frames and, with `--real DIR` (BeadTracking's layout:
//! `images/`, `ground_truth/trackdatatruth.csv`, `sequence_param.txt`), on real frames;
//! `--plots DIR` draws Figs. 6 and 7. The rows are computed by
//! `sillage::experiments::bedload`; this prints them.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sillage::bedload::detector::BeadDetectorSources;
use sillage::eval::Table;
use sillage::experiments::bedload::figures::write_figures;
use sillage::experiments::bedload::sequences::Sequence;
use sillage::experiments::bedload::{Row, Scope, TABLE_THRESHOLD, evaluate, lowest_threshold};
use sillage::track::bedload::BedloadTrackerKind;

use crate::progress::FrameProgress;
use crate::shared_args::{BeadDetectorArgs, JsonArg};

/// `sillage bench bedload`.
#[derive(Debug, Args)]
pub struct BenchBedloadArgs {
    /// Frames of the synthetic sequence.
    #[arg(long, default_value_t = 100)]
    pub frames: usize,
    /// Seed of the synthetic sequence.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// A real sequence in BeadTracking's layout (images/, ground_truth/trackdatatruth.csv,
    /// sequence_param.txt), detected with the options below.
    #[arg(long, value_name = "DIR")]
    pub real: Option<PathBuf>,
    /// The detector, for --real.
    #[command(flatten)]
    pub detector: BeadDetectorArgs,
    /// The τ_t values of the Fig. 6 sweep, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [0.15, 0.17, 0.19, 0.21, 0.23, 0.25, 0.27, 0.29, 0.31, 0.33, 0.35])]
    pub thresholds: Vec<f64>,
    /// Draw Fig. 6 (correct tracks and MOTA of transparent beads against τ_t) and Fig. 7
    /// (motion-state F-scores) into this folder, as PNG and SVG.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
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
    let lowest = lowest_threshold(&args.thresholds);
    let mut progress = FrameProgress::new(Some(args.frames), "rendering and detecting");
    let synthetic = Sequence::synthetic(args.frames, args.seed, lowest, &mut || progress.tick());
    progress.finish();
    let mut sequences = vec![synthetic?];
    if let Some(dir) = &args.real {
        let detector = BeadDetectorSources::from(&args.detector);
        sequences.push(Sequence::real(dir, &detector, lowest)?);
    }
    let rows = evaluate(&sequences, &args.thresholds)?;
    if let Some(dir) = &args.plots {
        let written = write_figures(dir, &rows)?;
        eprintln!("figures: {}", written.join(", "));
    }
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        let (table1, sweep): (Vec<&Row>, Vec<&Row>) =
            rows.iter().partition(|r| r.scope == Scope::AllBeads);
        print_table1(&table1);
        print_sweep(&sweep);
    }
    Ok(())
}

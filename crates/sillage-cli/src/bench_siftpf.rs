//! `sillage bench siftpf`: the SIFT-PF paper's evaluation (§3, Tables 1 and 3), run by
//! `sillage::experiments::siftpf`, printed as a Markdown table (or JSON).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sillage::experiments::siftpf::{BenchProgress, Report, Row, bench, seeds};
use sillage::pedestrian::{GroundPlaneFile, SiftPfSettings};
use sillage::track::siftpf::FeatureSelection;

use crate::progress::FrameProgress;
use crate::shared_args::{ConfigFileArgs, JsonArg};

/// The paper's three feature selections (§3.1.1), in its order.
pub const SIFTPF_SELECTIONS: [&str; 3] = ["whole-object", "detection-order", "reliability"];

/// `sillage bench siftpf`.
#[derive(Debug, Args)]
pub struct BenchSiftpfArgs {
    /// MOTChallenge sequence folders: `gt/gt.txt`, `seqinfo.ini`, and the frames in `img1/`
    /// or, without `img1/`, one video `video/*.mp4`.
    #[arg(required = true)]
    pub sequences: Vec<PathBuf>,
    /// Feature selections, comma-separated (default: the paper's three).
    #[arg(long, value_delimiter = ',', default_values_t = SIFTPF_SELECTIONS.map(String::from))]
    pub selections: Vec<String>,
    /// Use the first N frames of each sequence.
    #[arg(long, value_name = "N")]
    pub max_frames: Option<usize>,
    /// Random seed of the particles, of the first run (the tracker is deterministic for a
    /// seed).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Runs per selection, with seeds `seed`, `seed + 1`, …; the table gives each score's
    /// median over the runs and in how many runs each selection was best on M̄.
    #[arg(long, default_value_t = 1, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub runs: u64,
    /// Ground plane, as `sillage track siftpf --ground-plane`.
    #[arg(long, value_name = "FILE")]
    pub ground_plane: Option<PathBuf>,
    /// `--config FILE` and `--set KEY=VALUE`: the parameters.
    #[command(flatten)]
    pub params: ConfigFileArgs,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// `sillage bench siftpf SEQ... [--selections ...]`.
pub fn run(args: &BenchSiftpfArgs) -> Result<()> {
    let seeds = seeds(args.seed, args.runs)?;
    let settings =
        SiftPfSettings::load(args.params.config.as_deref(), &args.params.overrides, None)?;
    let selections = args
        .selections
        .iter()
        .map(|s| FeatureSelection::parse(s))
        .collect::<sillage::core::Result<Vec<_>>>()?;
    let homography = args
        .ground_plane
        .as_deref()
        .map(GroundPlaneFile::read_homography)
        .transpose()?;
    let mut progress: Option<FrameProgress> = None;
    let report = bench(
        &args.sequences,
        &settings,
        &selections,
        homography,
        seeds,
        args.max_frames,
        &mut |event| match event {
            BenchProgress::Frame(expected) => progress
                .get_or_insert_with(|| FrameProgress::new(expected, "tracking"))
                .tick(),
            BenchProgress::Run(row, seed) => {
                if let Some(p) = progress.take() {
                    p.finish();
                }
                eprintln!(
                    "{} {} seed {seed}: M̄ {:.2}, MOTA {:.1} %, IDF1 {:.1} %, HOTA {:.1} %",
                    row.sequence, row.selection, row.mean, row.mota, row.idf1, row.hota
                );
            }
        },
    );
    if let Some(p) = progress {
        p.finish();
    }
    let report = report?;
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!("{}", markdown(&report));
    }
    Ok(())
}

const HEADER: &str = "| sequence | selection | frames | M1 | M2 | M3 | M̄ | best M̄ in | MOTA % | IDF1 % | HOTA % | IDSW | tracks | tracking ms/frame | fps |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|";

fn format_row(row: &Row) -> String {
    format!(
        "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {}/{} | {:.1} | {:.1} | {:.1} | {} | {} | {:.1} | {:.1} |",
        row.sequence,
        row.selection,
        row.frames,
        row.tracking_time,
        row.id_persistence,
        row.id_confusion,
        row.mean,
        row.best_mean_in,
        row.runs,
        row.mota,
        row.idf1,
        row.hota,
        row.id_switches,
        row.tracks,
        row.tracking_ms_per_frame,
        row.fps
    )
}

fn markdown(report: &Report) -> String {
    let mut text = String::from(HEADER);
    for row in report.sequences.iter().chain(&report.combined) {
        text.push('\n');
        text.push_str(&format_row(row));
    }
    text
}

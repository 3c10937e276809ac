//! `sillage bench immpf`: the IMM-PF paper's evaluation (Tables 1-2), run by
//! `sillage::experiments::immpf`, printed as a Markdown table (or JSON).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sillage::experiments::immpf::{BenchInput, BenchProgress, Row, bench};
use sillage::pedestrian::ImmpfSettings;
use sillage::pedestrian::immpf::Scene;
use sillage::track::immpf::ModelName;

use crate::shared_args::{ConfigFileArgs, JsonArg};

/// The paper's seven model combinations (Table 1).
pub const IMMPF_COMBINATIONS: [&str; 7] = [
    "CA",
    "CV",
    "MP",
    "CV_CA",
    "CV_CA_MP",
    "CP_CV_CA",
    "CP_CV_CA_MP",
];

/// `sillage bench immpf`.
#[derive(Debug, Args)]
pub struct BenchImmpfArgs {
    /// MOTChallenge sequence folders (`img1/`, `det/det.txt`, `gt/gt.txt`, `seqinfo.ini`).
    #[arg(required = true)]
    pub sequences: Vec<PathBuf>,
    /// Model combinations, comma-separated (default: the paper's seven).
    #[arg(long, value_delimiter = ',', default_values_t = IMMPF_COMBINATIONS.map(String::from))]
    pub models: Vec<String>,
    /// Seeds per combination; the table gives medians (the paper: 30).
    #[arg(long, default_value_t = 30)]
    pub runs: usize,
    /// Track `det/det.txt` alone (no frames): for sequences without images.
    #[arg(long)]
    pub detections_only: bool,
    /// With frames, start trackers on `det/det.txt` instead of motion blobs.
    #[arg(long)]
    pub births_from_detections: bool,
    /// Ground plane for box sizes (see `sillage track immpf --ground-plane`).
    #[arg(long, value_name = "FILE")]
    pub ground_plane: Option<PathBuf>,
    /// Motion prior for MP (default: learned from the sequence's own CV_CA tracks, no truth).
    #[arg(long, value_name = "FILE")]
    pub motion_prior: Option<PathBuf>,
    /// `--config FILE` and `--set KEY=VALUE`: the parameters.
    #[command(flatten)]
    pub params: ConfigFileArgs,
    /// Use the first N frames of each sequence.
    #[arg(long, value_name = "N")]
    pub max_frames: Option<usize>,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// `sillage bench immpf SEQ... [--runs 30]`.
pub fn run(args: &BenchImmpfArgs) -> Result<()> {
    let settings =
        ImmpfSettings::load(args.params.config.as_deref(), &args.params.overrides, None)?;
    let scene = Scene::load(args.ground_plane.as_deref(), args.motion_prior.as_deref())?;
    let combinations = args
        .models
        .iter()
        .map(|m| ModelName::parse_combination(m))
        .collect::<sillage::core::Result<Vec<_>>>()?;
    let input = BenchInput {
        detections_only: args.detections_only,
        births_from_detections: args.births_from_detections,
        max_frames: args.max_frames,
    };
    let rows = bench(
        &args.sequences,
        input,
        &settings,
        &scene,
        &combinations,
        args.runs,
        &mut |progress| match progress {
            BenchProgress::Prepared { sequence, frames } => {
                eprintln!("{sequence}: {frames} frames prepared")
            }
            BenchProgress::Row(row) => eprintln!("{}", format_row(row)),
        },
    )?;
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        println!("{}", markdown(&rows));
    }
    Ok(())
}

const HEADER: &str = "| sequence | models | runs | SFDA | ATA | ATA(0.5) | N-MODP | MOTP | MOTA % | IDF1 % | HOTA % | IDSW | tracks | ms/frame |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|";

fn format_row(row: &Row) -> String {
    let m = &row.median;
    format!(
        "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1} | {:.1} | {:.1} | {:.0} | {:.0} | {:.2} |",
        row.sequence,
        row.models,
        row.runs,
        m.sfda,
        m.ata,
        m.ata_relaxed,
        m.n_modp,
        m.motp,
        m.mota,
        m.idf1,
        m.hota,
        m.id_switches,
        m.tracks,
        m.tracking_ms_per_frame
    )
}

fn markdown(rows: &[Row]) -> String {
    let mut text = String::from(HEADER);
    for row in rows {
        text.push('\n');
        text.push_str(&format_row(row));
    }
    text
}

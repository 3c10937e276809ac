//! `sillage bench siftpf`: the SIFT-PF paper's evaluation (§3, Tables 1 and 3), run by
//! `sillage::experiments::siftpf`, printed as a Markdown table (or JSON).

use anyhow::Result;
use sillage::experiments::siftpf::{BenchProgress, Report, Row, bench, seeds};
use sillage::pedestrian::{GroundPlaneFile, SiftPfSettings};
use sillage::track::siftpf::FeatureSelection;

use crate::cli::BenchSiftpfArgs;
use crate::progress::FrameProgress;

/// `sillage bench siftpf SEQ... [--selections ...]`.
pub fn run(args: &BenchSiftpfArgs) -> Result<()> {
    let seeds = seeds(args.seed, args.runs)?;
    let settings = SiftPfSettings::load(args.config.as_deref(), &args.overrides, None)?;
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
    if args.json {
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

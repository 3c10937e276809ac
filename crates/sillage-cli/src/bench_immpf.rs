//! `sillage bench immpf`: the IMM-PF paper's evaluation (Tables 1-2), run by
//! `sillage::experiments::immpf`, printed as a Markdown table (or JSON).

use anyhow::Result;
use sillage::experiments::immpf::{BenchInput, BenchProgress, Row, bench};
use sillage::pedestrian::ImmpfSettings;
use sillage::pedestrian::immpf::Scene;
use sillage::track::immpf::ModelName;

use crate::cli::BenchImmpfArgs;

/// `sillage bench immpf SEQ... [--runs 30]`.
pub fn run(args: &BenchImmpfArgs) -> Result<()> {
    let settings = ImmpfSettings::load(args.config.as_deref(), &args.overrides, None)?;
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
    if args.json {
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

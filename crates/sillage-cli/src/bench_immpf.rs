//! `sillage bench immpf`: the IMM-PF paper's evaluation (Tables 1-2), run by
//! `sillage::experiments::immpf`, printed as a Markdown table (or JSON).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use sillage::experiments::held_out::{
    GridAxis, HeldOutProgress, HeldOutRow, Split, bench_held_out, criterion,
};
use sillage::experiments::immpf::{BenchInput, BenchProgress, Row, RunScores, bench};
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
    /// MOTChallenge sequence folders (`img1/` or one `video/*.mp4`, `det/det.txt`, `gt/gt.txt`,
    /// `seqinfo.ini`).
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
    /// With frames, also read `det/det.txt`: the measurements that drive the trackers, the
    /// frames adding colour (or only the births, instead of motion blobs, with `--set
    /// tracker.detection.with_frames=births`).
    #[arg(long, alias = "births-from-detections")]
    pub with_detections: bool,
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
    /// Settings chosen on other sequences than the one reported: every combination of the
    /// grid's values is benched, and each sequence is reported with the combination of best
    /// mean (MOTA + IDF1) / 2 on the others (repeatable; e.g. `--grid
    /// tracker.detection.min_hits=3,4,5`).
    #[arg(long, value_name = "KEY=V1,V2")]
    pub grid: Vec<String>,
    /// With `--grid`: choose once on these sequences (folder names, comma-separated) and
    /// report on the others, instead of leaving each sequence out in turn.
    #[arg(long, value_delimiter = ',', value_name = "NAME")]
    pub tune_on: Vec<String>,
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
        with_detections: args.with_detections,
        max_frames: args.max_frames,
        skip_baselines: false,
    };
    if !args.grid.is_empty() || !args.tune_on.is_empty() {
        return run_held_out(args, input, &scene, &combinations);
    }
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

/// `--grid` / `--tune-on`: settings chosen on some sequences, reported on the others.
fn run_held_out(
    args: &BenchImmpfArgs,
    input: BenchInput,
    scene: &Scene,
    combinations: &[Vec<ModelName>],
) -> Result<()> {
    let axes = args
        .grid
        .iter()
        .map(|g| GridAxis::parse(g))
        .collect::<sillage::core::Result<Vec<_>>>()?;
    let split = if args.tune_on.is_empty() {
        Split::LeaveOneOut
    } else {
        Split::TuneOn(args.tune_on.clone())
    };
    let rows = bench_held_out(
        &args.sequences,
        input,
        args.params.config.as_deref(),
        &args.params.overrides,
        &axes,
        &split,
        scene,
        combinations,
        args.runs,
        &mut |progress| match progress {
            HeldOutProgress::Combination {
                index,
                total,
                overrides,
            } => eprintln!("combination {}/{total}: {}", index + 1, overrides.join(" ")),
            HeldOutProgress::Bench(BenchProgress::Row(row)) => eprintln!("{}", format_row(row)),
            HeldOutProgress::Bench(BenchProgress::Prepared { .. }) => {}
        },
    )?;
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        println!("{}", held_out_markdown(&rows));
    }
    Ok(())
}

/// `MOTA / IDF1` of a baseline, or a dash.
fn mota_idf1(scores: Option<&RunScores>) -> String {
    scores.map_or("–".into(), |s| format!("{:.1} / {:.1}", s.mota, s.idf1))
}

fn held_out_markdown(rows: &[HeldOutRow]) -> String {
    let mut text = String::from(
        "| reported | chosen on | chosen | tuning (MOTA+IDF1)/2 | MOTA / IDF1 | SORT | ByteTrack |\n\
         |---|---|---|---:|---|---|---|",
    );
    for r in rows {
        text.push_str(&format!(
            "\n| {} | {} | {} | {:.1} | {} | {} | {} |",
            r.sequence,
            r.tuned_on.join(", "),
            r.chosen.join(" "),
            r.tuning_score,
            mota_idf1(Some(&r.held_out)),
            mota_idf1(r.sort.as_ref()),
            mota_idf1(r.bytetrack.as_ref()),
        ));
    }
    let mean = |f: &dyn Fn(&HeldOutRow) -> Option<f64>| -> String {
        let values: Vec<f64> = rows.iter().filter_map(f).collect();
        if values.len() == rows.len() && !values.is_empty() {
            format!("{:.1}", values.iter().sum::<f64>() / values.len() as f64)
        } else {
            "–".into()
        }
    };
    text.push_str(&format!(
        "\n| **mean (MOTA+IDF1)/2** | | | | {} | {} | {} |",
        mean(&|r| Some(criterion(&r.held_out))),
        mean(&|r| r.sort.as_ref().map(criterion)),
        mean(&|r| r.bytetrack.as_ref().map(criterion)),
    ));
    text
}

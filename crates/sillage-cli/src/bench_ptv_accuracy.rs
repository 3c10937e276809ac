//! `sillage bench ptv-accuracy`: PTV accuracy on a family of synthetic flows, defaults against
//! the old defaults and the best of a grid search per case.

use anyhow::Result;
use clap::{Args, ValueEnum};
use sillage::PipelineConfig;
use sillage::ptv_accuracy_bench::{FamilyRow, Half, Recoveries, family, moderate_family, run_case};

use crate::shared_args::JsonArg;

/// Which cases of the family to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum HalfArg {
    /// The cases defaults were chosen on.
    Tune,
    /// The cases defaults were never chosen on (the figures to quote).
    Report,
    /// Both halves.
    All,
}

/// Which family of cases to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FamilyArg {
    /// Six flows × σ 0.7–3 px × 0.001–0.05 particles per pixel × 0.5–10 px per frame.
    Main,
    /// Displacements 0.3–0.6 of the particle spacing (σ 1–2 px), where the automatic
    /// first-link vote decides how a run starts.
    Moderate,
}

/// `sillage bench ptv-accuracy`.
#[derive(Debug, Args)]
pub struct BenchPtvAccuracyArgs {
    /// Which family of cases.
    #[arg(long, value_enum, default_value_t = FamilyArg::Main)]
    pub family: FamilyArg,
    /// Which half of the family to run.
    #[arg(long, value_enum, default_value_t = HalfArg::Report)]
    pub half: HalfArg,
    /// Frame side, px (square frames).
    #[arg(long, default_value_t = 512)]
    pub size: usize,
    /// Frames per case.
    #[arg(long, default_value_t = 10)]
    pub frames: usize,
    /// Skip the grid search (defaults and old defaults only; much faster).
    #[arg(long)]
    pub no_search: bool,
    /// Score the defaults with this key set, e.g. `--set detector.deblend=false` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// `--json`: a machine-readable table on stdout.
    #[command(flatten)]
    pub json: JsonArg,
}

/// `sillage bench ptv-accuracy`.
pub fn run(args: &BenchPtvAccuracyArgs) -> Result<()> {
    let mut defaults = PipelineConfig::default();
    for assignment in &args.set {
        defaults.set(assignment)?;
    }
    defaults.validate()?;
    let cases = match args.family {
        FamilyArg::Main => family(),
        FamilyArg::Moderate => moderate_family(),
    };
    let cases: Vec<_> = cases
        .into_iter()
        .filter(|c| match args.half {
            HalfArg::Tune => c.half == Half::Tune,
            HalfArg::Report => c.half == Half::Report,
            HalfArg::All => true,
        })
        .collect();
    if !args.json.enabled {
        println!(
            "sillage bench ptv-accuracy: {} cases, {}² px, {} frames; true / false recoveries, %",
            cases.len(),
            args.size,
            args.frames
        );
        println!(
            "{:<22} {:>6} {:>5} {:>6} {:>5} {:>4} {:>5} {:>6} {:>13} {:>13} {:>13}",
            "case",
            "half",
            "σ px",
            "ppp",
            "disp",
            "SNR",
            "int.",
            "σ̂ px",
            "defaults",
            "old defaults",
            "tuned"
        );
    }
    let mut rows = Vec::new();
    for case in &cases {
        let row = run_case(case, args.size, args.frames, !args.no_search, &defaults)?;
        if !args.json.enabled {
            print_row(&row);
        }
        rows.push(row);
    }
    if args.json.enabled {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        print_means(&rows);
    }
    Ok(())
}

/// `true / false` of one run.
fn pair(r: &Recoveries) -> String {
    format!("{:.1} / {:.1}", r.true_pct, r.false_pct)
}

fn print_row(row: &FamilyRow) {
    let c = &row.case;
    println!(
        "{:<22} {:>6} {:>5.1} {:>6.3} {:>5.1} {:>4.0} {:>5.2} {:>6} {:>13} {:>13} {:>13}",
        c.name,
        format!("{:?}", c.half).to_lowercase(),
        c.sigma_px,
        c.density_ppp,
        c.max_displacement_px,
        c.snr,
        c.intermittency,
        row.measured_sigma_px
            .map_or("–".into(), |s| format!("{s:.2}")),
        pair(&row.defaults),
        pair(&row.old_defaults),
        row.tuned.as_ref().map_or("–".into(), |(_, r)| pair(r)),
    );
}

fn print_means(rows: &[FamilyRow]) {
    if rows.is_empty() {
        return;
    }
    let n = rows.len() as f64;
    let mean = |f: &dyn Fn(&FamilyRow) -> Option<f64>| {
        let values: Vec<f64> = rows.iter().filter_map(f).collect();
        (values.len() == rows.len()).then(|| values.iter().sum::<f64>() / n)
    };
    let show = |t: Option<f64>, f: Option<f64>| match (t, f) {
        (Some(t), Some(f)) => format!("{t:.1} / {f:.1}"),
        _ => "–".into(),
    };
    println!(
        "{:<22} {:>59} {:>13} {:>13}",
        "mean",
        show(
            mean(&|r| Some(r.defaults.true_pct)),
            mean(&|r| Some(r.defaults.false_pct))
        ),
        show(
            mean(&|r| Some(r.old_defaults.true_pct)),
            mean(&|r| Some(r.old_defaults.false_pct))
        ),
        show(
            mean(&|r| r.tuned.map(|(_, t)| t.true_pct)),
            mean(&|r| r.tuned.map(|(_, t)| t.false_pct))
        ),
    );
    let tuned: Vec<_> = rows
        .iter()
        .filter_map(|r| r.tuned.map(|(_, t)| (r, t)))
        .collect();
    if tuned.len() == rows.len() {
        let within = tuned.iter().filter(|(r, t)| r.defaults.near(t)).count();
        let sparse: Vec<_> = rows.iter().filter(|r| r.case.density_ppp <= 0.02).collect();
        let clean = sparse
            .iter()
            .filter(|r| r.defaults.false_pct <= 2.0)
            .count();
        println!(
            "defaults within 2 points of the tuned true recovery in {within} of {} cases; \
             false recoveries ≤ 2 % in {clean} of the {} cases with ≤ 0.02 particles per pixel",
            rows.len(),
            sparse.len()
        );
    }
}

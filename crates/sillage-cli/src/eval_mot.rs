//! `sillage eval mot`: HOTA, CLEAR MOT and IDF1 — and with `--papers` each paper's own
//! scores — of predictions against ground truth, per sequence and combined, as tables or
//! JSON, with the per-frame events as CSV on request.

use std::io::Write as _;
use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, ValueEnum};
use sillage::eval::mot::{MatchRule, MotChallengeProtocol, MotConvention};
use sillage::evaluate::{EvalOptions, evaluate_files};

use crate::shared_args::JsonArg;

/// `sillage eval mot`.
#[derive(Debug, Args)]
pub struct EvalMotArgs {
    /// Ground truth: a MOTChallenge gt.txt, a sequence folder (SEQ/gt/gt.txt, SEQ/seqinfo.ini),
    /// a folder of sequence folders, a bead ground-truth CSV (frame,id,x,y,category,...) or a
    /// truth CSV (frame,track_id,x,y).
    #[arg(long, value_name = "FILE_OR_DIR")]
    pub gt: PathBuf,
    /// Predictions: a MOTChallenge results file, a folder of files named after the sequences
    /// (<seq>.txt), a sillage track file (TracTrac _track.txt, CSV, Parquet) or a bead CSV.
    #[arg(long, value_name = "FILE_OR_DIR")]
    pub pred: PathBuf,
    /// How a prediction matches a true object: iou[:T] (box IoU ≥ T, default 0.5), dist:R
    /// (centres at most R px apart), disc[:T] (bead disc IoU ≥ T, default 0.43).
    #[arg(long = "match", value_name = "RULE", default_value = "iou")]
    pub rule: MatchRule,
    /// MOTChallenge ground-truth rules: which rows are scored, which are distractors.
    #[arg(long, value_enum, default_value_t = ProtocolArg::Mot15)]
    pub protocol: ProtocolArg,
    /// Whose conventions to follow where the reference evaluators differ.
    #[arg(long, value_enum, default_value_t = ConventionArg::Trackeval)]
    pub convention: ConventionArg,
    /// Also print the papers' own scores: MMPF+ correct tracks, FN/FP rates and motion-state
    /// F-scores, IMM-PF's VACE, SIFT-PF's ETISEO M1-M3.
    #[arg(long)]
    pub papers: bool,
    /// `--json`: a machine-readable summary on stdout.
    #[command(flatten)]
    pub json: JsonArg,
    /// Write every frame's events (match, switch, miss, false positive) to this CSV.
    #[arg(long, value_name = "FILE.csv")]
    pub per_frame: Option<PathBuf>,
}

/// `--protocol`.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ProtocolArg {
    /// 2D MOT 2015: rows with a zero consider flag are ignored; no classes.
    Mot15,
    /// MOT16/17: pedestrians scored, distractor classes removed.
    Mot17,
    /// MOT20: as MOT17, non-motorised vehicles also distractors.
    Mot20,
}

impl From<ProtocolArg> for MotChallengeProtocol {
    fn from(p: ProtocolArg) -> Self {
        match p {
            ProtocolArg::Mot15 => MotChallengeProtocol::Mot15,
            ProtocolArg::Mot17 => MotChallengeProtocol::Mot17,
            ProtocolArg::Mot20 => MotChallengeProtocol::Mot20,
        }
    }
}

/// `--convention`.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ConventionArg {
    /// TrackEval, MOTChallenge's official evaluator.
    Trackeval,
    /// py-motmetrics 1.4.0.
    Pymotmetrics,
}

impl From<ConventionArg> for MotConvention {
    fn from(c: ConventionArg) -> Self {
        match c {
            ConventionArg::Trackeval => MotConvention::TrackEval,
            ConventionArg::Pymotmetrics => MotConvention::PyMotMetrics,
        }
    }
}

/// `sillage eval mot --gt FILE_OR_DIR --pred FILE_OR_DIR`.
pub fn run(args: &EvalMotArgs) -> Result<()> {
    let options = EvalOptions {
        rule: args.rule,
        protocol: args.protocol.into(),
        convention: args.convention.into(),
        papers: args.papers,
        events: args.per_frame.is_some(),
    };
    let evaluation = evaluate_files(&args.gt, &args.pred, &options)?;
    if let Some(path) = &args.per_frame {
        let written = evaluation.write_events(path)?;
        eprintln!(
            "wrote {} events to {}",
            written.rows,
            written.path.display()
        );
    }
    let text = if args.json.enabled {
        format!("{}\n", serde_json::to_string_pretty(&evaluation)?)
    } else {
        evaluation.to_string()
    };
    print_stdout(&text)
}

/// Writes `text` to stdout; a reader that stops early (`| head`) is not an error.
fn print_stdout(text: &str) -> Result<()> {
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(anyhow::Error::new(e).context("cannot write to stdout"))
        }
        _ => Ok(()),
    }
}

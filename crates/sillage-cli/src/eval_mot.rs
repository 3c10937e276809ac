//! `sillage eval mot`: HOTA, CLEAR MOT and IDF1 — and with `--papers` each paper's own
//! scores — of predictions against ground truth, per sequence and combined, as tables or
//! JSON, with the per-frame events as CSV on request.

use std::io::Write as _;

use anyhow::Result;
use sillage::evaluate::{EvalOptions, evaluate_files};

use crate::cli::EvalMotArgs;

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
    let text = if args.json {
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

//! Progress bars on stderr; hidden when stderr is not a terminal, so logs stay clean.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use sillage::FrameReport;

/// A per-frame progress bar showing detections and speed.
pub struct FrameProgress {
    bar: ProgressBar,
}

impl FrameProgress {
    /// A bar for `total` frames (a spinner when the length is unknown, e.g. a video).
    pub fn new(total: Option<usize>, what: &str) -> Self {
        let bar = match total {
            Some(n) => ProgressBar::with_draw_target(Some(n as u64), ProgressDrawTarget::stderr()),
            None => ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr()),
        };
        let template =
            format!("{what} {{bar:30}} {{pos}}/{{len}} frames {{per_sec}} · {{msg}} · eta {{eta}}");
        if let Ok(style) = ProgressStyle::with_template(&template) {
            bar.set_style(style);
        }
        Self { bar }
    }

    /// Advances by one frame.
    pub fn frame(&mut self, report: &FrameReport) {
        self.bar
            .set_message(format!("{} detections", report.detections));
        self.bar.inc(1);
    }

    /// Advances by one item that has no report (rendering, writing).
    pub fn tick(&mut self) {
        self.bar.inc(1);
    }

    /// Clears the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// A spinner counting the rows of a table read in one pass (its length is unknown).
pub struct RowProgress {
    bar: ProgressBar,
    rows: u64,
}

impl RowProgress {
    /// Rows between two redraws: drawing per row would cost more than the work.
    const STEP: u64 = 1 << 16;

    /// A spinner labelled `what`.
    pub fn new(what: &str) -> Self {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        if let Ok(style) =
            ProgressStyle::with_template(&format!("{what} {{spinner}} {{pos}} rows {{per_sec}}"))
        {
            bar.set_style(style);
        }
        Self { bar, rows: 0 }
    }

    /// Counts one row.
    pub fn tick(&mut self) {
        self.rows += 1;
        if self.rows.is_multiple_of(Self::STEP) {
            self.bar.set_position(self.rows);
        }
    }

    /// Clears the spinner.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

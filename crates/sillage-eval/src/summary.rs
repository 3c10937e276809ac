//! Small helpers shared by the metrics: running means and the text of a summary.

/// A running mean; `value` is `None` before the first sample.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct Mean {
    sum: f64,
    count: usize,
}

impl Mean {
    pub fn add(&mut self, sample: f64) {
        self.sum += sample;
        self.count += 1;
    }

    pub fn count(&self) -> usize {
        self.count
    }

    pub fn value(&self) -> Option<f64> {
        (self.count > 0).then(|| self.sum / self.count as f64)
    }
}

/// A rate as a percentage with one decimal, or `n/a`.
pub(crate) fn percent(rate: Option<f64>) -> String {
    rate.map_or_else(|| "n/a".to_owned(), |r| format!("{:.1} %", 100.0 * r))
}

/// A length in px with three decimals, or `n/a`.
pub(crate) fn px(value: Option<f64>) -> String {
    value.map_or_else(|| "n/a".to_owned(), |v| format!("{v:.3} px"))
}

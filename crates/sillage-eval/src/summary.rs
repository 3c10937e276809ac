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

/// A score in `[0, 1]` as a percentage with three decimals (TrackEval's tables).
pub(crate) fn score(value: f64) -> String {
    format!("{:.3}", 100.0 * value)
}

/// An optional score as [`score`], or `n/a`.
pub(crate) fn optional_score(value: Option<f64>) -> String {
    value.map_or_else(|| "n/a".to_owned(), score)
}

/// A count.
pub(crate) fn count(value: u64) -> String {
    value.to_string()
}

/// The columns of one metric family for one row of a report (`None`: the row has no value
/// for this family).
pub(crate) type FamilyColumns<T> = fn(&T) -> Option<Vec<(&'static str, String)>>;

/// Writes one table per metric family (`(title, columns)`), each with a row per named item
/// that has values for it; a family without any row is left out.
pub(crate) fn family_tables<T>(
    f: &mut std::fmt::Formatter<'_>,
    rows: &[(&str, &T)],
    families: &[(String, FamilyColumns<T>)],
) -> std::fmt::Result {
    let mut first = true;
    for (title, columns) in families {
        let mut table: Option<Table> = None;
        for (name, item) in rows {
            let Some(values) = columns(item) else {
                continue;
            };
            let table = table.get_or_insert_with(|| {
                let header = values.iter().map(|(column, _)| (*column).to_owned());
                Table::new(std::iter::once("sequence".to_owned()).chain(header))
            });
            table.push(
                std::iter::once((*name).to_owned()).chain(values.into_iter().map(|(_, v)| v)),
            );
        }
        if let Some(table) = table {
            if !first {
                writeln!(f)?;
            }
            first = false;
            writeln!(f, "{title}")?;
            write!(f, "{table}")?;
        }
    }
    Ok(())
}

/// A plain-text table: a header row and value rows, columns right-aligned to their widest
/// cell (the first column left-aligned).
#[derive(Debug, Clone, Default)]
pub struct Table {
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with the given column names.
    pub fn new(header: impl IntoIterator<Item = String>) -> Self {
        Self {
            rows: vec![header.into_iter().collect()],
        }
    }

    /// A header and one row from `(name, value)` columns.
    pub fn single(columns: &[(&str, String)]) -> Self {
        let mut table = Self::new(columns.iter().map(|(name, _)| (*name).to_owned()));
        table.push(columns.iter().map(|(_, value)| value.clone()));
        table
    }

    /// Appends a row.
    pub fn push(&mut self, row: impl IntoIterator<Item = String>) {
        self.rows.push(row.into_iter().collect());
    }
}

impl std::fmt::Display for Table {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let columns = self.rows.iter().map(Vec::len).max().unwrap_or(0);
        let widths: Vec<usize> = (0..columns)
            .map(|c| {
                self.rows
                    .iter()
                    .filter_map(|row| row.get(c))
                    .map(|cell| cell.chars().count())
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        for row in &self.rows {
            let mut line = String::new();
            for (c, cell) in row.iter().enumerate() {
                if c > 0 {
                    line.push_str("  ");
                }
                let pad = " ".repeat(widths[c] - cell.chars().count());
                if c == 0 && columns > 1 {
                    line.push_str(cell);
                    line.push_str(&pad);
                } else {
                    line.push_str(&pad);
                    line.push_str(cell);
                }
            }
            writeln!(f, "{}", line.trim_end())?;
        }
        Ok(())
    }
}

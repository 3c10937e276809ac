//! Shared plumbing of the text tables (TracTrac `_track.txt`, CSV tracks, truth and
//! detections): a whole-row writer on a partial file, a header-checked CSV reader that names
//! the file, line and column of every error, and number formatting.

use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use sillage_core::{Error, Result};

use crate::WrittenSummary;
use crate::partial::PartialFile;

/// Writes rows to a `.NAME.partial` file, one whole batch at a time, and renames it on
/// [`RowWriter::finish`]. An interrupted run leaves only complete rows behind.
#[derive(Debug)]
pub(crate) struct RowWriter {
    file: PartialFile,
    buffer: String,
    rows: u64,
}

impl RowWriter {
    /// Creates the partial file and writes `header` (whole lines, newline-terminated).
    pub(crate) fn create(path: &Path, header: &str) -> Result<Self> {
        let mut file = PartialFile::create(path)?;
        file.write_all(header.as_bytes())?;
        Ok(Self {
            file,
            buffer: String::new(),
            rows: 0,
        })
    }

    /// Formats every item of `items` as one row with `format_row` (which writes the row
    /// without its newline) and writes the batch in one call. Large batches are formatted in
    /// parallel chunks, joined in order (the bytes do not depend on the number of threads).
    pub(crate) fn write_rows<T: Sync>(
        &mut self,
        items: &[T],
        format_row: impl Fn(&mut String, &T) -> Result<()> + Sync,
    ) -> Result<()> {
        let format_chunk = |out: &mut String, chunk: &[T]| -> Result<()> {
            for item in chunk {
                format_row(out, item)?;
                out.push('\n');
            }
            Ok(())
        };
        self.buffer.clear();
        if items.len() < 2 * PARALLEL_CHUNK_ROWS {
            format_chunk(&mut self.buffer, items)?;
        } else {
            let chunks: Vec<String> = items
                .par_chunks(PARALLEL_CHUNK_ROWS)
                .map(|chunk| {
                    let mut out = String::with_capacity(64 * chunk.len());
                    format_chunk(&mut out, chunk).map(|()| out)
                })
                .collect::<Result<_>>()?;
            for chunk in &chunks {
                self.buffer.push_str(chunk);
            }
        }
        self.file.write_all(self.buffer.as_bytes())?;
        self.rows += items.len() as u64;
        Ok(())
    }

    /// Closes the file under its final name.
    pub(crate) fn finish(self) -> Result<WrittenSummary> {
        let rows = self.rows;
        let path = self.file.commit()?;
        Ok(WrittenSummary { rows, path })
    }
}

/// Appends `value` in its shortest exact form (lossless round trip), or nothing for `None`.
pub(crate) fn push_opt(out: &mut String, value: Option<f64>) {
    if let Some(v) = value {
        push_f64(out, v);
    }
}

/// Appends `value` in its shortest exact form, byte for byte what `format!("{value}")` gives
/// (the shortest digits that read back to the same number, never an exponent: `1`, `0.1`,
/// `0.0000001`, `-0`): the digits from `ryu`, faster than the standard library's shortest
/// path, then placed around the decimal point here. Values where two shortest candidates
/// could tie ([`may_tie`]) and non-finite ones take the standard library's path.
pub(crate) fn push_f64(out: &mut String, value: f64) {
    if !value.is_finite() || may_tie(value) {
        // Writing to a String cannot fail.
        let _ = write!(out, "{value}");
        return;
    }
    let mut buffer = ryu::Buffer::new();
    let text = buffer.format_finite(value);
    // Without an exponent, ryu's text is already the plain form (integral values, which it
    // writes "3.0", took the standard library's path above).
    if text.contains('e') {
        push_plain_decimal(out, text);
    } else {
        out.push_str(text);
    }
}

/// Whether two shortest decimal candidates could lie exactly as close to finite `value`: only
/// when its exact decimal expansion has at most 18 significant digits (zero, integers, and
/// fractions of few binary digits such as 2.25 or 264310078315752.625). `ryu` and the
/// standard library break such ties differently (…752.62 against …752.63). Positions and
/// velocities, with 40-odd exact digits, never do.
fn may_tie(value: f64) -> bool {
    let bits = value.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i64;
    let fraction = bits & ((1 << 52) - 1);
    // value = ±m · 2^e.
    let (mut m, mut e) = if biased == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1 << 52), biased - 1075)
    };
    if m == 0 {
        return true;
    }
    let zeros = m.trailing_zeros();
    m >>= zeros;
    e += i64::from(zeros);
    if e >= 0 {
        return true;
    }
    // m odd and k = −e: the expansion is m·5^k / 10^k, whose significant digits are those of
    // m·5^k, at least ⌊log₁₀ m⌋ + ⌊k log₁₀ 5⌋ + 1 (log₁₀ 5 rounded down).
    let k = e.unsigned_abs();
    u64::from(m.ilog10()) + k * 69_897 / 100_000 < 18
}

/// Appends the number `text` (ryu's form: `-`, digits with at most one `.`, then perhaps `e`
/// and a signed exponent) in plain decimal notation without redundant zeros.
fn push_plain_decimal(out: &mut String, text: &str) {
    let (negative, text) = match text.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, text),
    };
    let (mantissa, exponent) = match text.split_once('e') {
        Some((m, e)) => (m, e.parse::<i32>().unwrap_or(0)),
        None => (text, 0),
    };
    let (whole, fraction) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    // The significant digits and where the point goes among them.
    let mut digits = [0u8; 32];
    let mut len = 0;
    for &d in whole.as_bytes().iter().chain(fraction.as_bytes()) {
        digits[len] = d;
        len += 1;
    }
    let mut point = whole.len() as i32 + exponent;
    let leading = digits[..len].iter().take_while(|&&d| d == b'0').count();
    let digits = &digits[leading..len];
    point -= leading as i32;
    let significant = digits.len() - digits.iter().rev().take_while(|&&d| d == b'0').count();
    let digits = &digits[..significant];
    if negative {
        out.push('-');
    }
    if digits.is_empty() {
        out.push('0');
        return;
    }
    if point <= 0 {
        out.push_str("0.");
        out.extend(std::iter::repeat_n('0', point.unsigned_abs() as usize));
        out.extend(digits.iter().map(|&d| char::from(d)));
    } else if point as usize >= digits.len() {
        out.extend(digits.iter().map(|&d| char::from(d)));
        out.extend(std::iter::repeat_n('0', point as usize - digits.len()));
    } else {
        let (before, after) = digits.split_at(point as usize);
        out.extend(before.iter().map(|&d| char::from(d)));
        out.push('.');
        out.extend(after.iter().map(|&d| char::from(d)));
    }
}

/// Rows formatted per parallel task when a batch is large.
const PARALLEL_CHUNK_ROWS: usize = 4096;

/// Appends `value` with `decimals` digits after the point, byte for byte what
/// `format!("{value:.decimals$}")` (and C's `%.Nf`) gives, through a scaled integer: the
/// standard library's exact-precision path is some 10× slower. Values within rounding error
/// of a tie, beyond 2⁴⁰ once scaled, or not finite take the standard library's path.
pub(crate) fn push_fixed(out: &mut String, value: f64, decimals: usize) {
    const POW10: [f64; 10] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9];
    // |scaled| < 2^40: the product's rounding error (≤ 2^-13) stays below the tie margin.
    const LIMIT: f64 = (1u64 << 40) as f64;
    const TIE_MARGIN: f64 = 2.5e-4;
    if let Some(&scale) = POW10.get(decimals) {
        let scaled = value.abs() * scale;
        if scaled < LIMIT {
            let floor = scaled.floor();
            let fraction = scaled - floor;
            if (fraction - 0.5).abs() > TIE_MARGIN {
                if value.is_sign_negative() {
                    out.push('-');
                }
                push_scaled(out, floor as u64 + u64::from(fraction > 0.5), decimals);
                return;
            }
        }
    }
    // Writing to a String cannot fail.
    let _ = write!(out, "{value:.decimals$}");
}

/// Appends `n / 10^decimals` with exactly `decimals` digits after the point.
fn push_scaled(out: &mut String, mut n: u64, decimals: usize) {
    // "00" to "99": two digits per division.
    const PAIRS: [u8; 200] = {
        let mut table = [0u8; 200];
        let mut i = 0;
        while i < 100 {
            table[2 * i] = b'0' + (i / 10) as u8;
            table[2 * i + 1] = b'0' + (i % 10) as u8;
            i += 1;
        }
        table
    };
    let mut digits = [0u8; 32];
    let mut start = digits.len();
    // The decimals, right to left (two at a time while two remain).
    let mut left = decimals;
    while left >= 2 {
        let pair = (n % 100) as usize * 2;
        n /= 100;
        start -= 2;
        digits[start..start + 2].copy_from_slice(&PAIRS[pair..pair + 2]);
        left -= 2;
    }
    if left == 1 {
        start -= 1;
        digits[start] = b'0' + (n % 10) as u8;
        n /= 10;
    }
    if decimals > 0 {
        start -= 1;
        digits[start] = b'.';
    }
    // The integer part, at least one digit.
    loop {
        start -= 1;
        digits[start] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    out.push_str(std::str::from_utf8(&digits[start..]).expect("ASCII digits"));
}

/// A CSV file with a header row, read with every column looked up by name.
///
/// Rows are streamed from the file (memory does not grow with its length); an error's line
/// is found by scanning the file again up to the row (the `csv` crate's own line count
/// skips blank lines).
pub(crate) struct CsvTable {
    path: PathBuf,
    /// For each wanted column, its index in the file (None: optional and absent).
    indices: Vec<Option<usize>>,
    names: Vec<&'static str>,
}

/// One data row of a [`CsvTable`].
pub(crate) struct CsvRow<'a> {
    table: &'a CsvTable,
    record: &'a csv::StringRecord,
}

/// A reader that skips `#` comment lines. Fields are trimmed where they are read
/// ([`CsvRow::text`]): the reader's own trimming rebuilds every record.
fn csv_reader<R: Read>(source: R) -> csv::Reader<R> {
    csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_reader(source)
}

impl CsvTable {
    /// Opens `path` and finds the `required` and `optional` columns in its header.
    /// `expected` describes the header for error messages.
    pub(crate) fn open(
        path: &Path,
        required: &[&'static str],
        optional: &[&'static str],
        expected: &str,
    ) -> Result<Self> {
        let mut table = Self {
            path: path.to_path_buf(),
            indices: Vec::new(),
            names: required.iter().chain(optional).copied().collect(),
        };
        let mut reader = csv_reader(table.open_file()?);
        let header = reader.headers().map_err(|e| table.csv_error(&e))?.clone();
        let find = |name: &str| {
            header
                .iter()
                .position(|h| h.trim().eq_ignore_ascii_case(name))
        };
        for &name in required {
            let index = find(name).ok_or_else(|| {
                Error::format(
                    path,
                    Some(1),
                    format!("missing column `{name}`; the header must be `{expected}`"),
                )
            })?;
            table.indices.push(Some(index));
        }
        table.indices.extend(optional.iter().map(|name| find(name)));
        Ok(table)
    }

    /// Whether wanted column `column` is in the file (always, for a required one).
    pub(crate) fn has(&self, column: usize) -> bool {
        self.indices[column].is_some()
    }

    /// Calls `each` on every data row, in order.
    pub(crate) fn for_each_row(
        &self,
        mut each: impl FnMut(&CsvRow<'_>) -> Result<()>,
    ) -> Result<()> {
        let mut reader = csv_reader(self.open_file()?);
        let mut record = csv::StringRecord::new();
        loop {
            match reader.read_record(&mut record) {
                Ok(false) => return Ok(()),
                Ok(true) => each(&CsvRow {
                    table: self,
                    record: &record,
                })?,
                Err(e) => return Err(self.csv_error(&e)),
            }
        }
    }

    fn open_file(&self) -> Result<BufReader<File>> {
        let file = File::open(&self.path).map_err(|e| Error::io(&self.path, e))?;
        Ok(BufReader::with_capacity(1 << 16, file))
    }

    /// The 1-based line of the record the reader started at `byte` (its position includes
    /// the blank and comment lines skipped before the record). Reads the file again up to
    /// the record: only errors need it.
    fn line_at(&self, byte: u64) -> Option<usize> {
        let mut bytes = self.open_file().ok()?.bytes();
        let mut newlines = 0;
        for _ in 0..byte {
            newlines += usize::from(bytes.next()?.ok()? == b'\n');
        }
        // Skip the blank and comment lines the reader skipped.
        let mut in_comment = false;
        for b in bytes {
            match b.ok()? {
                b'\n' => {
                    newlines += 1;
                    in_comment = false;
                }
                b'\r' => {}
                b'#' => in_comment = true,
                _ if in_comment => {}
                _ => break,
            }
        }
        Some(newlines + 1)
    }

    fn csv_error(&self, error: &csv::Error) -> Error {
        let line = error.position().and_then(|p| self.line_at(p.byte()));
        let message = match error.kind() {
            csv::ErrorKind::UnequalLengths {
                expected_len, len, ..
            } => format!(
                "this row has {len} fields but the header has {expected_len}; fix the row so \
                 every row has one value per column"
            ),
            csv::ErrorKind::Utf8 { .. } => "not valid UTF-8 text; save the file as UTF-8".into(),
            _ => format!("cannot read CSV: {error}"),
        };
        Error::format(&self.path, line, message)
    }
}

impl CsvRow<'_> {
    /// An error at this row's line.
    pub(crate) fn error(&self, message: impl Into<String>) -> Error {
        let line = self
            .record
            .position()
            .and_then(|p| self.table.line_at(p.byte()));
        Error::format(&self.table.path, line, message)
    }

    /// Wanted column `column` as text, trimmed; `None` when empty or absent.
    pub(crate) fn text(&self, column: usize) -> Option<&str> {
        self.table.indices[column]
            .and_then(|i| self.record.get(i))
            .map(str::trim)
            .filter(|t| !t.is_empty())
    }

    /// Wanted column `column` as a non-negative integer (also accepts `3.0`).
    pub(crate) fn index(&self, column: usize) -> Result<u64> {
        let name = self.table.names[column];
        let text = self.text(column).ok_or_else(|| {
            self.error(format!("`{name}` is empty; fill it in or remove the row"))
        })?;
        parse_index(text).ok_or_else(|| {
            self.error(format!(
                "`{name}` = `{text}` is not a non-negative integer; fix or remove the row"
            ))
        })
    }

    /// Wanted column `column` as a finite number (positions: NaN or empty is an error).
    pub(crate) fn finite(&self, column: usize) -> Result<f64> {
        let name = self.table.names[column];
        match self.optional(column)? {
            Some(v) if v.is_finite() => Ok(v),
            Some(v) => Err(self.error(format!(
                "`{name}` is {v}; positions must be finite numbers, fix or remove the row"
            ))),
            None => Err(self.error(format!(
                "`{name}` is empty; positions are required, fill it in or remove the row"
            ))),
        }
    }

    /// Wanted column `column` as a number; empty, absent or NaN gives `None`.
    pub(crate) fn optional(&self, column: usize) -> Result<Option<f64>> {
        let Some(text) = self.text(column) else {
            return Ok(None);
        };
        let name = self.table.names[column];
        let value: f64 = text.parse().map_err(|_| {
            self.error(format!(
                "`{name}` = `{text}` is not a number; fix or remove the row"
            ))
        })?;
        Ok(Some(value))
    }
}

/// Parses a frame or track index: an integer, or a float with no fractional part.
pub(crate) fn parse_index(text: &str) -> Option<u64> {
    text.parse::<u64>().ok().or_else(|| {
        let v: f64 = text.parse().ok()?;
        (v >= 0.0 && v.fract() == 0.0 && v < u64::MAX as f64).then_some(v as u64)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A xorshift generator of test values.
    fn xorshift(mut state: u64) -> impl FnMut() -> u64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        }
    }

    #[test]
    fn shortest_digits_are_those_of_the_standard_library() {
        let mut next = xorshift(0x2545_f491_4f6c_dd1d);
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            1e-7,
            1.5e-300,
            1e21,
            1e22,
            123_456.789,
            // A tie: −264310078315752.625 exactly.
            -(264_310_078_315_752.0 + 0.625),
            2.25,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for _ in 0..200_000 {
            // Any bit pattern (every exponent, subnormals), and positions and velocities.
            values.push(f64::from_bits(next()));
            let magnitude = 10f64.powi((next() % 14) as i32 - 6);
            let unit = (next() >> 11) as f64 / (1u64 << 53) as f64;
            values.push((unit - 0.5) * magnitude);
            values.push((next() % 4_000_000) as f64 / 1000.0);
        }
        let mut fast = String::new();
        for v in values {
            fast.clear();
            push_f64(&mut fast, v);
            assert_eq!(fast, format!("{v}"), "{v:e}");
        }
    }

    #[test]
    fn fixed_decimals_are_those_of_the_standard_library() {
        let mut next = xorshift(0x9e37_79b9_7f4a_7c15);
        let mut values = vec![
            0.0,
            -0.0,
            0.0625,
            -0.0625,
            0.0005,
            1.0005,
            2.5e-4,
            -2.5e-4,
            0.125,
            2.675,
            1e12,
            -1e12,
            1.5e15,
            123_456.789_5,
            0.999_95,
            9.999_5,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            -1e-300,
        ];
        for _ in 0..200_000 {
            let bits = next();
            // Positions and velocities of every size, and exact ties on binary fractions.
            let magnitude = 10f64.powi((bits % 14) as i32 - 6);
            let unit = (next() >> 11) as f64 / (1u64 << 53) as f64;
            values.push((unit - 0.5) * magnitude);
            values.push(((next() % 200_000) as f64 - 100_000.0) / 1024.0);
        }
        let mut fast = String::new();
        for v in values {
            for decimals in 0..=9 {
                fast.clear();
                push_fixed(&mut fast, v, decimals);
                assert_eq!(
                    fast,
                    format!("{v:.decimals$}"),
                    "{v:e} with {decimals} decimals"
                );
            }
        }
    }
}

//! The text track tables: TracTrac's `_track.txt` and CSV. Both are written by one
//! [`TextTrackWriter`] that formats each accepted batch into a string and writes it whole.

use std::fmt::Write as _;
use std::io::BufRead;
use std::path::Path;

use sillage_core::{Error, MotionState, Point2, Result, TrackPoint, TrackSink};

use super::columns::{
    STATE_COLUMNS, TRACK_COLUMNS, TrackLayout, check_position, class_from_value, kinematics,
    point_from_values,
};
use super::{TrackFileHeader, TrackWriter, WrittenSummary};
use crate::text_table::{CsvTable, RowWriter, parse_index, push_f64, push_fixed, push_opt};

/// The column line of TracTrac's `_track.txt` (its third header line, after `#  `).
pub const TRACTRAC_COLUMNS_LINE: &str =
    "Frame ID x y Vx Vy Ax Ay Vx(prediction) Vy(prediction) Error(prediction)";

/// Decimals of TracTrac's columns x..Error: `%.3f %.3f %.5f %.5f %.4f %.4f %.4f %.4f %.3f`
/// in the order x, y, Vx, Vy, Ax, Ay, Vx(pred), Vy(pred), Error.
const TRACTRAC_DECIMALS: [usize; 9] = [3, 3, 5, 5, 4, 4, 4, 4, 3];

/// Which text layout a [`TextTrackWriter`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum TextStyle {
    /// TracTrac's `_track.txt`.
    Tractrac,
    /// CSV with the columns of the layout.
    Csv(TrackLayout),
}

impl TextStyle {
    fn header(self, header: &TrackFileHeader) -> String {
        match self {
            // numpy.savetxt(header='TracTrac v'+version+' \n Parameters: '+str(th[0])+'\n Frame ID ...',
            // comments='# ') writes exactly these three lines.
            Self::Tractrac => format!(
                "# TracTrac v{} \n#  Parameters: {}\n#  {TRACTRAC_COLUMNS_LINE}\n",
                header.program_version,
                python_dict(&header.parameters)
            ),
            Self::Csv(layout) => format!("{}\n", layout.columns().join(",")),
        }
    }

    fn row(self, out: &mut String, point: &TrackPoint) -> Result<()> {
        check_position(point)?;
        let values = kinematics(point);
        // Writing to a String cannot fail.
        match self {
            Self::Tractrac => {
                let _ = write!(out, "{} {}", point.frame, point.track_id);
                let all = [Some(point.pos_px.x), Some(point.pos_px.y)]
                    .into_iter()
                    .chain(values);
                for (value, decimals) in all.zip(TRACTRAC_DECIMALS) {
                    match value {
                        Some(v) => {
                            out.push(' ');
                            push_fixed(out, v, decimals);
                        }
                        None => out.push_str(" nan"),
                    }
                }
            }
            Self::Csv(layout) => {
                let _ = write!(out, "{},{},", point.frame, point.track_id);
                push_f64(out, point.pos_px.x);
                out.push(',');
                push_f64(out, point.pos_px.y);
                for value in values {
                    out.push(',');
                    push_opt(out, value);
                }
                if layout == TrackLayout::WithStates {
                    let _ = write!(out, ",{},{},", point.class, point.motion_state.name());
                    push_opt(out, point.spread_px.filter(|s| s.is_finite()));
                }
            }
        }
        Ok(())
    }
}

/// `params` as Python prints a dict: `{'key': value, ...}`, numbers bare, other text quoted.
fn python_dict(params: &[(String, String)]) -> String {
    let items: Vec<String> = params
        .iter()
        .map(|(key, value)| {
            if value.parse::<f64>().is_ok() {
                format!("'{key}': {value}")
            } else {
                format!("'{key}': '{value}'")
            }
        })
        .collect();
    format!("{{{}}}", items.join(", "))
}

/// Writes TracTrac or CSV track tables, one whole batch per write.
#[derive(Debug)]
pub(crate) struct TextTrackWriter {
    rows: RowWriter,
    style: TextStyle,
}

impl TextTrackWriter {
    /// Creates `.NAME.partial` beside `path` and writes the header.
    pub(crate) fn create(path: &Path, style: TextStyle, header: &TrackFileHeader) -> Result<Self> {
        Ok(Self {
            rows: RowWriter::create(path, &style.header(header))?,
            style,
        })
    }
}

impl TrackSink for TextTrackWriter {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        let style = self.style;
        self.rows.write_rows(points, |out, p| style.row(out, p))
    }
}

impl TrackWriter for TextTrackWriter {
    fn finish(self: Box<Self>) -> Result<WrittenSummary> {
        self.rows.finish()
    }
}

/// Reads TracTrac's `_track.txt`: `#` lines skipped, 11 space-separated columns, `nan` for
/// unknown kinematics.
pub(crate) fn read_tractrac(
    path: &Path,
    each: &mut dyn FnMut(TrackPoint) -> Result<()>,
) -> Result<TrackLayout> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    for (i, line) in std::io::BufReader::new(file).lines().enumerate() {
        let line_no = i + 1;
        let line = line.map_err(|e| {
            Error::format(path, Some(line_no), format!("cannot read the line: {e}"))
        })?;
        let text = line.trim();
        if text.is_empty() || text.starts_with('#') {
            continue;
        }
        each(parse_tractrac_row(text).map_err(|message| {
            Error::format(
                path,
                Some(line_no),
                format!("{message}; a row is `{TRACTRAC_COLUMNS_LINE}` (11 numbers)"),
            )
        })?)?;
    }
    Ok(TrackLayout::Kinematics)
}

fn parse_tractrac_row(text: &str) -> std::result::Result<TrackPoint, String> {
    let fields: Vec<&str> = text.split_whitespace().collect();
    if fields.len() != 11 {
        return Err(format!("found {} columns instead of 11", fields.len()));
    }
    let index = |i: usize, name: &str| {
        parse_index(fields[i])
            .ok_or_else(|| format!("{name} `{}` is not a non-negative integer", fields[i]))
    };
    let frame = index(0, "Frame")?;
    let id = index(1, "ID")?;
    let mut numbers = [0.0; 9];
    for (k, number) in numbers.iter_mut().enumerate() {
        let field = fields[k + 2];
        *number = field
            .parse()
            .map_err(|_| format!("column {} `{field}` is not a number", k + 3))?;
    }
    let pos = Point2::new(numbers[0], numbers[1]);
    if !pos.is_finite() {
        return Err(format!(
            "position ({}, {}) is not finite; x and y are required",
            fields[2], fields[3]
        ));
    }
    let mut rest = [None; 7];
    for (slot, &v) in rest.iter_mut().zip(&numbers[2..]) {
        *slot = Some(v);
    }
    Ok(point_from_values(frame, id, pos, rest))
}

/// Reads a CSV track table (columns found by name; the kinematic and state ones are
/// optional, so a trackpy `frame,particle,x,y` table is read too). The layout is
/// [`TrackLayout::WithStates`] when the table has a `motion_state` column.
pub(crate) fn read_csv(
    path: &Path,
    each: &mut dyn FnMut(TrackPoint) -> Result<()>,
) -> Result<TrackLayout> {
    let [frame, particle, x, y, kinematic @ ..] = TRACK_COLUMNS;
    let optional: Vec<&'static str> = kinematic.iter().chain(&STATE_COLUMNS).copied().collect();
    let table = CsvTable::open(
        path,
        &[frame, particle, x, y],
        &optional,
        &TrackLayout::WithStates.columns().join(","),
    )?;
    let [class, motion_state, spread] = [11, 12, 13];
    table.for_each_row(|row| {
        let pos = Point2::new(row.finite(2)?, row.finite(3)?);
        let mut rest = [None; 7];
        for (k, slot) in rest.iter_mut().enumerate() {
            *slot = row.optional(4 + k)?;
        }
        let mut point = point_from_values(row.index(0)?, row.index(1)?, pos, rest);
        if table.has(class) {
            point.class = class_from_value(row.index(class)?)
                .map_err(|e| row.error(format!("{e}; fix or remove the row")))?;
        }
        if let Some(name) = row.text(motion_state) {
            point.motion_state = MotionState::from_name(name).ok_or_else(|| {
                row.error(format!(
                    "`motion_state` = `{name}`; it is resting, rolling, saltating or unknown"
                ))
            })?;
        }
        point.spread_px = row.optional(spread)?.filter(|s| s.is_finite());
        each(point)
    })?;
    Ok(if table.has(motion_state) {
        TrackLayout::WithStates
    } else {
        TrackLayout::Kinematics
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_core::Vec2;

    #[test]
    fn tractrac_row_uses_numpy_formats_and_nan() {
        let mut point = TrackPoint::at(3, 17, Point2::new(10.12345, -2.5));
        point.vel_px_per_frame = Some(Vec2::new(0.123456, -1.0));
        point.log10_pred_err = Some(-0.4567);
        let mut out = String::new();
        TextStyle::Tractrac.row(&mut out, &point).unwrap();
        assert_eq!(
            out,
            "3 17 10.123 -2.500 0.12346 -1.00000 nan nan nan nan -0.457"
        );
        out.clear();
        TextStyle::Csv(TrackLayout::Kinematics)
            .row(&mut out, &point)
            .unwrap();
        assert_eq!(out, "3,17,10.12345,-2.5,0.123456,-1,,,,,-0.4567");
        out.clear();
        point.class = 1;
        point.motion_state = MotionState::Rolling;
        TextStyle::Csv(TrackLayout::WithStates)
            .row(&mut out, &point)
            .unwrap();
        assert_eq!(out, "3,17,10.12345,-2.5,0.123456,-1,,,,,-0.4567,1,rolling,");
    }

    #[test]
    fn parameters_are_printed_as_a_python_dict() {
        let params = vec![
            ("peak_th".to_string(), "0.02".to_string()),
            ("tracker".to_string(), "ptv".to_string()),
        ];
        assert_eq!(python_dict(&params), "{'peak_th': 0.02, 'tracker': 'ptv'}");
    }
}

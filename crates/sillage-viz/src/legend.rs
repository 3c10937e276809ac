//! Legends: a row of entries (a filled box or a short line in the series' colour, then its
//! label) across a strip above a chart.

use plotters::coord::Shift;
use plotters::prelude::*;
use sillage_core::Result;

use crate::canvas::drawing_error;
use crate::font::FAMILY;

/// How a legend entry shows its colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Mark {
    /// A filled box (bars, categories).
    Box,
    /// A short line (curves).
    Line,
}

/// One legend entry.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LegendEntry<'a> {
    /// Its text.
    pub label: &'a str,
    /// Its colour.
    pub colour: RGBColor,
    /// Box or line.
    pub mark: Mark,
}

/// Draws `entries` left to right from `x0`, centred on the height of `area`.
pub(crate) fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    x0: i32,
    entries: &[LegendEntry<'_>],
) -> Result<()> {
    let font: TextStyle = (FAMILY, 13).into_font().into();
    let mut x = x0;
    let y = (area.dim_in_pixel().1 / 2) as i32;
    for entry in entries {
        match entry.mark {
            Mark::Line => area.draw(&PathElement::new(
                [(x, y), (x + 14, y)],
                entry.colour.stroke_width(2),
            )),
            Mark::Box => area.draw(&Rectangle::new(
                [(x, y - 6), (x + 14, y + 6)],
                entry.colour.filled(),
            )),
        }
        .map_err(drawing_error)?;
        let text = Text::new(entry.label.to_owned(), (x + 18, y - 5), font.clone());
        area.draw(&text).map_err(drawing_error)?;
        let (width, _) = area
            .estimate_text_size(entry.label, &font)
            .map_err(drawing_error)?;
        x += 18 + width as i32 + 16;
    }
    Ok(())
}

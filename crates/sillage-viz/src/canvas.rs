//! The one PNG/SVG dispatch of every chart: a [`Plot`] draws itself onto any plotters
//! backend, and gets pixels ([`Plot::to_rgb`]) and SVG text ([`Plot::to_svg`]) from it.

use plotters::coord::Shift;
use plotters::prelude::*;
use sillage_core::{Error, Result, RgbImage};

use crate::font::ensure_registered;

/// A chart drawn the same way into PNG pixels and into SVG text.
pub trait Plot {
    /// Checks that the data can be drawn; the error says what is wrong.
    fn validate(&self) -> Result<()>;

    /// Draws the chart onto `root`, already filled white, in its whole size.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>;

    /// The chart as a picture of `width × height` pixels.
    fn to_rgb(&self, width: u32, height: u32) -> Result<RgbImage> {
        self.validate()?;
        check_size(width, height)?;
        ensure_registered()?;
        let mut picture = RgbImage::new(width as usize, height as usize);
        let backend =
            BitMapBackend::with_buffer(picture.as_mut_slice().as_flattened_mut(), (width, height));
        present(self, backend.into_drawing_area())?;
        Ok(picture)
    }

    /// The chart as an SVG document of `width × height` units.
    fn to_svg(&self, width: u32, height: u32) -> Result<String> {
        self.validate()?;
        check_size(width, height)?;
        ensure_registered()?;
        let mut svg = String::new();
        present(
            self,
            SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area(),
        )?;
        Ok(svg)
    }
}

/// Fills `root` white, draws `plot` and presents the result.
fn present<P: Plot + ?Sized, DB: DrawingBackend>(
    plot: &P,
    root: DrawingArea<DB, Shift>,
) -> Result<()> {
    root.fill(&WHITE).map_err(drawing_error)?;
    plot.draw(&root)?;
    root.present().map_err(drawing_error)
}

/// Charts need room for their axes: at least 64 × 64.
fn check_size(width: u32, height: u32) -> Result<()> {
    if width < 64 || height < 64 {
        return Err(Error::parameter(
            "size",
            format!("{width}x{height}"),
            "give a picture of at least 64x64 px",
        ));
    }
    Ok(())
}

/// A plotters failure as our error (it only fails on backend errors or a missing font).
pub(crate) fn drawing_error(e: impl std::fmt::Display) -> Error {
    Error::input(format!("drawing failed: {e}"))
}

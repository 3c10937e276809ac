//! The one typeface of every chart and overlay, built in so pictures need no system fonts:
//! DejaVu Sans (Bitstream Vera licence, `assets/DejaVuSans-LICENSE.txt`).

use std::sync::OnceLock;

use sillage_core::{Error, Result};

/// The family name charts and overlays ask plotters for.
pub(crate) const FAMILY: &str = "sans-serif";

static DEJAVU_SANS: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the built-in typeface with plotters, once per process.
pub(crate) fn ensure_registered() -> Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FAMILY, plotters::style::FontStyle::Normal, DEJAVU_SANS)
            .is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(Error::input(
            "the built-in DejaVu Sans typeface could not be read (a corrupt build?)",
        ))
    }
}

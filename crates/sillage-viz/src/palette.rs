//! Colours that stay apart for colour-blind readers (Okabe & Ito, 2008), and the colour of
//! each motion state.

use plotters::style::RGBColor;
use sillage_core::MotionState;

/// Okabe–Ito's eight colours, black last.
const OKABE_ITO: [RGBColor; 8] = [
    RGBColor(0, 114, 178),   // blue
    RGBColor(213, 94, 0),    // vermillion
    RGBColor(0, 158, 115),   // bluish green
    RGBColor(230, 159, 0),   // orange
    RGBColor(204, 121, 167), // reddish purple
    RGBColor(86, 180, 233),  // sky blue
    RGBColor(240, 228, 66),  // yellow
    RGBColor(0, 0, 0),       // black
];

/// The colour of the `i`-th series (cycles through the seven non-black colours).
pub(crate) fn series_colour(i: usize) -> RGBColor {
    OKABE_ITO[i % 7]
}

/// The colour of a motion state on overlays: resting blue, rolling orange, saltating
/// vermillion, unknown grey.
pub(crate) fn state_colour(state: MotionState) -> RGBColor {
    match state {
        MotionState::Resting => OKABE_ITO[0],
        MotionState::Rolling => OKABE_ITO[3],
        MotionState::Saltating => OKABE_ITO[1],
        MotionState::Unknown => RGBColor(160, 160, 160),
    }
}

/// The RGB triple a motion state is drawn in on overlays (for legends and checks).
pub fn state_rgb(state: MotionState) -> [u8; 3] {
    let c = state_colour(state);
    [c.0, c.1, c.2]
}

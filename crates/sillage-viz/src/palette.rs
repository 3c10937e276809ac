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

/// The colour of a pedestrian motion model on overlays, as the IMM-PF paper draws them:
/// `CP` (constant position) red, `CV` (constant velocity) green, `CA` (constant
/// acceleration) blue, and `MP` (the learned motion prior) magenta; any other name takes the
/// Okabe–Ito colour of its `position` in the list of models.
pub fn model_rgb(name: &str, position: usize) -> [u8; 3] {
    match name.to_ascii_uppercase().as_str() {
        "CP" => [230, 25, 25],
        "CV" => [20, 200, 40],
        "CA" => [30, 90, 255],
        "MP" => [235, 0, 235],
        _ => {
            let c = series_colour(position);
            [c.0, c.1, c.2]
        }
    }
}

/// Viridis (matplotlib's perceptually uniform colormap) sampled at nine evenly spaced
/// points, dark blue to yellow.
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// The viridis colour of `t` in [0, 1] (clamped; NaN reads 0), linearly interpolated
/// between the nine samples: for values on a scale (speeds, densities), readable in grey
/// and by colour-blind readers.
pub fn viridis_rgb(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let position = t * (VIRIDIS.len() - 1) as f64;
    let below = (position.floor() as usize).min(VIRIDIS.len() - 2);
    let fraction = position - below as f64;
    let (a, b) = (VIRIDIS[below], VIRIDIS[below + 1]);
    std::array::from_fn(|k| {
        (f64::from(a[k]) + (f64::from(b[k]) - f64::from(a[k])) * fraction).round() as u8
    })
}

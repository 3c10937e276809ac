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

/// The colour of track `track_id` when tracks are coloured by identity: hues a golden angle
/// apart (so consecutive ids differ most), strong and mid-bright enough to show on black and
/// on white.
pub fn id_rgb(track_id: u64) -> [u8; 3] {
    const GOLDEN: f64 = 0.618_033_988_749_895;
    // Wrapping the id keeps the product exact for any u64.
    let hue = ((track_id % 1_000_003) as f64 * GOLDEN).fract() * 6.0;
    let (saturation, value) = (0.8, 0.9);
    let sector = hue.floor();
    let f = hue - sector;
    let (p, q, t) = (
        value * (1.0 - saturation),
        value * (1.0 - saturation * f),
        value * (1.0 - saturation * (1.0 - f)),
    );
    let (r, g, b) = match sector as u8 {
        0 => (value, t, p),
        1 => (q, value, p),
        2 => (p, value, t),
        3 => (p, q, value),
        4 => (t, p, value),
        _ => (value, p, q),
    };
    [r, g, b].map(|c| (c * 255.0).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neighbouring_ids_take_distinct_hues() {
        let colours: Vec<[u8; 3]> = (0..8).map(id_rgb).collect();
        for (i, a) in colours.iter().enumerate() {
            for b in &colours[i + 1..] {
                let distance: i32 = a
                    .iter()
                    .zip(b)
                    .map(|(&x, &y)| (i32::from(x) - i32::from(y)).abs())
                    .sum();
                assert!(distance > 40, "{a:?} vs {b:?}");
            }
        }
        assert_eq!(id_rgb(0), [230, 46, 46]);
        assert_eq!(id_rgb(u64::MAX), id_rgb(u64::MAX));
    }
}

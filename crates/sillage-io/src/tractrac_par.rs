//! TracTrac parameter files (`*_par.txt`): `key value` lines, `#` comments (full-line and
//! trailing) and blank lines. Every key is checked against TracTrac's list (Python keys plus
//! the Matlab ones), so a typo fails with its line instead of being silently ignored.
//!
//! Only the syntax is checked here; ranges are validated where the values are mapped to
//! detector and tracker parameters.

use std::fmt::Write as _;
use std::path::Path;

use sillage_core::{Error, Result};

use crate::partial::PartialFile;

/// Declares the keys once: the struct fields, the key list, and the lookup by key.
macro_rules! tractrac_keys {
    ($( $field:ident = $key:literal : $doc:literal ),* $(,)?) => {
        /// The values of a TracTrac parameter file, one `Option` per key (`None`: not in the
        /// file, so the default applies).
        #[derive(Debug, Clone, Copy, Default, PartialEq)]
        pub struct TractracPar {
            $( #[doc = $doc] pub $field: Option<f64>, )*
        }

        /// Every key a TracTrac parameter file may hold, in TracTrac's order.
        pub const TRACTRAC_KEYS: &[&str] = &[$($key),*];

        /// The comment written after each key by [`write_tractrac_par`].
        const KEY_COMMENTS: &[&str] = &[$($doc),*];

        impl TractracPar {
            /// The slot of `key` (exact spelling), or `None` for an unknown key.
            fn slot_mut(&mut self, key: &str) -> Option<&mut Option<f64>> {
                match key {
                    $( $key => Some(&mut self.$field), )*
                    _ => None,
                }
            }

            /// `(key, value)` for every key, in [`TRACTRAC_KEYS`] order.
            pub fn entries(&self) -> [(&'static str, Option<f64>); TRACTRAC_KEYS.len()] {
                [$( ($key, self.$field) ),*]
            }
        }
    };
}

tractrac_keys! {
    vid_loop = "vid_loop": "Extra back/forward passes to train the motion model (TracTrac CLI default 2).",
    roi_xmin = "ROIxmin": "Region of interest, first column (1-based; default 0 = whole image).",
    roi_ymin = "ROIymin": "Region of interest, first row (1-based).",
    roi_xmax = "ROIxmax": "Region of interest, last column (default: image width).",
    roi_ymax = "ROIymax": "Region of interest, last row (default: image height).",
    bg = "BG": "Background subtraction on (1) or off (0, default).",
    bg_speed = "BGspeed": "Maximum background change per frame, intensity 0-1 (default 0.01).",
    noise = "noise": "Median filter on (1) or off (0, default).",
    noise_size = "noise_size": "Median kernel size, 3 or 5 (default 3).",
    peak_th_auto = "peak_th_auto": "Automatic detection threshold on (1, default) or off (0).",
    peak_th = "peak_th": "Manual detection threshold on the filtered image (default 0.02).",
    peak_neigh = "peak_neigh": "Local-maximum half window: n = 1 + 2 peak_neigh (default 1).",
    peak_conv = "peak_conv": "Blob filter: 0 none, 1 DoG (default), 2 LoG, 3 Shi-Tomasi corners.",
    peak_conv_size = "peak_conv_size": "Blob filter scale in px (default 2).",
    peak_subpix = "peak_subpix": "Sub-pixel fit: 0 quadratic, 1 gaussian (default).",
    peak_minima = "peak_minima": "Track dark objects (1) instead of bright ones (0, default).",
    motion = "motion": "Use the motion model to predict displacements (1, default).",
    motion_av = "motion_av": "Nearest tracklets averaged by the motion model (default 10).",
    motion_it = "motion_it": "Extra motion-model/association iterations (default 0).",
    filter = "filter": "Outlier filter on (1, default) or off (0).",
    filter_std = "filter_std": "Outlier threshold, standard deviations of the log10 error (default 1.5).",
    filter_time = "filter_time": "Memory weight of the motion model and threshold (default 1).",
    plot = "plot": "Live plot (ignored by sillage).",
    plot_image = "plot_image": "Live plot: raw (0), filtered (1) or background (2) image (ignored).",
    plot_data = "plot_data": "Live plot colour: speed (0), model speed (1), model error (2) (ignored).",
    plot_data_type = "plot_data_type": "Live plot: vectors (1) or scatter (2) (ignored).",
    plot_cmin = "plot_cmin": "Live plot colour-scale minimum (ignored).",
    plot_cmax = "plot_cmax": "Live plot colour-scale maximum (ignored).",
    plot_alpha = "plot_alpha": "Live plot transparency, 0-1 (ignored).",
    motion_steady = "motion_steady": "Matlab: steady motion model (1) or not (0).",
    bg_speed_matlab = "BG_speed": "Matlab spelling of the background adaptation speed.",
    fps = "fps": "Matlab post-processing: frames per second.",
    res = "res": "Matlab post-processing: resolution (length per px).",
    bin_x = "binX": "Matlab post-processing: bin width along x (px).",
    bin_y = "binY": "Matlab post-processing: bin width along y (px).",
    rot = "rot": "Matlab post-processing: rotation.",
}

/// Reads a TracTrac parameter file. Unknown keys, missing or non-numeric values, extra
/// words and keys given twice are errors naming the line.
pub fn read_tractrac_par(path: impl AsRef<Path>) -> Result<TractracPar> {
    let path = path.as_ref();
    let text = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse_tractrac_par(path, &String::from_utf8_lossy(&text))
}

/// Parses the text of a parameter file; `path` only names the file in errors.
pub fn parse_tractrac_par(path: &Path, text: &str) -> Result<TractracPar> {
    let mut par = TractracPar::default();
    let mut seen_on: Vec<(&str, usize)> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        let mut words = content.split_whitespace();
        let Some(key) = words.next() else { continue };
        let error = |message: String| Error::format(path, Some(line), message);
        let slot = par.slot_mut(key).ok_or_else(|| {
            error(format!(
                "unknown key `{key}`; known keys are {}",
                TRACTRAC_KEYS.join(", ")
            ))
        })?;
        let value = words
            .next()
            .ok_or_else(|| error(format!("`{key}` has no value; write `{key} VALUE`")))?;
        if let Some(extra) = words.next() {
            return Err(error(format!(
                "`{key}` is followed by `{value} {extra}`; write one value, and start comments with #"
            )));
        }
        let number: f64 = value
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| error(format!("`{key}` = `{value}` is not a finite number")))?;
        if let Some((_, first)) = seen_on.iter().find(|(k, _)| *k == key) {
            return Err(error(format!(
                "`{key}` is already set on line {first}; keep one of the two lines"
            )));
        }
        *slot = Some(number);
        seen_on.push((key, line));
    }
    Ok(par)
}

/// Writes `par` as a TracTrac parameter file (the keys that are set, in TracTrac's order,
/// each with a comment), readable by TracTrac and by [`read_tractrac_par`].
pub fn write_tractrac_par(path: impl AsRef<Path>, par: &TractracPar) -> Result<()> {
    let mut text = String::from("# TracTrac parameter file written by sillage\n");
    for ((key, value), comment) in par.entries().iter().zip(KEY_COMMENTS) {
        if let Some(value) = value {
            // Writing to a String cannot fail.
            let _ = writeln!(text, "{key} {value} \t\t# {comment}");
        }
    }
    let mut file = PartialFile::create(path.as_ref())?;
    file.write_all(text.as_bytes())?;
    file.commit().map(drop)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_of_the_reference_table_is_known() {
        assert_eq!(TRACTRAC_KEYS.len(), 36);
        let mut par = TractracPar::default();
        for key in TRACTRAC_KEYS {
            assert!(par.slot_mut(key).is_some(), "{key}");
        }
    }

    #[test]
    fn duplicate_key_names_both_lines() {
        let err = parse_tractrac_par(Path::new("a_par.txt"), "peak_th 1\n\npeak_th 2\n")
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("a_par.txt:3:"), "{err}");
        assert!(err.contains("line 1"), "{err}");
    }
}

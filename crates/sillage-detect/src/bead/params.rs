//! Parameters of the bead detector, in physical units where the MMPF+ paper gives them, with
//! the paper's values (§3.3.1, §5.3) and, where it gives none, those of BeadTracking, its
//! authors' code (`RunDetection.m`, `SetDetectionParameters.m`).

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result};
use sillage_image::{MAX_ELEMENT_RADIUS_PX, MAX_TEMPLATE_RADIUS_PX};

/// Settings of [`crate::bead::BeadDetector`]. Grey levels are in `[0, 1]` (8-bit / 255).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BeadParams {
    /// Image scale, m/px (`mByPx` of the sequence file). Default 2.056e-4, the paper's flume.
    pub m_per_px: f64,
    /// Diameter of the black beads, m (`diamBlackBead`). Default 0.006 (§2).
    pub black_diameter_m: f64,
    /// Diameter of the transparent beads, m (`diamTransBead`). Default 0.004 (§2).
    pub transparent_diameter_m: f64,
    /// Inner diameter of the built-in ring template over its outer one
    /// (`rateDiamTransBeadInside`). Default 0.6: a ring from 6 to 10 px in the paper's flume.
    pub ring_inner_ratio: f64,
    /// τ_b, the grey level at or below which a pixel is black (§3.3.1), in `(0, 1)`.
    /// Default 25/255, BeadTracking's floor for its automatic threshold (which gives 25 on the
    /// paper's frames).
    pub black_threshold: f64,
    /// Radius of the disk the black mask is eroded by, over the black bead radius (rounded
    /// up), in `(0, 1)`: it separates touching beads. Default 0.5 (BeadTracking: ⌈r_b/2⌉).
    pub black_erosion_ratio: f64,
    /// Smallest area of an eroded black component, over `π(r_e + 1)²` (`r_e` the erosion
    /// radius), in `[0, max)`. Default 0: BeadTracking has no lower bound, and beads cut by
    /// the frame's edge are small (23 px² on the shared frames, where whole ones are ~106).
    pub black_min_area_ratio: f64,
    /// Largest area of an eroded black component, over `π(r_e + 1)²`: larger ones are merged
    /// beads or dark structures (§3.3.1, "an area close to the mean bead area"). Default 1,
    /// BeadTracking's bound (254 px² in the paper's flume).
    pub black_max_area_ratio: f64,
    /// Radius of the disk around each black centre replaced by the background, over the black
    /// bead radius. Default 1 (BeadTracking: a disk of radius r_b).
    pub erase_radius_ratio: f64,
    /// Radius of the closing disk that estimates the background, over the black bead radius,
    /// rounded down; must exceed 1 (§3.3.1: "just greater than bead radius"). Default 1.5
    /// (BeadTracking: ⌊1.5·r_b⌋ = 22 px).
    pub background_radius_ratio: f64,
    /// h of the h-concave transform of the black top-hat (§3.3.1's "hconvex"), grey levels in
    /// `(0, 1]`. Default 44/255 (BeadTracking's `transBeadDetectHMax`).
    pub h_concave_height: f64,
    /// Passes of the 3×3 mean filter over the correlation map before the maxima, `0..=10`.
    /// Default 2 (BeadTracking's `transBeadDetectNbFilt`; without it the map's maxima are
    /// mostly noise: 33 % precision at τ_t = 0.20 on the shared frames, 85 % with).
    pub smoothing_passes: usize,
    /// τ_t, the correlation a maximum needs to be a transparent bead (§3.3.1), in `(−1, 1)`.
    /// Default 0.25, the paper's value for its experimental sequence (§5.3; BeadTracking's
    /// default is 0.23).
    pub transparent_threshold: f64,
    /// The "very low threshold" down to which correlation maxima are kept as the
    /// detector-confidence candidates of Eq. (1) (§3.3.2), at most τ_t. Default 0.20
    /// (BeadTracking's `threshTransBeadDetectConf`).
    pub candidate_threshold: f64,
    /// Maxima on a pixel of the input frame at or below this many times τ_b are dropped (a
    /// transparent bead is never that dark; remnants of black beads are). `None` keeps them,
    /// as the paper; default `Some(2.0)`, BeadTracking's rule, which raises the precision at
    /// τ_t = 0.25 from 94.3 % to 99.0 % on the shared frames (recall unchanged).
    pub dark_rejection_ratio: Option<f64>,
}

impl Default for BeadParams {
    fn default() -> Self {
        Self {
            m_per_px: 2.056e-4,
            black_diameter_m: 0.006,
            transparent_diameter_m: 0.004,
            ring_inner_ratio: 0.6,
            black_threshold: 25.0 / 255.0,
            black_erosion_ratio: 0.5,
            black_min_area_ratio: 0.0,
            black_max_area_ratio: 1.0,
            erase_radius_ratio: 1.0,
            background_radius_ratio: 1.5,
            h_concave_height: 44.0 / 255.0,
            smoothing_passes: 2,
            transparent_threshold: 0.25,
            candidate_threshold: 0.20,
            dark_rejection_ratio: Some(2.0),
        }
    }
}

/// The sizes in pixels the parameters give, rounded as BeadTracking rounds them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BeadGeometry {
    /// Black bead radius `round(round(d_b / m_per_px) / 2)`, px (15 in the paper's flume).
    pub black_radius_px: usize,
    /// Transparent bead radius, the ring's outer radius, px (10).
    pub transparent_radius_px: usize,
    /// The ring's inner radius `round(round(d_t / m_per_px)·ratio / 2)`, px (6).
    pub ring_inner_radius_px: usize,
    /// Erosion disk radius of the black mask, px (8).
    pub erosion_radius_px: usize,
    /// Disk radius erased around each black centre, px (15).
    pub erase_radius_px: usize,
    /// Closing disk radius of the background, px (22).
    pub background_radius_px: usize,
}

/// Largest value of `smoothing_passes`.
const MAX_SMOOTHING_PASSES: usize = 10;

impl BeadParams {
    /// Checks every value, then the pixel sizes they give; the error names the key and its
    /// allowed range.
    pub fn validate(&self) -> Result<()> {
        self.geometry().map(|_| ())
    }

    /// The sizes in pixels, after checking every value (see [`BeadParams::validate`]).
    pub fn geometry(&self) -> Result<BeadGeometry> {
        positive(
            "m_per_px",
            self.m_per_px,
            "metres per pixel, `mByPx` of sequence_param.txt",
        )?;
        positive("black_diameter_m", self.black_diameter_m, "metres")?;
        positive(
            "transparent_diameter_m",
            self.transparent_diameter_m,
            "metres",
        )?;
        open_unit("ring_inner_ratio", self.ring_inner_ratio)?;
        open_unit("black_threshold", self.black_threshold)?;
        open_unit("black_erosion_ratio", self.black_erosion_ratio)?;
        if !(self.black_max_area_ratio.is_finite() && self.black_max_area_ratio > 0.0) {
            return Err(Error::parameter(
                "black_max_area_ratio",
                self.black_max_area_ratio,
                "must be a finite number > 0 (times π(r_e + 1)²)",
            ));
        }
        if !(self.black_min_area_ratio >= 0.0
            && self.black_min_area_ratio < self.black_max_area_ratio)
        {
            return Err(Error::parameter(
                "black_min_area_ratio",
                self.black_min_area_ratio,
                format!(
                    "must be in [0, black_max_area_ratio = {})",
                    self.black_max_area_ratio
                ),
            ));
        }
        positive(
            "erase_radius_ratio",
            self.erase_radius_ratio,
            "times the black radius",
        )?;
        if !(self.background_radius_ratio.is_finite() && self.background_radius_ratio > 1.0) {
            return Err(Error::parameter(
                "background_radius_ratio",
                self.background_radius_ratio,
                "must be a finite number > 1: the closing disk must not fit in a black bead",
            ));
        }
        if !(self.h_concave_height > 0.0 && self.h_concave_height <= 1.0) {
            return Err(Error::parameter(
                "h_concave_height",
                self.h_concave_height,
                "must be a grey level in (0, 1]",
            ));
        }
        if self.smoothing_passes > MAX_SMOOTHING_PASSES {
            return Err(Error::parameter(
                "smoothing_passes",
                self.smoothing_passes,
                format!("must be an integer in 0..={MAX_SMOOTHING_PASSES}"),
            ));
        }
        if !(self.transparent_threshold > -1.0 && self.transparent_threshold < 1.0) {
            return Err(Error::parameter(
                "transparent_threshold",
                self.transparent_threshold,
                "must be a correlation in (−1, 1)",
            ));
        }
        if !(self.candidate_threshold > -1.0
            && self.candidate_threshold <= self.transparent_threshold)
        {
            return Err(Error::parameter(
                "candidate_threshold",
                self.candidate_threshold,
                format!(
                    "must be a correlation in (−1, transparent_threshold = {}]",
                    self.transparent_threshold
                ),
            ));
        }
        if let Some(ratio) = self.dark_rejection_ratio
            && !(ratio.is_finite() && ratio >= 0.0)
        {
            return Err(Error::parameter(
                "dark_rejection_ratio",
                ratio,
                "must be a finite number ≥ 0 (times black_threshold), or absent",
            ));
        }
        self.pixel_sizes()
    }

    /// The pixel sizes of values already checked one by one; errors when a size is out of the
    /// range the image primitives accept.
    fn pixel_sizes(&self) -> Result<BeadGeometry> {
        let diameter_px = |d: f64| (d / self.m_per_px).round();
        let black = (diameter_px(self.black_diameter_m) / 2.0).round();
        let transparent = (diameter_px(self.transparent_diameter_m) / 2.0).round();
        let inner =
            (diameter_px(self.transparent_diameter_m) * self.ring_inner_ratio / 2.0).round();
        let max_black = (MAX_ELEMENT_RADIUS_PX as f64 / self.background_radius_ratio).floor();
        if !(3.0..=max_black).contains(&black) {
            return Err(Error::parameter(
                "black_diameter_m",
                self.black_diameter_m,
                format!(
                    "gives a black bead radius of {black} px at m_per_px = {}; it must be in \
                     3..={max_black} px (check the units: metres and metres per pixel)",
                    self.m_per_px
                ),
            ));
        }
        if !(2.0..=MAX_TEMPLATE_RADIUS_PX as f64).contains(&transparent) {
            return Err(Error::parameter(
                "transparent_diameter_m",
                self.transparent_diameter_m,
                format!(
                    "gives a transparent bead radius of {transparent} px at m_per_px = {}; it \
                     must be in 2..={MAX_TEMPLATE_RADIUS_PX} px",
                    self.m_per_px
                ),
            ));
        }
        if !(inner >= 1.0 && inner < transparent) {
            return Err(Error::parameter(
                "ring_inner_ratio",
                self.ring_inner_ratio,
                format!(
                    "gives a ring from {inner} to {transparent} px; the inner radius must be \
                     at least 1 px and below the outer one"
                ),
            ));
        }
        let scaled =
            |ratio: f64, rounding: fn(f64) -> f64| (rounding(ratio * black) as usize).max(1);
        let erase = scaled(self.erase_radius_ratio, f64::round);
        if erase > MAX_ELEMENT_RADIUS_PX {
            return Err(Error::parameter(
                "erase_radius_ratio",
                self.erase_radius_ratio,
                format!("gives an erased disk over {MAX_ELEMENT_RADIUS_PX} px"),
            ));
        }
        Ok(BeadGeometry {
            black_radius_px: black as usize,
            transparent_radius_px: transparent as usize,
            ring_inner_radius_px: inner as usize,
            erosion_radius_px: scaled(self.black_erosion_ratio, f64::ceil),
            erase_radius_px: erase,
            background_radius_px: scaled(self.background_radius_ratio, f64::floor),
        })
    }
}

/// Errors unless `value` is finite and > 0.
fn positive(key: &str, value: f64, unit: &str) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::parameter(
            key,
            value,
            format!("must be a finite number > 0 ({unit})"),
        ))
    }
}

/// Errors unless `value` is in `(0, 1)`.
fn open_unit(key: &str, value: f64) -> Result<()> {
    if value > 0.0 && value < 1.0 {
        Ok(())
    } else {
        Err(Error::parameter(key, value, "must be a number in (0, 1)"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_give_beadtracking_sizes() {
        let g = BeadParams::default().geometry().unwrap();
        assert_eq!(
            g,
            BeadGeometry {
                black_radius_px: 15,
                transparent_radius_px: 10,
                ring_inner_radius_px: 6,
                erosion_radius_px: 8,
                erase_radius_px: 15,
                background_radius_px: 22,
            }
        );
    }

    #[test]
    fn errors_name_the_key() {
        let cases: [(&str, BeadParams); 8] = [
            (
                "m_per_px",
                BeadParams {
                    m_per_px: 0.0,
                    ..Default::default()
                },
            ),
            (
                "black_diameter_m",
                BeadParams {
                    black_diameter_m: 6.0,
                    ..Default::default()
                },
            ),
            (
                "transparent_diameter_m",
                BeadParams {
                    transparent_diameter_m: f64::NAN,
                    ..Default::default()
                },
            ),
            (
                "black_threshold",
                BeadParams {
                    black_threshold: 1.5,
                    ..Default::default()
                },
            ),
            (
                "black_min_area_ratio",
                BeadParams {
                    black_min_area_ratio: 2.0,
                    ..Default::default()
                },
            ),
            (
                "background_radius_ratio",
                BeadParams {
                    background_radius_ratio: 1.0,
                    ..Default::default()
                },
            ),
            (
                "candidate_threshold",
                BeadParams {
                    candidate_threshold: 0.3,
                    ..Default::default()
                },
            ),
            (
                "dark_rejection_ratio",
                BeadParams {
                    dark_rejection_ratio: Some(-1.0),
                    ..Default::default()
                },
            ),
        ];
        for (key, params) in cases {
            let err = params.validate().unwrap_err().to_string();
            assert!(err.contains(&format!("`{key}`")), "{key}: {err}");
        }
    }
}

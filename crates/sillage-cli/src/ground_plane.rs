//! The ground-plane file `sillage fit homography` writes and `sillage track immpf
//! --ground-plane` reads: `[homography]` (image px from ground m), `[pedestrian]` (the adult's
//! box in metres, §4 of the IMM-PF paper) and `[fit]` (where it came from, how well it fits).

use std::path::Path;

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use sillage::core::{Homography, PedestrianSize};
use sillage::toml_config::read_toml_file;
use sillage::track::immpf::BoxSizing;

/// The `[fit]` table: where the homography comes from and how well it fits.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitTable {
    /// The file the point pairs came from.
    pub source: String,
    /// Point pairs used.
    pub pairs: usize,
    /// Root-mean-square reprojection error, px.
    pub rms_reprojection_px: f64,
}

/// The whole file.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundPlaneFile {
    /// Image ↔ ground plane.
    pub homography: Homography,
    /// The adult's box, m (measured from ground-truth boxes; absent for `--points`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pedestrian: Option<PedestrianSize>,
    /// How it was fitted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<FitTable>,
}

impl GroundPlaneFile {
    /// Reads the homography of a ground-plane file.
    pub fn read_homography(path: &Path) -> Result<Homography> {
        let file: Self = read_toml_file(path)?;
        Ok(file.homography)
    }

    /// Reads a ground-plane file and the box sizing it gives: the adult's box at each foot
    /// point; the file must have a `[pedestrian]` table.
    pub fn read_sizing(path: &Path) -> Result<BoxSizing> {
        let file: Self = read_toml_file(path)?;
        let adult = file.pedestrian.with_context(|| {
            format!(
                "{}: no [pedestrian] table; add `[pedestrian]` with `height_m = 1.74` and \
                 `width_m = 0.58` (an adult), or fit the file from ground truth boxes",
                path.display()
            )
        })?;
        adult
            .validate()
            .with_context(|| format!("{}: [pedestrian]", path.display()))?;
        Ok(BoxSizing::Ground {
            homography: file.homography,
            adult,
        })
    }
}

//! The ground-plane file `sillage fit homography` writes and `sillage track immpf
//! --ground-plane` reads: `[homography]` (image px from ground m), `[pedestrian]` (the adult's
//! box in metres, §4 of the IMM-PF paper) and `[fit]` (where it came from, how well it fits).

use std::fmt::Write as _;
use std::path::Path;

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Homography, PedestrianSize, Result};
use sillage_track::immpf::BoxSizing;

use crate::toml_config::read_toml_file;

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
        let adult = file.pedestrian.ok_or_else(|| {
            Error::input(format!(
                "{}: no [pedestrian] table; add `[pedestrian]` with `height_m = 1.74` and \
                 `width_m = 0.58` (an adult), or fit the file from ground truth boxes",
                path.display()
            ))
        })?;
        adult
            .validate()
            .map_err(|e| super::within(format_args!("{}: [pedestrian]", path.display()), e))?;
        Ok(BoxSizing::Ground {
            homography: file.homography,
            adult,
        })
    }

    /// The file as TOML, under a comment naming the program, the fit and, with a
    /// `[pedestrian]` table, how the adult's box was measured.
    pub fn to_toml(&self) -> Result<String> {
        let mut text = String::new();
        let _ = writeln!(
            text,
            "# Image <-> ground-plane homography (image px from ground m), by `sillage fit \
             homography` (sillage {}).",
            env!("CARGO_PKG_VERSION")
        );
        if let Some(fit) = &self.fit {
            let _ = writeln!(
                text,
                "# {} pairs from {}; RMS reprojection error {:.3} px.",
                fit.pairs, fit.source, fit.rms_reprojection_px
            );
        }
        if self.pedestrian.is_some() {
            let _ = writeln!(
                text,
                "# [pedestrian]: medians of bb_height and bb_width / px_per_metre_across(foot \
                 point), the adult box of Madrigal & Hayet §4."
            );
        }
        text.push('\n');
        let table = toml::to_string(self)
            .map_err(|e| Error::input(format!("cannot write the homography as TOML: {e}")))?;
        text.push_str(&table);
        Ok(text)
    }

    /// Writes [`GroundPlaneFile::to_toml`] to `path` (a partial file renamed when complete).
    pub fn write(&self, path: &Path) -> Result<()> {
        sillage_io::write_text(path, &self.to_toml()?).map_err(|e| {
            let what = format!(
                "{}: cannot write the config; check that its folder exists and is writable",
                path.display()
            );
            super::within(what, e)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_core::Point2;

    #[test]
    fn a_written_file_reads_back_with_its_sizing() {
        let pairs = [(0.0, 0.0), (100.0, 0.0), (100.0, 100.0), (0.0, 100.0)]
            .map(|(u, v)| (Point2::new(u, v), Point2::new(u / 50.0, v / 50.0)));
        let file = GroundPlaneFile {
            homography: Homography::fit(&pairs).unwrap(),
            pedestrian: Some(PedestrianSize {
                height_m: 1.74,
                width_m: 0.58,
            }),
            fit: Some(FitTable {
                source: "pairs.txt".into(),
                pairs: 4,
                rms_reprojection_px: 0.0,
            }),
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("ground.toml");
        file.write(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.starts_with("# Image <-> ground-plane homography"),
            "{text}"
        );
        assert!(text.contains("# 4 pairs from pairs.txt"), "{text}");
        assert!(matches!(
            GroundPlaneFile::read_sizing(&path).unwrap(),
            BoxSizing::Ground { .. }
        ));
    }
}

//! Black beads (MMPF+ paper §3.3.1, BeadTracking's `DetectBlackBeads`): pixels at or below
//! τ_b, eroded so that touching beads separate, 8-connected components of a plausible area,
//! their centroids.

use sillage_core::{BLACK_BEAD_CLASS, Detection, GrayImage, Image, Result};
use sillage_image::{Component, ComponentLabeller, Morphology, StructuringElement};

/// The black-bead stage with its buffers.
#[derive(Debug, Clone)]
pub(crate) struct BlackStage {
    threshold: f32,
    erosion: StructuringElement,
    area_range: (f64, f64),
    morphology: Morphology,
    dilated: GrayImage,
    mask: Image<bool>,
    labeller: ComponentLabeller,
    components: Vec<Component>,
}

impl BlackStage {
    /// `threshold` τ_b, the erosion disk radius `r_e` and the accepted areas as fractions of
    /// `π(r_e + 1)²`.
    pub(crate) fn new(
        threshold: f64,
        erosion_radius_px: usize,
        area_ratios: (f64, f64),
    ) -> Result<Self> {
        let reference = std::f64::consts::PI * ((erosion_radius_px + 1) as f64).powi(2);
        Ok(Self {
            threshold: threshold as f32,
            erosion: StructuringElement::disk(erosion_radius_px)?,
            area_range: (area_ratios.0 * reference, area_ratios.1 * reference),
            morphology: Morphology::new(),
            dilated: GrayImage::default(),
            mask: Image::default(),
            labeller: ComponentLabeller::new(),
            components: Vec::new(),
        })
    }

    /// Appends to `out` the black beads of `frame` (base pixels already set bright), strength
    /// 1 (Eq. (1): `L(d) = 1` for black beads). The eroded mask `{f ≤ τ_b} ⊖ B` is
    /// `{δ_B(f) ≤ τ_b}`, so one grey dilation does it, pixels outside the frame counting as
    /// dark (MATLAB pads a binary erosion with 1).
    pub(crate) fn detect(&mut self, frame: &GrayImage, out: &mut Vec<Detection>) {
        self.morphology
            .dilate(frame, &self.erosion, &mut self.dilated);
        let (width, height) = frame.dimensions();
        self.mask.reshape(width, height);
        for (m, &v) in self
            .mask
            .as_mut_slice()
            .iter_mut()
            .zip(self.dilated.as_slice())
        {
            *m = v <= self.threshold;
        }
        self.labeller.label(&self.mask, &mut self.components);
        let (min_area, max_area) = self.area_range;
        out.extend(
            self.components
                .iter()
                .filter(|c| (min_area..=max_area).contains(&(c.area as f64)))
                .map(|c| Detection::of_class(c.centroid, 1.0, BLACK_BEAD_CLASS)),
        );
    }
}

//! Black beads (MMPF+ paper §3.3.1, BeadTracking's `DetectBlackBeads`): pixels at or below
//! τ_b, eroded so that touching beads separate, 8-connected components of a plausible area,
//! their centroids.

use sillage_core::{BLACK_BEAD_CLASS, Detection, GrayImage, Image, Result};
use sillage_image::{Component, ComponentLabeller, Morphology, StructuringElement};

/// The black-bead stage with its buffers.
#[derive(Debug, Clone)]
pub(crate) struct BlackStage {
    threshold: f32,
    /// The highest 8-bit level `k` with `k / 255 ≤ τ_b` (in `f32`, as the frames decode).
    threshold_level: u8,
    erosion: StructuringElement,
    area_range: (f64, f64),
    morphology: Morphology,
    dilated: GrayImage,
    dilated_levels: Image<u8>,
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
        let threshold = threshold as f32;
        Ok(Self {
            threshold,
            threshold_level: (0..=u8::MAX)
                .rev()
                .find(|&k| f32::from(k) / 255.0 <= threshold)
                .unwrap_or(0),
            erosion: StructuringElement::disk(erosion_radius_px)?,
            area_range: (area_ratios.0 * reference, area_ratios.1 * reference),
            morphology: Morphology::new(),
            dilated: GrayImage::default(),
            dilated_levels: Image::default(),
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
        threshold_mask(&self.dilated, self.threshold, &mut self.mask);
        self.label(out);
    }

    /// [`BlackStage::detect`] on the 8-bit levels of the frame: the same beads (the dilation
    /// and the threshold commute with decoding).
    pub(crate) fn detect_levels(&mut self, levels: &Image<u8>, out: &mut Vec<Detection>) {
        self.morphology
            .dilate_levels(levels, &self.erosion, &mut self.dilated_levels);
        threshold_mask(&self.dilated_levels, self.threshold_level, &mut self.mask);
        self.label(out);
    }

    /// The components of the mask with a plausible area, as beads.
    fn label(&mut self, out: &mut Vec<Detection>) {
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

/// `mask` (reshaped) `= image ≤ threshold`.
fn threshold_mask<T: Copy + Default + PartialOrd>(
    image: &Image<T>,
    threshold: T,
    mask: &mut Image<bool>,
) {
    mask.reshape(image.width(), image.height());
    for (m, &v) in mask.as_mut_slice().iter_mut().zip(image.as_slice()) {
        *m = v <= threshold;
    }
}

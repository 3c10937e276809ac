//! The bead detectors of the MMPF+ paper (Lafaye de Micheaux, Ducottet & Frey 2018, §3.3):
//! black beads by threshold and connected components, transparent beads by a morphological
//! chain and a ring-template correlation, and the detector-confidence candidates of Eq. (1),
//! on side views of a bedload flume with its fixed base masked out.
//!
//! Per frame:
//! 1. pixels of the base mask are set bright (they are never beads);
//! 2. **black beads** (module `black`): `f ≤ τ_b`, eroded by a disk of radius `⌈r_b/2⌉` so that
//!    touching beads separate, 8-connected components with an area up to `π(⌈r_b/2⌉+1)²`,
//!    their centroids (sub-pixel);
//! 3. **erasing** (the closing runs beside step 2): the background is the closing of the
//!    frame by a disk of radius `⌊1.5·r_b⌋`; the black top-hat `closing − f` is set to 0 on
//!    the base and on a disk of radius `r_b` around each black bead (the frame replaced by
//!    its background there);
//! 4. **transparent beads** (module `transparent`): h-concave transform of the top-hat (basins
//!    filled up to h), normalised cross-correlation with the ring template, two 3×3 means,
//!    local maxima; maxima on pixels darker than `2·τ_b` are dropped; those with a
//!    correlation `≥ τ_t` are transparent beads (integer positions, as the authors' code),
//!    those above the candidate threshold (0.20) are the candidates `D` of Eq. (1), each
//!    with its correlation as `L(d)`.
//!
//! Sizes follow BeadTracking, the authors' code: its disks (MATLAB's `strel('disk', r, 8)`,
//! see [`sillage_image::StructuringElement::disk`]), its h = 44/255, its smoothing and its
//! rejection of dark maxima, none of which the paper gives; where the paper gives a value it
//! is the default (τ_t = 0.25 rather than the code's 0.23). `docs/bedload.md` lists the
//! differences and the measured recall and precision.
//!
//! ```
//! use sillage_core::GrayImage;
//! use sillage_detect::{BeadDetections, BeadDetector, BeadParams};
//!
//! // A backlit frame (0.85) with a black bead (r = 14 px) at (50, 60) and a transparent one
//! // (a dark ring from 6 to 10 px around a bright centre) at (130, 60).
//! let (w, h) = (200, 120);
//! let data = (0..w * h)
//!     .map(|i| {
//!         let (x, y) = ((i % w) as f64, (i / w) as f64);
//!         let (black, ring) = ((x - 50.0).hypot(y - 60.0), (x - 130.0).hypot(y - 60.0));
//!         if black <= 14.0 { 0.05 } else if ring > 6.0 && ring <= 10.0 { 0.45 } else { 0.85 }
//!     })
//!     .collect();
//! let frame = GrayImage::from_vec(w, h, data)?;
//! let mut detector = BeadDetector::new(BeadParams::default())?;
//! let mut beads = BeadDetections::default();
//! detector.detect_beads(&frame, &mut beads)?;
//! assert_eq!((beads.black.len(), beads.transparent.len()), (1, 1));
//! assert!((beads.black[0].pos_px.x - 50.0).abs() < 0.5);
//! assert_eq!((beads.transparent[0].pos_px.x, beads.transparent[0].pos_px.y), (130.0, 60.0));
//! # Ok::<(), sillage_core::Error>(())
//! ```

mod black;
mod params;
mod transparent;

use sillage_core::{Detection, Detector, Error, GrayImage, Image, Result};
use sillage_image::{RingTemplate, encode_levels};

pub use params::{BeadGeometry, BeadParams};

use black::BlackStage;
use transparent::{TransparentOutput, TransparentSettings, TransparentStage};

/// Everything the bead detector finds in one frame.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BeadDetections {
    /// Black bead centres (sub-pixel centroids), strength 1 (Eq. (1): `L(d) = 1`).
    pub black: Vec<Detection>,
    /// Transparent bead centres (integer maxima), strength = their correlation, `≥ τ_t`.
    pub transparent: Vec<Detection>,
    /// Every correlation maximum above the candidate threshold, the transparent beads
    /// included, strength = its correlation: the set `D` and likelihoods `L(d)` of Eq. (1)
    /// from which a tracker builds the detector-confidence map of transparent beads.
    pub candidates: Vec<Detection>,
}

impl BeadDetections {
    /// Empties the three lists, keeping their allocations.
    pub fn clear(&mut self) {
        self.black.clear();
        self.transparent.clear();
        self.candidates.clear();
    }
}

/// The MMPF+ bead detector: parameters validated once, buffers reused from frame to frame,
/// deterministic (the same output whatever the number of threads).
#[derive(Debug, Clone)]
pub struct BeadDetector {
    params: BeadParams,
    geometry: BeadGeometry,
    base: Option<Image<bool>>,
    bright_base: GrayImage,
    /// h as an 8-bit level, when it is one (`None`: frames take the `f32` path).
    h_level: Option<u8>,
    /// The 8-bit levels of the bright-base frame (the fast path).
    levels: Image<u8>,
    black: BlackStage,
    transparent: TransparentStage,
    beads: BeadDetections,
}

impl BeadDetector {
    /// A detector with validated `params`, no base mask and the ring template built from
    /// them (pixels at `r_in < d ≤ r_out` from the centre: 6 < d ≤ 10 px by default).
    pub fn new(params: BeadParams) -> Result<Self> {
        let geometry = params.geometry()?;
        let template = RingTemplate::annulus(
            geometry.ring_inner_radius_px as f64,
            geometry.transparent_radius_px as f64,
        )?;
        let settings = TransparentSettings {
            background_radius_px: geometry.background_radius_px,
            erase_radius_px: geometry.erase_radius_px,
            h: params.h_concave_height as f32,
            smoothing_passes: params.smoothing_passes,
            detection_threshold: params.transparent_threshold as f32,
            candidate_threshold: params.candidate_threshold as f32,
            dark_level: params
                .dark_rejection_ratio
                .map(|ratio| (ratio * params.black_threshold) as f32),
        };
        Ok(Self {
            black: BlackStage::new(
                params.black_threshold,
                geometry.erosion_radius_px,
                (params.black_min_area_ratio, params.black_max_area_ratio),
            )?,
            transparent: TransparentStage::new(settings, template)?,
            h_level: level_of(settings.h),
            params,
            geometry,
            base: None,
            bright_base: GrayImage::default(),
            levels: Image::default(),
            beads: BeadDetections::default(),
        })
    }

    /// Uses `template` (BeadTracking's `template_transparent_bead_rOut10_rIn6`, or another)
    /// for the transparent beads instead of the built-in ring; errors when it is not a ring
    /// (see [`RingTemplate`] for the check).
    pub fn with_ring_template(mut self, template: &GrayImage) -> Result<Self> {
        self.transparent
            .set_template(RingTemplate::from_image(template)?);
        Ok(self)
    }

    /// Ignores the fixed flume base: pixels of `mask` above 0.5 (white in BeadTracking's
    /// `sequence_base_mask.tif`) are never beads and are erased before the transparent
    /// beads are searched. Frames must then have the mask's size.
    pub fn with_base_mask(mut self, mask: &GrayImage) -> Self {
        let mut base = Image::new(mask.width(), mask.height());
        for (b, &v) in base.as_mut_slice().iter_mut().zip(mask.as_slice()) {
            *b = v > 0.5;
        }
        self.base = Some(base);
        self
    }

    /// The settings.
    pub fn params(&self) -> &BeadParams {
        &self.params
    }

    /// The pixel sizes derived from the settings.
    pub fn geometry(&self) -> BeadGeometry {
        self.geometry
    }

    /// Finds the beads of `frame` into `out` (cleared first). Errors when a base mask is set
    /// and `frame` has another size.
    pub fn detect_beads(&mut self, frame: &GrayImage, out: &mut BeadDetections) -> Result<()> {
        out.clear();
        if let Some(base) = &self.base
            && base.dimensions() != frame.dimensions()
        {
            return Err(Error::input(format!(
                "the frame is {}×{} px but the flume-base mask is {}×{} px; give a base mask \
                 made for this sequence's frames",
                frame.width(),
                frame.height(),
                base.width(),
                base.height()
            )));
        }
        if let Some(h) = self.h_level
            && encode_levels(frame, &mut self.levels)
        {
            // 8-bit frames: every stage on the levels, from this one encoding.
            if let Some(base) = &self.base {
                for (v, &b) in self.levels.as_mut_slice().iter_mut().zip(base.as_slice()) {
                    *v |= u8::from(b).wrapping_neg();
                }
            }
            // The black beads and the background closing are independent: side by side.
            let (black, transparent, levels) =
                (&mut self.black, &mut self.transparent, &self.levels);
            rayon::join(
                || black.detect_levels(levels, &mut out.black),
                || transparent.close_levels(levels),
            );
            self.transparent.detect_levels(
                frame,
                &self.levels,
                h,
                self.base.as_ref(),
                &out.black,
                TransparentOutput {
                    beads: &mut out.transparent,
                    candidates: &mut out.candidates,
                },
            );
            return Ok(());
        }
        match &self.base {
            Some(base) => {
                self.bright_base.reshape(frame.width(), frame.height());
                for ((v, &f), &b) in self
                    .bright_base
                    .as_mut_slice()
                    .iter_mut()
                    .zip(frame.as_slice())
                    .zip(base.as_slice())
                {
                    // Branch-free (a bit select), so that it vectorises.
                    let keep = u32::from(b).wrapping_sub(1);
                    *v = f32::from_bits((f.to_bits() & keep) | (1.0f32.to_bits() & !keep));
                }
            }
            None => self.bright_base.clone_from(frame),
        }
        let (black, transparent, bright_base) =
            (&mut self.black, &mut self.transparent, &self.bright_base);
        rayon::join(
            || black.detect(bright_base, &mut out.black),
            || transparent.close(bright_base),
        );
        self.transparent.detect(
            frame,
            self.base.as_ref(),
            &out.black,
            TransparentOutput {
                beads: &mut out.transparent,
                candidates: &mut out.candidates,
            },
        )
    }
}

/// The 8-bit level `k` with `k / 255 = value` in `f32` (as frames decode), if there is one.
fn level_of(value: f32) -> Option<u8> {
    (0..=u8::MAX).find(|&k| f32::from(k) / 255.0 == value)
}

/// All beads as plain detections, black ones first (strength 1) then transparent ones
/// (strength = correlation), for consumers that need positions only (PTV, detection scores,
/// overlays). The bead category and the confidence candidates, which the MMPF+ tracker
/// needs, are only in [`BeadDetector::detect_beads`]: [`Detection`] has no category.
impl Detector for BeadDetector {
    fn detect(&mut self, image: &GrayImage, out: &mut Vec<Detection>) -> Result<()> {
        let mut beads = std::mem::take(&mut self.beads);
        let result = self.detect_beads(image, &mut beads);
        out.clear();
        out.extend_from_slice(&beads.black);
        out.extend_from_slice(&beads.transparent);
        self.beads = beads;
        result
    }
}

#[cfg(test)]
mod tests {
    use sillage_io::read_image;

    use super::*;

    /// A real 8-bit frame of the shared sequence with its base mask takes the levels path; the
    /// `f32` path (forced) finds the same black beads exactly and the same transparent beads
    /// and candidates, with correlations within the `f32` path's rounding.
    #[test]
    fn levels_path_finds_what_the_f32_path_finds() {
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");
        let frame = read_image(format!(
            "{root}/bedload_beads_lafaye2018/images/BaumerBim10MegaAmont0507Image72040.tif"
        ))
        .unwrap();
        let mask = read_image(format!(
            "{root}/bedload_beads_lafaye2018/sequence_base_mask.tif"
        ))
        .unwrap();
        let params = BeadParams {
            candidate_threshold: 0.1,
            ..BeadParams::default()
        };
        let mut detector = BeadDetector::new(params).unwrap().with_base_mask(&mask);
        assert_eq!(detector.h_level, Some(44));
        let (mut levels, mut general) = (BeadDetections::default(), BeadDetections::default());
        detector.detect_beads(&frame, &mut levels).unwrap();
        detector.h_level = None;
        detector.detect_beads(&frame, &mut general).unwrap();
        assert!(levels.black.len() > 300 && levels.candidates.len() > 400);
        assert_eq!(levels.black, general.black);
        for (fast, slow) in [
            (&levels.transparent, &general.transparent),
            (&levels.candidates, &general.candidates),
        ] {
            assert_eq!(fast.len(), slow.len());
            for (a, b) in fast.iter().zip(slow) {
                assert_eq!(a.pos_px, b.pos_px);
                assert!((a.strength - b.strength).abs() < 1e-4, "{a:?} {b:?}");
            }
        }
    }
}

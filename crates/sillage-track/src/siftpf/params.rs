//! Every parameter of the SIFT-PF tracker. The paper prints only its SIFT thresholds (0.005
//! and 7.5, §3.1.1) and its validation period (10 frames, §2.5); the other defaults were
//! chosen on generated walkers and PETS 2009 S2.L1 (docs/siftpf.md) and are documented as such.

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result};
use sillage_image::SiftParams;

/// How features are chosen on an object: the three configurations of §3.1.1 (Table 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FeatureSelection {
    /// Configuration 1: Lowe's optimal thresholds (contrast 0.04, edge 10) on the whole object,
    /// every keypoint kept.
    WholeObject,
    /// Configuration 2: sub-regions, the permissive detector, the first keypoints each
    /// sub-region detects.
    DetectionOrder,
    /// Configuration 3 (the paper's): sub-regions, the permissive detector, the most robust
    /// keypoints (scale, curvature, contrast) on motion pixels first.
    Reliability,
}

impl FeatureSelection {
    /// Every configuration, in the paper's order.
    pub const ALL: [FeatureSelection; 3] = [
        FeatureSelection::WholeObject,
        FeatureSelection::DetectionOrder,
        FeatureSelection::Reliability,
    ];

    /// The name used on the command line and in tables.
    pub fn label(self) -> &'static str {
        match self {
            FeatureSelection::WholeObject => "whole-object",
            FeatureSelection::DetectionOrder => "detection-order",
            FeatureSelection::Reliability => "reliability",
        }
    }

    /// Parses a [`label`](Self::label).
    pub fn parse(text: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|s| s.label() == text)
            .ok_or_else(|| {
                Error::parameter(
                    "selection",
                    text,
                    "must be whole-object, detection-order or reliability",
                )
            })
    }
}

/// The per-feature particle filter of §2.2.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FeatureFilterParams {
    /// Particles per feature (a constant number, §2.2.2; the paper gives none); default 15
    /// (30 tracked PETS 2009 and the generated walkers no better at twice the time,
    /// docs/siftpf.md).
    pub particles: usize,
    /// σ of the position noise `n_(x,y)` of Eq. (3), px; default 1.5.
    pub position_noise_px: f64,
    /// σ of the velocity noise `n_(u,v)` of Eq. (4), px/frame; default 0.7.
    pub velocity_noise_px_per_frame: f64,
    /// σ of Eq. (5) until a feature has 3 descriptor variations to learn it from; default 0.2
    /// (unit-length descriptors: the same corner one frame later lies 0.1-0.3 away, unrelated
    /// descriptors 0.9-1.3).
    pub initial_sigma: f64,
    /// Floor of the learned σ of Eq. (5); default 0.08.
    pub min_sigma: f64,
    /// `c₀` of Eq. (5) for an object whose box is entirely motion pixels; it rises linearly
    /// to 1 as the density of motion pixels falls to 0 (§2.2.1); default 0.3.
    pub min_motion_confidence: f64,
    /// A feature whose descriptor varies by more than `mean + k·std` of its own history is
    /// dropped (§2.2.3); this is k; default 3.
    pub variation_sigmas: f64,
    /// ... or by more than this distance, whatever its history; default 0.6.
    pub max_variation: f64,
}

impl Default for FeatureFilterParams {
    fn default() -> Self {
        Self {
            particles: 15,
            position_noise_px: 1.5,
            velocity_noise_px_per_frame: 0.7,
            initial_sigma: 0.2,
            min_sigma: 0.08,
            min_motion_confidence: 0.3,
            variation_sigmas: 3.0,
            max_variation: 0.6,
        }
    }
}

/// Where features are placed on an object (§2.1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FeaturePlacementParams {
    /// Side of a sub-region, px: a box of `w × h` has `round(w/s) × round(h/s)` (at least one);
    /// default 12.
    pub subregion_px: f64,
    /// Features per sub-region (constant, §2.1; the paper gives no number); default 1 (2
    /// doubled the time for no gain on PETS 2009).
    pub features_per_subregion: usize,
    /// Two features closer than this are one too many: the less reliable is replaced
    /// (§2.3, "filtering out too close features"); default 3 px.
    pub min_spacing_px: f64,
}

impl Default for FeaturePlacementParams {
    fn default() -> Self {
        Self {
            subregion_px: 12.0,
            features_per_subregion: 1,
            min_spacing_px: 3.0,
        }
    }
}

/// Data association (§2.3) and occlusion management (§2.4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AssociationParams {
    /// A link score `s(i, j)` of Eq. (6) below this is no link; default 0.1.
    pub min_link_score: f64,
    /// An object linked to several blobs splits only when each holds at least this share of
    /// its link score; default 0.2.
    pub split_min_share: f64,
    /// An unlinked object whose box lies within this distance of the frame border is lost
    /// (it left), otherwise occluded; px, default 12.
    pub exit_margin_px: f64,
    /// An occluded object is kept this many frames for resumption (§2.4; the paper gives no
    /// value); default 50 (2 s at 25 frames/s: a walker hidden by another for 5 frames stays
    /// inside their merged blob for 25-30 frames before it leaves it).
    pub max_occluded_frames: u32,
    /// Lowe's ratio test when matching an occluded object's features to a candidate's
    /// keypoints; default 0.8.
    pub match_ratio: f64,
    /// Dominant colours per object (§2.4, the MPEG-7 descriptor's k); default 4.
    pub dominant_colours: usize,
    /// Candidate sizes and speeds further than this many σ from an occluded object's learned
    /// Gaussians cannot resume it (§2.4); default 3.
    pub coherence_sigmas: f64,
    /// A candidate resumes an occluded object when `(sift + colour) / 2` reaches this;
    /// default 0.35.
    pub min_resume_score: f64,
}

impl Default for AssociationParams {
    fn default() -> Self {
        Self {
            min_link_score: 0.1,
            split_min_share: 0.2,
            exit_margin_px: 12.0,
            max_occluded_frames: 50,
            match_ratio: 0.8,
            dominant_colours: 4,
            coherence_sigmas: 3.0,
            min_resume_score: 0.35,
        }
    }
}

/// Validation of new objects (§2.5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ValidationParams {
    /// Frames a new object is watched before it becomes an object of interest; default 10
    /// (§2.5: "during 10 frames at least").
    pub frames: u32,
    /// Share of those frames it must be linked to a blob (persistence); default 0.8.
    pub min_presence: f64,
    /// Net displacement over path length at least this (an oscillating blob — foliage, a
    /// flickering light — goes nowhere); default 0.3.
    pub min_straightness: f64,
    /// Net displacement over the period at least this, px (a ghost of the background model
    /// does not move); default 3.
    pub min_displacement_px: f64,
    /// Mean speed over the period at most this, px/frame; default 25.
    pub max_speed_px_per_frame: f64,
}

impl Default for ValidationParams {
    fn default() -> Self {
        Self {
            frames: 10,
            min_presence: 0.8,
            min_straightness: 0.3,
            min_displacement_px: 3.0,
            max_speed_px_per_frame: 25.0,
        }
    }
}

/// Parameters of the SIFT-PF tracker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SiftPfParams {
    /// Which features are tracked; default the paper's configuration 3.
    pub selection: FeatureSelection,
    /// The permissive SIFT detector of configurations 2 and 3 (contrast 0.005, edge 7.5,
    /// §3.1.1), without Lowe's doubling of the first octave: people at surveillance
    /// resolution carry features of σ ≥ 1.6 px, and the doubled octave quadruples the
    /// pyramid for no gain on PETS 2009 (docs/siftpf.md). Configuration 1 uses Lowe's
    /// thresholds with this detector's other values.
    pub sift: SiftParams,
    /// Feature placement (§2.1).
    pub placement: FeaturePlacementParams,
    /// The per-feature particle filter (§2.2).
    pub filter: FeatureFilterParams,
    /// Data association and occlusions (§2.3-2.4).
    pub association: AssociationParams,
    /// Validation of new objects (§2.5).
    pub validation: ValidationParams,
}

impl Default for SiftPfParams {
    fn default() -> Self {
        Self {
            selection: FeatureSelection::Reliability,
            sift: SiftParams {
                upsample: false,
                ..SiftParams::permissive()
            },
            placement: FeaturePlacementParams::default(),
            filter: FeatureFilterParams::default(),
            association: AssociationParams::default(),
            validation: ValidationParams::default(),
        }
    }
}

impl SiftPfParams {
    /// The parameters of one of the paper's configurations, the others default.
    pub fn configuration(selection: FeatureSelection) -> Self {
        Self {
            selection,
            ..Self::default()
        }
    }

    /// The SIFT thresholds the selection uses: Lowe's for configuration 1, `sift` otherwise.
    pub fn detector_params(&self) -> SiftParams {
        match self.selection {
            FeatureSelection::WholeObject => SiftParams {
                contrast_threshold: SiftParams::default().contrast_threshold,
                edge_threshold: SiftParams::default().edge_threshold,
                ..self.sift
            },
            _ => self.sift,
        }
    }

    /// Checks every value; errors name the key and the accepted range.
    pub fn validate(&self) -> Result<()> {
        self.sift.validate().map_err(|e| e.in_section("sift"))?;
        let f = &self.filter;
        let p = &self.placement;
        let a = &self.association;
        let v = &self.validation;
        if f.particles == 0 {
            return Err(Error::parameter("filter.particles", 0, "must be ≥ 1"));
        }
        if p.features_per_subregion == 0 {
            return Err(Error::parameter(
                "placement.features_per_subregion",
                0,
                "must be ≥ 1",
            ));
        }
        if a.dominant_colours == 0 {
            return Err(Error::parameter(
                "association.dominant_colours",
                0,
                "must be ≥ 1",
            ));
        }
        if v.frames == 0 {
            return Err(Error::parameter("validation.frames", 0, "must be ≥ 1"));
        }
        for (key, value) in [
            ("filter.position_noise_px", f.position_noise_px),
            (
                "filter.velocity_noise_px_per_frame",
                f.velocity_noise_px_per_frame,
            ),
            ("placement.min_spacing_px", p.min_spacing_px),
            ("association.exit_margin_px", a.exit_margin_px),
            ("validation.min_displacement_px", v.min_displacement_px),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::parameter(key, value, "must be finite and ≥ 0"));
            }
        }
        for (key, value) in [
            ("filter.initial_sigma", f.initial_sigma),
            ("filter.min_sigma", f.min_sigma),
            ("filter.variation_sigmas", f.variation_sigmas),
            ("filter.max_variation", f.max_variation),
            ("placement.subregion_px", p.subregion_px),
            ("association.coherence_sigmas", a.coherence_sigmas),
            (
                "validation.max_speed_px_per_frame",
                v.max_speed_px_per_frame,
            ),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::parameter(key, value, "must be finite and > 0"));
            }
        }
        for (key, value) in [
            ("filter.min_motion_confidence", f.min_motion_confidence),
            ("association.min_link_score", a.min_link_score),
            ("association.split_min_share", a.split_min_share),
            ("association.match_ratio", a.match_ratio),
            ("association.min_resume_score", a.min_resume_score),
            ("validation.min_presence", v.min_presence),
            ("validation.min_straightness", v.min_straightness),
        ] {
            if !(0.0..=1.0).contains(&value) {
                return Err(Error::parameter(key, value, "must be in [0, 1]"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_validate_and_bad_values_name_their_key() {
        assert!(SiftPfParams::default().validate().is_ok());
        let mut params = SiftPfParams::default();
        params.association.min_link_score = 1.5;
        let err = params.validate().unwrap_err().to_string();
        assert!(err.contains("association.min_link_score"), "{err}");
        let mut params = SiftPfParams::default();
        params.filter.particles = 0;
        assert!(params.validate().is_err());
        assert_eq!(
            FeatureSelection::parse("detection-order").unwrap(),
            FeatureSelection::DetectionOrder
        );
        assert!(FeatureSelection::parse("best").is_err());
    }

    #[test]
    fn configuration_one_uses_lowe_thresholds() {
        let whole = SiftPfParams::configuration(FeatureSelection::WholeObject);
        assert!(whole.detector_params().contrast_threshold > whole.sift.contrast_threshold);
        let paper = SiftPfParams::default();
        assert_eq!(paper.detector_params(), paper.sift);
    }
}

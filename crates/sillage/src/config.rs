//! One configuration for the whole pipeline: a TOML file, `--set key=value` overrides and
//! TracTrac `*_par.txt` files all end up here, and are validated once before any work runs.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result};

use crate::bedload::detector::BeadDetectorConfig;
use crate::toml_config::{parse_toml, read_toml_file, set_key};
use sillage_detect::blob::BlobParams;
use sillage_detect::preprocess::PreprocessParams;
use sillage_track::bedload::BedloadTrackerParams;
use sillage_track::ptv::PtvParams;

/// Everything a run needs besides its input and output paths.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PipelineConfig {
    /// Pre-processing of every frame before detection (median, background subtraction).
    pub preprocess: PreprocessParams,
    /// Mask image multiplied into every frame (TracTrac's `<name>_mask.tif`).
    pub mask: Option<PathBuf>,
    /// Which detector runs, with its parameters.
    pub detector: DetectorConfig,
    /// Which tracker runs, with its parameters.
    pub tracker: TrackerConfig,
    /// Extra passes over the sequence that only train the motion model before the output pass
    /// (TracTrac's `vid_loop`; its CLI default is 2, ours 0 because each pass costs a full
    /// tracking run). Detections are kept in memory while training passes are on.
    pub training_passes: usize,
}

/// The built-in detectors; one variant each (`kind = "blob"` in TOML).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum DetectorConfig {
    /// DoG/LoG blob detection with sub-pixel refinement (TracTrac §3.1.1).
    Blob(BlobParams),
    /// The MMPF+ bead detector: black beads by threshold, transparent beads by ring
    /// correlation, and the detector-confidence candidates of Eq. (1) (MMPF+ §3.3).
    Bead(BeadDetectorConfig),
}

impl Default for DetectorConfig {
    fn default() -> Self {
        DetectorConfig::Blob(BlobParams::default())
    }
}

/// The built-in trackers; one variant each (`kind = "ptv"` in TOML).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum TrackerConfig {
    /// TracTrac-class three-frame PTV with a local-flow predictor (TracTrac §3.1.2-3.1.4).
    Ptv(PtvParams),
    /// The bedload trackers of the MMPF+ paper's Table 1 (MMPF+ and its baselines), over
    /// detections with bead classes and the candidates of Eq. (1).
    Bedload(Box<BedloadTrackerParams>),
}

impl Default for TrackerConfig {
    fn default() -> Self {
        TrackerConfig::Ptv(PtvParams::default())
    }
}

/// Largest number of training passes accepted (each is a full tracking run).
const MAX_TRAINING_PASSES: usize = 20;

/// The optional keys (absent by default, so missing from the TOML output): key, an example
/// value, and what setting it does.
pub const OPTIONAL_KEYS: [(&str, &str, &str); 6] = [
    (
        "mask",
        "\"mask.png\"",
        "image whose black pixels are ignored",
    ),
    ("preprocess.median", "3", "median filter of 3×3 or 5×5 px"),
    (
        "preprocess.background.speed",
        "0.01",
        "subtract a slowly adapting background",
    ),
    (
        "detector.roi",
        "{ x0 = 0, y0 = 0, x1 = 512, y1 = 512 }",
        "region of interest, px",
    ),
    (
        "tracker.ambiguity_ratio",
        "0.3",
        "drop links whose nearest candidate is not clearly nearer than the second",
    ),
    (
        "tracker.max_displacement_px",
        "20",
        "reject links longer than this, px",
    ),
];

impl PipelineConfig {
    /// Reads a TOML configuration file.
    pub fn from_toml_file(path: &Path) -> Result<Self> {
        read_toml_file(path)
    }

    /// Parses a TOML configuration.
    pub fn from_toml_str(text: &str) -> Result<Self> {
        parse_toml(text)
    }

    /// The configuration as TOML text (what `sillage config` prints).
    /// Unset optional keys do not appear in TOML, so they are listed after it as comments
    /// ([`OPTIONAL_KEYS`]): every parameter can be found in the output.
    pub fn to_toml_string(&self) -> Result<String> {
        let mut text = toml::to_string_pretty(self)
            .map_err(|e| Error::input(format!("cannot serialise the configuration: {e}")))?;
        text.push_str("\n# Optional keys, off unless set (`--set KEY=VALUE` or in this file):\n");
        for (key, example, meaning) in OPTIONAL_KEYS {
            text.push_str(&format!("# {key} = {example}  # {meaning}\n"));
        }
        Ok(text)
    }

    /// Applies one `key=value` override, `key` being a dotted path such as
    /// `detector.scale_px` or `tracker.motion_av`; `value` is read as TOML (numbers, booleans,
    /// strings with or without quotes).
    pub fn set(&mut self, assignment: &str) -> Result<()> {
        set_key(self, assignment)
    }

    /// Checks every parameter once; the error names the key and its allowed range.
    pub fn validate(&self) -> Result<()> {
        self.preprocess.validate()?;
        match &self.detector {
            DetectorConfig::Blob(params) => params.validate()?,
            DetectorConfig::Bead(bead) => bead.params.validate()?,
        }
        match &self.tracker {
            TrackerConfig::Ptv(params) => params.validate()?,
            TrackerConfig::Bedload(params) => {
                params.validate()?;
                if self.training_passes > 0 {
                    return Err(Error::parameter(
                        "training_passes",
                        self.training_passes,
                        "training passes train PTV's motion model; set it to 0 for the bedload \
                         tracker",
                    ));
                }
            }
        }
        if self.training_passes > MAX_TRAINING_PASSES {
            return Err(Error::parameter(
                "training_passes",
                self.training_passes,
                format!("must be in 0..={MAX_TRAINING_PASSES}"),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_detect::Threshold;

    fn blob(config: &PipelineConfig) -> &BlobParams {
        match &config.detector {
            DetectorConfig::Blob(params) => params,
            other => panic!("not the blob detector: {other:?}"),
        }
    }

    #[test]
    fn overrides_reach_nested_keys_and_enum_variants() {
        let mut config = PipelineConfig::default();
        config.set("detector.scale_px=3.5").unwrap();
        config.set("tracker.motion_av = 4").unwrap();
        config.set("detector.threshold.fixed=0.015").unwrap();
        config.set("detector.subpixel=quadratic").unwrap();
        assert_eq!(blob(&config).scale_px, sillage_detect::Scale::Px(3.5));
        assert_eq!(blob(&config).threshold, Threshold::Fixed(0.015));
        let TrackerConfig::Ptv(ptv) = &config.tracker else {
            panic!("not PTV: {:?}", config.tracker);
        };
        assert_eq!(ptv.motion_av, 4);
        config.set("detector.threshold.auto.std_factor=2").unwrap();
        assert_eq!(blob(&config).threshold, Threshold::Auto { std_factor: 2.0 });
    }

    #[test]
    fn measured_settings_take_a_number_or_their_keywords() {
        let mut config = PipelineConfig::default();
        let text = config.to_toml_string().unwrap();
        assert!(text.contains("scale_px = \"auto\""), "{text}");
        assert!(text.contains("vote_search_px = \"auto\""), "{text}");
        config.set("tracker.vote_search_px=off").unwrap();
        config.set("detector.polarity=dark").unwrap();
        let back = PipelineConfig::from_toml_str(&config.to_toml_string().unwrap()).unwrap();
        assert_eq!(back, config);
        config.set("tracker.vote_search_px=12.5").unwrap();
        config.set("detector.scale_px=auto").unwrap();
        let back = PipelineConfig::from_toml_str(&config.to_toml_string().unwrap()).unwrap();
        assert_eq!(back, config);
        for (assignment, expected) in [
            (
                "detector.scale_px=big",
                "a number of px or \"auto\", found \"big\"",
            ),
            (
                "tracker.vote_search_px=maybe",
                "\"off\" or \"auto\", found \"maybe\"",
            ),
        ] {
            let err = config.set(assignment).unwrap_err().to_string();
            assert!(err.contains(expected), "{err}");
        }
    }

    #[test]
    fn bad_overrides_name_the_key() {
        let mut config = PipelineConfig::default();
        let err = config.set("detector.scale_pix=3").unwrap_err().to_string();
        assert!(err.contains("detector.scale_pix"), "{err}");
        let err = config
            .set("tracker.motion_av=many")
            .unwrap_err()
            .to_string();
        assert!(err.contains("tracker.motion_av"), "{err}");
        assert!(config.set("no_equals_sign").is_err());
        config.set("tracker.motion_av=0").unwrap();
        let err = config.validate().unwrap_err().to_string();
        assert!(err.contains("motion_av"), "{err}");
    }

    #[test]
    fn toml_round_trips_and_rejects_unknown_keys() {
        let mut config = PipelineConfig::default();
        config.set("training_passes=2").unwrap();
        let text = config.to_toml_string().unwrap();
        for (key, example, _) in OPTIONAL_KEYS {
            let mut with_key = PipelineConfig::default();
            with_key
                .set(&format!("{key}={example}"))
                .unwrap_or_else(|e| panic!("{key}: {e}"));
            assert_ne!(with_key, PipelineConfig::default(), "{key} changed nothing");
            assert!(text.contains(&format!("# {key} = ")), "{key} not listed");
        }
        assert_eq!(PipelineConfig::from_toml_str(&text).unwrap(), config);
        let err = PipelineConfig::from_toml_str("[tracker]\nkind = \"ptv\"\nmotion_avg = 3\n")
            .unwrap_err()
            .to_string();
        assert!(err.contains("motion_avg"), "{err}");
    }

    #[test]
    fn bead_detector_and_bedload_tracker_round_trip_through_toml() {
        let mut config = PipelineConfig::default();
        config.set("detector.kind=bead").unwrap();
        config
            .set("detector.params.transparent_threshold=0.3")
            .unwrap();
        config.set("tracker.kind=bedload").unwrap();
        config.set("tracker.likelihood.gamma=0.7").unwrap();
        let DetectorConfig::Bead(bead) = &config.detector else {
            panic!("not the bead detector: {:?}", config.detector);
        };
        assert_eq!(bead.params.transparent_threshold, 0.3);
        config.validate().unwrap();
        let text = config.to_toml_string().unwrap();
        assert_eq!(PipelineConfig::from_toml_str(&text).unwrap(), config);
        config
            .set("detector.params.transparent_threshold=2")
            .unwrap();
        let err = config.validate().unwrap_err().to_string();
        assert!(err.contains("transparent_threshold"), "{err}");
    }
}

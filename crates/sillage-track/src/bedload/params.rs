//! Parameters of the bedload trackers as the user writes them (serde, TOML sections), with the
//! MMPF+ paper's defaults (§4.3) and, where the paper gives none, its authors' code's
//! (`../shared/reference/beadtracking.md`, §2). Validated once into [`Settings`], in px and
//! px/frame, before any frame is tracked; errors name the key as written (`states.gamma`).

use serde::{Deserialize, Serialize};
use sillage_core::{Calibration, Error, Result};
use sillage_filter::{BedloadModel, BedloadParams, FilterParams, FilterSpec, PositionMeasurement};

use crate::bedload::contacts::StateRule;
use crate::bedload::smoother::{Smoother, SmootherParams};

/// Which tracker of Table 1 of the MMPF+ paper runs; all share the association, the
/// motion-state measurement and the parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BedloadTrackerKind {
    /// MMPF+: switching motion states with the motion-state cue γ of Eq. (9) (the default).
    #[default]
    MmpfPlus,
    /// MMPF (the authors' ICIP 2016 version): switching states, one saltating state, no
    /// motion-state cue.
    Mmpf,
    /// PF (Breitenstein et al.): one constant-velocity particle filter with the detector
    /// confidence, no motion states.
    Pf,
    /// IMM: the Kalman IMM of the three linear motions; a track ends at its first miss.
    Imm,
    /// DET: association of the raw detections only; a track ends at its first miss.
    Det,
}

impl BedloadTrackerKind {
    /// Every kind, in Table 1's order.
    pub const ALL: [Self; 5] = [Self::MmpfPlus, Self::Mmpf, Self::Pf, Self::Imm, Self::Det];

    /// The name used in configuration files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::MmpfPlus => "mmpf_plus",
            Self::Mmpf => "mmpf",
            Self::Pf => "pf",
            Self::Imm => "imm",
            Self::Det => "det",
        }
    }

    /// The name the MMPF+ paper prints (Table 1, Figs. 6-7).
    pub fn paper_name(self) -> &'static str {
        match self {
            Self::MmpfPlus => "MMPF+",
            Self::Mmpf => "MMPF",
            Self::Pf => "PF",
            Self::Imm => "IMM",
            Self::Det => "DET",
        }
    }
}

/// Where the association predicts a tracker before searching detections around it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Prediction {
    /// By the motion of the tracker's state at the previous frame (§3.4.1): resting stays,
    /// rolling moves by `(u, 0)`, saltating by `(u, v)` (the default).
    #[default]
    ByState,
    /// Always `x + u`, as the authors' code.
    ConstantVelocity,
}

/// The velocity observation `u_obs` of an associated tracker.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObservedVelocity {
    /// Raw detection to raw detection (§3.4.2; the default); after a miss, from the last
    /// estimate.
    #[default]
    RawDetections,
    /// The detection minus the previous estimate, as the authors' code.
    FromEstimate,
}

/// Which candidates make the detector-confidence density of Eq. (1) for a missed tracker.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ConfidenceSet {
    /// Every candidate not associated to another tracker this frame (the default): a
    /// detection another bead explains no longer attracts this one's particles. (The paper
    /// uses all maxima; the authors' code only those below the detection threshold.)
    #[default]
    Unclaimed,
    /// Every candidate, as the paper's Eq. (1).
    All,
}

/// The greedy association of §3.4 and its cost, Eq. (2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AssociationParams {
    /// α, weight of the distance term; default 0.75 (§4.3).
    pub alpha: f64,
    /// β, weight of the velocity term; default 0.25 (§4.3).
    pub beta: f64,
    /// r_s, radius of the search region around the prediction, px; default 31.05, the
    /// authors' code's flow velocity 0.83 m/s at 2.056e-4 m/px and 130 fps, in px/frame.
    pub search_radius_px: f64,
    /// Where the tracker is predicted; default by state (§3.4.1).
    pub prediction: Prediction,
    /// How `u_obs` is measured; default raw detection to raw detection (§3.4.2).
    pub observed_velocity: ObservedVelocity,
}

impl Default for AssociationParams {
    fn default() -> Self {
        Self {
            alpha: 0.75,
            beta: 0.25,
            search_radius_px: 0.83 / 2.056e-4 / 130.0,
            prediction: Prediction::default(),
            observed_velocity: ObservedVelocity::default(),
        }
    }
}

/// The observation model of §3.5.2: Eqs. (1), (8) and (9).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LikelihoodParams {
    /// Variance of the Gaussian position likelihood of Eq. (8), px² on each axis; default 3.
    pub position_variance_px2: f64,
    /// γ, the motion-state reward of Eq. (9), in (0, 1); default 2/3.
    pub gamma: f64,
    /// λ, decay of the exponential kernel of Eq. (1), 1/px; default 1.
    pub lambda_per_px: f64,
    /// Support of that kernel, px: candidates farther than this add nothing (the code's
    /// 20×20 window, ±10 px); default 10, where `exp(−λ·10)` < 5e-5.
    pub support_px: f64,
    /// Which candidates make the density; default those no other tracker claimed.
    pub confidence_set: ConfidenceSet,
    /// When no particle comes within this distance of the associated detection, px, the
    /// particles restart around the detection and the tracker keeps its identity (ours: a
    /// prediction that misses a take-off or a rebound otherwise leaves the estimate between
    /// prediction and detection). Default 6 (3.5 σ of the default likelihood); none to
    /// follow the paper.
    pub recapture_distance_px: Option<f64>,
}

impl Default for LikelihoodParams {
    fn default() -> Self {
        Self {
            position_variance_px2: 3.0,
            gamma: 2.0 / 3.0,
            lambda_per_px: 1.0,
            support_px: 10.0,
            confidence_set: ConfidenceSet::default(),
            recapture_distance_px: Some(6.0),
        }
    }
}

/// The motion-state measurement of Eq. (4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StateParams {
    /// nbN_rest: resting from this many neighbours in contact; default 5 (§4.3).
    pub neighbours_rest: u32,
    /// nbN_salt: saltating up to this many neighbours in contact; default 0 (§4.3).
    pub neighbours_salt: u32,
    /// u_rest, m/s: resting at or below this speed; default 0.015 (§4.3).
    pub speed_rest_m_per_s: f64,
    /// u_salt, m/s: saltating at or above this speed; default 0.25 (§4.3).
    pub speed_salt_m_per_s: f64,
    /// Two beads are in contact when their centres are at most this factor times the sum of
    /// their radii apart; default 1.07 (the code's `factNeigh`; the paper: "in contact").
    pub contact_factor: f64,
}

impl Default for StateParams {
    fn default() -> Self {
        Self {
            neighbours_rest: 5,
            neighbours_salt: 0,
            speed_rest_m_per_s: 0.015,
            speed_salt_m_per_s: 0.25,
            contact_factor: 1.07,
        }
    }
}

/// How many consecutive frames without a detection a tracker survives, by its motion state
/// at the last frame (§4.3); a tracker whose state is unknown uses the rolling limit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SurvivalParams {
    /// Resting; default 100.
    pub resting: u32,
    /// Rolling; default 10.
    pub rolling: u32,
    /// Saltating; default 5.
    pub saltating: u32,
}

impl Default for SurvivalParams {
    fn default() -> Self {
        Self {
            resting: 100,
            rolling: 10,
            saltating: 5,
        }
    }
}

/// Everything a bedload tracker reads (a TOML file with these sections).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BedloadTrackerParams {
    /// Which tracker; default MMPF+.
    pub tracker: BedloadTrackerKind,
    /// Seed of the run: each tracker's particles draw from `rng_stream(seed, serial)`.
    pub seed: u64,
    /// Pixel size and frame rate; default the authors' example sequence (2.056e-4 m/px,
    /// 130 fps). The speeds of `states` are converted with it.
    pub calibration: Calibration,
    /// Bead radius of each class, px, indexed by class (0 black, 1 transparent); default
    /// [15, 10], the authors' code's 6 mm and 4 mm beads at 2.056e-4 m/px.
    pub radius_px: Vec<f64>,
    /// The image, `[width, height]` px, when known: a missed tracker predicted outside it has
    /// left the field and ends (the code's edge rule). Default none.
    pub field_px: Option<[f64; 2]>,
    /// Emit the points predicted through missed frames at once, as the paper and the authors'
    /// code do. Default false: they are held until a detection is associated again and
    /// dropped if the tracker ends first, so that a lost tracker leaves no trail of
    /// predictions (false positives) behind; the output then lags by up to the survival limit.
    pub emit_predictions_at_once: bool,
    /// Association, Eq. (2).
    pub association: AssociationParams,
    /// Observation model, Eqs. (1), (8), (9).
    pub likelihood: LikelihoodParams,
    /// Motion-state measurement, Eq. (4).
    pub states: StateParams,
    /// Survival without detection.
    pub survival: SurvivalParams,
    /// Motion states smoothed over the trajectory (fixed lag).
    pub smoother: SmootherParams,
    /// Particles per tracker and resampling.
    pub filter: FilterParams,
    /// Motion models of Eq. (3), their switching and noises (`sillage fit bedload` writes
    /// this section).
    pub motion: BedloadParams,
}

impl Default for BedloadTrackerParams {
    fn default() -> Self {
        Self {
            tracker: BedloadTrackerKind::default(),
            seed: 0,
            calibration: Calibration {
                m_per_px: 2.056e-4,
                fps: 130.0,
            },
            radius_px: vec![15.0, 10.0],
            field_px: None,
            emit_predictions_at_once: false,
            association: AssociationParams::default(),
            likelihood: LikelihoodParams::default(),
            states: StateParams::default(),
            survival: SurvivalParams::default(),
            smoother: SmootherParams::default(),
            filter: FilterParams::default(),
            motion: BedloadParams::default(),
        }
    }
}

/// Validated parameters in px and px/frame, ready for the trackers.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct Settings {
    pub kind: BedloadTrackerKind,
    pub radius_px: Vec<f64>,
    pub field_px: Option<[f64; 2]>,
    pub emit_predictions_at_once: bool,
    pub association: AssociationParams,
    pub likelihood: LikelihoodParams,
    pub rule: StateRule,
    pub survival: SurvivalParams,
    /// `None` when the lag is 0 (states frame by frame).
    pub smoother: Option<Box<Smoother>>,
    pub spec: FilterSpec,
    pub model: BedloadModel,
    pub measurement: PositionMeasurement,
}

/// An error unless `ok`, naming `key` and its `value`.
fn check(ok: bool, key: &str, value: impl std::fmt::Display, message: &str) -> Result<()> {
    if ok {
        Ok(())
    } else {
        Err(Error::parameter(key, value, message))
    }
}

fn finite_non_negative(key: &str, value: f64) -> Result<()> {
    check(
        value.is_finite() && value >= 0.0,
        key,
        value,
        "must be a finite number ≥ 0",
    )
}

fn finite_positive(key: &str, value: f64) -> Result<()> {
    check(
        value.is_finite() && value > 0.0,
        key,
        value,
        "must be a finite number > 0",
    )
}

impl BedloadTrackerParams {
    /// Checks every value and converts to px and px/frame; errors name the key.
    pub fn validate(&self) -> Result<()> {
        self.settings().map(drop)
    }

    /// Checks that a sequence of `frames` frames is longer than the smoother's lag (a lag
    /// that spans the whole sequence would wait for frames that never come); the error
    /// names `smoother.lag` and the fix.
    pub fn check_sequence_length(&self, frames: usize) -> Result<()> {
        let lag = self.smoother.lag as usize;
        check(
            lag == 0 || lag < frames,
            "smoother.lag",
            lag,
            &format!(
                "is not shorter than the sequence ({frames} frames); set smoother.lag below \
                 {frames} (a few frames suffice), or 0 to decide the states frame by frame"
            ),
        )
    }

    pub(crate) fn settings(&self) -> Result<Settings> {
        let c = &self.calibration;
        Calibration::new(c.m_per_px, c.fps).map_err(|e| e.in_section("calibration"))?;
        check(
            !self.radius_px.is_empty(),
            "radius_px",
            "[]",
            "give one bead radius per class, px (e.g. [15, 10] for black and transparent)",
        )?;
        for (class, &r) in self.radius_px.iter().enumerate() {
            finite_positive(&format!("radius_px[{class}]"), r)?;
        }
        if let Some([w, h]) = self.field_px {
            finite_positive("field_px[0]", w)?;
            finite_positive("field_px[1]", h)?;
        }
        let a = &self.association;
        finite_non_negative("association.alpha", a.alpha)?;
        finite_non_negative("association.beta", a.beta)?;
        finite_positive("association.search_radius_px", a.search_radius_px)?;
        let l = &self.likelihood;
        finite_positive("likelihood.position_variance_px2", l.position_variance_px2)?;
        check(
            l.gamma > 0.0 && l.gamma < 1.0,
            "likelihood.gamma",
            l.gamma,
            "must lie strictly between 0 and 1 (the paper uses 2/3)",
        )?;
        finite_positive("likelihood.lambda_per_px", l.lambda_per_px)?;
        finite_positive("likelihood.support_px", l.support_px)?;
        if let Some(d) = l.recapture_distance_px {
            finite_positive("likelihood.recapture_distance_px", d)?;
        }
        let s = &self.states;
        finite_non_negative("states.speed_rest_m_per_s", s.speed_rest_m_per_s)?;
        finite_non_negative("states.speed_salt_m_per_s", s.speed_salt_m_per_s)?;
        finite_positive("states.contact_factor", s.contact_factor)?;
        let spec = FilterSpec::new(&self.filter, self.seed).map_err(|e| e.in_section("filter"))?;
        let smoother = self
            .smoother
            .smoother(&self.motion.transition, c)?
            .map(Box::new);
        let model = BedloadModel::new(self.motion.clone()).map_err(|e| e.in_section("motion"))?;
        let variance = l.position_variance_px2;
        let measurement = PositionMeasurement::new(
            "likelihood.position_variance_px2",
            &sillage_filter::Noise2::diagonal(variance, variance),
        )?;
        let px_per_frame = |m_per_s: f64| m_per_s / (c.m_per_px * c.fps);
        Ok(Settings {
            kind: self.tracker,
            radius_px: self.radius_px.clone(),
            field_px: self.field_px,
            emit_predictions_at_once: self.emit_predictions_at_once,
            association: a.clone(),
            likelihood: l.clone(),
            rule: StateRule {
                neighbours_rest: s.neighbours_rest,
                neighbours_salt: s.neighbours_salt,
                speed_rest_px_per_frame: px_per_frame(s.speed_rest_m_per_s),
                speed_salt_px_per_frame: px_per_frame(s.speed_salt_m_per_s),
                contact_factor: s.contact_factor,
            },
            survival: self.survival.clone(),
            smoother,
            spec,
            model,
            measurement,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_convert_speeds() {
        let settings = BedloadTrackerParams::default().settings().unwrap();
        // u_rest = 0.015 m/s = 0.561 px/frame, u_salt = 0.25 m/s = 9.35 px/frame (code §2.1).
        assert!((settings.rule.speed_rest_px_per_frame - 0.561).abs() < 1e-3);
        assert!((settings.rule.speed_salt_px_per_frame - 9.353).abs() < 1e-3);
        assert!((settings.association.search_radius_px - 31.05).abs() < 0.01);
    }

    #[test]
    fn errors_name_the_key_as_written() {
        type Edit = fn(&mut BedloadTrackerParams);
        let cases: [(Edit, &str); 6] = [
            (|p| p.filter.particles = 0, "`filter.particles`"),
            (
                |p| p.motion.transition[1] = [0.5, 0.5, 0.5],
                "`motion.transition`",
            ),
            (
                |p| p.motion.roll_pos_noise.var_x = -1.0,
                "`motion.roll_pos_noise",
            ),
            (|p| p.likelihood.gamma = 1.0, "`likelihood.gamma`"),
            (|p| p.radius_px = vec![15.0, f64::NAN], "`radius_px[1]`"),
            (|p| p.calibration.fps = 0.0, "`calibration.fps`"),
        ];
        for (edit, key) in cases {
            let mut params = BedloadTrackerParams::default();
            edit(&mut params);
            let e = params.validate().unwrap_err().to_string();
            assert!(e.contains(key), "{key}: {e}");
        }
    }

    #[test]
    fn smoother_settings_are_checked_naming_the_key() {
        let mut params = BedloadTrackerParams::default();
        params.motion.transition[1] = [0.0; 3];
        let e = params.validate().unwrap_err().to_string();
        assert!(
            e.contains("`motion.transition[1]`") && e.contains("row of zeros"),
            "{e}"
        );
        let mut params = BedloadTrackerParams::default();
        params.smoother.emission.rolling.log_speed.sd = 0.0;
        let e = params.validate().unwrap_err().to_string();
        assert!(
            e.contains("`smoother.emission.rolling.log_speed.sd`"),
            "{e}"
        );
        let mut params = BedloadTrackerParams::default();
        params.smoother.lag = 10;
        params.check_sequence_length(11).unwrap();
        let e = params.check_sequence_length(10).unwrap_err().to_string();
        assert!(
            e.contains("`smoother.lag`") && e.contains("10 frames"),
            "{e}"
        );
        params.smoother.lag = 0;
        params.check_sequence_length(1).unwrap();
        params.smoother.lag = crate::bedload::smoother::MAX_LAG + 1;
        let e = params.validate().unwrap_err().to_string();
        assert!(e.contains("`smoother.lag`"), "{e}");
        let mut params = BedloadTrackerParams::default();
        params.smoother.half_window = crate::bedload::smoother::MAX_LAG + 1;
        let e = params.validate().unwrap_err().to_string();
        assert!(e.contains("`smoother.half_window`"), "{e}");
        let mut params = BedloadTrackerParams::default();
        params.smoother.emission.saltation_speed_m_per_s = f64::NAN;
        let e = params.validate().unwrap_err().to_string();
        assert!(
            e.contains("`smoother.emission.saltation_speed_m_per_s`"),
            "{e}"
        );
        assert!(
            BedloadTrackerParams::default()
                .settings()
                .unwrap()
                .smoother
                .is_some()
        );
    }

    #[test]
    fn reads_toml_sections_and_rejects_unknown_keys() {
        let params: BedloadTrackerParams = toml::from_str(
            "tracker = \"det\"\n[association]\nalpha = 0.5\n[motion]\nyoung_frames = 2\n",
        )
        .unwrap();
        assert_eq!(params.tracker, BedloadTrackerKind::Det);
        assert_eq!(params.association.alpha, 0.5);
        assert_eq!(params.motion.young_frames, 2);
        assert_eq!(params.association.beta, 0.25);
        let e = toml::from_str::<BedloadTrackerParams>("[states]\ngama = 0.5\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("gama"), "{e}");
    }
}

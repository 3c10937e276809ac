//! Parameters of the pedestrian IMM-PF tracker, with the paper's values where it gives them.

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result};
use sillage_filter::ImmPfParams;

use super::appearance::AppearanceParams;

/// A motion model that can compete inside the filter (§5.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ModelName {
    /// Constant position, Eq. (10).
    Cp,
    /// Constant velocity, Eq. (11).
    Cv,
    /// Constant acceleration, Eq. (12).
    Ca,
    /// The learned motion prior (§5.1, `sillage fit motion-prior`).
    Mp,
}

impl ModelName {
    /// Every model, in the paper's order.
    pub const ALL: [ModelName; 4] = [Self::Cp, Self::Cv, Self::Ca, Self::Mp];

    /// The paper's abbreviation (`CP`, `CV`, `CA`, `MP`).
    pub const fn label(self) -> &'static str {
        match self {
            Self::Cp => "CP",
            Self::Cv => "CV",
            Self::Ca => "CA",
            Self::Mp => "MP",
        }
    }

    /// Parses a combination written as the paper's tables do (`CV_CA_MP`, any case, `_`,
    /// `+` or `,` between names).
    pub fn parse_combination(text: &str) -> Result<Vec<ModelName>> {
        let mut models = Vec::new();
        for part in text.split(['_', '+', ',']).filter(|p| !p.is_empty()) {
            let model = Self::ALL
                .into_iter()
                .find(|m| m.label().eq_ignore_ascii_case(part.trim()))
                .ok_or_else(|| {
                    Error::parameter(
                        "models",
                        text,
                        format!("`{part}` is not a model; use CP, CV, CA or MP, e.g. CV_CA_MP"),
                    )
                })?;
            if models.contains(&model) {
                return Err(Error::parameter("models", text, "names a model twice"));
            }
            models.push(model);
        }
        if models.is_empty() {
            return Err(Error::parameter(
                "models",
                text,
                "names no model; e.g. CV_CA",
            ));
        }
        Ok(models)
    }

    /// The combination's name as in the paper's tables (`CV_CA_MP`).
    pub fn combination_label(models: &[ModelName]) -> String {
        models
            .iter()
            .map(|m| m.label())
            .collect::<Vec<_>>()
            .join("_")
    }
}

/// What detections given beside colour frames do (`detection.with_frames`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DetectionsWithFrames {
    /// The detections drive the trackers as in the detections-only mode, and the frames add
    /// each person's colour to the assignment (`detection.colour_weight`): pixels and
    /// detections together.
    Measurements,
    /// The paper's image mode, the detections only starting trackers where motion blobs
    /// would; the colour and motion likelihood weighs the particles.
    Births,
}

/// The detection-driven mode (detections alone, or with frames as measurements): how
/// detections are assigned to trackers, how they weigh the particles, and the trackers' life
/// cycle there (the image mode's `confirm_frames`, `unsupported_frames`, revival and death
/// rules do not apply).
///
/// `high_score`, `min_hits`, `lost_frames`, `report_first_hits`, `velocity_proposal`,
/// `size_smoothing` and `size_rate` were chosen together leave-one-sequence-out on the nine
/// shared detection sequences (the eight MOT15 training sequences and PETS09-S2L1 frames 1-150,
/// public ACF detections; `sillage bench immpf --grid`, docs/immpf.md): each sequence held out
/// in turn, the best of 432 combinations on the other eight, scored on the held-out one, gave a
/// mean (MOTA + IDF1) / 2 of 55.6 % (SORT 52.0, ByteTrack 49.5; 55.0 without `size_rate` in
/// the grid, this mode before its rebuild 41.5); all nine folds chose the defaults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DetectionLikelihoodParams {
    /// Least IoU of a detection of score ≥ `high_score` with a tracker's predicted box for
    /// the Hungarian assignment to pair them; default 0.3 (SORT's). Among 0.1-0.3,
    /// leave-one-sequence-out over the nine detection sequences (CV_CA, medians of 3 seeds,
    /// boxes smoothed, 2026-11-30), eight folds chose 0.1 and one 0.15: held out 58.5 %
    /// against 58.3 % at 0.3 (mean (MOTA + IDF1) / 2), TUD-Stadtmitte's IDF1 73.1 → 71.0;
    /// among 0.2 and 0.3 every fold chose 0.2 (58.6 %), but jointly with `low_match_iou` the
    /// folds split and held out 58.1 %. No robust gain: SORT's value kept.
    pub match_iou: f64,
    /// Detections of at least this score are assigned first, to every tracker, and start
    /// trackers; the others are assigned second, to the trackers a detection held in the
    /// previous frame, and start none (ByteTrack's two stages); default 0.9 (chosen among
    /// 0.5, 0.7 and 0.9 on the public ACF detections, whose scores lie in 0.5-1, median
    /// 0.93-0.99: set it for your detector's scale — about its 25th percentile). Among 0.5,
    /// 0.7 and 0.9, leave-one-sequence-out (as for `match_iou`): every fold chose 0.9.
    pub high_score: f64,
    /// Least IoU of the second stage's pairs; default 0.5 (ByteTrack's). Among 0.3, 0.5 and
    /// 0.7, leave-one-sequence-out (as for `match_iou`): eight folds chose 0.3, one 0.7, and
    /// held out they give 57.9 % against 58.3 % at 0.5, so 0.5 is kept.
    pub low_match_iou: f64,
    /// Matches in a row, the birth included, before a tracker is confirmed and reported; a
    /// tracker that misses a detection before that ends; default 5 (chosen among 3-5; SORT's
    /// `min_hits` 3 counts the matches after the birth, so 4 detections).
    pub min_hits: u32,
    /// Frames a confirmed tracker is kept without a detection, unreported, its particles
    /// coasting on their models, before it ends; a detection on its predicted box in that
    /// time takes it back, identity and all; default 30, ByteTrack's buffer (chosen among 1,
    /// 5 and 30: by all nine folds with `size_rate`; 5 by seven folds of nine without it).
    pub lost_frames: u32,
    /// Share of a matched tracker's particles drawn around its detection's foot point (σ
    /// as the likelihood's) before weighting, so that a detection the prediction missed by
    /// more than a few σ still has particles on it; default 0.5 (0.25 to 0.9 within a point
    /// of each other on the nine detection sequences, 0 2-16 MOTA points lower; among 0.25,
    /// 0.5, 0.75 and 0.9, leave-one-sequence-out (as for `match_iou`), every fold chose 0.5,
    /// held out 58.3 %). 0: the paper's filter, whose particles follow their motion models
    /// only.
    pub proposal_share: f64,
    /// The proposed particles also take the velocity of the tracker's detections (the
    /// difference of its last two detections' foot points per frame, smoothed over a streak
    /// of matches); default true (chosen by every fold of a leave-one-sequence-out against
    /// false, as for `match_iou`).
    pub velocity_proposal: bool,
    /// Weight of the newest difference in that smoothed velocity; default 0.2 (among 0.1,
    /// 0.2, 0.35 and 0.5, leave-one-sequence-out as for `match_iou`: every fold chose 0.2,
    /// held out 58.3 %).
    pub velocity_smoothing: f64,
    /// A tracker that missed a detection is reported again only after `min_hits` new matches
    /// in a row (SORT); default true (chosen in all nine folds of a first round, with the
    /// velocity drawn at a streak's first match only, and again by every fold with the
    /// boxes smoothed, as for `match_iou`).
    pub reconfirm_after_loss: bool,
    /// When a tracker is (re)confirmed, report the frames of its streak before that too;
    /// default true (chosen by every fold of a leave-one-sequence-out against false, as for
    /// `match_iou`; SORT drops them, but reports every track in its first `min_hits`
    /// frames).
    pub report_first_hits: bool,
    /// σ of the Gaussian of the foot-point distance, as a fraction of the detection's
    /// height; default 0.1 (among 0.03, 0.05, 0.1, 0.15 and 0.2, leave-one-sequence-out as
    /// for `match_iou`: every fold chose 0.1, held out 58.3 %).
    pub foot_sigma_fraction: f64,
    /// Detections below this score are ignored; default −∞ (keep all).
    pub min_score: f64,
    /// Weight of a matched detection's size in the tracker's box size (exponential
    /// smoothing); default 0.7 (among 0.3, 0.5, 0.7 and 0.9, leave-one-sequence-out as for
    /// `match_iou`: every fold chose 0.7).
    pub size_smoothing: f64,
    /// Report a confirmed tracker on the frames where no detection matched it (its
    /// prediction); default false: reported only when a detection holds it, as SORT does.
    pub report_coasting: bool,
    /// With frames: detections as measurements (the default) or as births only.
    pub with_frames: DetectionsWithFrames,
    /// With frames, as measurements: weight w of the colour distance in the assignment's
    /// cost `1 − IoU + w·d²`, d² the mean of the squared Bhattacharyya distances of the top
    /// and bottom halves' HSV histograms (§4.3) of the detection and of the tracker's
    /// reference (taken at its birth, following its matched detections at
    /// `appearance.adapt_rate`); pairs still need IoU ≥ `match_iou` (`low_match_iou`).
    ///
    /// Default 6. Chosen leave-one-sequence-out on the three shared image sequences with
    /// detections (`sillage bench immpf --with-detections --grid
    /// tracker.detection.colour_weight=0,1,2,3,4,6,8`, CV_CA, medians of 3 seeds, with the
    /// boxes smoothed, `smooth_frames`): the fold holding out PETS09-S2L1 chose 2 (2 to 8 tie
    /// on the other two), those holding out TUD-Campus and TUD-Stadtmitte chose 6; held out,
    /// MOTA / IDF1 55.5 / 57.1, 69.6 / 73.7 and 77.9 / 75.9 % against 54.9 / 54.5, 69.6 /
    /// 73.7 and 76.2 / 73.1 with w = 0, mean (MOTA + IDF1) / 2 67.0 → 68.3 %. Colour decides
    /// where people cross, which IoU alone leaves to chance (TUD-Campus does not change from
    /// w = 0 to 8). Before the boxes were smoothed, the same protocol chose 1-2 and gained
    /// nothing held out (64.9 against 64.9 %).
    pub colour_weight: f64,
    /// The box size of a tracker's prediction follows the rate of change of its detections'
    /// sizes (width and height per frame, smoothed with `velocity_smoothing`), carried through
    /// misses as SORT's area rate is; false: the size stays as last smoothed. Default true:
    /// chosen by all nine folds of the leave-one-sequence-out grid (with `lost_frames`; see
    /// the struct's comment), held-out mean (MOTA + IDF1) / 2 55.0 → 55.6 %. Carrying the
    /// rate only while a detection holds the tracker (ByteTrack zeroes its height rate on lost
    /// tracks) held out 55.1 % in a smaller grid (`lost_frames` 5 or 30 × this key) where
    /// carrying it gave 55.6 %.
    pub size_rate: bool,
    /// A reported tracker that detections take back after it went unreported for at most this
    /// many frames is reported on the frames of that gap too, its box interpolated linearly
    /// between the last one reported before the gap and the first after (the linear
    /// interpolation ByteTrack's and StrongSORT's authors run on their output, done here as
    /// the tracker runs: the gap's rows are written when the tracker is reported again).
    /// 0: off. Default 30, `lost_frames`'s default: chosen among 0 and 30 by all nine folds
    /// of the leave-one-sequence-out grid of the struct's comment (864 combinations with this
    /// key), held-out mean (MOTA + IDF1) / 2 55.6 → 56.3 %; TUD-Campus held out 61.8 / 70.3 →
    /// 68.0 / 73.1, TUD-Stadtmitte 72.7 / 72.0 → 76.0 / 72.8, PETS09-S2L1 46.6 / 51.4 →
    /// 47.2 / 52.1.
    pub fill_gaps: u32,
    /// σ, in frames, of the smoothing of each tracker's reported boxes over its neighbouring
    /// frames: each box edge and size is replaced by the value at its frame of a line fitted
    /// to the tracker's boxes within 2σ frames, weighted by a Gaussian of the frame distance
    /// (local linear regression: the weighted mean where neighbours sit on both sides, the
    /// trend carried on at a track's ends). Like the Gaussian-smoothed interpolation
    /// StrongSORT's authors run on their output, done as the tracker runs: a box is written
    /// ⌈2σ⌉ frames after its frame, or when its tracker ends. 0: off, boxes written as
    /// estimated.
    ///
    /// Default 2: chosen leave-one-sequence-out on the nine detection sequences (`sillage
    /// bench immpf --detections-only --grid tracker.detection.smooth_frames=…`, CV_CA,
    /// medians of 3 seeds): among 0, 0.5, 1, 1.5 and 2 every fold chose 2, held-out mean
    /// (MOTA + IDF1) / 2 56.3 → 58.3 % (SORT 52.0, ByteTrack 49.5); among 0-4, eight folds
    /// chose 2 and the one holding out KITTI-13 chose 4 (22.0 / 46.7 there against 30.7 /
    /// 53.0 with 2). A plain Gaussian mean instead of the line held out 56.7 % (its folds
    /// chose 1 and 2): it pulls the boxes of short, fast-growing tracks inwards.
    pub smooth_frames: f64,
}

impl DetectionLikelihoodParams {
    /// Frames on either side of a box that the smoothing reads, and so by which it delays a
    /// reported box: the kernel cut at 2σ (weights below e⁻² ≈ 0.14 of the centre's left
    /// out), at least one frame; 0 without smoothing. A viewer of the boxes of each frame
    /// stays this far behind the current frame.
    pub fn smoothing_lag_frames(&self) -> u64 {
        if self.smooth_frames > 0.0 {
            (2.0 * self.smooth_frames).ceil().max(1.0) as u64
        } else {
            0
        }
    }

    /// Whether candidates drive the trackers as measurements (the detection-driven mode):
    /// always without frames; with frames, when they are detections (not motion blobs) and
    /// `with_frames` is `measurements`.
    pub fn drive_trackers(&self, with_frames: bool, candidates_are_detections: bool) -> bool {
        !with_frames
            || candidates_are_detections && self.with_frames == DetectionsWithFrames::Measurements
    }
}

impl Default for DetectionLikelihoodParams {
    fn default() -> Self {
        Self {
            match_iou: 0.3,
            high_score: 0.9,
            low_match_iou: 0.5,
            min_hits: 5,
            lost_frames: 30,
            proposal_share: 0.5,
            velocity_proposal: true,
            velocity_smoothing: 0.2,
            reconfirm_after_loss: true,
            report_first_hits: true,
            foot_sigma_fraction: 0.1,
            min_score: f64::NEG_INFINITY,
            size_smoothing: 0.7,
            report_coasting: false,
            with_frames: DetectionsWithFrames::Measurements,
            colour_weight: 6.0,
            size_rate: true,
            fill_gaps: 30,
            smooth_frames: 2.0,
        }
    }
}

/// The blob-driven proposal of the image mode (not in the paper): a share of the particles of
/// each tracker that a motion blob's person overlaps is moved onto that person's foot point
/// before weighting.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ProposalParams {
    /// Share of a matched tracker's particles moved; default 0.2. 0 gives the
    /// paper's filter, whose particles follow their motion models only.
    pub share: f64,
    /// Least IoU between a tracker's predicted box and a blob's person for the person to
    /// draw the tracker's particles (greedy one-to-one matching); default 0.3.
    pub min_iou: f64,
}

impl Default for ProposalParams {
    fn default() -> Self {
        Self {
            share: 0.2,
            min_iou: 0.3,
        }
    }
}

/// The revival gate in the frame of a tracker's death, box heights: a person born farther
/// than half a height from where the dead tracker was heading is someone else.
pub(super) const REVIVAL_GATE_AT_DEATH: f64 = 0.5;

/// Parameters of the pedestrian tracker: the filter, the competing models and their
/// noises, the observation model and the life cycle of trackers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PedestrianParams {
    /// The IMM particle filter (N = 200, ρ = 4, φ = 5, γ = 0.1·N).
    pub filter: ImmPfParams,
    /// The competing models; default CV_CA (the paper's combination of two linear models).
    pub models: Vec<ModelName>,
    /// σ of the position noise of every model, px per frame; default 3.
    pub pos_noise_px: f64,
    /// σ of the velocity noise (CV, CA), px/frame per frame; default 1.
    pub vel_noise_px_per_frame: f64,
    /// σ of the acceleration noise (CA), px/frame² per frame; default 0.3.
    pub acc_noise_px_per_frame2: f64,
    /// σ of the initial positions around the birth foot point, px; default 3.
    pub init_pos_noise_px: f64,
    /// σ of the initial velocities around zero, px/frame; default 2.
    pub init_vel_noise_px_per_frame: f64,
    /// The colour and motion likelihood (images).
    pub appearance: AppearanceParams,
    /// The detection-driven mode (detections alone, or beside the frames as measurements).
    pub detection: DetectionLikelihoodParams,
    /// The blob-driven proposal (images only).
    pub proposal: ProposalParams,
    /// A tracker dies after its mean particle likelihood stays below `exp` of this for
    /// `death_frames` frames (§5.3); default −14 (chosen on PETS 2009 S2.L1 among −14 to −26,
    /// docs/immpf.md; a person well followed scores −2 to −8, a box that lost its person
    /// below −15). Images only: on detections alone a tracker ends by
    /// `detection.lost_frames`.
    pub death_log_likelihood: f64,
    /// Consecutive frames below the threshold before a tracker dies; default 3.
    pub death_frames: u32,
    /// A tracker that no candidate (motion blob or detection) supports — none
    /// holds its foot point or overlaps its box — for this many frames in a row dies; default
    /// 7 (1 s at PETS 2009's 7 frames/s). Not in the paper, whose only death rule is the
    /// likelihood's: a tracker born on a spurious blob keeps matching the background it was
    /// born on. Set it high to follow people who stand still for long.
    pub unsupported_frames: u32,
    /// Image mode: a person is born only where at least this share of its box's pixels moved
    /// since the previous frame (frame difference beyond the first motion bin); default 0.1
    /// (walkers in PETS 2009 move 17 % or more of their box at 7 frames/s, the background
    /// subtraction's ghosts and flicker 1-7 %). 0 accepts every candidate.
    pub birth_min_motion: f64,
    /// Image mode with a foreground mask: a person is born only where at least this share
    /// of its box is foreground; default 0.25 (not in the paper). On PETS 2009 S2.L1, 97 % of
    /// the true people's boxes (adult-sized at their foot point) are at least 25 %
    /// foreground; the boxes the blob splitting puts beside a person, or on the fragments
    /// of a group behind an obstacle, much less (0.05-0.25). 0 accepts every candidate.
    pub birth_min_foreground: f64,
    /// A tracker is reported once it has lived this many frames, its first frames then
    /// reported at once; one that dies younger is never reported (SORT's `min_hits`); default
    /// 7 (1 s at PETS 2009's 7 frames/s; on its frames 1-150, 30 seeds, 6-8 gave ATA 0.39
    /// where 3 gave 0.36, docs/immpf.md). 1 reports every tracker from its birth.
    pub confirm_frames: u32,
    /// A person born within this many frames of the death of a confirmed tracker, where
    /// that tracker was heading (its last foot point, or that point moved on at its last
    /// velocity, within half a box height, wider on images: `revive_gate_growth`), takes the
    /// dead tracker's identity back; default 20, about 3 s at 7 frames/s (not in the paper:
    /// it reduces the identities a person lost in a crowd receives; on PETS 2009 S2.L1, 15
    /// to 40 frames gave ATA 0.28-0.29 where 10 gave 0.25, docs/immpf.md). 0 disables it,
    /// and the hand-down of an identity to a tracker born on the dying one's path shortly
    /// before its death with it.
    pub revive_frames: u32,
    /// Images: the revival gate (half a box height at the death) widens by this many box
    /// heights per frame since the death; default 0.1, a walker's pace at 7 frames/s
    /// (1.2 m/s for a 1.74 m adult): the dying tracker's velocity is least reliable when it
    /// lost its person, and the person walked on meanwhile. Not in the paper; on PETS 2009
    /// S2.L1, 30 seeds, MP's ATA 0.46 → 0.49 (0.07: 0.46, 0.13: 0.49; docs/immpf.md). 0
    /// keeps half a height. Scale it by 7 / frame rate for other videos.
    pub revive_gate_growth: f64,
    /// Images: the widest revival gate, box heights; default 1.5 (reached 10 frames after
    /// the death). Without a bound the gate reaches 2.5 heights 20 frames after a death: with
    /// births on public detections, CV_CA IDF1 62.3 → 59.3 % (docs/immpf.md).
    pub revive_gate_max: f64,
    /// A birth candidate (motion blob or detection) is explained by a tracker whose box it
    /// overlaps by at least this IoU; default 0.2.
    pub birth_overlap: f64,
    /// Two trackers whose boxes overlap by at least this IoU follow one person: the younger
    /// dies; default 0.5.
    pub duplicate_overlap: f64,
}

impl Default for PedestrianParams {
    fn default() -> Self {
        Self {
            filter: ImmPfParams::default(),
            models: vec![ModelName::Cv, ModelName::Ca],
            pos_noise_px: 3.0,
            vel_noise_px_per_frame: 1.0,
            acc_noise_px_per_frame2: 0.3,
            init_pos_noise_px: 3.0,
            init_vel_noise_px_per_frame: 2.0,
            appearance: AppearanceParams::default(),
            detection: DetectionLikelihoodParams::default(),
            proposal: ProposalParams::default(),
            death_log_likelihood: -14.0,
            death_frames: 3,
            unsupported_frames: 7,
            birth_min_motion: 0.1,
            birth_min_foreground: 0.25,
            confirm_frames: 7,
            revive_frames: 20,
            revive_gate_growth: 0.1,
            revive_gate_max: 1.5,
            birth_overlap: 0.2,
            duplicate_overlap: 0.5,
        }
    }
}

impl PedestrianParams {
    /// Checks every value; errors name the key.
    pub fn validate(&self) -> Result<()> {
        if self.models.is_empty() {
            return Err(Error::parameter(
                "models",
                "[]",
                "must list at least one model",
            ));
        }
        for (key, value) in [
            ("pos_noise_px", self.pos_noise_px),
            ("vel_noise_px_per_frame", self.vel_noise_px_per_frame),
            ("acc_noise_px_per_frame2", self.acc_noise_px_per_frame2),
            ("init_pos_noise_px", self.init_pos_noise_px),
            (
                "init_vel_noise_px_per_frame",
                self.init_vel_noise_px_per_frame,
            ),
            (
                "detection.foot_sigma_fraction",
                self.detection.foot_sigma_fraction,
            ),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::parameter(key, value, "must be a finite σ ≥ 0"));
            }
        }
        for (key, value) in [
            ("birth_overlap", self.birth_overlap),
            ("birth_min_motion", self.birth_min_motion),
            ("birth_min_foreground", self.birth_min_foreground),
            ("duplicate_overlap", self.duplicate_overlap),
            ("detection.match_iou", self.detection.match_iou),
            ("detection.low_match_iou", self.detection.low_match_iou),
            ("detection.proposal_share", self.detection.proposal_share),
            (
                "detection.velocity_smoothing",
                self.detection.velocity_smoothing,
            ),
            ("detection.size_smoothing", self.detection.size_smoothing),
            ("proposal.share", self.proposal.share),
            ("proposal.min_iou", self.proposal.min_iou),
        ] {
            if !(0.0..=1.0).contains(&value) {
                return Err(Error::parameter(key, value, "must be in [0, 1]"));
            }
        }
        for (key, value) in [("death_log_likelihood", self.death_log_likelihood)] {
            if !value.is_finite() {
                return Err(Error::parameter(
                    key,
                    value,
                    "must be a finite log-likelihood",
                ));
            }
        }
        let smooth = self.detection.smooth_frames;
        if !(smooth.is_finite() && (0.0..=100.0).contains(&smooth)) {
            return Err(Error::parameter(
                "detection.smooth_frames",
                smooth,
                "must be a σ in frames within [0, 100] (0: no smoothing; 1 is typical)",
            ));
        }
        let colour_weight = self.detection.colour_weight;
        if !(colour_weight.is_finite() && colour_weight >= 0.0) {
            return Err(Error::parameter(
                "detection.colour_weight",
                colour_weight,
                "must be a finite weight ≥ 0 (0: assign on IoU alone)",
            ));
        }
        if self.detection.high_score.is_nan() {
            return Err(Error::parameter(
                "detection.high_score",
                self.detection.high_score,
                "must be a score (default 0.5)",
            ));
        }
        if !(self.revive_gate_growth.is_finite() && self.revive_gate_growth >= 0.0) {
            return Err(Error::parameter(
                "revive_gate_growth",
                self.revive_gate_growth,
                "must be a finite number of box heights per frame ≥ 0 (default 0.1)",
            ));
        }
        if !(self.revive_gate_max.is_finite() && self.revive_gate_max >= REVIVAL_GATE_AT_DEATH) {
            return Err(Error::parameter(
                "revive_gate_max",
                self.revive_gate_max,
                "must be a finite number of box heights ≥ 0.5 (the gate at the death)",
            ));
        }
        for (key, frames) in [
            ("death_frames", self.death_frames),
            ("unsupported_frames", self.unsupported_frames),
            ("confirm_frames", self.confirm_frames),
            ("detection.min_hits", self.detection.min_hits),
        ] {
            if frames == 0 {
                return Err(Error::parameter(key, 0, "must be ≥ 1 frame"));
            }
        }
        self.appearance.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn combinations_parse_as_the_paper_writes_them() {
        let models = ModelName::parse_combination("cv_CA_Mp").unwrap();
        assert_eq!(models, [ModelName::Cv, ModelName::Ca, ModelName::Mp]);
        assert_eq!(ModelName::combination_label(&models), "CV_CA_MP");
        let err = ModelName::parse_combination("CV_XX")
            .unwrap_err()
            .to_string();
        assert!(err.contains("XX"), "{err}");
        assert!(ModelName::parse_combination("CV_CV").is_err());
        assert!(PedestrianParams::default().validate().is_ok());
    }
}

//! Parameters of the PTV tracker, with TracTrac's defaults.

use serde::{Deserialize, Serialize};
use sillage_core::{Error, NumberOrWord, Result};

/// Parameters of [`crate::ptv::PtvTracker`]. Keys and defaults are those of TracTrac's
/// parameter file as its command line fills them in (`set_default_parameter`), so a
/// TracTrac `*_par.txt` maps one to one; `vote_search_px`, `ambiguity_ratio`,
/// `max_displacement_px`, `dt`, `velocity_window`, `warm_up_frames`, `restore_flanked` and
/// `own_motion` are additions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PtvParams {
    /// Use the motion model to predict positions before associating (default `true`).
    pub motion: bool,
    /// k, the number of nearest model samples averaged (Eq. 8); default 10.
    pub motion_av: usize,
    /// Extra predict–associate iterations per frame, the model rebuilt from the frame's own
    /// tracklets (§3.1.2 "iterative sequence"); default 0.
    pub motion_it: usize,
    /// Reject tracklets whose prediction error is an outlier (§3.1.3); default `true`.
    pub filter: bool,
    /// n_σ of the outlier test on the log10 error (§3.1.3); default 1.5. May be negative.
    pub filter_std: f64,
    /// Memory weight of the motion model and of the threshold (TracTrac's relaxation weight;
    /// the paper's α ≈ 1 / (1 + filter_time)); default 1.0.
    pub filter_time: f64,
    /// Displacement voting for fast flows (p⁻¹ ≳ 0.5, see `voting`): at every frame, the
    /// motion model's prediction is corrected by the local displacement that the pairs
    /// within this many px of it vote for, and before the model has samples (the start of
    /// the first pass) the prediction is voted from zero motion. A number of px: the largest
    /// expected error of a zero-motion guess, i.e. the largest displacement; `"off"`:
    /// TracTrac's behaviour (the prediction is the model alone, zero at the start); `"auto"`
    /// (the default): decided on the first two frames, see [`VoteSearch::AUTO`].
    pub vote_search_px: VoteSearch,
    /// Ambiguity (ratio) test, for flows where objects appear and vanish (intermittency):
    /// a link is dropped when the nearest point of frame t to the prediction is not
    /// clearly nearer than the second, `d₁ > ambiguity_ratio · d₂` (Lowe's ratio test).
    /// A correct link sits at the prediction's error from it, far closer than the spacing;
    /// a point that appeared at random does not. 0.3 is a good value; default `None`
    /// (TracTrac's behaviour). In fast flows, use it with `vote_search_px`.
    pub ambiguity_ratio: Option<f64>,
    /// Reject pairs whose displacement exceeds this many px (TracTrac has no such gate);
    /// default `None`.
    pub max_displacement_px: Option<f64>,
    /// Time between frames in the unit velocities are reported in; 1.0 gives px/frame.
    pub dt: f64,
    /// Frames of a trajectory its reported velocity and acceleration are fitted over (odd, 3
    /// to [`MAX_VELOCITY_WINDOW`]): the slope of the least-squares line and twice the leading
    /// coefficient of the least-squares parabola through them, each window narrowed where the
    /// path bends or the trajectory ends; 3 is TracTrac's Eqs. 6 and 7. Default
    /// [`DEFAULT_VELOCITY_WINDOW`]. Points leave the tracker `window / 2 − 1` frames later.
    pub velocity_window: usize,
    /// Frames the first pass tracks only to learn the motion model before it starts again
    /// at its first frame with that model, its outlier threshold back at its start; 0
    /// starts from rest, as TracTrac does. A first link from rest, with nothing to predict
    /// from, is what breaks when particles move a good share of their spacing; after a few
    /// frames the model knows the flow. Those frames' points leave the tracker once the
    /// warm-up is over (or at the end of a shorter sequence). Default
    /// [`DEFAULT_WARM_UP_FRAMES`]; training passes (`training_passes`) replace it.
    #[serde(default)]
    pub warm_up_frames: usize,
    /// Write a point the outlier test rejected when its trajectory vouches for it: the
    /// points just before and just after it were kept, and the five positions around it lie
    /// on a path a cubic fits to within the positions' noise (their fourth difference). The
    /// test of §3.1.3 compares a central-difference velocity with the motion model's, and
    /// where the model errs (strong accelerations, a coarse local average) it rejects points
    /// of trajectories it keeps on both sides. Needs the fitted velocities
    /// (`velocity_window` ≥ 5); `false` writes what TracTrac writes. Default `true`
    /// ([`DEFAULT_RESTORE_FLANKED`]).
    #[serde(default = "default_restore_flanked")]
    pub restore_flanked: bool,
    /// Blend each point's prediction with its own trajectory's last displacement: a point of
    /// frame t−1 linked to frame t−2 by a tracklet of the previous step is predicted at
    /// `x + w·d_own + (1 − w)·U·Δt`, with `d_own` its last displacement (constant velocity),
    /// `U` the motion model (Eq. 8) and `w = e_U² / (e_U² + e_own²)` the inverse-variance
    /// weight of two estimates of errors `e_U` (the model's expected error there, 10^ε̄ of
    /// Eq. 11) and `e_own` (that tracklet's acceleration times Δt², the error of a
    /// constant-velocity step). Where the flow turns within the model's k neighbours (cells,
    /// vortices smaller than the seeding's reach) the model's average errs and the trajectory
    /// does not; where the positions are noisy the model's average wins. Only the prediction
    /// changes: the outlier test still compares with the model. `false` predicts with the
    /// model alone, as TracTrac does. Default `true` ([`DEFAULT_OWN_MOTION`]).
    #[serde(default = "default_own_motion")]
    pub own_motion: bool,
}

/// The default [`PtvParams::own_motion`]. Chosen on the tune halves of both accuracy
/// families among four forms against the model alone (mean true / false recoveries %, main
/// then moderate): the model alone 66.36 / 13.37 and 90.40 / 2.28; the trajectory's displacement alone 66.10 /
/// 13.23 and 90.73 / 1.91; their mean 66.25 / 13.27 and 90.83 / 2.05; the one of smaller
/// expected error 66.43 / 13.34 and 90.93 / 2.11; the inverse-variance blend 66.40 / 13.34
/// and 90.96 / 2.12 (no weight to tune). On the report halves, never used to choose: main
/// 51.68 / 25.87 → 51.66 / 25.74, moderate 90.85 / 1.99 → 91.61 / 1.74 (cellular vortex
/// arrays up to +11.9 points, `cellular_array-m7` 53.12 / 9.41 → 65.03 / 4.46; no case loses
/// more than 0.11 point); three unseen seeds of the paper's vortex (25,000 particles on
/// 2048², 5,000 on 1024² at two speeds) lose 0.10–0.13 point of true recoveries and 0.04–0.05
/// of false ones (`docs/ptv.md`, "Predictions that follow the trajectory").
pub const DEFAULT_OWN_MOTION: bool = true;

fn default_own_motion() -> bool {
    DEFAULT_OWN_MOTION
}

/// The default [`PtvParams::restore_flanked`]. Decided on the tune halves of both accuracy
/// families (no value to tune: the smoothness test uses the 3σ of the fitted velocities'
/// window rule); see `docs/ptv.md`, "Rejected points a trajectory vouches for".
pub const DEFAULT_RESTORE_FLANKED: bool = true;

fn default_restore_flanked() -> bool {
    DEFAULT_RESTORE_FLANKED
}

/// The default [`PtvParams::warm_up_frames`]. Chosen on the tune halves of both accuracy
/// families (`sillage bench ptv-accuracy --half tune --set tracker.warm_up_frames=K`, 10-frame
/// cases, mean true / false recoveries %): main 61.9 / 13.7 (0), 62.0 / 13.6 (3), 62.0 / 13.5
/// (5), 61.9 / 13.5 (10); moderate 81.7 / 4.5, 83.8 / 4.1, 84.2 / 3.9, 84.6 / 3.7. On the
/// report halves, never used to choose: main 48.0 / 24.7 → 48.7 / 24.4, moderate 82.6 / 4.1
/// → 85.1 / 3.3 (cellular array up to +12 points), no case losing more than 0.2 point; the
/// issue's cellular vortex array (5,000 particles on 1024², σ 1–1.25 px, ≤ 5 px/frame, SNR
/// 12) 88.3 / 1.6 → 93.4 / 0.1 (`docs/ptv.md`, "A warm-up before the first link"). Keeping
/// the outlier threshold learnt in the warm-up instead of restarting it lost up to 4 points
/// on sparse noisy cases.
pub const DEFAULT_WARM_UP_FRAMES: usize = 10;

/// The longest [`PtvParams::warm_up_frames`] (its detections are held in memory).
pub const MAX_WARM_UP_FRAMES: usize = 1000;

/// The default [`PtvParams::velocity_window`]. Chosen on the tune halves of both accuracy
/// families (`sillage bench ptv-accuracy --half tune --set tracker.velocity_window=W`, mean
/// true / false recoveries %): main family 58.4 / 17.9 (3 frames, Eq. 6), 60.9 / 14.9 (5),
/// 61.2 / 14.6 (7), 61.2 / 14.5 (9); moderate family 81.4 / 4.9, 81.6 / 4.6, 81.6 / 4.6,
/// 81.6 / 4.6. Seven is where the gain stops; a wider window is only more delay and, on
/// curved paths, more bias for Lepski's rule to refuse. On the report halves, never used to
/// choose: main 46.7 / 27.5 → 47.8 / 25.3 (no case worse; slow turbulence with σ 2 px
/// 51.8 / 37.6 → 62.8 / 24.4), moderate 82.4 / 4.4 → 82.6 / 4.2 (no case worse), the
/// median displacement error of true recoveries 0.069 → 0.048 and 0.078 → 0.053 px per
/// frame (`docs/ptv.md`, "Velocities fitted along trajectories").
pub const DEFAULT_VELOCITY_WINDOW: usize = 7;

/// The widest [`PtvParams::velocity_window`], frames.
pub const MAX_VELOCITY_WINDOW: usize = 21;

impl Default for PtvParams {
    fn default() -> Self {
        Self {
            motion: true,
            motion_av: 10,
            motion_it: 0,
            filter: true,
            filter_std: 1.5,
            filter_time: 1.0,
            vote_search_px: VoteSearch::AUTO,
            ambiguity_ratio: None,
            max_displacement_px: None,
            dt: 1.0,
            velocity_window: DEFAULT_VELOCITY_WINDOW,
            warm_up_frames: DEFAULT_WARM_UP_FRAMES,
            restore_flanked: DEFAULT_RESTORE_FLANKED,
            own_motion: DEFAULT_OWN_MOTION,
        }
    }
}

/// Displacement voting: off, on over a given radius, or decided from the first two frames. In
/// TOML, a number of px, `"off"` or `"auto"`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VoteSearch {
    /// On, searching this many px around the prediction.
    Px(f64),
    /// `"off"` or `"auto"`.
    Mode(VoteMode),
}

/// The named settings of [`VoteSearch`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum VoteMode {
    /// No voting (TracTrac's behaviour).
    Off,
    /// Measured on the first two frames of the first pass (see [`VoteSearch::AUTO`]).
    Auto,
}

impl Serialize for VoteSearch {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        match self {
            VoteSearch::Px(px) => serializer.serialize_f64(*px),
            VoteSearch::Mode(mode) => mode.serialize(serializer),
        }
    }
}

impl<'de> Deserialize<'de> for VoteSearch {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        NumberOrWord::read(
            deserializer,
            "a number of px, \"off\" or \"auto\"",
            VoteSearch::Px,
            |word| match word {
                "off" => Some(VoteSearch::OFF),
                "auto" => Some(VoteSearch::AUTO),
                _ => None,
            },
        )
    }
}

impl VoteSearch {
    /// Off (TracTrac's behaviour).
    pub const OFF: VoteSearch = VoteSearch::Mode(VoteMode::Off);
    /// The first two frames are voted on from zero motion within 0.9 mean spacings, or within
    /// four (16–64 px) when that vote carries a tenth more of the points onto a point of the
    /// second frame, or when the narrow one lands hardly more than random displacements
    /// would: when the 95th percentile of the voted displacements reaches
    /// [`AUTO_VOTE_FIRST_LINK_SPACINGS`] of the spacing the vote predicts the first link, and
    /// when it reaches [`AUTO_VOTE_SPACINGS`] voting stays on with a search radius of
    /// [`AUTO_VOTE_MARGIN`] × that displacement; else it is off. A vote that resolved less
    /// than [`AUTO_VOTE_MIN_VALID_SHARE`] of the points is not used at all, unless the
    /// displacements reach [`AUTO_VOTE_UNRESOLVED_SPACINGS`].
    pub const AUTO: VoteSearch = VoteSearch::Mode(VoteMode::Auto);
}

impl Default for VoteSearch {
    /// [`VoteSearch::AUTO`].
    fn default() -> Self {
        VoteSearch::AUTO
    }
}

/// The automatic vote predicts the first link (and seeds the motion model) when the measured
/// displacements (95th percentile) reach this share of the mean spacing; below, the first
/// link starts from zero motion as in TracTrac. Tuned on the **tune** half of the
/// `bench ptv-accuracy` family (12 cases; mean true / false recoveries, measured with a
/// single 4-spacing first vote): never 57.68 / 17.20 %, 0.3 the same, **0.2 57.73 / 17.13**,
/// 0.1 57.48 / 17.15, 0.05 57.48 / 17.13; with the final two-stage first vote 57.75 / 17.15.
/// On the report half (unseen): 45.1 / 22.6 % without automatic voting, 46.1 / 25.2 % with it
/// (fast flows +1 to +8 points; one case no setting can track, 0.05 ppp at 10 px/frame, goes
/// from 46 % to 87 % false recoveries because voting then stays on, see
/// [`AUTO_VOTE_SPACINGS`]).
pub const AUTO_VOTE_FIRST_LINK_SPACINGS: f64 = 0.2;

/// Voting stays on for the whole run when the measured displacements reach this share of the
/// mean spacing: p⁻¹ ≳ 0.5, where nearest neighbours start to fail (see `voting` and the
/// paper's fast-flow case). Not tuned: on the tune half of the family no case reaches it.
pub const AUTO_VOTE_SPACINGS: f64 = 0.5;

/// The automatic vote is used (to predict the first link and seed the motion model, or to
/// stay on) only when at least this share of the points lie in voting cells that found their
/// own displacement — a significant histogram peak that passed the normalised median test,
/// PIV's valid-vector ratio. Where the flow turns within a cell (a cellular array of
/// vortices about twice the cell across), the cell's points disagree, most cells find no peak
/// and take their neighbours' vector: that field is made up, and a model seeded with it
/// keeps linking wrongly for many frames. Then the run starts as TracTrac does, from rest.
///
/// Tuned on the **tune** half of `sillage::ptv_accuracy_bench::moderate_family`
/// (24 cases, 512², 10 frames, displacements 0.3–0.6 of the spacing; mean true / false
/// recoveries): no test 76.8 / 8.0 %, 0.3 78.5 / 6.6, 0.4 79.0 / 6.4, **0.5 79.3 / 6.4**, 0.6
/// 78.9 / 6.6, 0.7 78.7 / 6.7, never voting 76.1 / 8.1 (the test gating both uses; gating
/// only the first link: 0.5 78.1 / 7.3). Unseen, on its **report** half (24 cases): 78.0 / 7.9
/// → 79.9 / 6.0 %, cases within 2 points of the per-case tuned true recovery 7 → 9 (only
/// cellular arrays change, e.g. 53.3 / 14.1 → 68.1 / 8.3 and 16.5 / 55.2 → 43.5 / 16.0);
/// both halves of `family` unchanged (46.1 / 25.2 % on its report half).
pub const AUTO_VOTE_MIN_VALID_SHARE: f64 = 0.5;

/// From this many mean spacings of displacement (95th percentile) on, the automatic vote is
/// used even when it resolved less than [`AUTO_VOTE_MIN_VALID_SHARE`] of the points: there a
/// start from rest links almost every particle to a neighbour, and even a partly resolved vote
/// does better (a fast vortex at p⁻¹ ≈ 4.5 resolves 49.5 % of its points: its rim moves
/// beyond the first search). Not tuned (p⁻¹ ≈ 1, where nearest neighbours fail); no case of
/// either tune half reaches it.
pub const AUTO_VOTE_UNRESOLVED_SPACINGS: f64 = 1.0;

/// The automatic search radius is this multiple of the measured displacement (95th
/// percentile), so that faster particles of the same flow are still searched.
pub const AUTO_VOTE_MARGIN: f64 = 2.0;

/// Largest accepted `motion_it` (each iteration costs a full association).
const MAX_MOTION_IT: usize = 100;

impl PtvParams {
    /// Checks every value; the error names the key and its allowed range.
    pub fn validate(&self) -> Result<()> {
        if self.motion_av == 0 {
            return Err(Error::parameter(
                "motion_av",
                self.motion_av,
                "must be an integer ≥ 1 (number of neighbours averaged; TracTrac uses 10)",
            ));
        }
        if self.motion_it > MAX_MOTION_IT {
            return Err(Error::parameter(
                "motion_it",
                self.motion_it,
                format!("must be an integer in 0..={MAX_MOTION_IT}"),
            ));
        }
        if !self.filter_std.is_finite() {
            return Err(Error::parameter(
                "filter_std",
                self.filter_std,
                "must be a finite number (n_σ, typically 1.5)",
            ));
        }
        if !(self.filter_time.is_finite() && self.filter_time >= 0.0) {
            return Err(Error::parameter(
                "filter_time",
                self.filter_time,
                "must be a finite number ≥ 0 (typically 1)",
            ));
        }
        if let VoteSearch::Px(radius) = self.vote_search_px
            && !(radius.is_finite() && radius > 0.0)
        {
            return Err(Error::parameter(
                "vote_search_px",
                radius,
                "must be a finite number > 0 (the largest expected displacement, px), \
                 \"off\" or \"auto\"",
            ));
        }
        if let Some(ratio) = self.ambiguity_ratio
            && !(ratio > 0.0 && ratio <= 1.0)
        {
            return Err(Error::parameter(
                "ambiguity_ratio",
                ratio,
                "must be a number in (0, 1] (typically 0.3), or absent for no ambiguity test",
            ));
        }
        if let Some(gate) = self.max_displacement_px
            && !(gate.is_finite() && gate > 0.0)
        {
            return Err(Error::parameter(
                "max_displacement_px",
                gate,
                "must be a finite number > 0, or absent for no gate",
            ));
        }
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(Error::parameter(
                "dt",
                self.dt,
                "must be a finite number > 0 (backward passes negate it themselves)",
            ));
        }
        let window = self.velocity_window;
        if window.is_multiple_of(2) || !(3..=MAX_VELOCITY_WINDOW).contains(&window) {
            return Err(Error::parameter(
                "velocity_window",
                window,
                format!(
                    "must be an odd number of frames from 3 (TracTrac's central difference) \
                     to {MAX_VELOCITY_WINDOW}; the default is {DEFAULT_VELOCITY_WINDOW}"
                ),
            ));
        }
        if self.warm_up_frames > MAX_WARM_UP_FRAMES {
            return Err(Error::parameter(
                "warm_up_frames",
                self.warm_up_frames,
                format!(
                    "must be at most {MAX_WARM_UP_FRAMES} frames (their detections are held in \
                     memory); 0 starts from rest, the default is {DEFAULT_WARM_UP_FRAMES}"
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_errors_name_the_key() {
        PtvParams::default().validate().unwrap();
        let cases = [
            (
                "motion_av",
                PtvParams {
                    motion_av: 0,
                    ..Default::default()
                },
            ),
            (
                "motion_it",
                PtvParams {
                    motion_it: 1000,
                    ..Default::default()
                },
            ),
            (
                "filter_std",
                PtvParams {
                    filter_std: f64::NAN,
                    ..Default::default()
                },
            ),
            (
                "filter_time",
                PtvParams {
                    filter_time: -1.0,
                    ..Default::default()
                },
            ),
            (
                "vote_search_px",
                PtvParams {
                    vote_search_px: VoteSearch::Px(f64::INFINITY),
                    ..Default::default()
                },
            ),
            (
                "ambiguity_ratio",
                PtvParams {
                    ambiguity_ratio: Some(1.5),
                    ..Default::default()
                },
            ),
            (
                "max_displacement_px",
                PtvParams {
                    max_displacement_px: Some(0.0),
                    ..Default::default()
                },
            ),
            (
                "dt",
                PtvParams {
                    dt: 0.0,
                    ..Default::default()
                },
            ),
            (
                "velocity_window",
                PtvParams {
                    velocity_window: 6,
                    ..Default::default()
                },
            ),
            (
                "velocity_window",
                PtvParams {
                    velocity_window: 1,
                    ..Default::default()
                },
            ),
            (
                "velocity_window",
                PtvParams {
                    velocity_window: MAX_VELOCITY_WINDOW + 2,
                    ..Default::default()
                },
            ),
        ];
        for (key, params) in cases {
            let message = params.validate().unwrap_err().to_string();
            assert!(message.contains(&format!("`{key}`")), "{message}");
        }
    }
}

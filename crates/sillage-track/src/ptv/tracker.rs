//! The PTV tracker: three-frame association, kinematics, outlier filter, id hand-over.

use rayon::prelude::*;
use sillage_assoc::{Neighbour, NeighbourIndex, PointIndex, mutual_pairs_from_forward};
use sillage_core::{
    Detection, DiscardSink, Error, FrameIndex, FrameObservations, Point2, Result, TrackId,
    TrackPoint, TrackSink, Tracker, Vec2,
};

use super::filter::{INITIAL_THRESHOLD, log10_error, updated_threshold};
use super::motion::{MotionField, Samples};
use super::params::{
    AUTO_VOTE_FIRST_LINK_SPACINGS, AUTO_VOTE_MARGIN, AUTO_VOTE_MIN_VALID_SHARE, AUTO_VOTE_SPACINGS,
    AUTO_VOTE_UNRESOLVED_SPACINGS, PtvParams, VoteMode, VoteSearch,
};
use super::smoothing::{Linked, StepFrames, VelocitySmoother};
use super::voting::{Vote, mean_spacing, voted_displacements};

/// The automatic vote's first search radius, in mean spacings, and its smallest value in px.
const AUTO_VOTE_NEAR_SPACINGS: f64 = 0.9;
const AUTO_VOTE_NEAR_MIN_PX: f64 = 4.0;
/// A voted displacement "lands" when it carries its point to within this share of the
/// mean spacing of a point of the next frame (a random displacement does so with probability
/// ≈ π·0.25² ≈ 0.2). Not tuned: 0.15 and 0.35 give the tune halves of `bench ptv-accuracy`
/// the same means within 0.01 point.
const AUTO_VOTE_LANDING_SPACINGS: f64 = 0.25;
/// The wide vote replaces the narrow one when it lands this share of the points more. Tuned
/// on the tune halves of `bench ptv-accuracy` (with `detector.refit_crowded`; mean true /
/// false %, moderate half): 0.02 → 89.09 / 2.46, 0.05 → 89.78 / 2.14, **0.1 → 89.78 /
/// 2.14** (the main half 65.68 / 13.01 for all three), 0.1 being further from the drop. On
/// the report halves (unseen), against the rule it replaced (widen when the narrow vote's
/// 95th percentile reached 70 % of its radius): moderate 90.20 / 1.92 % both, main 51.27 /
/// 25.69 → 51.48 / 22.45 %. The paper's fast vortex (δ = 0.2), whose aliased narrow vote sat
/// on the old rule's edge, lands 26 % of its points narrow and 50 % wide.
const AUTO_VOTE_WIDEN_MARGIN: f64 = 0.1;
/// The wide vote is also taken when the narrow one lands fewer than this many times the
/// share that random displacements would land: the narrow vote is aliased, and when the
/// particles move further than the wide search too, both land at about chance (the paper's
/// vortex at δ = 0.3, p⁻¹ ≈ 6.75: 22–23 % and 25–27 %, chance 18 %), where the wide vote
/// then keeps voting on. Chosen on the tune halves of `bench ptv-accuracy` (no narrow vote
/// there lands under 33 %; 1.5 leaves them unchanged, 2 costs the moderate half 0.6 point)
/// and on `sillage synth vortex --frames 24 --delta 0.3` seeds 11 and 12 (1.2 / 96.7 → 47.1 /
/// 12.8 and 1.1 / 97.3 → 48.0 / 13.4 %). Unseen, seed 21 against the 70 % rule this replaced:
/// δ = 0.35 0.8 / 98.1 → 32.7 / 29.1 %, δ = 0.25 61.2 / 9.3 → 59.5 / 7.7 %, δ = 0.12 88.6 /
/// 0.9 → 88.9 / 0.7 %; the report halves unchanged by it.
const AUTO_VOTE_ALIASED_CHANCES: f64 = 1.5;
/// The widened search radius, in mean spacings, and its bounds in px.
const AUTO_VOTE_FIRST_SPACINGS: f64 = 4.0;
const AUTO_VOTE_FIRST_MIN_PX: f64 = 16.0;
const AUTO_VOTE_FIRST_MAX_PX: f64 = 64.0;

/// Voted corrections shorter than this share of the mean spacing between points are left
/// out: too small to change a nearest neighbour, they would only replace the model's own
/// prediction by the coarser voted one. Measured: taking every correction costs 2 points of
/// true recoveries on the paper's slow vortex; from 1/32 of the spacing on, the slow vortex
/// is tracked exactly as without voting. Larger shares help the moderately fast vortex
/// (δ = 0.05: 88.2 % at 1/32, 88.9 % at 1/16, 90.6 % at 1/8) but hurt a fast solid rotation,
/// whose centripetal lag they leave uncorrected (recall 0.883, 0.866, 0.844).
const VOTE_MIN_CORRECTION_SPACINGS: f64 = 0.0625;

/// When the outlier test rejects more than this share of a frame's tracklets, the motion model
/// is what failed (the flow changed: a pump starting, a shock, the camera knocked), not the
/// links: the frame's tracklets are kept, as across a missing frame, and the threshold
/// restarts from [`INITIAL_THRESHOLD`]. Without it a uniform flow that jumps from 2 to 8 px per
/// frame was lost for good: every tracklet of the new speed was rejected, so the model never
/// learned it (link recall 0.47 over 20 frames with the defaults, none after the jump's fourth
/// frame; 0.999 with the restart). Not tuned: in normal runs the test rejects at most 14–18 %
/// of a frame's tracklets (both accuracy families' tune halves, the vortex integration tests,
/// 25,000 particles on 2048²); on both halves of both families one case changes, one beyond PTV
/// for every setting (0.05 particles per pixel at 10 px per frame: 94.7 → 97.7 % false).
const FILTER_RESTART_KEPT_SHARE: f64 = 0.5;

/// A rejected tracklet among mostly rejected ones is kept when its velocity lies within this
/// share of the model's departure from their median velocity
/// ([`PtvTracker::keep_coherent_changes`]). Not tuned (chosen before any measurement). With
/// it a band of 30 % of a lattice that speeds up from 2 to 8 px per frame is tracked again
/// (recall 0.83 → 0.96); unseen, both accuracy families' means move by at most 0.26 point
/// (docs/ptv.md, "A change in part of the field").
const COHERENT_CHANGE_SHARE: f64 = 0.25;

/// The median of `values` (the upper one of an even count), reordering them.
fn median_in_place(values: &mut [f64]) -> f64 {
    let mid = values.len() / 2;
    *values.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// While the motion model predicts, a vote searches this many times the largest correction
/// the previous vote made to the model's displacements, at least [`VOTE_REACH_MIN_PX`], instead
/// of the whole decided radius: the model is usually right to a pixel or two, and the pairs a
/// vote weighs grow with the square of its radius (on 25,000 particles moving up to 10 px per
/// frame, corrections of at most 1.1–1.9 px under a decided radius of 19.5 px).
const VOTE_REACH_CORRECTIONS: f64 = 4.0;
/// The least radius of such a vote, px.
const VOTE_REACH_MIN_PX: f64 = 4.0;

/// The next vote's search radius after a vote within `radius` (the decided one `search_px`)
/// corrected the model's displacements `prior` into `voted`: [`VOTE_REACH_CORRECTIONS`] times
/// the largest correction, or `None` (the decided radius) when a correction reached half of
/// `radius`, where the model may have fallen behind the flow by more than the vote saw.
fn next_vote_reach(voted: &[Vec2], prior: &[Vec2], radius: f64, search_px: f64) -> Option<f64> {
    let largest = voted
        .iter()
        .zip(prior)
        .map(|(&v, &p)| (v - p).norm())
        .fold(0.0, f64::max);
    let reach = (VOTE_REACH_CORRECTIONS * largest).max(VOTE_REACH_MIN_PX);
    (largest < 0.5 * radius && reach < search_px).then_some(reach)
}

/// Fewest points a rayon task handles in the per-point loops (keeps task overhead small).
const PAR_MIN_LEN: usize = 1024;

/// Direction of a pass over the sequence (TracTrac's `vid_loop` alternates them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum PassDirection {
    /// Frames arrive in increasing order; time step `+dt`.
    #[default]
    Forward,
    /// Frames arrive in decreasing order; time step `−dt`, so velocities keep their
    /// forward-in-time sign and the motion model stays valid.
    Backward,
}

/// The time steps of a triplet t−2 → t−1 → t: one frame each, more across missing frames.
#[derive(Debug, Clone, Copy)]
struct Steps {
    /// Frames from t−2 to t−1.
    before: u64,
    /// Frames from t−1 to t.
    after: u64,
    /// The signed time step of one frame.
    dt: f64,
}

impl Steps {
    /// Whether a frame is missing within the triplet.
    fn spans_gap(self) -> bool {
        self.before > 1 || self.after > 1
    }
}

/// One point of frame t−1 linked backwards and forwards: a candidate tracklet.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
struct Triplet {
    /// Index in frame t−2.
    before: usize,
    /// Index in frame t−1 (the middle, emitted frame).
    middle: usize,
    /// Index in frame t.
    after: usize,
    vel: Vec2,
    acc: Vec2,
    log_err: f64,
    kept: bool,
}

/// TracTrac's tracker (see the [module docs](super)): emits the points of frame t−1, in
/// increasing track id order, with the velocity fitted along the trajectory over
/// `velocity_window` frames (Eq. 6 with 3, at the step of frame t; with more, `window / 2 − 1`
/// steps later), the acceleration (Eq. 7), the motion-model velocity (Eq. 8) and the log10
/// prediction error (Eq. 10).
///
/// `finish` hands out the frames still held for their velocity windows. The first and the
/// last frame of a pass are never the middle of a triplet (TracTrac also outputs frames
/// 1..n−2 only).
///
/// Warm-up ([`PtvParams::warm_up_frames`]): the first frames are tracked once with their
/// points discarded, then again from the first with the motion model they taught, emitting.
///
/// Training passes: [`PtvTracker::start_pass`] starts a new pass over the same sequence,
/// keeping the motion model and the outlier threshold. The caller (the facade) drives them,
/// e.g. TracTrac's `vid_loop = 2`: Forward over frames 0..n, Backward over n−1..=0, then
/// Forward again, keeping only the last pass's output (give the training passes a sink that
/// discards). Each pass restarts track ids at 0.
///
/// Deterministic: no random tie-break (nearest-neighbour ties go to the lower index), and
/// parallel work is per point with sequential reductions, so the output is the same bit for
/// bit whatever the number of rayon threads.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct PtvTracker {
    params: PtvParams,
    direction: PassDirection,
    /// Frames received in this pass, capped at 2 (then every frame makes a full step).
    frames_in_pass: u8,
    /// Frame index of `c1`.
    frame_c1: FrameIndex,
    /// Frames from `c0` to `c1`: 1, or more across frames missing from the sequence.
    gap_c1: u64,
    // Positions of frames t−2, t−1 and t, and raw indexes of t−1 and t.
    c0: Vec<Point2>,
    c1: Vec<Point2>,
    c2: Vec<Point2>,
    index_c1: PointIndex,
    index_c2: PointIndex,
    index_pred: PointIndex,
    /// Per point of `c1`: its mutual partner in `c0`.
    link01: Vec<Option<usize>>,
    /// Per point of `c1`: the acceleration of the tracklet of the previous step that ended
    /// on it (its trajectory's at t−2), for [`PtvParams::own_motion`]; and per point of `c2`,
    /// this step's, rotated in by [`PtvTracker::shift`] (absent from older checkpoints).
    #[serde(default)]
    back_acc: Vec<Option<Vec2>>,
    #[serde(default)]
    ahead_acc: Vec<Option<Vec2>>,
    /// Per point of `c0`: the track id its tracklet handed over.
    ids0: Vec<Option<TrackId>>,
    next_id: TrackId,
    // Learned state, kept across passes.
    /// Good tracklets of the previous step (model samples of weight 1).
    recent: Samples,
    /// Model stored at the previous step (samples of weight `filter_time`).
    stored: Samples,
    threshold: f64,
    // Buffers reused from frame to frame.
    field: MotionField,
    next_stored: Samples,
    current: Samples,
    vel_pred: Vec<Vec2>,
    log_err_pred: Vec<f64>,
    pred: Vec<Point2>,
    displacements: Vec<Vec2>,
    voted: Vec<Vec2>,
    /// Voting's search radius once decided (`None`: off); `decided` false while an
    /// automatic decision waits for the first two frames.
    vote_radius: Option<f64>,
    vote_decided: bool,
    /// The next vote's search radius while the model predicts ([`next_vote_reach`]): `None`
    /// searches the whole `vote_radius`.
    #[serde(default)]
    vote_reach: Option<f64>,
    /// An automatic decision taken elsewhere that this tracker follows (a time window of a
    /// longer run: `Some(radius)`, or `None` for off), see [`PtvTracker::follow_vote_decision`].
    #[serde(default)]
    followed_decision: Option<Option<f64>>,
    /// The displacement (95th percentile, px) the automatic decision measured.
    measured_displacement: Option<f64>,
    /// The automatic decision's vote: share of the points whose cell found its own peak.
    #[serde(default)]
    measured_valid_share: Option<f64>,
    forward: Vec<Option<Neighbour>>,
    two_nearest: Vec<Vec<Neighbour>>,
    link12: Vec<Option<usize>>,
    link21: Vec<Option<usize>>,
    triplets: Vec<Triplet>,
    errors: Vec<f64>,
    /// Per point of frame t−1: whether its tracklet was rejected (`None`: no tracklet), and
    /// its velocity (reused).
    #[serde(skip)]
    rejected_at: Vec<Option<bool>>,
    #[serde(skip)]
    velocity_at: Vec<Vec2>,
    ids1: Vec<Option<TrackId>>,
    /// (track id, triplet) of the points to emit, sorted into the emission order.
    emit_order: Vec<(TrackId, usize)>,
    /// (track id, triplet) of the rejected tracklets that carry an id, for the velocity fit.
    #[serde(skip)]
    carry_order: Vec<(TrackId, usize)>,
    /// Scratch of the radix sorts of `emit_order` and `carry_order`.
    emit_scratch: Vec<(TrackId, usize)>,
    emitted: Vec<TrackPoint>,
    /// The rejected tracklets' points that carry an id, in `carry_order`, for the smoother
    /// to restore where their trajectories vouch for them (`restore_flanked`).
    #[serde(skip)]
    rejected: Vec<TrackPoint>,
    /// Fits the emitted points' velocities along their trajectories, holding them until
    /// their windows are complete (absent from older checkpoints: Eq. 6 velocities). Boxed:
    /// its buffers would make the tracker the one large variant of the facade's tracker enum.
    #[serde(default)]
    smoother: Box<VelocitySmoother>,
    /// The positions of the emitted points' trajectories and of the rejected tracklets'
    /// carrying an id, around frame t−1.
    #[serde(skip)]
    linked: Vec<Linked>,
    #[serde(skip)]
    carried: Vec<Linked>,
    /// The first pass's warm-up ([`PtvParams::warm_up_frames`]); absent from older
    /// checkpoints, which are past it.
    #[serde(default)]
    warm_up: WarmUp,
}

/// log10 of a prediction error (px) below which a tracklet is never an outlier: 0.1 px. A
/// wrong link errs by about a particle spacing; TracTrac's relative test alone (§3.1.3)
/// refused a 0.04 px error on a drifting lattice once the model predicted to 0.014 px
/// (`tests/pipeline.rs`, with the warm-up's model). Neutral on the accuracy families (tune
/// halves 61.95 / 13.45 % and 84.60 / 3.72 % with and without it; report halves, never used
/// to choose, within 0.02 point), so not a tuned value.
const SURE_LINK_LOG_ERR: f64 = -1.0;

/// Where the first pass's warm-up stands.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
enum WarmUp {
    /// Over (or off): frames are tracked and emitted.
    #[default]
    Done,
    /// The frames tracked so far, their points discarded, kept to be tracked again.
    Collecting(Vec<(FrameIndex, Vec<Detection>)>),
}

impl PtvTracker {
    /// A tracker with validated `params`, starting a forward pass.
    pub fn new(params: PtvParams) -> Result<Self> {
        params.validate()?;
        let vote = params.vote_search_px;
        let params_warm_up = params.warm_up_frames;
        let smoother = Box::new(VelocitySmoother::new(
            params.velocity_window,
            params.dt,
            params.restore_flanked,
        ));
        Ok(Self {
            field: MotionField::new(params.motion_av, params.filter_time),
            params,
            direction: PassDirection::Forward,
            frames_in_pass: 0,
            frame_c1: 0,
            gap_c1: 1,
            c0: Vec::new(),
            c1: Vec::new(),
            c2: Vec::new(),
            index_c1: PointIndex::default(),
            index_c2: PointIndex::default(),
            index_pred: PointIndex::default(),
            link01: Vec::new(),
            back_acc: Vec::new(),
            ahead_acc: Vec::new(),
            ids0: Vec::new(),
            next_id: 0,
            recent: Samples::default(),
            stored: Samples::default(),
            threshold: INITIAL_THRESHOLD,
            next_stored: Samples::default(),
            current: Samples::default(),
            vel_pred: Vec::new(),
            log_err_pred: Vec::new(),
            pred: Vec::new(),
            displacements: Vec::new(),
            voted: Vec::new(),
            vote_radius: match vote {
                VoteSearch::Px(radius) => Some(radius),
                VoteSearch::Mode(_) => None,
            },
            vote_decided: vote != VoteSearch::Mode(VoteMode::Auto),
            vote_reach: None,
            followed_decision: None,
            measured_displacement: None,
            measured_valid_share: None,
            forward: Vec::new(),
            two_nearest: Vec::new(),
            link12: Vec::new(),
            link21: Vec::new(),
            triplets: Vec::new(),
            errors: Vec::new(),
            ids1: Vec::new(),
            emit_order: Vec::new(),
            carry_order: Vec::new(),
            emit_scratch: Vec::new(),
            rejected_at: Vec::new(),
            velocity_at: Vec::new(),
            emitted: Vec::new(),
            rejected: Vec::new(),
            smoother,
            linked: Vec::new(),
            carried: Vec::new(),
            warm_up: if params_warm_up > 0 {
                WarmUp::Collecting(Vec::with_capacity(params_warm_up))
            } else {
                WarmUp::Done
            },
        })
    }

    /// How many points the outlier test rejected were written in this pass because their
    /// trajectories vouch for them ([`PtvParams::restore_flanked`]).
    pub fn restored_points(&self) -> u64 {
        self.smoother.restored()
    }

    /// The parameters in use.
    pub fn params(&self) -> &PtvParams {
        &self.params
    }

    /// Voting's search radius in use (`None`: off, or an automatic decision not yet made).
    pub fn vote_radius(&self) -> Option<f64> {
        self.vote_radius
    }

    /// With `vote_search_px = "auto"`, links its first two frames as the automatic decision
    /// does (a vote from rest) but then follows `radius` (`Some`: voting on with that search
    /// radius; `None`: off) instead of deciding: a time window of a run whose decision was
    /// taken on the run's first frames, so that every window links as that run does.
    pub fn follow_vote_decision(&mut self, radius: Option<f64>) {
        self.followed_decision = Some(radius);
    }

    /// The displacement an automatic voting decision measured on the first two frames (95th
    /// percentile, px).
    pub fn measured_displacement(&self) -> Option<f64> {
        self.measured_displacement
    }

    /// The share of the points whose voting cell found its own displacement in the automatic
    /// decision's vote (PIV's valid-vector ratio); below [`AUTO_VOTE_MIN_VALID_SHARE`] the
    /// vote is not used.
    pub fn measured_vote_valid_share(&self) -> Option<f64> {
        self.measured_valid_share
    }

    /// Starts a new pass over the sequence in `direction` (TracTrac's `vid_loop`): forgets
    /// the frames and track ids of the current pass, keeps the motion model and the outlier
    /// threshold it has learned. In a `Backward` pass frames must arrive in decreasing order.
    /// A warm-up still under way is dropped: the passes train the model instead.
    pub fn start_pass(&mut self, direction: PassDirection) {
        self.warm_up = WarmUp::Done;
        self.direction = direction;
        self.frames_in_pass = 0;
        self.next_id = 0;
        self.smoother
            .start_pass(direction == PassDirection::Forward);
    }

    /// The time step of this pass, negative when going backwards.
    fn signed_dt(&self) -> f64 {
        match self.direction {
            PassDirection::Forward => self.params.dt,
            PassDirection::Backward => -self.params.dt,
        }
    }

    /// Copies the detections of `obs` into `c2`, checking frame order and positions.
    fn load_frame(&mut self, obs: &FrameObservations<'_>) -> Result<()> {
        if self.frames_in_pass > 0 {
            let (ok, order) = match self.direction {
                PassDirection::Forward => (obs.frame > self.frame_c1, "increasing"),
                PassDirection::Backward => (obs.frame < self.frame_c1, "decreasing"),
            };
            if !ok {
                return Err(Error::input(format!(
                    "frame {} arrived after frame {} in a {:?} pass; frames must come in \
                     {order} order (call start_pass to change direction)",
                    obs.frame, self.frame_c1, self.direction
                )));
            }
        }
        self.c2.clear();
        for (i, d) in obs.detections.iter().enumerate() {
            if !d.pos_px.is_finite() {
                return Err(Error::input(format!(
                    "frame {}: detection {i} is at ({}, {}); positions must be finite \
                     (check the detector)",
                    obs.frame, d.pos_px.x, d.pos_px.y
                )));
            }
            self.c2.push(d.pos_px);
        }
        Ok(())
    }

    /// Whether the motion model applies with `recent` samples: it is on, has samples to
    /// average and points to predict.
    fn model_applies(&self, recent: &Samples) -> bool {
        self.params.motion && recent.len() + self.stored.len() > 1 && !self.c1.is_empty()
    }

    /// Indexes frame t and, when the model applies, prepares it from the previous step's
    /// tracklets, side by side (the two are independent); returns whether it applies.
    fn index_frame_and_model(&mut self) -> bool {
        let applied = self.model_applies(&self.recent);
        let (index_c2, c2) = (&mut self.index_c2, &self.c2);
        let (field, recent, stored) = (&mut self.field, &self.recent, &self.stored);
        rayon::join(
            || index_c2.rebuild(c2),
            || {
                if applied {
                    field.prepare(recent, stored);
                }
            },
        );
        applied
    }

    /// Predicts `c1 + U·dt` with the prepared model when `model_applied` (zero motion
    /// otherwise), corrected by displacement voting when it is on.
    fn predict(&mut self, model_applied: bool, dt: f64) {
        if model_applied {
            self.field.evaluate(
                &self.c1,
                &mut self.vel_pred,
                &mut self.log_err_pred,
                &mut self.next_stored,
            );
        } else {
            self.vel_pred.clear();
            self.vel_pred.resize(self.c1.len(), Vec2::ZERO);
            self.log_err_pred.clear();
            self.log_err_pred.resize(self.c1.len(), 0.0);
        }
        if !self.vote_decided && !model_applied {
            self.decide_voting(dt);
        } else if let Some(search_px) = self.vote_radius {
            self.correct_by_voting(model_applied, search_px, dt);
        }
        self.pred.clear();
        self.pred.extend(
            self.c1
                .iter()
                .zip(&self.vel_pred)
                .map(|(&p, &u)| p + u * dt),
        );
        // The links back to frame t−2 and their accelerations are this pass's from the
        // second full step on.
        if self.params.own_motion && model_applied && self.frames_in_pass >= 2 {
            self.blend_own_motion(dt);
        }
    }

    /// [`PtvParams::own_motion`]: moves each prediction of a point linked back to frame t−2
    /// towards `x + d_own`, its last displacement scaled to this link's `dt`, by the
    /// inverse-variance weight of the two predictions' expected errors.
    fn blend_own_motion(&mut self, dt: f64) {
        let one_frame = self.signed_dt();
        let scale = dt / (one_frame * self.gap_c1 as f64);
        // The model's errors ε̄ were measured over one frame (`make_tracklets`).
        let model_frames = dt / one_frame;
        let (c0, c1, vel_pred) = (&self.c0, &self.c1, &self.vel_pred);
        let (log_err_pred, back_acc) = (&self.log_err_pred, &self.back_acc);
        self.pred
            .par_iter_mut()
            .zip(&self.link01)
            .enumerate()
            .with_min_len(PAR_MIN_LEN)
            .for_each(|(j, (pred, back))| {
                let (Some(i), Some(Some(acc))) = (*back, back_acc.get(j)) else {
                    return;
                };
                let own = (c1[j] - c0[i]) * scale;
                let model = vel_pred[j] * dt;
                let own_err = acc.max_abs() * dt * dt;
                let model_err = 10f64.powf(log_err_pred[j]) * model_frames;
                let total = own_err * own_err + model_err * model_err;
                if total > 0.0 {
                    let w = model_err * model_err / total;
                    *pred = c1[j] + own * w + model * (1.0 - w);
                }
            });
    }

    /// The automatic voting decision ([`VoteSearch::AUTO`]) on the first two frames: a vote
    /// from zero motion within 0.9 spacings, or over four where that one lands more points or
    /// the first lands about at random ([`Self::widened_if_it_lands_more`]), measures the
    /// displacements (95th percentile).
    /// When they reach [`AUTO_VOTE_FIRST_LINK_SPACINGS`] of the spacing, the vote predicts this
    /// first link (and seeds the motion model), as voting does; when they reach
    /// [`AUTO_VOTE_SPACINGS`], voting stays on for the rest of the run. Neither when the vote
    /// resolved less than [`AUTO_VOTE_MIN_VALID_SHARE`] of the points, unless the
    /// displacements reach [`AUTO_VOTE_UNRESOLVED_SPACINGS`].
    fn decide_voting(&mut self, dt: f64) {
        self.vote_decided = true;
        let spacing = mean_spacing(&self.c1);
        // A search within one spacing first: a regular pattern (a calibration grid) votes
        // as much for its period as for the true displacement, and slow flows need no more.
        // The wide search is taken only when its displacements carry clearly more points
        // onto the next frame's, or when the narrow one's land hardly more than at random.
        let near_radius = (AUTO_VOTE_NEAR_SPACINGS * spacing).max(AUTO_VOTE_NEAR_MIN_PX);
        let far_radius = (AUTO_VOTE_FIRST_SPACINGS * spacing)
            .clamp(AUTO_VOTE_FIRST_MIN_PX, AUTO_VOTE_FIRST_MAX_PX);
        let vote = match self.vote_from_rest(near_radius) {
            Some(near) => Some(self.widened_if_it_lands_more(near, far_radius, spacing)),
            None => self.vote_from_rest(far_radius),
        };
        let Some(vote) = vote else {
            self.vote_radius = self.followed_decision.flatten();
            return;
        };
        let p95 = percentile_norm(&self.voted, 0.95);
        self.measured_displacement = Some(p95);
        self.measured_valid_share = Some(vote.valid_share);
        // A vote that could not resolve the flow (most of its cells took their neighbours'
        // displacement) would seed the model with a field it made up: TracTrac's start,
        // unless the particles move a spacing or more, where a start from rest cannot work.
        let resolved = vote.valid_share >= AUTO_VOTE_MIN_VALID_SHARE
            || p95 >= AUTO_VOTE_UNRESOLVED_SPACINGS * spacing;
        if resolved && p95 >= AUTO_VOTE_FIRST_LINK_SPACINGS * spacing {
            self.displacements.clear();
            self.displacements.resize(self.c1.len(), Vec2::ZERO);
            self.apply_votes(&vote, false, dt);
        }
        self.vote_radius = match self.followed_decision {
            Some(radius) => radius,
            None => (resolved && p95 >= AUTO_VOTE_SPACINGS * spacing)
                .then(|| (AUTO_VOTE_MARGIN * p95).max(1.0)),
        };
    }

    /// The narrow vote `near` (its displacements in `self.voted`), or the vote within
    /// `far_radius` px when that one carries [`AUTO_VOTE_WIDEN_MARGIN`] more of the points
    /// onto a point of frame t ([`AUTO_VOTE_LANDING_SPACINGS`]), or when the narrow one
    /// lands under [`AUTO_VOTE_ALIASED_CHANCES`] times what random displacements would. An
    /// aliased narrow vote (the particles move further than it searched) lands its points
    /// about at random; on a regular pattern both land alike, and the narrow vote is kept.
    fn widened_if_it_lands_more(&mut self, near: Vote, far_radius: f64, spacing: f64) -> Vote {
        let landing_px = AUTO_VOTE_LANDING_SPACINGS * spacing;
        let near_landed = self.landing_share(landing_px);
        let near_voted = std::mem::take(&mut self.voted);
        let far_vote = self.vote_from_rest(far_radius);
        // A narrow vote that lands hardly more points than displacements drawn at random is
        // aliased whatever the wide one does: the wide search is larger, and voting then
        // stays on over twice its displacements.
        let aliased = near_landed < AUTO_VOTE_ALIASED_CHANCES * self.chance_landing_share();
        match far_vote {
            Some(far)
                if aliased
                    || self.landing_share(landing_px) > near_landed + AUTO_VOTE_WIDEN_MARGIN =>
            {
                far
            }
            _ => {
                self.voted = near_voted;
                near
            }
        }
    }

    /// Share of the points of frame t−1 that displacements drawn at random would carry to
    /// within [`AUTO_VOTE_LANDING_SPACINGS`] mean spacings of a point of frame t (points of
    /// frame t spread uniformly): `1 − exp(−π r² n_t / n_{t−1})` in spacings.
    fn chance_landing_share(&self) -> f64 {
        let density = self.c2.len() as f64 / self.c1.len().max(1) as f64;
        1.0 - (-std::f64::consts::PI * AUTO_VOTE_LANDING_SPACINGS.powi(2) * density).exp()
    }

    /// Share of the points of frame t−1 that their voted displacement (`self.voted`) carries
    /// to within `radius_px` of a point of frame t.
    fn landing_share(&self, radius_px: f64) -> f64 {
        if self.c1.is_empty() {
            return 0.0;
        }
        let landed = self
            .c1
            .par_iter()
            .zip(&self.voted)
            .filter(|&(&p, &d)| {
                let mut hit = false;
                self.index_c2
                    .for_each_within(p + d, radius_px, |_, _| hit = true);
                hit
            })
            .count();
        landed as f64 / self.c1.len() as f64
    }

    /// The displacements voted from zero motion within `radius` px, into `self.voted`.
    fn vote_from_rest(&mut self, radius: f64) -> Option<Vote> {
        let mut voted = std::mem::take(&mut self.voted);
        let vote = voted_displacements(&self.c1, &self.c2, None, radius, &mut voted);
        self.voted = voted;
        vote
    }

    /// Displacement voting (`vote_search_px`): replaces the predicted velocities by the
    /// displacement voted within `search_px` of them, where the two differ by more than
    /// [`VOTE_MIN_CORRECTION_SPACINGS`] of the spacing. Without a model (`model_applied`
    /// false) the vote starts from zero motion and its result is also stored as the model,
    /// so that the next frame is predicted from it.
    fn correct_by_voting(&mut self, model_applied: bool, search_px: f64, dt: f64) {
        self.displacements.clear();
        self.displacements
            .extend(self.vel_pred.iter().map(|&u| u * dt));
        let radius = match self.vote_reach {
            Some(reach) if model_applied => reach.min(search_px),
            _ => search_px,
        };
        let mut voted = std::mem::take(&mut self.voted);
        let vote = voted_displacements(
            &self.c1,
            &self.c2,
            Some(&self.displacements),
            radius,
            &mut voted,
        );
        self.voted = voted;
        self.vote_reach = match &vote {
            Some(_) if model_applied => {
                next_vote_reach(&self.voted, &self.displacements, radius, search_px)
            }
            _ => None,
        };
        if let Some(vote) = vote {
            self.apply_votes(&vote, model_applied, dt);
        }
    }

    /// Takes the voted displacements `self.voted` (priors in `self.displacements`) as the
    /// predicted velocities, where they differ from the prior by more than
    /// [`VOTE_MIN_CORRECTION_SPACINGS`] of the spacing (everywhere without a model, whose
    /// samples they then become).
    fn apply_votes(&mut self, vote: &Vote, model_applied: bool, dt: f64) {
        let min_correction_px = VOTE_MIN_CORRECTION_SPACINGS * vote.spacing_px;
        for ((u, &d), &prior) in self
            .vel_pred
            .iter_mut()
            .zip(&self.voted)
            .zip(&self.displacements)
        {
            if !model_applied || (d - prior).norm() > min_correction_px {
                *u = d / dt;
            }
        }
        if !model_applied {
            self.stored.clear();
            for (&p, &u) in self.c1.iter().zip(&self.vel_pred) {
                self.stored.push(p, u, vote.resolution_px.log10());
            }
        }
    }

    /// Mutual nearest neighbours between the predictions and frame t (Eq. 9 then §3.1.2),
    /// reusing frame t's index; without a model the predictions are frame t−1 itself and
    /// its index is reused too.
    fn associate(&mut self, model_applied: bool) {
        // The predictions' index is built while frame t's index answers the forward queries.
        let (pred, index_c2) = (&self.pred, &self.index_c2);
        let (forward, two_nearest) = (&mut self.forward, &mut self.two_nearest);
        let mut forward_queries = || {
            if self.params.ambiguity_ratio.is_some() {
                index_c2.k_nearest_batch(pred, 2, two_nearest);
                forward.clear();
                forward.extend(two_nearest.iter().map(|n| n.first().copied()));
            } else {
                index_c2.nearest_batch_near(pred, forward);
            }
        };
        let c2 = &self.c2;
        let (pred_index, pred) = if model_applied {
            let index_pred = &mut self.index_pred;
            rayon::join(|| index_pred.rebuild(pred), forward_queries);
            (&self.index_pred, pred)
        } else {
            forward_queries();
            (&self.index_c1, &self.c1)
        };
        // The backward half of the mutual test, checked within each forward pair's
        // distance only (a fraction of a nearest query when the prediction is good).
        mutual_pairs_from_forward(
            pred_index,
            pred,
            c2,
            &self.forward,
            &mut self.link12,
            &mut self.link21,
        );
        if let Some(ratio) = self.params.ambiguity_ratio {
            let two = &self.two_nearest;
            retain_links(
                &mut self.link12,
                &mut self.link21,
                |j, _| match two[j][..] {
                    [(_, d1), (_, d2)] => d1 <= ratio * d2,
                    _ => true,
                },
            );
        }
        if let Some(gate) = self.params.max_displacement_px {
            let (c1, c2) = (&self.c1, &self.c2);
            retain_links(&mut self.link12, &mut self.link21, |j, k| {
                c1[j].distance(c2[k]) <= gate
            });
        }
    }

    /// Builds the triplets t−2 ↔ t−1 ↔ t, their kinematics and errors, applies the outlier
    /// test and updates the threshold; the kept ones become `current`. Prediction errors are
    /// measured over one frame's `dt`. Across a missing frame the model predicts from older
    /// samples, so its errors are not comparable: the outlier test is not applied there and
    /// the threshold is left as it was (mutual nearest neighbours still decide the links).
    fn make_tracklets(&mut self, steps: Steps) {
        let (c0, c1, c2) = (&self.c0, &self.c1, &self.c2);
        let (vel_pred, log_err_pred) = (&self.vel_pred, &self.log_err_pred);
        let (filter, threshold) = (self.params.filter && !steps.spans_gap(), self.threshold);
        let (dt_before, dt_after, dt) = (
            steps.dt * steps.before as f64,
            steps.dt * steps.after as f64,
            steps.dt,
        );
        // The linked triplets in middle-point order, then their kinematics in parallel, in
        // place (the log10 dominates; collecting filtered results in parallel cost twice as
        // much in allocations and copies).
        self.triplets.clear();
        self.triplets
            .extend(self.link01.iter().zip(&self.link12).enumerate().filter_map(
                |(middle, (&back, &ahead))| {
                    Some(Triplet {
                        before: back?,
                        middle,
                        after: ahead?,
                        vel: Vec2::ZERO,
                        acc: Vec2::ZERO,
                        log_err: 0.0,
                        kept: false,
                    })
                },
            ));
        self.triplets
            .par_iter_mut()
            .with_min_len(PAR_MIN_LEN)
            .for_each(|t| {
                let (x0, x1, x2) = (c0[t.before], c1[t.middle], c2[t.after]);
                let u0 = (x1 - x0) / dt_before;
                let u1 = (x2 - x1) / dt_after;
                // Eq. (6): v(t−1) = (x(t) − x(t−2)) / 2Δt, the mean of the two finite
                // differences; across a missing frame, the three-point derivative for unequal
                // steps (each difference weighted by the other step).
                t.vel = if dt_before == dt_after {
                    (u0 + u1) * 0.5
                } else {
                    (u0 * dt_after + u1 * dt_before) / (dt_before + dt_after)
                };
                // Eq. (7), whose signs were lost in the text:
                // a(t−1) = (x(t) − 2x(t−1) + x(t−2)) / Δt² (the mean step for unequal ones).
                t.acc = (u1 - u0) / (0.5 * (dt_before + dt_after));
                t.log_err = log10_error(vel_pred[t.middle], t.vel, dt);
                // §3.1.3: outlier when ε − ε̄ ≥ threshold (the threshold stands for
                // n_σ·σ̄_ε).
                t.kept = !filter
                    || t.log_err - log_err_pred[t.middle] < threshold
                    || t.log_err < SURE_LINK_LOG_ERR;
            });
        let kept = self.triplets.iter().filter(|t| t.kept).count();
        let model_failed =
            filter && (kept as f64) < FILTER_RESTART_KEPT_SHARE * self.triplets.len() as f64;
        if model_failed {
            // Most tracklets far from the model at once: the flow changed, not the links.
            // They are kept, as across a missing frame, and the threshold restarts.
            self.triplets.iter_mut().for_each(|t| t.kept = true);
            self.threshold = INITIAL_THRESHOLD;
        } else if filter && kept < self.triplets.len() {
            self.keep_coherent_changes();
        }
        self.errors.clear();
        self.errors.extend(self.triplets.iter().map(|t| t.log_err));
        self.current.clear();
        for t in self.triplets.iter().filter(|t| t.kept) {
            self.current.push(self.c1[t.middle], t.vel, t.log_err);
        }
        if !steps.spans_gap() {
            self.threshold = updated_threshold(
                self.threshold,
                &self.errors,
                self.params.filter_std,
                self.params.filter_time,
            );
        }
    }

    /// Keeps the rejected tracklets that move with the rejected ones around them: among the
    /// `motion_av + 1` nearest points of frame t−1 more than half carry a rejected tracklet,
    /// and the tracklet's velocity lies within [`COHERENT_CHANGE_SHARE`] of the model's
    /// departure from their median velocity. A part of the flow that changed at once moves
    /// together, away from the model; wrong links, even many together, scatter.
    fn keep_coherent_changes(&mut self) {
        let n = self.c1.len();
        let (rejected_at, velocity_at) = (&mut self.rejected_at, &mut self.velocity_at);
        rejected_at.clear();
        rejected_at.resize(n, None);
        velocity_at.clear();
        velocity_at.resize(n, Vec2::ZERO);
        for t in &self.triplets {
            rejected_at[t.middle] = Some(!t.kept);
            velocity_at[t.middle] = t.vel;
        }
        let (triplets, c1, vel_pred) = (&self.triplets, &self.c1, &self.vel_pred);
        let queries: Vec<Point2> = triplets
            .iter()
            .filter(|t| !t.kept)
            .map(|t| c1[t.middle])
            .collect();
        let (rejected_at, velocity_at) = (&*rejected_at, &*velocity_at);
        let mut coherent = Vec::new();
        self.index_c1.map_k_nearest(
            &queries,
            self.params.motion_av + 1,
            &mut coherent,
            |ids, _| {
                let own = ids[0] as usize;
                let (mut xs, mut ys) = (Vec::new(), Vec::new());
                let mut kept = 0usize;
                for &i in &ids[1..] {
                    match rejected_at[i as usize] {
                        Some(true) => {
                            xs.push(velocity_at[i as usize].x);
                            ys.push(velocity_at[i as usize].y);
                        }
                        Some(false) => kept += 1,
                        None => {}
                    }
                }
                // The rejected ones, this tracklet included (xs.len() + 1), must outnumber
                // the kept ones.
                if xs.is_empty() || xs.len() < kept {
                    return false;
                }
                let median = Vec2::new(median_in_place(&mut xs), median_in_place(&mut ys));
                let departure = (median - vel_pred[own]).norm();
                (velocity_at[own] - median).norm() <= COHERENT_CHANGE_SHARE * departure
            },
        );
        let mut coherent = coherent.into_iter();
        for t in self.triplets.iter_mut().filter(|t| !t.kept) {
            t.kept = coherent.next().unwrap_or(false);
        }
    }

    /// §3.1.4: each tracklet takes the id of its t−2 ↔ t−1 link; kept tracklets without one
    /// get a new id; rejected ones still pass an inherited id on. Emits the kept ones, to the
    /// velocity fit with the positions of every tracklet carrying an id ([`Self::link`];
    /// frame t is `frame_c2`).
    ///
    /// The points are put in id order through (id, triplet) keys rather than by sorting the
    /// points themselves (16-byte keys instead of whole track points), then built in parallel.
    fn hand_over_ids(&mut self, frame_c2: FrameIndex, sink: &mut dyn TrackSink) -> Result<()> {
        let fits = !self.smoother.passes_through();
        self.ids1.clear();
        self.ids1.resize(self.c1.len(), None);
        self.emit_order.clear();
        self.carry_order.clear();
        for (n, t) in self.triplets.iter().enumerate() {
            let mut id = self.ids0[t.before];
            if id.is_none() && t.kept {
                id = Some(self.next_id);
                self.next_id += 1;
            }
            self.ids1[t.middle] = id;
            match (id, t.kept) {
                (Some(track_id), true) => self.emit_order.push((track_id, n)),
                (Some(track_id), false) if fits => self.carry_order.push((track_id, n)),
                _ => {}
            }
        }
        sort_by_track_id(&mut self.emit_order, &mut self.emit_scratch);
        let mut emitted = std::mem::take(&mut self.emitted);
        self.points_of(&self.emit_order, &mut emitted);
        self.emitted = emitted;
        let frame = self.frame_c1;
        let frames = StepFrames {
            before: match self.direction {
                PassDirection::Forward => frame.saturating_sub(self.gap_c1),
                PassDirection::Backward => frame + self.gap_c1,
            },
            at: frame,
            after: frame_c2,
        };
        if fits {
            sort_by_track_id(&mut self.carry_order, &mut self.emit_scratch);
            let (mut linked, mut carried) = (
                std::mem::take(&mut self.linked),
                std::mem::take(&mut self.carried),
            );
            self.link(&self.emit_order, &mut linked);
            self.link(&self.carry_order, &mut carried);
            (self.linked, self.carried) = (linked, carried);
            if self.params.restore_flanked {
                let mut rejected = std::mem::take(&mut self.rejected);
                self.points_of(&self.carry_order, &mut rejected);
                self.rejected = rejected;
            }
        }
        self.smoother.push(
            frames,
            &mut self.emitted,
            &mut self.rejected,
            &self.linked,
            &self.carried,
            sink,
        )
    }

    /// The track points (frame t−1) of the tracklets `order` names, into `points`.
    fn points_of(&self, order: &[(TrackId, usize)], points: &mut Vec<TrackPoint>) {
        let (triplets, vel_pred, c1, frame) =
            (&self.triplets, &self.vel_pred, &self.c1, self.frame_c1);
        order
            .par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map(|&(track_id, n)| {
                let t = &triplets[n];
                TrackPoint {
                    vel_px_per_frame: Some(t.vel),
                    acc_px_per_frame2: Some(t.acc),
                    vel_pred_px_per_frame: Some(vel_pred[t.middle]),
                    log10_pred_err: Some(t.log_err),
                    detection: Some(t.middle as u32),
                    ..TrackPoint::at(frame, track_id, c1[t.middle])
                }
            })
            .collect_into_vec(points);
    }

    /// The three positions (frames t−2, t−1, t) of the tracklets `order` names, for the
    /// velocity fit, into `linked`.
    fn link(&self, order: &[(TrackId, usize)], linked: &mut Vec<Linked>) {
        let (triplets, c0, c1, c2) = (&self.triplets, &self.c0, &self.c1, &self.c2);
        order
            .par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map(|&(id, n)| {
                let t = &triplets[n];
                Linked {
                    id,
                    positions: [c0[t.before], c1[t.middle], c2[t.after]],
                }
            })
            .collect_into_vec(linked);
    }

    /// Frame t (`gap` frames after t−1) becomes t−1: rotates positions, indexes, links and
    /// ids.
    fn shift(&mut self, frame: FrameIndex, gap: u64) {
        self.gap_c1 = gap;
        std::mem::swap(&mut self.c0, &mut self.c1);
        std::mem::swap(&mut self.c1, &mut self.c2);
        std::mem::swap(&mut self.index_c1, &mut self.index_c2);
        std::mem::swap(&mut self.link01, &mut self.link21);
        std::mem::swap(&mut self.back_acc, &mut self.ahead_acc);
        std::mem::swap(&mut self.ids0, &mut self.ids1);
        self.frame_c1 = frame;
    }
}

/// Sorts (track id, triplet) keys by track id with a least-significant-digit radix sort on
/// the id's bytes, up to the highest byte an id uses: a few linear passes instead of a
/// comparison sort, which was half of the id hand-over (570 µs for 20k keys). Ids are unique
/// among the emitted points, so the result is that of any sort.
fn sort_by_track_id(keys: &mut Vec<(TrackId, usize)>, scratch: &mut Vec<(TrackId, usize)>) {
    let largest = keys.iter().map(|&(id, _)| id).max().unwrap_or(0);
    let bytes = (TrackId::BITS - largest.leading_zeros()).div_ceil(8);
    scratch.clear();
    scratch.resize(keys.len(), (0, 0));
    for byte in 0..bytes {
        let digit = |id: TrackId| ((id >> (8 * byte)) & 0xff) as usize;
        let mut starts = [0usize; 256];
        for &(id, _) in keys.iter() {
            starts[digit(id)] += 1;
        }
        let mut total = 0;
        for start in &mut starts {
            (*start, total) = (total, total + *start);
        }
        for &key in keys.iter() {
            let slot = &mut starts[digit(key.0)];
            scratch[*slot] = key;
            *slot += 1;
        }
        std::mem::swap(keys, scratch);
    }
}

/// Drops the mutual links `j ↔ k` (kept in both directions) for which `keep(j, k)` is false.
fn retain_links(
    link12: &mut [Option<usize>],
    link21: &mut [Option<usize>],
    keep: impl Fn(usize, usize) -> bool,
) {
    for (j, link) in link12.iter_mut().enumerate() {
        if let Some(k) = *link
            && !keep(j, k)
        {
            *link = None;
            link21[k] = None;
        }
    }
}

/// The `q` quantile of the norms of `vectors` (0 when empty).
fn percentile_norm(vectors: &[Vec2], q: f64) -> f64 {
    if vectors.is_empty() {
        return 0.0;
    }
    let mut norms: Vec<f64> = vectors.iter().map(|d| d.norm()).collect();
    let at = ((norms.len() - 1) as f64 * q).round() as usize;
    *norms.select_nth_unstable_by(at, f64::total_cmp).1
}

impl PtvTracker {
    /// Tracks the warm-up's frames again from the first, emitting their points, with the
    /// motion model they taught and the outlier threshold back at its start (carried from
    /// the end of the warm-up, it was tighter than the early links of a pass can meet).
    fn end_warm_up(&mut self, sink: &mut dyn TrackSink) -> Result<()> {
        let WarmUp::Collecting(frames) = std::mem::take(&mut self.warm_up) else {
            return Ok(());
        };
        self.start_pass(PassDirection::Forward);
        self.threshold = INITIAL_THRESHOLD;
        for (frame, detections) in &frames {
            self.step_pass(
                &FrameObservations::from_detections(*frame, detections),
                sink,
            )?;
        }
        Ok(())
    }

    /// One frame of the current pass.
    fn step_pass(&mut self, obs: &FrameObservations<'_>, sink: &mut dyn TrackSink) -> Result<()> {
        self.load_frame(obs)?;
        let dt = self.signed_dt();
        // Frames missing from the sequence (skipped bad frames) lengthen the link to this one:
        // predictions reach over the gap and the kinematics use the true time steps.
        let gap = obs.frame.abs_diff(self.frame_c1).max(1);
        let dt_link = dt * gap as f64;
        match self.frames_in_pass {
            0 => {
                std::mem::swap(&mut self.c1, &mut self.c2);
                self.index_c1.rebuild(&self.c1);
                self.frame_c1 = obs.frame;
            }
            1 => {
                // First link of the pass (TracTrac's initialisation): frame 0 ↔ frame 1,
                // predicted with whatever model earlier passes learned, which stays stored.
                let applied = self.index_frame_and_model();
                self.predict(applied, dt_link);
                self.associate(applied);
                self.ids1.clear();
                self.ids1.resize(self.c1.len(), None);
                self.ahead_acc.clear();
                self.ahead_acc.resize(self.c2.len(), None);
                self.shift(obs.frame, gap);
            }
            _ => {
                let mut applied = self.index_frame_and_model();
                let mut model_updated = false;
                for it in 0..=self.params.motion_it {
                    if it > 0 {
                        // Further iterations average this step's own tracklets.
                        applied = self.model_applies(&self.current);
                        if applied {
                            self.field.prepare(&self.current, &self.stored);
                        }
                    }
                    self.predict(applied, dt_link);
                    model_updated |= applied;
                    self.associate(applied);
                    self.make_tracklets(Steps {
                        before: self.gap_c1,
                        after: gap,
                        dt,
                    });
                }
                if model_updated {
                    std::mem::swap(&mut self.stored, &mut self.next_stored);
                }
                self.ahead_acc.clear();
                self.ahead_acc.resize(self.c2.len(), None);
                for t in &self.triplets {
                    self.ahead_acc[t.after] = Some(t.acc);
                }
                self.hand_over_ids(obs.frame, sink)?;
                std::mem::swap(&mut self.recent, &mut self.current);
                self.shift(obs.frame, gap);
            }
        }
        self.frames_in_pass = (self.frames_in_pass + 1).min(2);
        Ok(())
    }
}

impl Tracker for PtvTracker {
    fn step(&mut self, obs: &FrameObservations<'_>, sink: &mut dyn TrackSink) -> Result<()> {
        let WarmUp::Collecting(frames) = &mut self.warm_up else {
            return self.step_pass(obs, sink);
        };
        frames.push((obs.frame, obs.detections.to_vec()));
        let complete = frames.len() >= self.params.warm_up_frames;
        self.step_pass(obs, &mut DiscardSink)?;
        if complete {
            self.end_warm_up(sink)?;
        }
        Ok(())
    }

    fn finish(&mut self, sink: &mut dyn TrackSink) -> Result<()> {
        self.end_warm_up(sink)?;
        self.smoother.flush(sink)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;
    use sillage_core::rng_stream;

    #[test]
    fn the_next_vote_searches_four_times_the_largest_correction_until_one_reaches_half_its_radius()
    {
        let prior = vec![Vec2::new(3.0, 0.0); 3];
        let voted = |dx: f64| {
            vec![
                Vec2::new(3.0, 0.0),
                Vec2::new(3.0 + dx, 0.0),
                Vec2::new(3.0, 0.5),
            ]
        };
        let reach = next_vote_reach(&voted(1.5), &prior, 19.5, 19.5).unwrap();
        assert!((reach - 6.0).abs() < 1e-12, "{reach}");
        // Never below the floor, never the decided radius itself.
        assert_eq!(
            next_vote_reach(&voted(0.1), &prior, 19.5, 19.5),
            Some(VOTE_REACH_MIN_PX)
        );
        assert_eq!(next_vote_reach(&voted(5.0), &prior, 19.5, 19.5), None);
        // A correction at half the searched radius: the model may have fallen behind by more
        // than the vote could see, so the next vote searches the decided radius again.
        assert_eq!(next_vote_reach(&voted(3.0), &prior, 6.0, 19.5), None);
        assert!(next_vote_reach(&voted(2.9), &prior, 6.0, 19.5).is_some());
    }

    #[test]
    fn radix_sort_by_track_id_matches_a_comparison_sort() {
        let mut rng = rng_stream(3, 0);
        let mut scratch = Vec::new();
        for (n, range) in [
            (0, 1),
            (1, 1),
            (300, 256),
            (5000, 1 << 20),
            (5000, 1u64 << 40),
        ] {
            let mut ids: Vec<TrackId> = (0..n).map(|_| rng.random_range(0..range)).collect();
            ids.sort_unstable();
            ids.dedup();
            let mut keys: Vec<(TrackId, usize)> =
                ids.iter().map(|&id| (id, id as usize % 97)).collect();
            for i in (1..keys.len()).rev() {
                keys.swap(i, rng.random_range(0..=i));
            }
            let mut expected = keys.clone();
            expected.sort_unstable();
            sort_by_track_id(&mut keys, &mut scratch);
            assert_eq!(keys, expected, "{n} ids below {range}");
        }
    }
}

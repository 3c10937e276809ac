//! Motion states decided over the trajectory: a fixed-lag forward–backward smoother over the
//! jump-Markov chain of the MMPF+ paper (the transition table π of Eq. (12), `[motion]`), with
//! per-frame evidence from the bead's observed velocity `u_obs` (§3.4.2) and its contact with
//! the nearest bead (Eq. (4)'s contacts, as a distance ratio), both averaged over a window
//! centred on the point. Each point waits for the `half_window` points after it (its evidence)
//! and then `lag` more; its state is the most probable one given everything up to then.
//! Saltating is decided apart, over the steadiest stretch of points around each one
//! ([`SaltationRule`]). The emission model and the saltation threshold are learnt from ground
//! truth with states ([`fit_emission`], `sillage fit bedload --tracks`).

use std::collections::{BTreeMap, VecDeque};

use serde::{Deserialize, Serialize};
use sillage_core::{Calibration, Error, MotionState, Point2, Result, TrackId, TrackPoint, Vec2};

use crate::bedload::contacts::{Contacts, radius_of};

/// A Gaussian over one log-feature of one state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LogGaussian {
    /// Mean of the natural logarithm of the feature.
    pub mean: f64,
    /// Standard deviation of that logarithm, > 0.
    pub sd: f64,
}

impl LogGaussian {
    /// The log-density of `x` (a logarithm already), up to the constant `−½ ln 2π`.
    fn log_density(&self, x: f64) -> f64 {
        let z = (x - self.mean) / self.sd;
        -0.5 * z * z - self.sd.ln()
    }

    /// Mean and standard deviation of `values`, the deviation floored at `min_sd`; `None`
    /// without values.
    fn fit(values: &[f64], min_sd: f64) -> Option<Self> {
        if values.is_empty() {
            return None;
        }
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        Some(Self {
            mean,
            sd: var.sqrt().max(min_sd),
        })
    }
}

/// What one motion state looks like in the evidence of one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StateEmission {
    /// `ln(|ū| + speed_floor)`: `ū` the mean observed velocity over the window, in m/s.
    pub log_speed: LogGaussian,
    /// `ln(mean ratio)`, the ratio the centre distance to the nearest bead over the sum of the
    /// two radii (1 = touching; capped at [`CONTACT_RATIO_CAP`]), averaged over the window.
    pub log_contact: LogGaussian,
}

/// The evidence model of the smoother, in physical units.
///
/// The defaults were learnt by [`fit_emission`] on frames 1–5 of the authors' ten real
/// flume frames (`shared/data/bedload_beads_lafaye2018`, MMPF+ tracks of those frames from
/// our detector, features over ±2 frames; 1,028 resting, 520 rolling, 36 saltating samples).
/// Scored on frames 6–10 only, not used to learn them, the default smoother gives F-scores
/// resting / rolling / saltating of 0.893 / 0.729 / 0.893, against 0.862 / 0.549 / 0.893 for
/// the frame-by-frame Eq. (4) (`docs/bedload.md`). Other set-ups (another camera, detector or
/// noise) should learn their own.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EmissionParams {
    /// Added to the speed before its logarithm, m/s: speeds well below it look alike
    /// (default 0.0013 m/s, 0.05 px/frame on the default calibration — below the jitter of
    /// the position estimates).
    pub speed_floor_m_per_s: f64,
    /// Saltating at or above this speed over the point's steadiest stretch, m/s
    /// ([`SaltationRule::SteadiestSpeed`]); `sillage fit bedload` learns it from the training
    /// points (the centre of the thresholds whose saltating F-score is within
    /// [`SALTATION_PLATEAU_F`] of the best). Default 0.2597 m/s (9.7 px/frame
    /// on the default calibration; the paper's u_salt is 0.25), learnt with the rest of the
    /// defaults on frames 1–5 of the real frames (36 saltating samples).
    pub saltation_speed_m_per_s: f64,
    /// Resting.
    pub resting: StateEmission,
    /// Rolling.
    pub rolling: StateEmission,
    /// Saltating.
    pub saltating: StateEmission,
}

impl Default for EmissionParams {
    fn default() -> Self {
        let state = |speed: (f64, f64), contact: (f64, f64)| StateEmission {
            log_speed: LogGaussian {
                mean: speed.0,
                sd: speed.1,
            },
            log_contact: LogGaussian {
                mean: contact.0,
                sd: contact.1,
            },
        };
        Self {
            speed_floor_m_per_s: 0.05 * 2.056e-4 * 130.0,
            saltation_speed_m_per_s: 0.2597,
            resting: state((-6.410, 0.380), (-0.136, 0.105)),
            rolling: state((-4.413, 1.562), (-0.102, 0.097)),
            saltating: state((-1.181, 0.320), (0.146, 0.132)),
        }
    }
}

/// The largest contact ratio the evidence uses: a bead with no other bead within twice the
/// contact distance counts as at twice the contact distance.
pub const CONTACT_RATIO_CAP: f64 = 2.0;

/// The `[smoother]` section: fixed-lag smoothing of the motion states.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SmootherParams {
    /// Frames a point waits for the ones after it before its state is final. 0 gives the
    /// frame-by-frame state of Eq. (4) (the paper's §3.5.3). Default 4: the F-scores on the
    /// unseen half of the real frames were flat from 1 to 6 (`docs/bedload.md`); the output
    /// lags the input by this many frames.
    pub lag: u32,
    /// Points on each side of a point over which its evidence is averaged: the velocities
    /// `u_obs` (summed as vectors, so that a resting bead's detection jitter cancels) and the
    /// contact ratios of the `2 · half_window + 1` points centred on it (fewer at a
    /// trajectory's ends). 0 gives one frame's evidence. Default 2, the ±2-frame window of the
    /// authors' state labelling (`ComputeMotionStates`); chosen among 0–4 on the synthetic
    /// sequence of `sillage synth bedload` (seed 1, evidence learnt on one half and scored on
    /// the other: 1 and 2 best), and reported on data not used to choose it in
    /// `docs/bedload.md`. A point waits `half_window` frames more for its evidence.
    pub half_window: u32,
    /// How the written saltating states are decided (`saltation`, default `steadiest_speed`).
    pub saltation: SaltationRule,
    /// The evidence model (learnt with the same `half_window`).
    pub emission: EmissionParams,
}

impl Default for SmootherParams {
    fn default() -> Self {
        Self {
            lag: 4,
            half_window: 2,
            saltation: SaltationRule::default(),
            emission: EmissionParams::default(),
        }
    }
}

/// How the smoother writes saltating states.
///
/// A saltation is an event of a few frames, which a window blurs into the rolling before and
/// after it (a rolling bead's window mean takes the hop's speed; the hop's own mean takes the
/// roll's), where resting and rolling are regimes that a window separates. So by default
/// saltating is decided on its own, from a speed estimate that does not cross the hop's ends,
/// and the smoother chooses between resting and rolling elsewhere.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SaltationRule {
    /// Saltating where the speed over the point's steadiest stretch (of the stretches of up
    /// to [`STRETCH_POINTS`] consecutive points that contain it within the evidence window,
    /// the one whose velocities vary least: the stretch that does not cross a take-off or a
    /// landing) is at least `emission.saltation_speed_m_per_s`. The default: chosen on the
    /// synthetic sequences of seeds 1–3 (`sillage synth bedload --frames 1000`, Python
    /// prototype, threshold learnt on one half and scored on the other). Reported on data that
    /// chose nothing: saltating F on synthetic seeds 4–7 (both halves) 0.832–0.866 (Eq. (4))
    /// → 0.889–0.932; on the unseen half of the real frames 0.893 → 0.922 and 0.919 → 0.909,
    /// resting and rolling unchanged (`docs/bedload.md`).
    #[default]
    SteadiestSpeed,
    /// Saltating where the frame-by-frame state of Eq. (4) says so (u ≥ u_salt, or no bead
    /// in contact): the previous default.
    Frame,
    /// All three states smoothed by the forward–backward messages.
    Smoothed,
}

/// The most points of a stretch in [`SaltationRule::SteadiestSpeed`]: a take-off or a
/// landing leaves at least one stretch of three on either side of it for the points of a
/// hop or a roll of three frames or more. Chosen on synthetic seeds 1–3 (mean saltating F
/// 0.926 with 3 points, 0.909 with 2); on seeds 4–7 see [`SaltationRule::SteadiestSpeed`].
pub const STRETCH_POINTS: usize = 3;

/// The most frames a lag may span.
pub const MAX_LAG: u32 = 1000;

/// What the tracker observed of one point for the smoother: its velocity (`u_obs`, or the
/// filtered velocity through a miss) and its contact ratio with the nearest bead.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(crate) struct Cues {
    /// Velocity, px/frame.
    pub vel_px_per_frame: Vec2,
    /// Centre distance to the nearest bead over the sum of the radii, capped at
    /// [`CONTACT_RATIO_CAP`].
    pub contact_ratio: f64,
}

/// The cues of a point (`None` for a trajectory's first point, which has no velocity).
pub(crate) type Evidence = Option<Cues>;

/// What the window around a point says of it, in px and px/frame.
#[derive(Debug, Clone, Copy, PartialEq)]
struct WindowFeatures {
    /// Speed of the mean velocity over the window.
    speed: f64,
    /// Mean contact ratio over the window.
    contact_ratio: f64,
    /// Speed over the steadiest stretch ([`SaltationRule::SteadiestSpeed`]).
    steadiest_speed: f64,
}

/// The window features of point `centre` of `cues` (consecutive points of one trajectory),
/// over the points within `half_window` of it that have cues; `None` when the point itself
/// has none.
fn window_features(cues: &[Evidence], centre: usize, half_window: usize) -> Option<WindowFeatures> {
    let own = cues[centre]?;
    let first = centre.saturating_sub(half_window);
    let last = (centre + half_window).min(cues.len() - 1);
    let (mut vel, mut ratio, mut n) = (Vec2::ZERO, 0.0, 0.0);
    for c in cues[first..=last].iter().flatten() {
        vel = vel + c.vel_px_per_frame;
        ratio += c.contact_ratio;
        n += 1.0;
    }
    // The stretches of STRETCH_POINTS frames containing the point, cut at the window's ends.
    let steadiest = (0..STRETCH_POINTS)
        .filter_map(|after| {
            let start = (centre + after + 1)
                .saturating_sub(STRETCH_POINTS)
                .max(first);
            stretch_spread(&cues[start..=(centre + after).min(last)])
        })
        .min_by(|a, b| a.0.total_cmp(&b.0));
    Some(WindowFeatures {
        speed: vel.norm() / n,
        contact_ratio: ratio / n,
        steadiest_speed: steadiest.map_or(own.vel_px_per_frame.norm(), |(_, speed)| speed),
    })
}

/// The spread of the velocities of `stretch` (the sum of the variances of their two
/// components) and the speed of their mean; `None` with fewer than two velocities.
fn stretch_spread(stretch: &[Evidence]) -> Option<(f64, f64)> {
    let velocities = || stretch.iter().flatten().map(|c| c.vel_px_per_frame);
    let n = velocities().count();
    if n < 2 {
        return None;
    }
    let mean = velocities().fold(Vec2::ZERO, |sum, v| sum + v) / n as f64;
    let spread = velocities().map(|v| (v - mean).norm_squared()).sum::<f64>() / n as f64;
    Some((spread, mean.norm()))
}

/// The validated smoother, features in px and px/frame.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct Smoother {
    lag: usize,
    half_window: usize,
    saltation: SaltationRule,
    /// `emission.saltation_speed_m_per_s` in px/frame.
    saltation_speed_px_per_frame: f64,
    transition: [[f64; 3]; 3],
    states: [StateEmission; 3],
    /// px/frame → m/s.
    m_per_s_per_px_per_frame: f64,
    speed_floor_m_per_s: f64,
}

/// The three states in the smoother's order.
const STATES: [MotionState; 3] = [
    MotionState::Resting,
    MotionState::Rolling,
    MotionState::Saltating,
];

/// `v` scaled to sum to 1 (left as it is when it sums to 0).
fn normalised(v: [f64; 3]) -> [f64; 3] {
    let sum: f64 = v.iter().sum();
    if sum > 0.0 { v.map(|x| x / sum) } else { v }
}

/// The likelihoods of log-likelihoods `e`, scaled so that the largest is 1 (the scale
/// cancels in the smoother's normalised messages).
fn likelihoods(e: [f64; 3]) -> [f64; 3] {
    let max = e.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    e.map(|v| (v - max).exp())
}

fn argmax(values: [f64; 3]) -> usize {
    (1..3).fold(0, |best, i| if values[i] > values[best] { i } else { best })
}

impl SmootherParams {
    /// The smoother over the transition table `transition` (rows: from resting, rolling,
    /// saltating), or `None` for a lag of 0; errors name the key.
    pub(crate) fn smoother(
        &self,
        transition: &[[f64; 3]; 3],
        calibration: &Calibration,
    ) -> Result<Option<Smoother>> {
        for (key, frames, zero) in [
            ("smoother.half_window", self.half_window, "averages nothing"),
            ("smoother.lag", self.lag, "turns smoothing off"),
        ] {
            if frames > MAX_LAG {
                return Err(Error::parameter(
                    key,
                    frames,
                    format!("must be at most {MAX_LAG} frames (a few frames suffice; 0 {zero})"),
                ));
            }
        }
        let e = &self.emission;
        if !(e.speed_floor_m_per_s.is_finite() && e.speed_floor_m_per_s > 0.0) {
            return Err(Error::parameter(
                "smoother.emission.speed_floor_m_per_s",
                e.speed_floor_m_per_s,
                "must be a finite number > 0",
            ));
        }
        if !(e.saltation_speed_m_per_s.is_finite() && e.saltation_speed_m_per_s > 0.0) {
            return Err(Error::parameter(
                "smoother.emission.saltation_speed_m_per_s",
                e.saltation_speed_m_per_s,
                "must be a finite number > 0",
            ));
        }
        for (name, state) in [
            ("resting", &e.resting),
            ("rolling", &e.rolling),
            ("saltating", &e.saltating),
        ] {
            for (feature, g) in [
                ("log_speed", &state.log_speed),
                ("log_contact", &state.log_contact),
            ] {
                let key = format!("smoother.emission.{name}.{feature}");
                if !g.mean.is_finite() {
                    return Err(Error::parameter(
                        format!("{key}.mean"),
                        g.mean,
                        "must be a finite number",
                    ));
                }
                if !(g.sd.is_finite() && g.sd > 0.0) {
                    return Err(Error::parameter(
                        format!("{key}.sd"),
                        g.sd,
                        "must be a finite number > 0",
                    ));
                }
            }
        }
        for (i, row) in transition.iter().enumerate() {
            if row.iter().all(|&p| p <= 0.0) {
                return Err(Error::parameter(
                    format!("motion.transition[{i}]"),
                    format!("{row:?}"),
                    "a row of zeros leaves the state nowhere to go; give each row probabilities \
                     summing to 1",
                ));
            }
        }
        if self.lag == 0 {
            return Ok(None);
        }
        Ok(Some(Smoother {
            lag: self.lag as usize,
            half_window: self.half_window as usize,
            saltation: self.saltation,
            saltation_speed_px_per_frame: e.saltation_speed_m_per_s
                / (calibration.m_per_px * calibration.fps),
            transition: *transition,
            states: [e.resting, e.rolling, e.saltating],
            m_per_s_per_px_per_frame: calibration.m_per_px * calibration.fps,
            speed_floor_m_per_s: e.speed_floor_m_per_s,
        }))
    }
}

/// A point waiting for its state, with its forward message.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct Pending {
    point: TrackPoint,
    /// The evidence as likelihoods scaled to a largest of 1; `None` for no evidence.
    likelihood: Option<[f64; 3]>,
    /// p(state | evidence up to this point), normalised.
    alpha: [f64; 3],
    /// Saltating by the smoother's [`SaltationRule`] (never under `Smoothed`).
    #[serde(default)]
    saltating: bool,
}

/// The points of one trajectory whose states are not final yet.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct StateChain {
    /// The cues of the last `2 · half_window + 1` points pushed (fewer at the start).
    cues: VecDeque<Evidence>,
    /// The last points pushed whose window is not complete yet (at most `half_window`).
    waiting: VecDeque<TrackPoint>,
    /// Points with evidence, waiting for `lag` more.
    pending: VecDeque<Pending>,
    /// The forward message of the last point pushed.
    last_alpha: Option<[f64; 3]>,
}

impl Smoother {
    /// The log-likelihoods of a point observed at `speed_px_per_frame` whose nearest bead is
    /// at `contact_ratio` times the contact distance (window means).
    pub fn evidence(&self, speed_px_per_frame: f64, contact_ratio: f64) -> [f64; 3] {
        let speed =
            (speed_px_per_frame * self.m_per_s_per_px_per_frame + self.speed_floor_m_per_s).ln();
        let contact = contact_ratio.clamp(1e-3, CONTACT_RATIO_CAP).ln();
        self.states
            .map(|s| s.log_speed.log_density(speed) + s.log_contact.log_density(contact))
    }

    /// Adds the next point of a trajectory with its cues; the points whose state became final
    /// are appended to `out`, in frame order.
    pub fn push(
        &self,
        chain: &mut StateChain,
        point: TrackPoint,
        cues: Evidence,
        out: &mut Vec<TrackPoint>,
    ) {
        chain.cues.push_back(cues);
        if chain.cues.len() > 2 * self.half_window + 1 {
            chain.cues.pop_front();
        }
        chain.waiting.push_back(point);
        if chain.waiting.len() > self.half_window {
            let centre = chain.cues.len() - 1 - self.half_window;
            self.advance_first_waiting(chain, centre, out);
        }
    }

    /// Decides every pending point of a trajectory that ends (with what follows each; the last
    /// points' windows are cut at the end).
    pub fn flush(&self, chain: &mut StateChain, out: &mut Vec<TrackPoint>) {
        while !chain.waiting.is_empty() {
            let centre = chain.cues.len() - chain.waiting.len();
            self.advance_first_waiting(chain, centre, out);
        }
        while !chain.pending.is_empty() {
            self.emit_first(chain, out);
        }
        chain.cues.clear();
        chain.last_alpha = None;
    }

    /// The first waiting point, whose cues are `chain.cues[centre]`, gets its evidence and
    /// forward message; the points `lag` behind it are emitted. The messages are normalised
    /// probabilities (no logarithm in the recursion).
    fn advance_first_waiting(
        &self,
        chain: &mut StateChain,
        centre: usize,
        out: &mut Vec<TrackPoint>,
    ) {
        let Some(point) = chain.waiting.pop_front() else {
            return;
        };
        let features = window_features(chain.cues.make_contiguous(), centre, self.half_window);
        let likelihood = features.map(|f| likelihoods(self.evidence(f.speed, f.contact_ratio)));
        let saltating = match self.saltation {
            SaltationRule::SteadiestSpeed => {
                features.is_some_and(|f| f.steadiest_speed >= self.saltation_speed_px_per_frame)
            }
            SaltationRule::Frame => point.motion_state == MotionState::Saltating,
            SaltationRule::Smoothed => false,
        };
        let e = likelihood.unwrap_or([1.0; 3]);
        let alpha = match chain.last_alpha {
            None => normalised(e),
            Some(prev) => normalised(std::array::from_fn(|j| {
                (0..3).map(|i| prev[i] * self.transition[i][j]).sum::<f64>() * e[j]
            })),
        };
        chain.last_alpha = Some(alpha);
        chain.pending.push_back(Pending {
            point,
            likelihood,
            alpha,
            saltating,
        });
        while chain.pending.len() > self.lag {
            self.emit_first(chain, out);
        }
    }

    /// The first pending point with its smoothed state: forward message × the backward
    /// message of the points after it.
    fn emit_first(&self, chain: &mut StateChain, out: &mut Vec<TrackPoint>) {
        let mut beta = [1.0; 3];
        for later in chain.pending.iter().skip(1).rev() {
            let e = later.likelihood.unwrap_or([1.0; 3]);
            beta = normalised(std::array::from_fn(|i| {
                (0..3)
                    .map(|j| self.transition[i][j] * e[j] * beta[j])
                    .sum::<f64>()
            }));
        }
        let Some(first) = chain.pending.pop_front() else {
            return;
        };
        let mut point = first.point;
        if first.likelihood.is_some() {
            let posterior: [f64; 3] = std::array::from_fn(|i| first.alpha[i] * beta[i]);
            point.motion_state = if self.saltation == SaltationRule::Smoothed {
                STATES[argmax(posterior)]
            } else if first.saltating {
                MotionState::Saltating
            } else {
                STATES[argmax([posterior[0], posterior[1], f64::NEG_INFINITY])]
            };
        }
        out.push(point);
    }
}

/// One point for [`fit_emission`]: a tracker's point or a true one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LabelledPoint {
    /// 0-based frame.
    pub frame: u64,
    /// Trajectory.
    pub track_id: TrackId,
    /// Position, px.
    pub x: f64,
    /// Position, px.
    pub y: f64,
    /// Bead class (0 black, 1 transparent).
    pub class: u32,
    /// Observed velocity, px/frame (`None` on a trajectory's first point).
    pub vel_px_per_frame: Option<Vec2>,
    /// Motion state (the truth's; ignored for the tracker's points).
    pub state: MotionState,
}

impl LabelledPoint {
    fn position(&self) -> Point2 {
        Point2::new(self.x, self.y)
    }

    /// A tracker's (or a truth's) point.
    pub fn of(point: &TrackPoint) -> Self {
        Self {
            frame: point.frame,
            track_id: point.track_id,
            x: point.pos_px.x,
            y: point.pos_px.y,
            class: point.class,
            vel_px_per_frame: point.vel_px_per_frame,
            state: point.motion_state,
        }
    }
}

/// What [`fit_emission`] learnt from, per state (resting, rolling, saltating).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct EmissionReport {
    /// Tracker points paired with a true point of a known state, per state.
    pub samples: [u64; 3],
    /// Tracker points in the training frames with no true point within a bead radius.
    pub unpaired: u64,
}

/// The window features of every estimate, as the tracker's smoother computes them over
/// `half_window`: the contact ratios among each frame's estimates, the windows along each
/// trajectory in frame order.
fn estimate_features(
    estimates: &[LabelledPoint],
    radius_px: &[f64],
    half_window: usize,
) -> Vec<Option<WindowFeatures>> {
    let mut by_frame: BTreeMap<u64, Vec<usize>> = BTreeMap::new();
    let mut by_track: BTreeMap<TrackId, Vec<usize>> = BTreeMap::new();
    for (i, e) in estimates.iter().enumerate() {
        by_frame.entry(e.frame).or_default().push(i);
        by_track.entry(e.track_id).or_default().push(i);
    }
    let mut ratio = vec![CONTACT_RATIO_CAP; estimates.len()];
    let mut frame_beads = Contacts::default();
    for members in by_frame.values() {
        frame_beads.rebuild(
            members
                .iter()
                .map(|&i| (estimates[i].position(), estimates[i].class)),
            radius_px,
        );
        for (k, &i) in members.iter().enumerate() {
            let e = &estimates[i];
            ratio[i] = frame_beads.nearest_ratio(
                e.position(),
                e.class,
                Some(k),
                radius_px,
                CONTACT_RATIO_CAP,
            );
        }
    }
    let mut features = vec![None; estimates.len()];
    for mut members in by_track.into_values() {
        members.sort_by_key(|&i| estimates[i].frame);
        let cues: Vec<Evidence> = members
            .iter()
            .map(|&i| {
                estimates[i].vel_px_per_frame.map(|vel_px_per_frame| Cues {
                    vel_px_per_frame,
                    contact_ratio: ratio[i],
                })
            })
            .collect();
        for (centre, &i) in members.iter().enumerate() {
            features[i] = window_features(&cues, centre, half_window);
        }
    }
    features
}

/// Learns the smoother's evidence model from a tracker's points (`estimates`, whole
/// trajectories) and the true points with states (`truth`) of the same frames, over `frames`
/// (inclusive): each estimate's window features (over `base.half_window`, as the tracker
/// computes them) are paired with the state of the nearest true point of its class and frame
/// within its bead radius, and each state's Gaussians are the mean and deviation of the paired
/// log-features (deviations floored at 0.05). A state with fewer than `min_samples` samples
/// keeps `base`'s model. The saltation threshold is learnt from the speeds over the steadiest
/// stretch of the same points (`best_saltation_threshold`) when there are at least
/// `min_samples` saltating ones. Errors when no true point has a known state.
pub fn fit_emission(
    estimates: &[LabelledPoint],
    truth: &[LabelledPoint],
    frames: [u64; 2],
    radius_px: &[f64],
    calibration: &Calibration,
    base: &SmootherParams,
    min_samples: u64,
) -> Result<(EmissionParams, EmissionReport)> {
    if truth.iter().all(|p| {
        !matches!(
            p.state,
            MotionState::Resting | MotionState::Rolling | MotionState::Saltating
        )
    }) {
        return Err(Error::input(
            "the ground truth has no motion state (every point unknown, or no `motion_state` \
             column); the evidence model is learnt from states: give a truth file with states 0 \
             resting, 1 rolling, 2 saltating",
        ));
    }
    let features = estimate_features(estimates, radius_px, base.half_window as usize);
    let in_frames = |frame: u64| (frames[0]..=frames[1]).contains(&frame);
    let mut truth_by_frame: BTreeMap<u64, Vec<&LabelledPoint>> = BTreeMap::new();
    for t in truth.iter().filter(|t| in_frames(t.frame)) {
        truth_by_frame.entry(t.frame).or_default().push(t);
    }
    let floor = base.emission.speed_floor_m_per_s;
    let scale = calibration.m_per_px * calibration.fps;
    let mut speeds: [Vec<f64>; 3] = Default::default();
    let mut contacts: [Vec<f64>; 3] = Default::default();
    let mut steadiest = Vec::new();
    let mut unpaired = 0;
    for (e, features) in estimates.iter().zip(&features) {
        if !in_frames(e.frame) {
            continue;
        }
        let Some(features) = *features else {
            continue;
        };
        let r = radius_of(radius_px, e.class);
        let nearest = truth_by_frame
            .get(&e.frame)
            .into_iter()
            .flatten()
            .filter(|t| t.class == e.class)
            .map(|t| ((t.x - e.x).hypot(t.y - e.y), t.state))
            .filter(|(d, _)| *d <= r)
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let Some((_, state)) = nearest else {
            unpaired += 1;
            continue;
        };
        let Some(slot) = STATES.iter().position(|&s| s == state) else {
            continue;
        };
        speeds[slot].push((features.speed * scale + floor).ln());
        contacts[slot].push(features.contact_ratio.max(1e-3).ln());
        steadiest.push((
            features.steadiest_speed * scale,
            state == MotionState::Saltating,
        ));
    }
    let mut params = base.emission.clone();
    let models = [
        &mut params.resting,
        &mut params.rolling,
        &mut params.saltating,
    ];
    for ((model, s), c) in models.into_iter().zip(&speeds).zip(&contacts) {
        if (s.len() as u64) < min_samples.max(2) {
            continue;
        }
        if let (Some(log_speed), Some(log_contact)) =
            (LogGaussian::fit(s, 0.05), LogGaussian::fit(c, 0.05))
        {
            *model = StateEmission {
                log_speed,
                log_contact,
            };
        }
    }
    if speeds[2].len() as u64 >= min_samples.max(2)
        && let Some(threshold) = best_saltation_threshold(&mut steadiest)
    {
        params.saltation_speed_m_per_s = threshold;
    }
    let report = EmissionReport {
        samples: std::array::from_fn(|i| speeds[i].len() as u64),
        unpaired,
    };
    Ok((params, report))
}

/// Saltating F-scores within this of the best count as equal when the saltation threshold is
/// learnt: about one standard error of F with 600 saltating samples. On a flat stretch of the
/// F curve the single best threshold wanders from one end to the other (the first half of the
/// synthetic sequence of seed 7: 7.3 px/frame where the plateau runs from 7.3 to 9.0); its
/// centre does not. On the real frames the plateau is 0.2 px/frame wide (the same threshold).
pub const SALTATION_PLATEAU_F: f64 = 0.01;

/// The saltation threshold learnt from `samples`, (speed, truly saltating): every sample at
/// or above a threshold is called saltating; of the thresholds halfway between two distinct
/// consecutive speeds (or at the slowest), those whose saltating F-score is within
/// [`SALTATION_PLATEAU_F`] of the best span a plateau, and its centre is returned. `None`
/// without a saltating sample.
fn best_saltation_threshold(samples: &mut [(f64, bool)]) -> Option<f64> {
    let saltating = samples.iter().filter(|s| s.1).count();
    if saltating == 0 {
        return None;
    }
    samples.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut hits = 0;
    let mut cuts = Vec::new();
    for k in 1..=samples.len() {
        hits += usize::from(samples[k - 1].1);
        let threshold = match samples.get(k) {
            Some(next) if next.0 == samples[k - 1].0 => continue,
            Some(next) => 0.5 * (samples[k - 1].0 + next.0),
            None => samples[k - 1].0,
        };
        cuts.push((threshold, 2.0 * hits as f64 / (k + saltating) as f64));
    }
    let best = cuts.iter().map(|c| c.1).fold(0.0, f64::max);
    let plateau = cuts.iter().filter(|c| c.1 >= best - SALTATION_PLATEAU_F);
    let (low, high) = plateau.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
        (lo.min(c.0), hi.max(c.0))
    });
    Some(0.5 * (low + high))
}

#[cfg(test)]
mod tests {
    use super::*;

    const EQ12: [[f64; 3]; 3] = [[0.8, 0.15, 0.05], [0.1, 0.8, 0.1], [0.05, 0.15, 0.8]];

    /// A smoother with the default evidence, averaged over `half_window`.
    fn windowed(lag: u32, half_window: u32) -> Smoother {
        SmootherParams {
            lag,
            half_window,
            ..SmootherParams::default()
        }
        .smoother(&EQ12, &Calibration::new(2.056e-4, 130.0).unwrap())
        .unwrap()
        .unwrap()
    }

    /// A smoother with one frame's evidence.
    fn smoother(lag: u32) -> Smoother {
        windowed(lag, 0)
    }

    /// The cues of a bead moving at `vel` px/frame along x, near its neighbours.
    fn cues(vel: f64) -> Evidence {
        Some(Cues {
            vel_px_per_frame: Vec2::new(vel, 0.0),
            contact_ratio: 0.95,
        })
    }

    fn point(frame: u64) -> TrackPoint {
        TrackPoint::at(frame, 1, sillage_core::Point2::new(frame as f64, 0.0))
    }

    /// The states of a bead moving at `velocities` px/frame along x, touching its neighbours.
    fn run(s: &Smoother, velocities: &[f64]) -> Vec<TrackPoint> {
        let mut chain = StateChain::default();
        let mut out = Vec::new();
        for (frame, &vel) in velocities.iter().enumerate() {
            s.push(&mut chain, point(frame as u64), cues(vel), &mut out);
        }
        s.flush(&mut chain, &mut out);
        out
    }

    #[test]
    fn a_lag_of_zero_is_no_smoother() {
        let params = SmootherParams {
            lag: 0,
            ..SmootherParams::default()
        };
        let calibration = Calibration::new(2.056e-4, 130.0).unwrap();
        assert!(params.smoother(&EQ12, &calibration).unwrap().is_none());
    }

    #[test]
    fn evidence_orders_the_states_by_speed() {
        let s = smoother(2);
        let best = |speed: f64| argmax(s.evidence(speed, 0.95));
        assert_eq!(STATES[best(0.0)], MotionState::Resting);
        assert_eq!(STATES[best(2.0)], MotionState::Rolling);
        assert_eq!(STATES[best(14.0)], MotionState::Saltating);
    }

    #[test]
    fn points_wait_lag_and_half_window_frames_and_come_out_in_order() {
        let s = windowed(3, 2);
        let mut chain = StateChain::default();
        let mut out = Vec::new();
        for frame in 0..10 {
            s.push(&mut chain, point(frame), cues(2.0), &mut out);
            assert_eq!(out.len(), (frame as usize + 1).saturating_sub(3 + 2));
        }
        s.flush(&mut chain, &mut out);
        let frames: Vec<u64> = out.iter().map(|p| p.frame).collect();
        assert_eq!(frames, (0..10).collect::<Vec<_>>());
        // A point without evidence (a trajectory's first) keeps its state.
        let mut chain = StateChain::default();
        let mut out = Vec::new();
        s.push(&mut chain, point(0), None, &mut out);
        s.flush(&mut chain, &mut out);
        assert_eq!(out[0].motion_state, MotionState::Unknown);
    }

    #[test]
    fn one_still_frame_inside_a_roll_stays_rolling() {
        // A bead rolling at 2 px/frame that seems to stop for one frame: frame by frame
        // that frame is resting; over the trajectory it is rolling.
        let speeds = [2.0, 2.5, 1.8, 0.0, 2.2, 1.9, 2.4];
        let frame_by_frame = STATES[argmax(smoother(1).evidence(0.0, 0.95))];
        assert_eq!(frame_by_frame, MotionState::Resting);
        let out = run(&smoother(2), &speeds);
        assert!(
            out.iter().all(|p| p.motion_state == MotionState::Rolling),
            "{out:?}"
        );
        // A real stop (several frames) is kept.
        let out = run(&smoother(2), &[2.0, 2.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let states: Vec<_> = out.iter().map(|p| p.motion_state).collect();
        assert_eq!(states[1], MotionState::Rolling);
        assert_eq!(states[6], MotionState::Resting);
    }

    #[test]
    fn a_resting_bead_whose_detections_jitter_is_resting_over_the_window() {
        // Detections 0.2 px apart back and forth: each frame's speed, 0.2 px/frame, is a
        // rolling bead's; the mean velocity over ±2 frames, 0.04 px/frame, a resting one's.
        let jitter: Vec<f64> = (0..12)
            .map(|k| if k % 2 == 0 { 0.2 } else { -0.2 })
            .collect();
        let states = |s: &Smoother| -> Vec<MotionState> {
            run(s, &jitter).iter().map(|p| p.motion_state).collect()
        };
        assert!(
            states(&smoother(4))
                .iter()
                .all(|&m| m == MotionState::Rolling),
            "{:?}",
            states(&smoother(4))
        );
        assert!(
            states(&windowed(4, 2))
                .iter()
                .all(|&m| m == MotionState::Resting),
            "{:?}",
            states(&windowed(4, 2))
        );
    }

    /// The written states of a bead moving at `velocities` px/frame along x under `rule`,
    /// its frame-by-frame state saltating above 10 px/frame and rolling below.
    fn states_with(rule: SaltationRule, velocities: &[f64]) -> Vec<MotionState> {
        let s = SmootherParams {
            lag: 3,
            half_window: 2,
            saltation: rule,
            ..SmootherParams::default()
        }
        .smoother(&EQ12, &Calibration::new(2.056e-4, 130.0).unwrap())
        .unwrap()
        .unwrap();
        let mut chain = StateChain::default();
        let mut out = Vec::new();
        for (frame, &vel) in velocities.iter().enumerate() {
            let eq4 = if vel > 10.0 {
                MotionState::Saltating
            } else {
                MotionState::Rolling
            };
            let p = TrackPoint {
                motion_state: eq4,
                ..point(frame as u64)
            };
            s.push(&mut chain, p, cues(vel), &mut out);
        }
        s.flush(&mut chain, &mut out);
        out.iter().map(|p| p.motion_state).collect()
    }

    #[test]
    fn a_hop_is_saltating_over_its_steadiest_stretch_and_a_one_frame_jump_is_not() {
        use MotionState::{Rolling as R, Saltating as S};
        // Rolling at 2 px/frame with a hop of three frames at 12 px/frame: each hop point has
        // a stretch of three points inside the hop; each rolling point one inside the roll.
        let hop = [2.0, 2.0, 2.0, 12.0, 12.0, 12.0, 2.0, 2.0, 2.0];
        let expected = vec![R, R, R, S, S, S, R, R, R];
        assert_eq!(states_with(SaltationRule::SteadiestSpeed, &hop), expected);
        assert_eq!(states_with(SaltationRule::Frame, &hop), expected);
        assert_eq!(states_with(SaltationRule::Smoothed, &hop), expected);
        // One frame at 12 px/frame (a hop, or a detection off by 10 px): Eq. (4) calls it
        // saltating; no stretch of the steadiest-speed rule is steady there, and the smoother
        // blurs it.
        let blip = [2.0, 2.0, 2.0, 12.0, 2.0, 2.0, 2.0];
        let mut eq4 = vec![R; 7];
        eq4[3] = S;
        assert_eq!(states_with(SaltationRule::Frame, &blip), eq4);
        assert_eq!(
            states_with(SaltationRule::SteadiestSpeed, &blip),
            vec![R; 7]
        );
        assert_eq!(states_with(SaltationRule::Smoothed, &blip), vec![R; 7]);
    }

    #[test]
    fn the_steadiest_stretch_does_not_cross_a_take_off() {
        let cues: Vec<Evidence> = [None, Some(2.0), Some(2.0), Some(12.0), Some(12.0)]
            .iter()
            .map(|v| v.and_then(cues))
            .collect();
        let steadiest = |centre: usize, half_window: usize| {
            window_features(&cues, centre, half_window).map(|f| f.steadiest_speed)
        };
        // The first point has no velocity; the second's stretches are cut at the start.
        assert_eq!(steadiest(0, 2), None);
        assert_eq!(steadiest(1, 2), Some(2.0));
        assert_eq!(steadiest(3, 2), Some(12.0));
        assert_eq!(steadiest(4, 2), Some(12.0));
        // Without a window, a point's own speed.
        assert_eq!(steadiest(3, 0), Some(12.0));
        assert_eq!(steadiest(2, 0), Some(2.0));
        // (2, 2) (the first point has no velocity) against (2, 2, 12) and (2, 12, 12).
        assert_eq!(steadiest(2, 2), Some(2.0));
    }

    #[test]
    fn the_saltation_threshold_is_the_centre_of_the_best_f_scores() {
        // Saltating at 10-12, rolling at 1-9 with one rolling bead at 11: above 9.5 the F is
        // 2·3/(4+3) = 0.857, above 10.5 2·2/(3+3) = 0.67.
        let mut samples = vec![
            (1.0, false),
            (5.0, false),
            (9.0, false),
            (10.0, true),
            (11.0, false),
            (11.5, true),
            (12.0, true),
        ];
        assert_eq!(best_saltation_threshold(&mut samples), Some(9.5));
        let mut none = vec![(1.0, false), (2.0, false)];
        assert_eq!(best_saltation_threshold(&mut none), None);
        // Ties are never split: all at 5, the threshold is 5.
        let mut tied = vec![(5.0, true), (5.0, false), (5.0, true)];
        assert_eq!(best_saltation_threshold(&mut tied), Some(5.0));
        // A plateau: 100 saltating samples at 10, 11, ... 109 and rolling ones at 9, 5, 5
        // and 1. Above 9.5 F = 1; above 7 (one rolling) and above 10.5 (one saltating left
        // out) F = 0.995, within 0.01; above 3 (three rolling) 0.985 and above 11.5 (two left
        // out) 0.98990, not: the plateau runs from 7 to 10.5, its centre 8.75.
        let mut plateau: Vec<(f64, bool)> = (0..100).map(|i| (10.0 + i as f64, true)).collect();
        plateau.extend([(9.0, false), (5.0, false), (5.0, false), (1.0, false)]);
        assert_eq!(best_saltation_threshold(&mut plateau), Some(8.75));
    }

    /// A point of trajectory `x as TrackId` at `x` moving at `vel` px/frame along x.
    fn labelled(frame: u64, x: f64, vel: f64, state: MotionState) -> LabelledPoint {
        LabelledPoint {
            frame,
            track_id: x as TrackId,
            x,
            y: 0.0,
            class: 0,
            vel_px_per_frame: Some(Vec2::new(vel, 0.0)),
            state,
        }
    }

    #[test]
    fn fit_learns_each_state_from_the_paired_points_of_the_training_frames() {
        // Two beads 60 px apart (contact ratio 2, the cap): one resting at 0.1 px/frame,
        // one rolling at 2 or 4 px/frame; frames 5.. are outside the training range and
        // would spoil the rolling model.
        let mut estimates = Vec::new();
        let mut truth = Vec::new();
        for frame in 0..10 {
            let roll_speed = if frame < 5 {
                2.0 + 2.0 * (frame % 2) as f64
            } else {
                50.0
            };
            estimates.push(labelled(frame, 0.0, 0.1, MotionState::Unknown));
            estimates.push(labelled(frame, 60.0, roll_speed, MotionState::Unknown));
            truth.push(labelled(frame, 0.5, 0.0, MotionState::Resting));
            truth.push(labelled(frame, 60.5, 0.0, MotionState::Rolling));
        }
        let calibration = Calibration::new(2.056e-4, 130.0).unwrap();
        let params = SmootherParams {
            half_window: 0,
            ..SmootherParams::default()
        };
        let base = &params.emission;
        let (fitted, report) = fit_emission(
            &estimates,
            &truth,
            [0, 4],
            &[15.0],
            &calibration,
            &params,
            2,
        )
        .unwrap();
        assert_eq!(report.samples, [5, 5, 0]);
        let scale = 2.056e-4 * 130.0;
        let floor = base.speed_floor_m_per_s;
        let rest = (0.1 * scale + floor).ln();
        assert!((fitted.resting.log_speed.mean - rest).abs() < 1e-12);
        assert_eq!(fitted.resting.log_speed.sd, 0.05);
        let (a, b) = ((2.0 * scale + floor).ln(), (4.0 * scale + floor).ln());
        let mean = (3.0 * a + 2.0 * b) / 5.0;
        assert!((fitted.rolling.log_speed.mean - mean).abs() < 1e-12);
        assert!((fitted.rolling.log_contact.mean - 2f64.ln()).abs() < 1e-12);
        // Too few saltating samples: the base model is kept.
        assert_eq!(fitted.saltating, base.saltating);
    }

    #[test]
    fn fit_averages_the_velocities_over_the_window_as_the_tracker_does() {
        // A resting bead whose detections jitter back and forth by 0.4 px: one frame's speed
        // is 0.4 px/frame, three frames' mean velocity 0.4/3 px/frame.
        let estimates: Vec<_> = (0..10)
            .map(|frame| {
                let vel = if frame % 2 == 0 { 0.4 } else { -0.4 };
                labelled(frame, 0.0, vel, MotionState::Unknown)
            })
            .collect();
        let truth: Vec<_> = (0..10)
            .map(|frame| labelled(frame, 0.5, 0.0, MotionState::Resting))
            .collect();
        let calibration = Calibration::new(2.056e-4, 130.0).unwrap();
        let scale = 2.056e-4 * 130.0;
        for (half_window, speed) in [(0, 0.4), (1, 0.4 / 3.0)] {
            let params = SmootherParams {
                half_window,
                ..SmootherParams::default()
            };
            // Frames 1-8: every window whole.
            let (fitted, report) = fit_emission(
                &estimates,
                &truth,
                [1, 8],
                &[15.0],
                &calibration,
                &params,
                2,
            )
            .unwrap();
            assert_eq!(report.samples, [8, 0, 0]);
            let expected = (speed * scale + params.emission.speed_floor_m_per_s).ln();
            assert!(
                (fitted.resting.log_speed.mean - expected).abs() < 1e-12,
                "half window {half_window}: {} vs {expected}",
                fitted.resting.log_speed.mean
            );
        }
    }

    #[test]
    fn a_truth_without_states_is_refused() {
        let points = [labelled(0, 0.0, 1.0, MotionState::Unknown)];
        let calibration = Calibration::new(2.056e-4, 130.0).unwrap();
        let e = fit_emission(
            &points,
            &points,
            [0, 0],
            &[15.0],
            &calibration,
            &SmootherParams::default(),
            1,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("no motion state"), "{e}");
    }
}

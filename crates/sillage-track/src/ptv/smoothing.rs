//! Velocities and accelerations fitted along trajectories.
//!
//! TracTrac reports the central difference over three frames (Eq. 6), `(x(t+1) − x(t−1)) / 2`:
//! with positions of independent error σ per axis, its error is σ/√2. The slope of the
//! least-squares line through the `2h + 1` positions of the trajectory centred on the point
//! (the first derivative of a Savitzky–Golay filter, exact for a uniformly accelerated point)
//! has the error σ/√(2 Σₖ k²): σ/5.3 over seven frames, 2.6 times smaller. Where the
//! trajectory does not reach `h` frames on both sides (its first and last frames, a frame
//! missing), the centred windows stop at the frames it has on both sides, and one more
//! reaches a frame further on the side it still has: at a trajectory's first point, the line
//! through its frames −1 to +2 has the error σ/√5 per axis against Eq. 6's σ/√2. Such a line
//! is exact only for a point in uniform motion (a centred one for a uniformly accelerated
//! point too; off-centre by half a frame, it carries half the acceleration as an error), and
//! the rule below keeps it only where the path is straight enough. Reaching on to `h` frames
//! on that side (frames −1 to +3: σ/√10, a whole frame off-centre) was tried on the accuracy
//! families' tune halves: recoveries within 0.2 point of one frame's, and on the moderate
//! family a median displacement error 9 % higher (0.052 against 0.048 px per frame).
//!
//! A line through a curved path is biased: a point turning by ω per frame gets
//! `Σₖ k sin kω / (ω Σₖ k²)` of its speed from seven frames, 0.74 at ω = 0.5 rad, where Eq. 6
//! gets `sin ω / ω` = 0.96. So each point's window is chosen by Lepski's rule: the widest
//! whose slope agrees with the slope of every narrower window, their difference within
//! [`AGREEMENT_SIGMAS`] times its root-mean-square length under noise alone. That needs the
//! positions' noise σ, which the trajectories themselves give: the fourth difference of five
//! positions cancels any cubic path and leaves noise of variance 70σ² per axis; σ is measured
//! per frame from its median.
//!
//! Accelerations the same way: Eq. 7's second difference has the error σ√6 per axis; twice
//! the leading coefficient of the least-squares parabola over seven frames has σ/√21, 11
//! times smaller, and its window is chosen by the same rule. The positions' noise is measured
//! around the frame, or around the next or the previous one where no trajectory reaches two
//! frames on both sides of it (the first and last frames of a sequence).
//!
//! The fit needs the positions up to `h` frames ahead, so a point leaves `h − 1` frames later
//! than it would with Eq. 6; [`VelocitySmoother::flush`] hands out the rest at the end.
//!
//! The same look at a trajectory on both sides of a point decides whether a point the outlier
//! test rejected is written after all: when its trajectory's points just before and just after
//! it were kept, and its fourth difference (the five positions around it) stays within
//! [`AGREEMENT_SIGMAS`] of the positions' noise, the path through it is as smooth as a true
//! particle's.

use std::collections::VecDeque;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sillage_core::{FrameIndex, Point2, Result, TrackId, TrackPoint, TrackSink, Vec2};

/// Fewest points a rayon task fits (keeps task overhead small).
const PAR_MIN_LEN: usize = 1024;

/// Widest half-window, frames on each side (`MAX_VELOCITY_WINDOW / 2`).
const MAX_HALF: usize = crate::ptv::MAX_VELOCITY_WINDOW / 2;

/// Lepski's rule: the squared length of the difference between a wider window's slope and
/// a narrower one's must stay within this factor squared of its expectation under noise
/// alone, `σ² (1/Σ_ρ − 1/Σ_r)` over both axes (`Σ_r = Σ_{k ≤ r} k²`; nested least-squares
/// slopes differ by the difference of their variances). With 3, noise alone fails the test
/// once in ≈ 8,000 comparisons (χ² of two degrees of freedom above 18). Chosen before any
/// measurement; 2 (χ² above 8, once in 55) was tried on the accuracy families' tune halves
/// and was worse on every figure (main 60.8 / 15.1 % against 61.2 / 14.6 %, median
/// displacement error 0.055 against 0.049 px per frame).
pub(crate) const AGREEMENT_SIGMAS: f64 = 3.0;

/// Median of χ² with one degree of freedom: a squared standard normal's median.
const CHI2_1_MEDIAN: f64 = 0.454_936_4;

/// Variance of a fourth difference per unit position variance: 1 + 16 + 36 + 16 + 1.
const FOURTH_DIFFERENCE_VARIANCE: f64 = 70.0;

/// Least position noise assumed, px²: exact synthetic positions still differ by rounding.
const LEAST_NOISE_VARIANCE: f64 = 1e-12;

/// The frames of one tracker step's three positions: t−2, t−1 (whose points it emits) and
/// t (more than one frame apart across a missing frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct StepFrames {
    pub before: FrameIndex,
    pub at: FrameIndex,
    pub after: FrameIndex,
}

/// Three positions of trajectory `id` at a step's frames: one of its points (emitted, or
/// rejected by the outlier test but passing the id on) and the positions the tracker linked
/// it to in the frames before and after.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Linked {
    pub id: TrackId,
    pub positions: [Point2; 3],
}

/// One recorded position of a trajectory: a ring slot, `frame` `EMPTY` when unused.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
struct Slot {
    frame: FrameIndex,
    pos: Point2,
    /// Whether the trajectory's point of that frame passed the outlier test (was emitted).
    #[serde(default)]
    kept: bool,
}

const EMPTY: Slot = Slot {
    frame: FrameIndex::MAX,
    pos: Point2 { x: 0.0, y: 0.0 },
    kept: false,
};

/// `Σ_{k=1}^{r} k²`.
fn sum_of_squares(r: usize) -> f64 {
    (r * (r + 1) * (2 * r + 1)) as f64 / 6.0
}

/// Where the frames around one frame sit in every trajectory's ring.
struct Around {
    frame: FrameIndex,
    half: usize,
    /// `slots[h + k]`: the ring slot of frame + k.
    slots: [usize; 2 * MAX_HALF + 1],
}

impl Around {
    fn new(frame: FrameIndex, half: usize) -> Self {
        let ring = (2 * half + 1) as u64;
        let mut slots = [0; 2 * MAX_HALF + 1];
        for (i, slot) in slots.iter_mut().enumerate().take(2 * half + 1) {
            // Frame + k ≡ frame + k + ring (mod ring), which stays unsigned.
            *slot = ((frame % ring + ring + i as u64 - half as u64) % ring) as usize;
        }
        Self { frame, half, slots }
    }

    /// The slot of a trajectory (its `ring`) at frame + `k`, if recorded.
    fn slot(&self, ring: &[Slot], k: i64) -> Option<Slot> {
        let frame = self.frame.checked_add_signed(k)?;
        let slot = ring[self.slots[(self.half as i64 + k) as usize]];
        (slot.frame == frame).then_some(slot)
    }

    /// The position of a trajectory (its `ring`) at frame + `k`, if recorded.
    fn position(&self, ring: &[Slot], k: i64) -> Option<Point2> {
        self.slot(ring, k).map(|slot| slot.pos)
    }

    /// Whether a trajectory's rejected point at the frame is vouched for: its points of the
    /// frames just before and after were kept, and its fourth difference around the frame
    /// has a squared length within `limit` (needs `h` ≥ 2).
    fn vouched_for(&self, ring: &[Slot], limit: f64) -> bool {
        let kept = |k: i64| self.slot(ring, k).is_some_and(|slot| slot.kept);
        self.half >= 2
            && kept(-1)
            && kept(1)
            && self
                .fourth_difference(ring, 0)
                .is_some_and(|d| d.norm_squared() <= limit)
    }

    /// `x(c−2) − 4x(c−1) + 6x(c) − 4x(c+1) + x(c+2)` around frame + `c` (|c| ≤ h − 2):
    /// zero on any cubic path.
    fn fourth_difference(&self, ring: &[Slot], c: i64) -> Option<Vec2> {
        let centre = self.position(ring, c)?;
        let at = |k: i64| self.position(ring, c + k).map(|p| p - centre);
        let (b2, b1, a1, a2) = (at(-2)?, at(-1)?, at(1)?, at(2)?);
        Some(b2 + a2 - (b1 + a1) * 4.0)
    }

    /// The velocity (the slope of a least-squares line) and the acceleration (twice the
    /// leading coefficient of a least-squares parabola) over the widest windows Lepski's rule
    /// accepts with position variance `noise` (px² per axis), per frame and per frame²; each
    /// `None` where that is Eq. 6's or Eq. 7's three frames, or the trajectory lacks the
    /// positions for more. The windows grow by one frame on each side while the trajectory
    /// has both, then (near its ends) by one frame on the side it still has.
    fn kinematics(&self, ring: &[Slot], noise: f64) -> (Option<Vec2>, Option<Vec2>) {
        let Some(centre) = self.position(ring, 0) else {
            return (None, None);
        };
        let mut velocities = Estimates::default();
        let mut accelerations = Estimates::default();
        // Σ k (x(k) − x(−k)), Σ (x(k) + x(−k)) and Σ k² (x(k) + x(−k)), positions taken from
        // the centre's.
        let (mut odd, mut even, mut even_k2) = (Vec2::ZERO, Vec2::ZERO, Vec2::ZERO);
        let mut reach = 0;
        for r in 1..=self.half {
            let k = r as i64;
            let (Some(back), Some(ahead)) = (self.position(ring, -k), self.position(ring, k))
            else {
                break;
            };
            let (back, ahead) = (back - centre, ahead - centre);
            let k = k as f64;
            odd = odd + (ahead - back) * k;
            even = even + (ahead + back);
            even_k2 = even_k2 + (ahead + back) * (k * k);
            velocities.push(odd * (0.5 / sum_of_squares(r)), 1.0 / sum_of_squares(r));
            let mean_k2 = 2.0 * sum_of_squares(r) / (2 * r + 1) as f64;
            accelerations.push(
                (even_k2 - even * mean_k2) * (2.0 / parabola_spread(r)),
                8.0 / parabola_spread(r),
            );
            reach = r;
        }
        if (1..self.half).contains(&reach) {
            // One frame further on the side the trajectory still has.
            let k = reach as i64 + 1;
            let further = [-k, k]
                .into_iter()
                .find_map(|k| self.position(ring, k).map(|p| (k, p)));
            if let Some((k, p)) = further {
                let mut window = OneSided::from_centred(reach, odd, even, even_k2);
                window.add(k as f64, p - centre);
                velocities.push(window.slope(), window.slope_variance());
                accelerations.push(window.acceleration(), window.acceleration_variance());
            }
        }
        let limit = AGREEMENT_SIGMAS * AGREEMENT_SIGMAS * noise;
        (
            velocities.widest_agreeing(limit),
            accelerations.widest_agreeing(limit),
        )
    }
}

/// Estimates from nested windows, narrowest first, each with its variance over both axes
/// per unit position variance.
#[derive(Default)]
struct Estimates {
    values: [Vec2; MAX_HALF],
    variances: [f64; MAX_HALF],
    len: usize,
}

impl Estimates {
    fn push(&mut self, value: Vec2, variance: f64) {
        self.values[self.len] = value;
        self.variances[self.len] = variance;
        self.len += 1;
    }

    /// Lepski's rule: the widest estimate past the first (Eq. 6 or 7) that agrees with every
    /// narrower one, the squared difference within `limit` (κ²σ²) times the difference of
    /// their variances (nested least-squares estimates of a path they all fit exactly
    /// differ by that); `None` when none past the first does.
    fn widest_agreeing(&self, limit: f64) -> Option<Vec2> {
        let mut chosen = None;
        for wide in 1..self.len {
            let agrees = (0..wide).all(|narrow| {
                let spread = self.variances[narrow] - self.variances[wide];
                (self.values[wide] - self.values[narrow]).norm_squared() <= limit * spread
            });
            if !agrees {
                break;
            }
            chosen = Some(self.values[wide]);
        }
        chosen
    }
}

/// The moments of a window of frame offsets k (from the point) and positions y (from the
/// point's) that reaches further on one side: `Σ kʲ` for j = 0–4 and `Σ kʲ y` for j = 0–2.
/// Its line's slope estimates the velocity where the path is straight (its null hypothesis
/// in Lepski's rule; uniformly accelerated for the centred windows), its parabola's leading
/// coefficient the acceleration where that is uniform.
struct OneSided {
    k: [f64; 5],
    y: [Vec2; 3],
}

impl OneSided {
    /// The moments of the centred window ±`r` from its sums (see [`Around::kinematics`]).
    fn from_centred(r: usize, odd: Vec2, even: Vec2, even_k2: Vec2) -> Self {
        Self {
            k: [
                (2 * r + 1) as f64,
                0.0,
                2.0 * sum_of_squares(r),
                0.0,
                2.0 * sum_of_fourth_powers(r),
            ],
            y: [even, odd, even_k2],
        }
    }

    /// Adds the position `y` at offset `k`.
    fn add(&mut self, k: f64, y: Vec2) {
        let mut power = 1.0;
        for (j, moment) in self.k.iter_mut().enumerate() {
            *moment += power;
            if j < 3 {
                self.y[j] = self.y[j] + y * power;
            }
            power *= k;
        }
    }

    /// `n Σk² − (Σk)²`.
    fn line_spread(&self) -> f64 {
        self.k[0] * self.k[2] - self.k[1] * self.k[1]
    }

    /// The least-squares line's slope.
    fn slope(&self) -> Vec2 {
        (self.y[1] * self.k[0] - self.y[0] * self.k[1]) * (1.0 / self.line_spread())
    }

    /// Over both axes per unit position variance: 2n / (n Σk² − (Σk)²).
    fn slope_variance(&self) -> f64 {
        2.0 * self.k[0] / self.line_spread()
    }

    /// The determinant of the parabola's normal matrix `[Σk^(i+j)]`.
    fn determinant(&self) -> f64 {
        let [n, s1, s2, s3, s4] = self.k;
        n * (s2 * s4 - s3 * s3) - s1 * (s1 * s4 - s2 * s3) + s2 * (s1 * s3 - s2 * s2)
    }

    /// Twice the parabola's leading coefficient (the last row of the normal matrix's inverse
    /// times the data moments).
    fn acceleration(&self) -> Vec2 {
        let [n, s1, s2, s3, _] = self.k;
        let row = [s1 * s3 - s2 * s2, s1 * s2 - n * s3, self.line_spread()];
        (self.y[0] * row[0] + self.y[1] * row[1] + self.y[2] * row[2]) * (2.0 / self.determinant())
    }

    /// Over both axes per unit position variance: 8 (n Σk² − (Σk)²) / det.
    fn acceleration_variance(&self) -> f64 {
        8.0 * self.line_spread() / self.determinant()
    }
}

/// The points of `a` and `b` (each in increasing id order, ids distinct) in one list in
/// increasing id order.
fn merge_by_id(a: Vec<TrackPoint>, b: Vec<TrackPoint>) -> Vec<TrackPoint> {
    let mut merged = Vec::with_capacity(a.len() + b.len());
    let (mut a, mut b) = (a.into_iter().peekable(), b.into_iter().peekable());
    while let (Some(x), Some(y)) = (a.peek(), b.peek()) {
        let next = if x.track_id < y.track_id {
            a.next()
        } else {
            b.next()
        };
        merged.extend(next);
    }
    merged.extend(a);
    merged.extend(b);
    merged
}

/// `Σ_{k=1}^{r} k⁴`.
fn sum_of_fourth_powers(r: usize) -> f64 {
    (r * (r + 1) * (2 * r + 1) * (3 * r * r + 3 * r - 1)) as f64 / 30.0
}

/// `Σ_{k=−r}^{r} (k² − m)²`, m the mean of k² over the window: the spread of a parabola's
/// regressor (its leading coefficient has the variance σ² over it).
fn parabola_spread(r: usize) -> f64 {
    let squares = 2.0 * sum_of_squares(r);
    2.0 * sum_of_fourth_powers(r) - squares * squares / (2 * r + 1) as f64
}

/// Holds each frame's points until the frames their windows need have arrived, keeping the
/// last `2h + 1` positions of every recent trajectory, and replaces their velocities and
/// accelerations by the fitted ones (see the [module docs](self)). Trajectories are kept sorted by id, so a
/// frame's positions (in increasing id order, as the tracker emits them) are recorded in one
/// merge. Deterministic: each point's fit reads only its own trajectory, and the noise is a
/// median.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub(crate) struct VelocitySmoother {
    /// h: frames on each side of a point (1: Eq. 6, points pass straight through).
    half: usize,
    /// Whether rejected points a trajectory vouches for are emitted (see the [module
    /// docs](self)).
    #[serde(default)]
    restore: bool,
    /// Time between frames.
    dt: f64,
    /// Whether this pass fits (forward passes only: training passes' output is discarded).
    active: bool,
    /// Frames of points waiting for their windows, oldest first.
    pending: VecDeque<Vec<TrackPoint>>,
    /// Per frame of `pending`: the points the outlier test rejected that carry an id
    /// (increasing ids), candidates for [`Self::restore`].
    #[serde(default)]
    pending_rejected: VecDeque<Vec<TrackPoint>>,
    /// Rejected points emitted in this pass because their trajectories vouched for them.
    #[serde(default)]
    restored: u64,
    /// Emptied batches, reused.
    #[serde(skip)]
    spare: Vec<Vec<TrackPoint>>,
    /// Trajectory ids, increasing; `last_seen` and the `2h + 1` ring slots of each alongside.
    ids: Vec<TrackId>,
    last_seen: Vec<FrameIndex>,
    slots: Vec<Slot>,
    /// Frames recorded since trajectories last seen too long ago were dropped.
    since_pruned: usize,
    /// Per point of the frame being emitted: its trajectory's index (reused).
    #[serde(skip)]
    tracks_of: Vec<Option<usize>>,
    /// The squared fourth differences of that frame (reused).
    #[serde(skip)]
    squares: Vec<f64>,
}

impl VelocitySmoother {
    /// A smoother fitting over `window` frames (odd, ≥ 3; 3 passes points through) with
    /// `dt` between frames, emitting the rejected points a trajectory vouches for when
    /// `restore`.
    pub fn new(window: usize, dt: f64, restore: bool) -> Self {
        Self {
            half: window / 2,
            restore,
            dt,
            active: true,
            ..Self::default()
        }
    }

    /// Forgets the trajectories and points of the pass before (which a new pass's ids would
    /// collide with); `active` false passes points straight through.
    pub fn start_pass(&mut self, active: bool) {
        self.active = active;
        self.pending.clear();
        self.pending_rejected.clear();
        self.restored = 0;
        self.ids.clear();
        self.last_seen.clear();
        self.slots.clear();
        self.since_pruned = 0;
    }

    /// How many rejected points this pass has emitted because their trajectories vouched
    /// for them.
    pub fn restored(&self) -> u64 {
        self.restored
    }

    /// Whether points go straight to the sink with their Eq. 6 and 7 kinematics.
    pub fn passes_through(&self) -> bool {
        self.half < 2 || !self.active
    }

    fn ring(&self) -> usize {
        2 * self.half + 1
    }

    /// Takes the points of frame `frames.at` (increasing ids) from `batch`, and the points of
    /// that frame the outlier test rejected that carry an id from `rejected` (increasing
    /// ids; both get empty buffers back), with the positions of the trajectories through that
    /// frame: `emitted`'s and `carried`'s (each in increasing id order); hands to `sink` the
    /// frames whose windows are now complete.
    pub fn push(
        &mut self,
        frames: StepFrames,
        batch: &mut Vec<TrackPoint>,
        rejected: &mut Vec<TrackPoint>,
        emitted: &[Linked],
        carried: &[Linked],
        sink: &mut dyn TrackSink,
    ) -> Result<()> {
        if self.passes_through() {
            rejected.clear();
            let result = if batch.is_empty() {
                Ok(())
            } else {
                sink.accept(batch)
            };
            batch.clear();
            return result;
        }
        self.record(frames, emitted, true);
        self.record(frames, carried, false);
        let mut recycled = self.spare.pop().unwrap_or_default();
        recycled.clear();
        self.pending.push_back(std::mem::replace(batch, recycled));
        self.pending_rejected.push_back(std::mem::take(rejected));
        self.since_pruned += 1;
        if self.since_pruned >= self.ring() {
            self.prune(frames.at);
        }
        // A point of frame g needs the positions up to g + h; the points of g + h − 1 bring
        // that frame's (their `after`).
        while self.pending.len() >= self.half {
            self.emit_oldest(sink)?;
        }
        Ok(())
    }

    /// Hands out every point still waiting, each fitted over the frames at hand.
    pub fn flush(&mut self, sink: &mut dyn TrackSink) -> Result<()> {
        while !self.pending.is_empty() {
            self.emit_oldest(sink)?;
        }
        Ok(())
    }

    fn emit_oldest(&mut self, sink: &mut dyn TrackSink) -> Result<()> {
        let Some(mut points) = self.pending.pop_front() else {
            return Ok(());
        };
        let rejected = self.pending_rejected.pop_front().unwrap_or_default();
        if let Some(frame) = points.first().or(rejected.first()).map(|p| p.frame) {
            let around = Around::new(frame, self.half);
            self.find_tracks(&points);
            let noise = self.noise_variance(&around);
            if self.restore && !rejected.is_empty() {
                self.restore(&around, noise, rejected, &mut points);
            }
            let per_time = 1.0 / self.dt;
            let (ring, slots, tracks_of) = (self.ring(), &self.slots, &self.tracks_of);
            points
                .par_iter_mut()
                .zip(tracks_of)
                .with_min_len(PAR_MIN_LEN)
                .for_each(|(p, &track)| {
                    let Some(track) = track else { return };
                    let own = &slots[track * ring..(track + 1) * ring];
                    let (velocity, acceleration) = around.kinematics(own, noise);
                    if let Some(v) = velocity {
                        p.vel_px_per_frame = Some(v * per_time);
                    }
                    if let Some(a) = acceleration {
                        p.acc_px_per_frame2 = Some(a * (per_time * per_time));
                    }
                });
            sink.accept(&points)?;
        }
        points.clear();
        self.spare.push(points);
        Ok(())
    }

    /// Adds to `points` (a frame's emitted points, increasing ids; their trajectories found)
    /// the `rejected` points of the same frame that their trajectories vouch for, with the
    /// positions' noise variance `noise` around the frame, and finds the trajectories of the
    /// merged points.
    fn restore(
        &mut self,
        around: &Around,
        noise: f64,
        rejected: Vec<TrackPoint>,
        points: &mut Vec<TrackPoint>,
    ) {
        // The fourth difference of a point on a smooth path has the variance 70σ² per axis;
        // its squared length over both axes is then 70σ²·χ²₂, held to AGREEMENT_SIGMAS² · 2.
        let limit = AGREEMENT_SIGMAS * AGREEMENT_SIGMAS * 2.0 * FOURTH_DIFFERENCE_VARIANCE * noise;
        self.find_tracks(&rejected);
        let (ring, slots) = (self.ring(), &self.slots);
        let vouched: Vec<TrackPoint> = rejected
            .into_iter()
            .zip(&self.tracks_of)
            .filter(|&(_, &track)| {
                track.is_some_and(|t| around.vouched_for(&slots[t * ring..(t + 1) * ring], limit))
            })
            .map(|(p, _)| p)
            .collect();
        if !vouched.is_empty() {
            self.restored += vouched.len() as u64;
            let emitted = std::mem::take(points);
            *points = merge_by_id(emitted, vouched);
        }
        self.find_tracks(points);
    }

    /// The trajectory of every point of `points` (increasing ids), by one merge.
    fn find_tracks(&mut self, points: &[TrackPoint]) {
        self.tracks_of.clear();
        let mut cursor = 0;
        for p in points {
            while cursor < self.ids.len() && self.ids[cursor] < p.track_id {
                cursor += 1;
            }
            let found = self.ids.get(cursor) == Some(&p.track_id);
            self.tracks_of.push(found.then_some(cursor));
        }
    }

    /// The positions' noise variance around a frame, px² per axis, from the median squared
    /// fourth difference of its points' trajectories (see the [module docs](self)), centred
    /// on the frame or, where none reaches two frames on both sides of it (the first and last
    /// frames of a sequence), on the next or the previous frame.
    fn noise_variance(&mut self, around: &Around) -> f64 {
        let (ring, slots) = (self.ring(), &self.slots);
        let reach = around.half as i64 - 2;
        for centre in [0, 1, -1].into_iter().filter(|c: &i64| c.abs() <= reach) {
            self.squares.clear();
            self.squares.par_extend(
                self.tracks_of
                    .par_iter()
                    .with_min_len(PAR_MIN_LEN)
                    .filter_map(|&track| {
                        let track = track?;
                        around.fourth_difference(&slots[track * ring..(track + 1) * ring], centre)
                    })
                    .flat_map_iter(|d| [d.x * d.x, d.y * d.y]),
            );
            if !self.squares.is_empty() {
                let mid = self.squares.len() / 2;
                let median = *self.squares.select_nth_unstable_by(mid, f64::total_cmp).1;
                return (median / (FOURTH_DIFFERENCE_VARIANCE * CHI2_1_MEDIAN))
                    .max(LEAST_NOISE_VARIANCE);
            }
        }
        LEAST_NOISE_VARIANCE
    }

    /// Records the positions of `linked` (increasing ids) at `frames`, their points of
    /// `frames.at` as `kept` or not.
    fn record(&mut self, frames: StepFrames, linked: &[Linked], kept: bool) {
        let ring = self.ring() as u64;
        let places = [frames.before, frames.at, frames.after].map(|f| (f, (f % ring) as usize));
        let mut cursor = 0;
        let mut late = Vec::new();
        for l in linked {
            while cursor < self.ids.len() && self.ids[cursor] < l.id {
                cursor += 1;
            }
            if cursor == self.ids.len() {
                self.add_track(cursor, l.id);
            } else if self.ids[cursor] != l.id {
                // An id seen before but dropped since: inserted after the merge.
                late.push(l);
                continue;
            }
            self.write(cursor, &places, l, frames.after, kept);
        }
        for l in late {
            let at = self.ids.partition_point(|&id| id < l.id);
            self.add_track(at, l.id);
            self.write(at, &places, l, frames.after, kept);
        }
    }

    fn add_track(&mut self, at: usize, id: TrackId) {
        let ring = self.ring();
        self.ids.insert(at, id);
        self.last_seen.insert(at, 0);
        self.slots
            .splice(at * ring..at * ring, std::iter::repeat_n(EMPTY, ring));
    }

    fn write(
        &mut self,
        track: usize,
        places: &[(FrameIndex, usize); 3],
        linked: &Linked,
        last: FrameIndex,
        kept: bool,
    ) {
        let ring = self.ring();
        let slots = &mut self.slots[track * ring..(track + 1) * ring];
        for (i, (&(frame, slot), &pos)) in places.iter().zip(&linked.positions).enumerate() {
            // The middle point's status is this step's; a neighbour's stays what its own
            // step recorded.
            let kept = if i == 1 {
                kept
            } else {
                slots[slot].frame == frame && slots[slot].kept
            };
            slots[slot] = Slot { frame, pos, kept };
        }
        self.last_seen[track] = self.last_seen[track].max(last);
    }

    /// Drops the trajectories no window from `frame` on can reach.
    fn prune(&mut self, frame: FrameIndex) {
        self.since_pruned = 0;
        let oldest_needed = frame.saturating_sub(2 * self.half as u64);
        let ring = self.ring();
        let mut kept = 0;
        for track in 0..self.ids.len() {
            if self.last_seen[track] >= oldest_needed {
                self.ids[kept] = self.ids[track];
                self.last_seen[kept] = self.last_seen[track];
                self.slots
                    .copy_within(track * ring..(track + 1) * ring, kept * ring);
                kept += 1;
            }
        }
        self.ids.truncate(kept);
        self.last_seen.truncate(kept);
        self.slots.truncate(kept * ring);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One point as the tracker hands it over: the point, its trajectory's positions, and
    /// the step's frames.
    type Entry = (TrackPoint, Linked, StepFrames);

    /// A point moving along `path(frame)` over `frames`, linked to its neighbours.
    fn trajectory(
        id: TrackId,
        frames: std::ops::Range<FrameIndex>,
        path: impl Fn(FrameIndex) -> Point2,
    ) -> Vec<Entry> {
        frames
            .map(|f| {
                let (before, at, after) = (path(f - 1), path(f), path(f + 1));
                let point = TrackPoint {
                    vel_px_per_frame: Some((after - before) * 0.5),
                    acc_px_per_frame2: Some((after - at) - (at - before)),
                    ..TrackPoint::at(f, id, at)
                };
                let linked = Linked {
                    id,
                    positions: [path(f - 1), path(f), path(f + 1)],
                };
                let step = StepFrames {
                    before: f - 1,
                    at: f,
                    after: f + 1,
                };
                (point, linked, step)
            })
            .collect()
    }

    /// A reproducible noise in [−a, a) px from the frame and id.
    fn jitter(id: TrackId, frame: FrameIndex, axis: u64, a: f64) -> f64 {
        let mut z =
            (id * 1_000_003 + frame * 7919 + axis * 104_729).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        z ^= z >> 29;
        z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z ^= z >> 32;
        a * (2.0 * (z >> 11) as f64 / (1u64 << 53) as f64 - 1.0)
    }

    /// Frame-major batches of `tracks`, each in increasing id order.
    fn by_frame(tracks: &[Vec<Entry>]) -> Vec<Vec<Entry>> {
        let mut frames: std::collections::BTreeMap<FrameIndex, Vec<Entry>> = Default::default();
        for entry in tracks.iter().flatten() {
            frames.entry(entry.0.frame).or_default().push(*entry);
        }
        let mut frames: Vec<_> = frames.into_values().collect();
        for frame in &mut frames {
            frame.sort_by_key(|(p, _, _)| p.track_id);
        }
        frames
    }

    fn run(smoother: &mut VelocitySmoother, frames: &[Vec<Entry>]) -> Vec<TrackPoint> {
        run_rejecting(smoother, frames, |_| false)
    }

    /// Hands `frames` to `smoother` as the tracker does, the points `rejected` picks as
    /// rejected by the outlier test (carried), the others as emitted.
    fn run_rejecting(
        smoother: &mut VelocitySmoother,
        frames: &[Vec<Entry>],
        rejected: impl Fn(&TrackPoint) -> bool,
    ) -> Vec<TrackPoint> {
        let mut out = Vec::new();
        for frame in frames {
            let (rejects, kept): (Vec<Entry>, Vec<Entry>) =
                frame.iter().partition(|(p, _, _)| rejected(p));
            let points = |entries: &[Entry]| entries.iter().map(|(p, _, _)| *p).collect();
            let links =
                |entries: &[Entry]| -> Vec<Linked> { entries.iter().map(|(_, l, _)| *l).collect() };
            let (mut batch, mut candidates): (Vec<TrackPoint>, Vec<TrackPoint>) =
                (points(&kept), points(&rejects));
            smoother
                .push(
                    frame[0].2,
                    &mut batch,
                    &mut candidates,
                    &links(&kept),
                    &links(&rejects),
                    &mut out,
                )
                .unwrap();
            assert!(batch.is_empty() && candidates.is_empty());
        }
        smoother.flush(&mut out).unwrap();
        out
    }

    #[test]
    fn a_uniformly_accelerated_point_keeps_its_exact_velocity_and_every_point_comes_out_once() {
        let path = |t: FrameIndex| {
            let t = t as f64;
            Point2::new(2.0 + 3.0 * t + 0.25 * t * t, 5.0 - t)
        };
        let frames = by_frame(&[trajectory(4, 1..20, path)]);
        let out = run(&mut VelocitySmoother::new(7, 1.0, true), &frames);
        assert_eq!(out.len(), 19);
        for (p, f) in out.iter().zip(1..) {
            assert_eq!(p.frame, f);
            let v = p.vel_px_per_frame.unwrap();
            let exact = Vec2::new(3.0 + 0.5 * f as f64, -1.0);
            assert!((v - exact).norm() < 1e-9, "frame {f}: {v:?}");
            let a = p.acc_px_per_frame2.unwrap();
            assert!((a - Vec2::new(0.5, 0.0)).norm() < 1e-9, "frame {f}: {a:?}");
        }
    }

    /// 200 trajectories along x at 1.5 px per frame and `acceleration` px per frame², with
    /// ±0.3 px of noise.
    fn noisy_tracks(acceleration: f64) -> Vec<Vec<Entry>> {
        (0..200)
            .map(|id| {
                trajectory(id, 1..30, move |f| {
                    let t = f as f64;
                    Point2::new(
                        10.0 + 1.5 * t + 0.5 * acceleration * t * t + jitter(id, f, 0, 0.3),
                        5.0 * id as f64 + jitter(id, f, 1, 0.3),
                    )
                })
            })
            .collect()
    }

    fn noisy_straight_tracks() -> Vec<Vec<Entry>> {
        noisy_tracks(0.0)
    }

    /// The mean of `error` over the points of frames 5–24 of `frames` smoothed over
    /// `window` frames.
    fn mean_error(frames: &[Vec<Entry>], window: usize, error: fn(&TrackPoint) -> f64) -> f64 {
        let out = run(&mut VelocitySmoother::new(window, 1.0, true), frames);
        let inner: Vec<f64> = out
            .iter()
            .filter(|p| (5..25).contains(&p.frame))
            .map(error)
            .collect();
        inner.iter().sum::<f64>() / inner.len() as f64
    }

    #[test]
    fn noise_on_the_positions_reaches_the_velocity_far_less_than_with_three_frames() {
        let frames = by_frame(&noisy_straight_tracks());
        let error = |p: &TrackPoint| (p.vel_px_per_frame.unwrap() - Vec2::new(1.5, 0.0)).norm();
        let (three, seven) = (mean_error(&frames, 3, error), mean_error(&frames, 7, error));
        assert!(seven < 0.5 * three, "3 frames: {three}, 7 frames: {seven}");
    }

    #[test]
    fn the_first_and_last_points_of_a_trajectory_carry_less_noise_than_with_three_frames() {
        // Lines through frames 0–3 and 27–30 (variance σ²/5 per axis against Eq. 6's σ²/2: a
        // mean error √(2/5) = 0.63 times Eq. 6's).
        let frames = by_frame(&noisy_straight_tracks());
        let ends = |window: usize| {
            let out = run(&mut VelocitySmoother::new(window, 1.0, true), &frames);
            let errors: Vec<f64> = out
                .iter()
                .filter(|p| p.frame == 1 || p.frame == 29)
                .map(|p| (p.vel_px_per_frame.unwrap() - Vec2::new(1.5, 0.0)).norm())
                .collect();
            errors.iter().sum::<f64>() / errors.len() as f64
        };
        let (three, seven) = (ends(3), ends(7));
        assert!(seven < 0.75 * three, "3 frames: {three}, 7 frames: {seven}");
    }

    #[test]
    fn noise_reaches_the_acceleration_far_less_than_with_three_frames() {
        let frames = by_frame(&noisy_tracks(0.1));
        let error = |p: &TrackPoint| (p.acc_px_per_frame2.unwrap() - Vec2::new(0.1, 0.0)).norm();
        let (three, seven) = (mean_error(&frames, 3, error), mean_error(&frames, 7, error));
        // A parabola over seven frames: the error's deviation 11× smaller than Eq. 7's.
        assert!(seven < 0.25 * three, "3 frames: {three}, 7 frames: {seven}");
    }

    #[test]
    fn a_point_turning_fast_keeps_the_three_frame_velocity() {
        // Half a radian per frame on a 20 px circle, among the noisy straight tracks that
        // set the noise level: a line through seven of its positions would give 0.74 of its
        // chord, and Lepski's rule refuses it.
        let circle = |f: FrameIndex| {
            let angle = 0.5 * f as f64;
            Point2::new(500.0 + 20.0 * angle.cos(), 500.0 + 20.0 * angle.sin())
        };
        let mut tracks = noisy_straight_tracks();
        tracks.push(trajectory(1000, 1..30, circle));
        let out = run(&mut VelocitySmoother::new(7, 1.0, true), &by_frame(&tracks));
        let turning: Vec<&TrackPoint> = out.iter().filter(|p| p.track_id == 1000).collect();
        assert_eq!(turning.len(), 29);
        for p in turning {
            let chord = (circle(p.frame + 1) - circle(p.frame - 1)) * 0.5;
            assert!((p.vel_px_per_frame.unwrap() - chord).norm() < 1e-9, "{p:?}");
        }
    }

    #[test]
    fn windows_reach_past_the_ends_of_a_trajectory_and_a_missing_frame_on_the_side_they_have() {
        let line = |f: FrameIndex| Point2::new(2.0 * f as f64, 0.0);
        let mut track = trajectory(1, 1..16, line);
        // Frame 8 is missing from the sequence: the tracker links 7 to 9 across it.
        track.retain(|(p, _, _)| p.frame != 8);
        for (p, linked, step) in &mut track {
            if p.frame == 7 {
                step.after = 9;
                linked.positions[2] = line(9);
            } else if p.frame == 9 {
                step.before = 7;
                linked.positions[0] = line(7);
            }
        }
        // Positions run from frame 0 to 16, without 8.
        let has = |f: FrameIndex| f <= 16 && f != 8;
        let back = |g: FrameIndex| (1..=3).take_while(|&k| g >= k && has(g - k)).count();
        let ahead = |g: FrameIndex| (1..=3).take_while(|&k| has(g + k)).count();
        let expected = |g: FrameIndex| back(g).min(ahead(g));
        for g in (1..16).filter(|&g| g != 8) {
            // Record up to frame g + 3 (the last point's `after`), then look around g.
            let mut smoother = VelocitySmoother::new(7, 1.0, true);
            for (_, linked, step) in track.iter().filter(|(p, _, _)| p.frame < g + 3) {
                smoother.record(*step, std::slice::from_ref(linked), true);
            }
            let around = Around::new(g, 3);
            let reach = (1..=3)
                .take_while(|&k| {
                    around.position(&smoother.slots, -k).is_some()
                        && around.position(&smoother.slots, k).is_some()
                })
                .count();
            assert_eq!(reach, expected(g), "frame {g}");
            let fourth = around.fourth_difference(&smoother.slots, 0);
            assert_eq!(fourth.is_some(), expected(g) >= 2, "frame {g}");
            // Fitted when a window wider than Eq. 6's fits: centred, or reaching further on
            // the side the trajectory has.
            let fitted = expected(g) >= 1 && back(g).max(ahead(g)) >= 2;
            let (velocity, acceleration) = around.kinematics(&smoother.slots, 1e-6);
            assert_eq!(velocity.is_some(), fitted, "frame {g}");
            assert_eq!(acceleration.is_some(), fitted, "frame {g}");
            if let (Some(v), Some(a)) = (velocity, acceleration) {
                assert!((v - Vec2::new(2.0, 0.0)).norm() < 1e-12, "frame {g}: {v:?}");
                assert!(a.norm() < 1e-12, "frame {g}: {a:?}");
            }
        }
    }

    #[test]
    fn a_rejected_point_is_written_only_between_kept_ones_on_a_smooth_path() {
        // Curved paths with 0.05 px of position noise; ids 0-5 set the noise level.
        let path = |id: TrackId, shift_at_10: f64| {
            move |f: FrameIndex| {
                let t = f as f64;
                let shift = if f == 10 { shift_at_10 } else { 0.0 };
                Point2::new(
                    10.0 * id as f64 + 3.0 * t + 0.1 * t * t + jitter(id, f, 0, 0.05) + shift,
                    2.0 * t + jitter(id, f, 1, 0.05),
                )
            }
        };
        let mut tracks: Vec<Vec<Entry>> = (0..6)
            .map(|id| trajectory(id, 1..20, path(id, 0.0)))
            .collect();
        // 6: rejected at frame 10 on its path; 7: rejected there 1.5 px off its path (a
        // wrong point the links run through); 8: rejected at frames 10 and 11.
        tracks.push(trajectory(6, 1..20, path(6, 0.0)));
        tracks.push(trajectory(7, 1..20, path(7, 1.5)));
        tracks.push(trajectory(8, 1..20, path(8, 0.0)));
        let frames = by_frame(&tracks);
        let rejected = |p: &TrackPoint| {
            (p.track_id >= 6 && p.frame == 10) || (p.track_id == 8 && p.frame == 11)
        };
        let written = |restore: bool| {
            let out = run_rejecting(
                &mut VelocitySmoother::new(7, 1.0, restore),
                &frames,
                rejected,
            );
            let ids_at = |frame| -> Vec<TrackId> {
                out.iter()
                    .filter(|p| p.frame == frame)
                    .map(|p| p.track_id)
                    .collect()
            };
            (ids_at(10), ids_at(11), out)
        };
        let (at_10, at_11, out) = written(true);
        assert_eq!(
            at_10,
            vec![0, 1, 2, 3, 4, 5, 6],
            "only id 6 restored, in id order"
        );
        assert_eq!(at_11, vec![0, 1, 2, 3, 4, 5, 6, 7]);
        let restored = out
            .iter()
            .find(|p| p.track_id == 6 && p.frame == 10)
            .unwrap();
        let v = restored.vel_px_per_frame.unwrap();
        assert!(
            (v - Vec2::new(5.0, 2.0)).norm() < 0.1,
            "fitted velocity {v:?}"
        );
        let (at_10, at_11, _) = written(false);
        assert_eq!(at_10, vec![0, 1, 2, 3, 4, 5]);
        assert_eq!(at_11, vec![0, 1, 2, 3, 4, 5, 6, 7]);
    }

    #[test]
    fn a_velocity_is_in_px_per_dt_and_three_frames_pass_points_straight_through() {
        let path = |f: FrameIndex| Point2::new(4.0 * f as f64, 0.0);
        let frames = by_frame(&[trajectory(0, 1..10, path)]);
        let out = run(&mut VelocitySmoother::new(7, 0.5, true), &frames);
        // Fitted: 8 px per unit of time, the first and last points over the frames on their
        // one side (they came with 4, in px per frame).
        assert!(
            out.iter()
                .all(|p| (p.vel_px_per_frame.unwrap().x - 8.0).abs() < 1e-12)
        );
        let mut through = VelocitySmoother::new(3, 1.0, true);
        let mut out = Vec::new();
        let (point, linked, step) = frames[0][0];
        let mut batch = vec![point];
        through
            .push(step, &mut batch, &mut Vec::new(), &[linked], &[], &mut out)
            .unwrap();
        assert_eq!(out.len(), 1, "no delay with three frames");
    }

    #[test]
    fn trajectories_out_of_reach_are_dropped_and_an_id_seen_again_is_taken_back() {
        let mut smoother = VelocitySmoother::new(5, 1.0, true);
        let early = trajectory(3, 1..4, |f| Point2::new(f as f64, 0.0));
        let steady = trajectory(5, 1..40, |f| Point2::new(0.0, 2.0 * f as f64));
        let late = trajectory(3, 30..40, |f| Point2::new(3.0 * f as f64, 0.0));
        let out = run(&mut smoother, &by_frame(&[early, steady, late]));
        assert_eq!(smoother.ids, vec![3, 5]);
        assert_eq!(out.len(), 3 + 39 + 10);
        for p in out.iter().filter(|p| p.track_id == 3 && p.frame >= 30) {
            assert!((p.vel_px_per_frame.unwrap().x - 3.0).abs() < 1e-9);
        }
    }
}

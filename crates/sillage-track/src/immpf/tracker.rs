//! The multi-pedestrian tracker of the IMM-PF paper: one IMM particle filter per person
//! (§4). On frames, born on motion blobs or detections that no tracker explains, scored by
//! colour and motion histograms (§4.3), and removed when the mean likelihood of its
//! particles stays low for some frames (§5.3); on detections (alone, or with frames adding
//! each person's colour), the detections are assigned to the filters' predicted boxes and
//! weigh them, with SORT's and ByteTrack's life cycle (`on_detections`).

mod on_detections;
mod smoothing;

use std::collections::VecDeque;

use rayon::prelude::*;
use sillage_assoc::LapSolver;
use sillage_core::{Error, FrameIndex, Point2, Result, TrackId, Vec2};
use sillage_filter::{
    CompetingMotion, ImmParticleFilter, ImmPfSpec, InitialSpread, KinematicModel, Noise2,
    linear_model,
};

use super::appearance::{Appearance, FrameCues, HistogramScratch};
use super::models::PedestrianMotion;
use super::params::{ModelName, PedestrianParams, REVIVAL_GATE_AT_DEATH};
use super::sizing::BoxSizing;
use sillage_core::BoundingBox;

/// A box that may start a tracker: a motion blob or a detection, with its score (1 for
/// blobs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// The box, px.
    pub bbox: BoundingBox,
    /// Detector score (larger is surer).
    pub score: f64,
}

/// What the tracker sees of one frame.
#[derive(Debug, Clone, Copy)]
pub struct PedestrianFrame<'a> {
    /// 0-based frame index, increasing.
    pub frame: FrameIndex,
    /// Colour and motion bins of the frame; `None` in the detections-only mode, where the
    /// candidates also score the particles.
    pub cues: Option<&'a FrameCues>,
    /// Motion blobs or detections of the frame.
    pub candidates: &'a [Candidate],
    /// Whether the candidates come from a person detector (a MOTChallenge `det.txt`) rather
    /// than from motion blobs: with frames, detections then drive the trackers
    /// (`detection.with_frames`).
    pub candidates_are_detections: bool,
}

/// One person's estimate in one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PedestrianEstimate {
    /// Frame.
    pub frame: FrameIndex,
    /// Tracker identity.
    pub track_id: TrackId,
    /// The box on the posterior mean foot point.
    pub bbox: BoundingBox,
    /// Posterior mean velocity of the foot point, px/frame.
    pub vel_px_per_frame: Vec2,
    /// πₘ, the weight of each model, in the order of `PedestrianParams::models`.
    pub model_weights: Vec<f64>,
}

/// Least IoU of a candidate with a tracker's box for it to support the tracker.
const SUPPORT_IOU: f64 = 0.1;

/// One live tracker.
#[derive(Debug, Clone)]
struct Track {
    /// The identity it reports: its filter's, or that of a tracker it took over
    /// ([`PedestrianTracker::hand_down`]).
    id: TrackId,
    filter: ImmParticleFilter,
    appearance: Option<Appearance>,
    /// Width and height, px, used where the sizing has no ground plane.
    size_px: (f64, f64),
    /// Rate of change of width and height, px/frame (detections-only mode).
    size_rate: (f64, f64),
    low_frames: u32,
    /// Consecutive frames without a candidate on the tracker's box (on detections alone:
    /// without a matched detection).
    unsupported_frames: u32,
    /// The detection matched this frame (detections-only mode).
    matched: Option<BoundingBox>,
    /// Consecutive frames with a matched detection, the birth included (detections-only
    /// mode).
    hit_streak: u32,
    /// Held by `detection.min_hits` detections in a row once (detections-only mode).
    confirmed: bool,
    /// Reported on the frames a detection holds it (detections-only mode): confirmed, and
    /// not re-confirming after a miss (`detection.reconfirm_after_loss`).
    reported: bool,
    /// The frame and box of its last matched detection (detections-only mode).
    last_detection: Option<(FrameIndex, BoundingBox)>,
    /// The velocity of its detections, smoothed over the streak, px/frame
    /// (detections-only mode, `detection.velocity_proposal`).
    detection_velocity: Option<Vec2>,
    bbox: BoundingBox,
    /// Frames lived, the birth frame included.
    age: u32,
    /// Estimates held until the tracker is confirmed (`confirm_frames`).
    held: Vec<PedestrianEstimate>,
    /// The last estimate reported (detections-driven mode), where a filled gap starts
    /// (`detection.fill_gaps`).
    last_reported: Option<PedestrianEstimate>,
    /// Its foot point in its last `confirm_frames` frames, oldest first.
    recent_feet: VecDeque<(FrameIndex, Point2)>,
    /// Its reported estimates not yet written (detection-driven mode,
    /// `detection.smooth_frames`).
    smoother: smoothing::BoxSmoother,
}

impl Track {
    /// Records this frame's foot point, keeping the last `keep`.
    fn remember_foot(&mut self, frame: FrameIndex, keep: u32) {
        if self.recent_feet.len() >= keep.max(1) as usize {
            self.recent_feet.pop_front();
        }
        self.recent_feet.push_back((frame, self.bbox.foot()));
    }

    /// True while its foot point is in a frame of `frame_size_px` (width, height), or below
    /// it by less than half the box (a person walking out at the bottom edge).
    fn foot_inside(&self, frame_size_px: (usize, usize)) -> bool {
        let foot = self.bbox.foot();
        foot.x >= 0.0
            && foot.x < frame_size_px.0 as f64
            && foot.y >= 0.0
            && foot.y < frame_size_px.1 as f64 + self.bbox.height_px / 2.0
    }
}

/// The pedestrian IMM-PF tracker. Each filter draws from its own stream
/// `rng_stream(seed, track_id)`, and trackers are stepped in parallel: results are the same
/// for any number of threads.
#[derive(Debug)]
pub struct PedestrianTracker {
    params: PedestrianParams,
    spec: ImmPfSpec,
    models: Vec<PedestrianMotion>,
    sizing: BoxSizing,
    frame_size_px: (usize, usize),
    tracks: Vec<Track>,
    /// Confirmed trackers that died in the last `revive_frames` frames.
    departed: Vec<Departed>,
    next_id: TrackId,
    last_frame: Option<FrameIndex>,
    /// The assignment solver of the detections-only mode, its buffers reused.
    solver: LapSolver,
    /// Rows reported so far over the gaps `detection.fill_gaps` filled.
    gap_rows: u64,
}

/// A confirmed tracker that died recently: where it was going, so that a birth on its way
/// takes its identity back, and where it was in its last frames, so that a tracker born on
/// its person shortly before it died takes it over.
#[derive(Debug, Clone)]
struct Departed {
    track_id: TrackId,
    foot: Point2,
    vel_px_per_frame: Vec2,
    /// Its last frame.
    frame: FrameIndex,
    /// Its foot point in its last frames, oldest first.
    recent_feet: Vec<(FrameIndex, Point2)>,
}

impl Departed {
    /// `track`, removed at `frame`: its identity, last foot point and velocity.
    fn of(track: &Track, frame: FrameIndex) -> Self {
        let mean = track.filter.estimate().mean;
        Self {
            track_id: track.id,
            foot: track.bbox.foot(),
            vel_px_per_frame: Vec2::new(mean.at(2), mean.at(3)),
            frame,
            recent_feet: track.recent_feet.iter().copied().collect(),
        }
    }
}

impl PedestrianTracker {
    /// A tracker for frames of `frame_size_px` (width, height); `prior` is the learned
    /// motion prior, required when the models include MP. Parameters are validated here.
    pub fn new(
        params: &PedestrianParams,
        sizing: BoxSizing,
        prior: Option<&sillage_filter::MotionPrior>,
        frame_size_px: (usize, usize),
        seed: u64,
    ) -> Result<Self> {
        params.validate()?;
        let spec = ImmPfSpec::new(&params.filter, params.models.len(), seed)?;
        let models = params
            .models
            .iter()
            .map(|&name| PedestrianMotion::new(name, params, prior))
            .collect::<Result<_>>()?;
        Ok(Self {
            params: params.clone(),
            spec,
            models,
            sizing,
            frame_size_px,
            tracks: Vec::new(),
            departed: Vec::new(),
            next_id: 1,
            last_frame: None,
            solver: LapSolver::new(),
            gap_rows: 0,
        })
    }

    /// The live trackers.
    pub fn len(&self) -> usize {
        self.tracks.len()
    }

    /// True when no tracker is alive.
    pub fn is_empty(&self) -> bool {
        self.tracks.is_empty()
    }

    /// Rows reported so far over the gaps that `detection.fill_gaps` filled (interpolated,
    /// not measured).
    pub fn gap_rows(&self) -> u64 {
        self.gap_rows
    }

    /// Appends to `out` the estimates still held back for `detection.smooth_frames` (those of
    /// the last frames): call it once after the last frame; the tracker is done afterwards.
    /// Nothing is held back without smoothing.
    pub fn finish(&mut self, out: &mut Vec<PedestrianEstimate>) {
        let kernel = self.smoothing_kernel();
        for track in &mut self.tracks {
            track.smoother.write_all(kernel, out);
        }
    }

    /// Tracks one frame and appends to `out` the estimate of every confirmed tracker, preceded
    /// by the held estimates of earlier frames of those confirmed at this frame (and, on
    /// detections, by the rows of the gaps `detection.fill_gaps` fills). With
    /// `detection.smooth_frames`, the estimates come out smoothed, a few frames late
    /// ([`crate::immpf::DetectionLikelihoodParams::smoothing_lag_frames`]); [`PedestrianTracker::finish`]
    /// gives the last ones.
    pub fn step(
        &mut self,
        frame: &PedestrianFrame<'_>,
        out: &mut Vec<PedestrianEstimate>,
    ) -> Result<()> {
        if self.last_frame.is_some_and(|last| frame.frame <= last) {
            return Err(Error::input(format!(
                "frame {} comes after frame {}: frames must come in increasing order",
                frame.frame,
                self.last_frame.unwrap_or_default()
            )));
        }
        self.last_frame = Some(frame.frame);
        let candidates: Vec<Candidate> = frame
            .candidates
            .iter()
            .filter(|c| c.bbox.is_valid() && c.score >= self.params.detection.min_score)
            .copied()
            .collect();
        let drive = self
            .params
            .detection
            .drive_trackers(frame.cues.is_some(), frame.candidates_are_detections);
        let cues = match frame.cues {
            Some(cues) if !drive => cues,
            cues => {
                self.step_on_detections(frame.frame, &candidates, cues, out);
                return Ok(());
            }
        };
        self.predict_and_correct(cues, &candidates);
        self.count_support(&candidates);
        self.bury(frame.frame);
        self.give_birth(frame.frame, cues, &candidates);
        let confirm = self.params.confirm_frames;
        let models = self.models.len();
        for track in &mut self.tracks {
            track.age += 1;
            track.remember_foot(frame.frame, confirm);
            if track.age < confirm {
                track.held.push(estimate_of(track, frame.frame, models));
            } else {
                out.append(&mut track.held);
                out.push(estimate_of(track, frame.frame, models));
            }
        }
        Ok(())
    }

    /// Prediction, weighting by colour and motion (§4.3) and resampling of every tracker, in
    /// parallel.
    fn predict_and_correct(&mut self, cues: &FrameCues, candidates: &[Candidate]) {
        let models = &self.models;
        self.tracks
            .par_iter_mut()
            .for_each(|track| track.filter.predict(models));
        self.propose_on_blobs(candidates);
        let (params, sizing) = (&self.params, &self.sizing);
        let death = params.death_log_likelihood.exp();
        self.tracks
            .par_iter_mut()
            .for_each_init(HistogramScratch::default, |scratch, track| {
                let size = track.size_px;
                let weighting = match &track.appearance {
                    Some(appearance) => track.filter.weight(|p| {
                        let b = sizing.box_at(p.pos_px, size);
                        appearance.log_likelihood(&params.appearance, cues, &b, scratch)
                    }),
                    None => track.filter.weight(|_| 0.0),
                };
                track.filter.resample();
                if weighting.mean_likelihood < death {
                    track.low_frames += 1;
                } else {
                    track.low_frames = 0;
                }
                let foot = estimate_foot(&track.filter);
                track.bbox = sizing.box_at(foot, track.size_px);
                if let Some(appearance) = &mut track.appearance {
                    appearance.adapt(&params.appearance, cues, &track.bbox, scratch);
                }
            });
    }

    /// Image mode: the motion blobs' people (`BoxSizing::people_in`) matched to the trackers
    /// as detections are ([`Self::match_predicted`], IoU ≥ `proposal.min_iou`), and a share
    /// of each matched tracker's particles moved onto its person's foot point
    /// (`ImmParticleFilter::propose_near`, σ = `init_pos_noise_px`). Not in the paper, whose
    /// particles follow their motion models only: there a box that lags behind a walker or
    /// slides off a person of uniform colour has no hypothesis left on the person.
    fn propose_on_blobs(&mut self, candidates: &[Candidate]) {
        let share = self.params.proposal.share;
        if share <= 0.0 || self.tracks.is_empty() {
            return;
        }
        let people: Vec<BoundingBox> = candidates
            .iter()
            .flat_map(|c| self.sizing.people_in(&c.bbox))
            .collect();
        let sd = self.params.init_pos_noise_px;
        for (t, p) in self.match_predicted(&people, self.params.proposal.min_iou) {
            self.tracks[t]
                .filter
                .propose_near(share, people[p].foot(), sd);
        }
    }

    /// Greedy one-to-one matching of the trackers' predicted boxes (on their posterior mean
    /// foot point) to `boxes`, best IoU first, pairs of IoU ≥ `min_iou` only; ties go to the
    /// lower tracker, then box, index. Returns (tracker, box) pairs.
    fn match_predicted(&self, boxes: &[BoundingBox], min_iou: f64) -> Vec<(usize, usize)> {
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (t, track) in self.tracks.iter().enumerate() {
            let predicted = self
                .sizing
                .box_at(estimate_foot(&track.filter), track.size_px);
            for (d, b) in boxes.iter().enumerate() {
                let iou = predicted.iou(b);
                if iou >= min_iou {
                    pairs.push((iou, t, d));
                }
            }
        }
        pairs.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut track_used = vec![false; self.tracks.len()];
        let mut box_used = vec![false; boxes.len()];
        let mut matches = Vec::new();
        for (_, t, d) in pairs {
            if !track_used[t] && !box_used[d] {
                track_used[t] = true;
                box_used[d] = true;
                matches.push((t, d));
            }
        }
        matches
    }

    /// Counts the frames in a row where no candidate (motion blob or detection) holds a
    /// tracker's foot point or overlaps its box.
    fn count_support(&mut self, candidates: &[Candidate]) {
        for track in &mut self.tracks {
            let foot = track.bbox.foot();
            let supported = candidates.iter().any(|c| {
                let b = &c.bbox;
                let holds_foot = foot.x >= b.left_px
                    && foot.x <= b.right_px()
                    && foot.y >= b.top_px
                    && foot.y <= b.bottom_px() + 0.25 * track.bbox.height_px;
                holds_foot || b.iou(&track.bbox) >= SUPPORT_IOU
            });
            track.unsupported_frames = if supported {
                0
            } else {
                track.unsupported_frames + 1
            };
        }
    }

    /// Removes the trackers whose likelihood stayed low for `death_frames` frames, that no
    /// candidate supported for `unsupported_frames` frames, whose foot left the image, and
    /// the younger of two that follow one person.
    fn bury(&mut self, frame: FrameIndex) {
        let unsupported = self.params.unsupported_frames;
        let frame_size = self.frame_size_px;
        let death_frames = self.params.death_frames;
        let (confirm, revive) = (self.params.confirm_frames, self.params.revive_frames);
        let departed = &mut self.departed;
        departed.retain(|d| frame - d.frame <= u64::from(revive));
        self.tracks.retain(|t| {
            let inside = t.foot_inside(frame_size);
            let alive = t.low_frames < death_frames && t.unsupported_frames < unsupported;
            if inside && !alive && t.age >= confirm && revive > 0 {
                departed.push(Departed::of(t, frame));
            }
            inside && alive
        });
        // Tracks are in birth order: a later one overlapping an earlier one is the duplicate.
        let mut keep = vec![true; self.tracks.len()];
        for later in 1..self.tracks.len() {
            for earlier in 0..later {
                if keep[earlier]
                    && self.tracks[later].bbox.iou(&self.tracks[earlier].bbox)
                        >= self.params.duplicate_overlap
                {
                    keep[later] = false;
                    break;
                }
            }
        }
        // A confirmed duplicate departs too: where two trackers met on one person (people
        // crossing, a group), the person the younger one lost is usually next to it and is
        // born again within a few frames; it then takes the identity back.
        let mut flags = keep.into_iter();
        let departed = &mut self.departed;
        self.tracks.retain(|t| {
            let keep = flags.next().unwrap_or(true);
            if !keep && t.age >= confirm && revive > 0 {
                departed.push(Departed::of(t, frame));
            }
            keep
        });
        self.hand_down(frame);
    }

    /// A tracker not yet confirmed takes over the identity of a confirmed one that died at
    /// `frame` when it was born on that tracker's path: its first foot point lies within half
    /// its height of the dead tracker's foot point in the same frame. The dead tracker had
    /// drifted off its person (onto a neighbour, in a group), the person was born again
    /// beside it, and the identity goes on with the person. The heir is reported from this
    /// frame; its earlier frames, which the dead tracker reported under that identity, are
    /// dropped. Not in the paper; off with `revive_frames = 0`.
    fn hand_down(&mut self, frame: FrameIndex) {
        let confirm = self.params.confirm_frames;
        let mut k = 0;
        while k < self.departed.len() {
            let heir = (self.departed[k].frame == frame)
                .then(|| heir_of(&self.departed[k], &self.tracks, confirm))
                .flatten();
            match heir {
                Some(i) => {
                    let d = self.departed.swap_remove(k);
                    let track = &mut self.tracks[i];
                    track.id = d.track_id;
                    track.held.clear();
                    track.age = confirm;
                }
                None => k += 1,
            }
        }
    }

    /// Starts a tracker on every candidate that no live tracker explains.
    fn give_birth(&mut self, frame: FrameIndex, cues: &FrameCues, candidates: &[Candidate]) {
        for candidate in candidates {
            let explained = self
                .tracks
                .iter()
                .any(|t| t.bbox.iou(&candidate.bbox) >= self.params.birth_overlap);
            if explained {
                continue;
            }
            for person in self.sizing.people_in(&candidate.bbox) {
                let foot = person.foot();
                if self.tracks.iter().any(|t| {
                    t.bbox.iou(&person) >= self.params.birth_overlap || t.bbox.contains(foot)
                }) {
                    continue;
                }
                let appearance = match Appearance::capture(&self.params.appearance, cues, &person) {
                    Some(appearance)
                        if appearance.moving_share().unwrap_or(0.0)
                            >= self.params.birth_min_motion
                            && cues.foreground_share(&person).unwrap_or(1.0)
                                >= self.params.birth_min_foreground =>
                    {
                        appearance
                    }
                    _ => continue,
                };
                let (track_id, age) = match self.revive(frame, &person) {
                    Some(track_id) => (track_id, self.params.confirm_frames),
                    None => {
                        self.next_id += 1;
                        (self.next_id - 1, 0)
                    }
                };
                let track = self.spawn(track_id, &person, Some(appearance), age);
                self.tracks.push(track);
            }
        }
    }

    /// A new tracker `track_id` on `person` (its particles around the foot point, at rest),
    /// `age` frames old.
    fn spawn(
        &self,
        track_id: TrackId,
        person: &BoundingBox,
        appearance: Option<Appearance>,
        age: u32,
    ) -> Track {
        let init_pos = self.params.init_pos_noise_px.powi(2);
        let init_vel = self.params.init_vel_noise_px_per_frame.powi(2);
        let spread = InitialSpread {
            pos_px: person.foot(),
            pos_noise: Noise2::diagonal(init_pos, init_pos)
                .factor("init_pos_noise_px")
                .expect("validated σ"),
            vel_px_per_frame: Vec2::new(0.0, 0.0),
            vel_noise: Noise2::diagonal(init_vel, init_vel)
                .factor("init_vel_noise_px_per_frame")
                .expect("validated σ"),
            mode: 0,
        };
        Track {
            id: track_id,
            filter: self.spec.spawn(track_id, &spread),
            appearance,
            size_px: (person.width_px, person.height_px),
            size_rate: (0.0, 0.0),
            low_frames: 0,
            unsupported_frames: 0,
            matched: None,
            hit_streak: 0,
            confirmed: false,
            reported: false,
            last_detection: None,
            detection_velocity: None,
            bbox: *person,
            age,
            held: Vec::new(),
            last_reported: None,
            recent_feet: VecDeque::new(),
            smoother: smoothing::BoxSmoother::default(),
        }
    }
}

impl PedestrianTracker {
    /// The identity of the departed tracker whose extrapolated (or last) foot point is
    /// nearest to `person`'s, relative to its gate ([`revival_gate`]); removed from the
    /// departed.
    fn revive(&mut self, frame: FrameIndex, person: &BoundingBox) -> Option<TrackId> {
        let foot = person.foot();
        let (k, _) = self
            .departed
            .iter()
            .enumerate()
            .map(|(k, d)| {
                let gate = revival_gate(&self.params, frame - d.frame);
                let distance = revival_distance(d, frame, foot);
                (k, distance / (gate * person.height_px))
            })
            .filter(|&(_, relative)| relative <= 1.0)
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        Some(self.departed.swap_remove(k).track_id)
    }
}

/// The radius, in box heights, within which a person born `elapsed` frames after a tracker's
/// death takes its identity back: half a height, widened by `revive_gate_growth` per frame
/// up to `revive_gate_max`. The dying tracker's velocity is least reliable when it lost its
/// person (it lagged behind a walker who went behind others), so the farther the person may
/// have walked since, the wider the gate (docs/immpf.md).
fn revival_gate(params: &PedestrianParams, elapsed: FrameIndex) -> f64 {
    (REVIVAL_GATE_AT_DEATH + params.revive_gate_growth * elapsed as f64).min(params.revive_gate_max)
}

/// How far `foot` lies, at `frame`, from where the departed tracker `d` would be: the
/// nearest of its foot point when it died and its last reported one, each as it stood and
/// extrapolated by its velocity: the estimate of the frame it died in comes from a weighting
/// that failed and may have jumped off its path, and the velocity of a tracker that was
/// losing its person may be wrong, hence the unextrapolated points too.
fn revival_distance(d: &Departed, frame: FrameIndex, foot: Point2) -> f64 {
    let reported = d.recent_feet.last().copied();
    [(d.frame, d.foot)]
        .into_iter()
        .chain(reported)
        .flat_map(|(then, at)| {
            let elapsed = (frame - then) as f64;
            [at, at + d.vel_px_per_frame * elapsed]
        })
        .map(|at| (at - foot).norm())
        .fold(f64::INFINITY, f64::min)
}

/// The index of the unconfirmed tracker of `tracks` (younger than `confirm` frames) that
/// may take over `departed`'s identity ([`nearest_heir`]).
fn heir_of(departed: &Departed, tracks: &[Track], confirm: u32) -> Option<usize> {
    let young = tracks.iter().enumerate().filter_map(|(i, t)| {
        let first = *t.recent_feet.front()?;
        (t.age < confirm).then_some((i, first, t.bbox.height_px))
    });
    nearest_heir(&departed.recent_feet, young)
}

/// Among `young` trackers (index, first frame and foot point, box height), the one whose
/// first foot point lies nearest to `path`'s foot point (a dead tracker's last frames) in
/// that same frame, within half its height; none when the path does not reach that frame.
fn nearest_heir(
    path: &[(FrameIndex, Point2)],
    young: impl Iterator<Item = (usize, (FrameIndex, Point2), f64)>,
) -> Option<usize> {
    young
        .filter_map(|(i, (born, foot), height)| {
            let &(_, then) = path.iter().find(|(f, _)| *f == born)?;
            let distance = (then - foot).norm();
            (distance <= 0.5 * height).then_some((i, distance))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// A tracker's estimate in `frame`.
fn estimate_of(track: &Track, frame: FrameIndex, models: usize) -> PedestrianEstimate {
    let mut model_weights = vec![0.0; models];
    track.filter.model_weights(&mut model_weights);
    let mean = track.filter.estimate().mean;
    PedestrianEstimate {
        frame,
        track_id: track.id,
        bbox: track.bbox,
        vel_px_per_frame: Vec2::new(mean.at(2), mean.at(3)),
        model_weights,
    }
}

/// The posterior mean foot point.
fn estimate_foot(filter: &ImmParticleFilter) -> Point2 {
    let mean = filter.estimate().mean;
    Point2::new(mean.at(0), mean.at(1))
}

/// The linear model `name` with the tracker's noises (Eqs. (10)-(12)).
pub(super) fn kinematic(name: ModelName, params: &PedestrianParams) -> Result<KinematicModel> {
    let label = name.label().to_ascii_lowercase();
    let model = linear_model(
        &label,
        params.pos_noise_px,
        params.vel_noise_px_per_frame,
        params.acc_noise_px_per_frame2,
    )
    .ok_or_else(|| Error::parameter("models", name.label(), "is not a linear model"))?;
    KinematicModel::new(&format!("models.{label}"), &model)
}

impl CompetingMotion for PedestrianMotion {
    fn advance(
        &self,
        columns: &mut sillage_filter::Columns<'_>,
        i: usize,
        normals: &mut sillage_filter::Normals<'_>,
    ) {
        self.advance_particle(columns, i, normals);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_heir_is_the_young_tracker_born_on_the_dead_ones_path() {
        // The dead tracker walked right 2 px a frame over frames 10-14.
        let path: Vec<(FrameIndex, Point2)> = (10..15)
            .map(|f| (f, Point2::new(100.0 + 2.0 * (f - 10) as f64, 200.0)))
            .collect();
        let young = |list: &[(usize, FrameIndex, f64, f64)]| {
            list.iter()
                .map(|&(i, born, x, height)| (i, (born, Point2::new(x, 200.0)), height))
                .collect::<Vec<_>>()
        };
        // Born at frame 12 (the dead one at x = 104): 30 px away with a 70 px box is
        // within half its height, 40 px is not; the nearer of two wins.
        let pick =
            |list: &[(usize, FrameIndex, f64, f64)]| nearest_heir(&path, young(list).into_iter());
        assert_eq!(pick(&[(3, 12, 134.0, 70.0)]), Some(3));
        assert_eq!(pick(&[(3, 12, 144.0, 70.0)]), None);
        assert_eq!(pick(&[(3, 12, 134.0, 70.0), (5, 13, 110.0, 70.0)]), Some(5));
        // Born before the path's frames kept: no comparison, no heir.
        assert_eq!(pick(&[(3, 8, 100.0, 70.0)]), None);
    }

    #[test]
    fn revival_looks_from_the_last_reported_foot_too() {
        // Reported at x = 700 in frame 121 while walking left 5 px a frame; in frame 122,
        // the one it died in, its estimate jumped back to x = 730.
        let departed = Departed {
            track_id: 12,
            foot: Point2::new(730.0, 300.0),
            vel_px_per_frame: Vec2::new(-5.0, 0.0),
            frame: 122,
            recent_feet: vec![
                (120, Point2::new(706.0, 300.0)),
                (121, Point2::new(700.0, 300.0)),
            ],
        };
        // A birth at x = 680 in frame 123: 10 px from the reported foot extrapolated by two
        // frames (690), 45 px from the dying estimate extrapolated by one (725).
        let born = Point2::new(680.0, 300.0);
        assert_eq!(revival_distance(&departed, 123, born), 10.0);
        // Without any reported foot, the dying estimate alone.
        let alone = Departed {
            recent_feet: Vec::new(),
            ..departed
        };
        assert_eq!(revival_distance(&alone, 123, born), 45.0);
    }

    #[test]
    fn the_revival_gate_widens_with_time() {
        let params = PedestrianParams::default();
        // Half a height at the death; a walker's pace (0.1 height a frame) after it, up to
        // 1.5 heights.
        assert_eq!(revival_gate(&params, 0), 0.5);
        assert!((revival_gate(&params, 5) - 1.0).abs() < 1e-12);
        assert_eq!(revival_gate(&params, 20), 1.5);
        let still = PedestrianParams {
            revive_gate_growth: 0.0,
            ..params
        };
        assert_eq!(revival_gate(&still, 20), 0.5);
    }
}

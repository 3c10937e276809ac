//! The frame loop shared by the five bedload trackers: prediction, greedy association
//! (Eq. (2)), motion-state measurement (Eq. (4)), the estimators' update in parallel over
//! trackers, the motion state re-assessed (§3.5.3), survival without detection, births and
//! the emitted points.

use rayon::prelude::*;
use sillage_core::{
    Detection, Error, FrameIndex, FrameObservations, MotionState, ObjectClass, Point2, Result,
    TrackId, TrackPoint, TrackSink, Tracker, Vec2,
};

use crate::bedload::association::{GreedyAssociation, Query};
use crate::bedload::confidence::ConfidenceDensity;
use crate::bedload::contacts::{Contacts, radius_of};
use crate::bedload::filters::{Estimate, Observation, Shared, TrackFilter};
use crate::bedload::params::{
    BedloadTrackerKind, BedloadTrackerParams, ObservedVelocity, Prediction, Settings,
};
use crate::bedload::particle::{ParticleMotion, Weighting};
use crate::bedload::smoother::{CONTACT_RATIO_CAP, Cues, Evidence, Smoother, StateChain};

/// Counts over a run, for reports and tests.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct BedloadStats {
    /// Frames stepped through (frames absent from the input included).
    pub frames: u64,
    /// Trackers started on an unassociated detection.
    pub births: u64,
    /// Trackers confirmed by a second detection: the trajectories of the output.
    pub tracks: u64,
    /// Frames in which a confirmed tracker had no detection and went on predicting.
    pub coasted: u64,
    /// Particle updates whose weights were all zero and were reset to uniform.
    pub weight_recoveries: u64,
}

/// One tracker (a candidate trajectory until a second detection confirms it).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct Track {
    /// Output id, given on confirmation.
    track_id: Option<TrackId>,
    class: ObjectClass,
    filter: TrackFilter,
    /// Estimate at the last frame.
    pos_px: Point2,
    /// Velocity at the last frame (none before the first association).
    vel_px_per_frame: Option<Vec2>,
    /// The detection of the last frame, when there was one.
    raw_px: Option<Point2>,
    /// Motion state at the last frame, as re-assessed (§3.5.3).
    state: MotionState,
    /// Consecutive frames without a detection.
    misses: u32,
    spread_px: Option<f64>,
    /// The birth point, emitted on confirmation.
    birth: TrackPoint,
    /// Points predicted through the current run of misses, with their state evidence, held
    /// until a detection confirms them (unless `emit_predictions_at_once`).
    held: Vec<(TrackPoint, Evidence)>,
    /// Emitted points whose smoothed state is not final yet (with a smoother).
    chain: StateChain,
    /// Still tracked after this frame.
    alive: bool,
}

/// A bedload tracker of Table 1 of the MMPF+ paper (MMPF+, MMPF, PF, IMM or DET) over
/// detections with classes (bead categories) and, for the particle trackers, the
/// detector-confidence candidates of `FrameObservations::candidates`.
///
/// Each frame's points are emitted at that frame's step; a tracker's first point is emitted
/// when a second detection confirms it, so a batch may also hold points of the previous frame.
/// With a smoother (`smoother.lag` > 0) a point is emitted `lag + half_window` frames later,
/// when its state is final, and the rest at the end of its trajectory or at
/// [`Tracker::finish`]. The output is identical for any number of threads.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct BedloadTracker {
    settings: Settings,
    motion: ParticleMotion,
    tracks: Vec<Track>,
    next_track_id: TrackId,
    next_serial: u64,
    next_frame: Option<FrameIndex>,
    stats: BedloadStats,
    association: GreedyAssociation,
    contacts: Contacts,
    density: ConfidenceDensity,
    queries: Vec<Query>,
    assignment: Vec<Option<usize>>,
    observations: Vec<Option<Observation>>,
    estimates: Vec<Option<Estimate>>,
    assigned: Vec<bool>,
    emitted: Vec<TrackPoint>,
}

impl BedloadTracker {
    /// A tracker with validated `params` (errors name the key).
    pub fn new(params: &BedloadTrackerParams) -> Result<Self> {
        let settings = params.settings()?;
        let motion = match settings.kind {
            BedloadTrackerKind::Pf => ParticleMotion::constant_velocity(&settings.model),
            BedloadTrackerKind::Mmpf => {
                // One saltating state (the ICIP 2016 version): no rebound sub-state.
                let mut single = settings.model.params().clone();
                single.rebound_probability = 0.0;
                ParticleMotion::Switching(Box::new(sillage_filter::BedloadModel::new(single)?))
            }
            _ => ParticleMotion::Switching(Box::new(settings.model.clone())),
        };
        Ok(Self {
            settings,
            motion,
            tracks: Vec::new(),
            next_track_id: 1,
            next_serial: 0,
            next_frame: None,
            stats: BedloadStats::default(),
            association: GreedyAssociation::default(),
            contacts: Contacts::default(),
            density: ConfidenceDensity::default(),
            queries: Vec::new(),
            assignment: Vec::new(),
            observations: Vec::new(),
            estimates: Vec::new(),
            assigned: Vec::new(),
            emitted: Vec::new(),
        })
    }

    /// The counts so far.
    pub fn stats(&self) -> BedloadStats {
        self.stats
    }

    /// Trackers alive after the last frame (confirmed or not).
    pub fn live_trackers(&self) -> usize {
        self.tracks.len()
    }

    /// Checks the classes and positions of one frame's input.
    fn check(&self, frame: FrameIndex, what: &str, detections: &[Detection]) -> Result<()> {
        let classes = self.settings.radius_px.len();
        for d in detections {
            if !d.pos_px.is_finite() || !d.strength.is_finite() {
                return Err(Error::input(format!(
                    "frame {frame}: a {what} at ({}, {}) with score {} is not finite; remove it \
                     or fix the detector",
                    d.pos_px.x, d.pos_px.y, d.strength
                )));
            }
            if d.class as usize >= classes {
                return Err(Error::input(format!(
                    "frame {frame}: a {what} has class {} but `radius_px` lists {classes} \
                     classes; give a radius for every class (0 black, 1 transparent)",
                    d.class
                )));
            }
        }
        Ok(())
    }

    /// The prediction x̂ of a tracker (§3.4.1).
    fn predict(&self, track: &Track) -> Point2 {
        let u = track.vel_px_per_frame.unwrap_or(Vec2::ZERO);
        match (self.settings.association.prediction, track.state) {
            (Prediction::ByState, MotionState::Resting) => track.pos_px,
            (Prediction::ByState, MotionState::Rolling) => track.pos_px + Vec2::new(u.x, 0.0),
            _ => track.pos_px + u,
        }
    }

    /// The most frames a tracker in `state` may go without a detection.
    fn survival(&self, state: MotionState) -> u32 {
        let s = &self.settings.survival;
        match state {
            MotionState::Resting => s.resting,
            MotionState::Saltating => s.saltating,
            MotionState::Rolling | MotionState::Unknown => s.rolling,
        }
    }

    /// True when `p` lies outside the field by more than a bead radius.
    fn left_field(&self, p: Point2, class: ObjectClass) -> bool {
        self.settings.field_px.is_some_and(|[w, h]| {
            let r = radius_of(&self.settings.radius_px, class);
            p.x < -r || p.y < -r || p.x > w + r || p.y > h + r
        })
    }

    /// One frame.
    fn advance(
        &mut self,
        frame: FrameIndex,
        detections: &[Detection],
        candidates: &[Detection],
        sink: &mut dyn TrackSink,
    ) -> Result<()> {
        self.stats.frames += 1;
        // 1. Association (§3.4).
        self.queries.clear();
        for track in &self.tracks {
            self.queries.push(Query {
                pred_px: self.predict(track),
                class: track.class,
                speed: track.vel_px_per_frame.map_or(0.0, Vec2::norm),
            });
        }
        self.association.associate(
            &self.settings.association,
            &self.queries,
            detections,
            &mut self.assignment,
        );
        // 2. Observations: u_obs and s_obs (Eq. (4)) for associated trackers; survival for
        // the others.
        let radii = &self.settings.radius_px;
        let rule = self.settings.rule;
        self.contacts
            .rebuild(detections.iter().map(|d| (d.pos_px, d.class)), radii);
        self.observations.clear();
        let mut any_missed_particles = false;
        for (k, track) in self.tracks.iter().enumerate() {
            let observation = match self.assignment[k] {
                Some(d) => {
                    let z = detections[d].pos_px;
                    let from = match self.settings.association.observed_velocity {
                        ObservedVelocity::RawDetections => track.raw_px.unwrap_or(track.pos_px),
                        ObservedVelocity::FromEstimate => track.pos_px,
                    };
                    let u_obs = z - from;
                    let n =
                        self.contacts
                            .count(z, track.class, Some(d), radii, rule.contact_factor);
                    Some(Observation::Detected {
                        pos_px: z,
                        vel_px_per_frame: u_obs,
                        state: rule.state(n, u_obs.norm()),
                    })
                }
                None => {
                    let confirmed = track.track_id.is_some();
                    let survives = track.misses < self.survival(track.state)
                        && !self.left_field(self.queries[k].pred_px, track.class);
                    let coasts = confirmed && survives;
                    any_missed_particles |=
                        coasts && matches!(track.filter, TrackFilter::Particles(_));
                    coasts.then_some(Observation::Missed)
                }
            };
            self.observations.push(observation);
        }
        if any_missed_particles {
            let claimed = self.assignment.iter().flatten().copied();
            self.density.rebuild(
                &self.settings.likelihood,
                radii.len(),
                candidates,
                detections,
                claimed,
            );
        }
        // 3. The estimators, in parallel over trackers (each with its own random stream).
        let l = &self.settings.likelihood;
        let state_cue = (self.settings.kind == BedloadTrackerKind::MmpfPlus)
            .then(|| (l.gamma.ln(), (1.0 - l.gamma).ln()));
        let shared = Shared {
            settings: &self.settings,
            motion: &self.motion,
            weighting: Weighting {
                inv_two_variance: 1.0 / (2.0 * l.position_variance_px2),
                state_cue,
                density: &self.density,
                recapture: l
                    .recapture_distance_px
                    .map(|d| (d * d, &self.settings.model)),
            },
        };
        self.tracks
            .par_iter_mut()
            .zip(self.observations.par_iter())
            .map(|(track, observation)| {
                let observation = observation.as_ref()?;
                track.filter.update(observation, track.class, &shared)
            })
            .collect_into_vec(&mut self.estimates);
        // 4. Apply the estimates; trackers without one end.
        for ((track, estimate), &detection) in self
            .tracks
            .iter_mut()
            .zip(&self.estimates)
            .zip(&self.assignment)
        {
            let Some(estimate) = estimate else {
                track.alive = false;
                continue;
            };
            if let TrackFilter::Particles(filter) = &track.filter {
                self.stats.weight_recoveries += u64::from(filter.last_report().recovered);
            }
            track.pos_px = estimate.pos_px;
            track.vel_px_per_frame = Some(estimate.vel_px_per_frame);
            track.spread_px = estimate.spread_px;
            track.raw_px = detection.map(|d| detections[d].pos_px);
            if detection.is_some() {
                track.misses = 0;
            } else {
                track.misses += 1;
                self.stats.coasted += 1;
            }
        }
        // 5. Motion states re-assessed from the estimates (§3.5.3), then the points.
        self.contacts.rebuild(
            self.tracks
                .iter()
                .filter(|t| t.alive)
                .map(|t| (t.pos_px, t.class)),
            radii,
        );
        self.emitted.clear();
        let smoother = self.settings.smoother.as_deref();
        for track in self.tracks.iter_mut().filter(|t| !t.alive) {
            // A trajectory that ends: its pending states are decided on what it has.
            if let Some(smoother) = smoother {
                smoother.flush(&mut track.chain, &mut self.emitted);
            }
        }
        for (live, track) in self.tracks.iter_mut().filter(|t| t.alive).enumerate() {
            let n = self.contacts.count(
                track.pos_px,
                track.class,
                Some(live),
                radii,
                rule.contact_factor,
            );
            let speed = track.vel_px_per_frame.map_or(0.0, Vec2::norm);
            track.state = rule.state(n, speed);
            let evidence = smoother
                .and(track.vel_px_per_frame)
                .map(|vel_px_per_frame| Cues {
                    vel_px_per_frame,
                    contact_ratio: self.contacts.nearest_ratio(
                        track.pos_px,
                        track.class,
                        Some(live),
                        radii,
                        CONTACT_RATIO_CAP,
                    ),
                });
            let mut out = Emit {
                smoother,
                chain: &mut track.chain,
                emitted: &mut self.emitted,
            };
            let track_id = match track.track_id {
                Some(id) => id,
                None => {
                    let id = self.next_track_id;
                    self.next_track_id += 1;
                    self.stats.tracks += 1;
                    track.track_id = Some(id);
                    out.push(
                        TrackPoint {
                            track_id: id,
                            ..track.birth
                        },
                        None,
                    );
                    id
                }
            };
            let point = TrackPoint {
                vel_px_per_frame: track.vel_px_per_frame,
                motion_state: track.state,
                class: track.class,
                spread_px: track.spread_px,
                ..TrackPoint::at(frame, track_id, track.pos_px)
            };
            if track.misses > 0 && !self.settings.emit_predictions_at_once {
                track.held.push((point, evidence));
            } else {
                for (held, evidence) in track.held.drain(..) {
                    out.push(held, evidence);
                }
                out.push(point, evidence);
            }
        }
        self.tracks.retain(|t| t.alive);
        // 6. Births from the detections no tracker took.
        self.assigned.clear();
        self.assigned.resize(detections.len(), false);
        for &d in self.assignment.iter().flatten() {
            self.assigned[d] = true;
        }
        for (d, detection) in detections.iter().enumerate() {
            if self.assigned[d] {
                continue;
            }
            let serial = self.next_serial;
            self.next_serial += 1;
            self.stats.births += 1;
            let pos_px = detection.pos_px;
            self.tracks.push(Track {
                track_id: None,
                class: detection.class,
                filter: TrackFilter::spawn(&self.settings, serial, pos_px),
                pos_px,
                vel_px_per_frame: None,
                raw_px: Some(pos_px),
                state: MotionState::Unknown,
                misses: 0,
                spread_px: None,
                held: Vec::new(),
                chain: StateChain::default(),
                birth: TrackPoint {
                    class: detection.class,
                    ..TrackPoint::at(frame, 0, pos_px)
                },
                alive: true,
            });
        }
        self.emitted.sort_unstable_by_key(|p| (p.frame, p.track_id));
        if self.emitted.is_empty() {
            Ok(())
        } else {
            sink.accept(&self.emitted)
        }
    }
}

/// Where a tracker's confirmed points go: through its state chain when smoothing, else
/// straight out.
struct Emit<'a> {
    smoother: Option<&'a Smoother>,
    chain: &'a mut StateChain,
    emitted: &'a mut Vec<TrackPoint>,
}

impl Emit<'_> {
    fn push(&mut self, point: TrackPoint, evidence: Evidence) {
        match self.smoother {
            Some(smoother) => smoother.push(self.chain, point, evidence, self.emitted),
            None => self.emitted.push(point),
        }
    }
}

impl Tracker for BedloadTracker {
    fn step(
        &mut self,
        observations: &FrameObservations<'_>,
        sink: &mut dyn TrackSink,
    ) -> Result<()> {
        let frame = observations.frame;
        if let Some(next) = self.next_frame
            && frame < next
        {
            return Err(Error::input(format!(
                "frame {frame} comes after frame {}; give the frames in increasing order",
                next - 1
            )));
        }
        self.check(frame, "detection", observations.detections)?;
        self.check(frame, "candidate", observations.candidates)?;
        // Frames absent from the input had no detection: every tracker missed them.
        for missing in self.next_frame.unwrap_or(frame)..frame {
            self.advance(missing, &[], &[], sink)?;
        }
        self.advance(
            frame,
            observations.detections,
            observations.candidates,
            sink,
        )?;
        self.next_frame = Some(frame + 1);
        Ok(())
    }

    fn finish(&mut self, sink: &mut dyn TrackSink) -> Result<()> {
        // Unconfirmed trackers are not trajectories; points held through misses stay
        // unconfirmed; the smoothed states still pending are decided on what came.
        self.emitted.clear();
        if let Some(smoother) = self.settings.smoother.as_deref() {
            for track in &mut self.tracks {
                smoother.flush(&mut track.chain, &mut self.emitted);
            }
        }
        self.tracks.clear();
        self.emitted.sort_unstable_by_key(|p| (p.frame, p.track_id));
        if self.emitted.is_empty() {
            Ok(())
        } else {
            sink.accept(&self.emitted)
        }
    }
}

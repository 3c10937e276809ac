//! The true bead motion of the synthetic bedload scene, streamed frame by frame.

use rand::RngExt;
use serde::{Deserialize, Serialize};
use sillage_core::{
    BLACK_BEAD_CLASS, FrameIndex, MotionState, ObjectClass, Point2, Result, RngStream,
    TRANSPARENT_BEAD_CLASS, TrackId, TrackPoint, TruthPoint, Vec2, rng_stream,
};

use super::BedloadSceneParams;
use super::bed::{Bed, BedSurface, disk_offset};
use super::creep::Creep;
use super::motion::{Dynamics, Mover, uniform};
use super::pile::{Pile, Proposal};

/// Stream of the bed's disorder.
pub(crate) const STREAM_BED: u64 = 0xBED0_0001;
/// Stream of the mobile beads' initial positions and states.
pub(crate) const STREAM_START: u64 = 0xBED0_0002;
/// Stream of the state transitions, speeds, hops and births.
pub(crate) const STREAM_MOTION: u64 = 0xBED0_0003;
/// Stream of the resting beads' jitter.
pub(crate) const STREAM_JITTER: u64 = 0xBED0_0004;
/// Stream of the creeping layers' phases, spells and speeds.
pub(crate) const STREAM_CREEP: u64 = 0xBED0_0005;

/// Width of the span at the upstream edge where new beads enter (at its lowest point), in
/// black bead diameters: wide enough that arrivals spread rather than heap up at the edge.
const ENTRY_SPAN_BLACK_DIAMETERS: f64 = 4.0;

/// One true bead in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrueBead {
    /// Identity of the bead; never reused once the bead has left.
    pub track_id: TrackId,
    /// [`BLACK_BEAD_CLASS`] or [`TRANSPARENT_BEAD_CLASS`].
    pub class: ObjectClass,
    /// True centre, px; always inside the frame.
    pub pos_px: Point2,
    /// Displacement from the previous frame, px/frame; `None` in the bead's first frame.
    pub vel_px_per_frame: Option<Vec2>,
    /// The state of the step that led to this frame (Eq. (3): state first, then motion).
    pub motion_state: MotionState,
    /// True for the beads of the static bed (black, and the transparent ones lodged in
    /// it): always resting, outside the Markov chain. The creeping layers' beads are not.
    pub in_bed: bool,
}

/// The true beads of one frame: the static bed's beads first (fixed order), then the
/// creeping layers' and the mobile ones (a bead that leaves is replaced in its slot by the
/// newcomer).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BedloadFrame {
    /// Index of the frame.
    pub index: FrameIndex,
    /// Every bead of the frame.
    pub beads: Vec<TrueBead>,
}

impl BedloadFrame {
    /// The beads as truth points. Their velocity is the displacement *from the previous*
    /// frame (as BeadTracking's ground truth and MMPF+'s estimates), not to the next one.
    pub fn truth_points(&self) -> Vec<TruthPoint> {
        self.beads
            .iter()
            .map(|bead| TruthPoint {
                frame: self.index,
                track_id: bead.track_id,
                pos_px: bead.pos_px,
                vel_px_per_frame: bead.vel_px_per_frame,
            })
            .collect()
    }

    /// The beads as track points with their class and motion state: the ground truth of
    /// bedload trackers, as scored by `sillage_eval::papers::score_bead_tracks` and written in
    /// BeadTracking's layout. Velocities as [`BedloadFrame::truth_points`].
    pub fn track_points(&self) -> impl Iterator<Item = TrackPoint> + '_ {
        self.beads.iter().map(|bead| TrackPoint {
            vel_px_per_frame: bead.vel_px_per_frame,
            motion_state: bead.motion_state,
            class: bead.class,
            ..TrackPoint::at(self.index, bead.track_id, bead.pos_px)
        })
    }
}

/// The synthetic bedload scene: a static bed of black beads in hexagonal layers in contact,
/// some transparent beads lodged in its top layers, creeping layers of black beads slipping
/// over it ([`BedloadSceneParams::creeping_layers`]), and mobile beads (the other black and
/// transparent ones) resting on them or on each other, rolling downstream over them and
/// over lower beads, or saltating above them in hops, their states drawn per frame from
/// the transition table.
///
/// The creeping layers, the real sequence's top 2–3 bead layers moving at about
/// 1 px/frame (MMPF+ §4.2), are rows of black beads lying on the surface below them, each
/// slipping over the layer below in stop-and-go spells (starting and stopping with the
/// table's resting ↔ rolling probabilities, at a speed drawn from
/// `creep_speed_px_per_frame`) and carried by it; their beads roll while their layer moves
/// and rest while it stands. A layer wraps around the frame: a bead leaving downstream
/// comes back upstream as a new identity. The top layer carries the mobile beads lying on
/// the deposit or on each other: one that rests on it is reported rolling while carried.
///
/// The flume is 6.5 mm wide, about one bead (MMPF+ §4.1), so beads do not pass through each
/// other: no two beads come closer than their contact distance (`contact_factors` times the
/// sum of their radii, the real frames' typical distance of touching beads), see
/// [`BedloadSceneParams::contact_factors`]. Each frame, every mobile bead draws its state
/// and its move, then takes its place among the others, bottom first: it lies on the upper
/// envelope of the deposit and of the beads below it, is held back where it would have to
/// climb onto a bead not lower than itself (`min_climb_angle_deg`) or run into a bead
/// above, and does not roll while another bead lies on it. Moves are continuous, at most
/// 25 px a frame (below BeadTracking's 31 px search radius, MMPF+ §4.3): a bead that runs
/// off a ledge or loses its support falls under `gravity_px_per_frame2` with a capped
/// speed.
///
/// The motion agrees with the state: a resting bead moves by at most `resting_jitter_px`;
/// a rolling one advances downstream by at most its speed (plus the carry), on the deposit
/// or on beads (never upstream, but it may be held back to a standstill); a saltation
/// keeps its horizontal speed and flies in ballistic hops, at least `hop_clearance_px`
/// above the pile's top between contacts, rebounding on the deposit or on a bead it meets
/// (Eq. (3)'s saltating-rebound). So that saltations can land, their length is drawn at
/// take-off from the geometric law of the table's saltating row and the hops are fitted to
/// land on the last frame: the transition frequencies are still the table's (the next
/// state after a landing is drawn from the saltating row without its saltating entry).
///
/// A mobile bead whose centre would pass the downstream edge is replaced by a new bead (a
/// new identity) of the same class entering, rolling, from above at the lowest point of the
/// 4 black diameters next to the upstream edge, so the counts stay constant; centres never
/// leave the frame. Streams frames `0..n_frames` in bounded memory.
#[derive(Debug, Clone)]
pub struct BedloadScene {
    params: BedloadSceneParams,
    bed: Bed,
    bed_pos: Vec<Point2>,
    creep: Creep,
    creep_seen: Vec<(TrackId, Point2, MotionState)>,
    deposit_before: BedSurface,
    movers: Vec<Mover>,
    positions: Vec<Point2>,
    pile: Pile,
    proposals: Vec<Proposal>,
    next_states: Vec<MotionState>,
    top: BedSurface,
    previous: Vec<(TrackId, Point2)>,
    motion: RngStream,
    jitter: RngStream,
    creep_rng: RngStream,
    next_id: TrackId,
    yielded: usize,
}

impl BedloadScene {
    /// Frame 0 of the scene `params` describe; fails on invalid parameters, naming the key.
    /// Mobile beads are dropped at uniform x, in slot order, on the deposit and the beads
    /// already there, in states drawn from the table's stationary distribution.
    pub fn new(params: BedloadSceneParams) -> Result<Self> {
        params.validate()?;
        let bed = Bed::new(&params, &mut rng_stream(params.seed, STREAM_BED));
        let mut start = rng_stream(params.seed, STREAM_START);
        let mut creep_rng = rng_stream(params.seed, STREAM_CREEP);
        let mut next_id = bed.anchors.len() as TrackId;
        let creep = Creep::new(&params, &bed.surface, &mut creep_rng, &mut next_id);
        let stationary = params.stationary_distribution();
        let lodged = bed
            .anchors
            .iter()
            .filter(|(_, class)| *class == TRANSPARENT_BEAD_CLASS)
            .count();
        let bed_black = bed.anchors.len() - lodged + creep.len();
        let classes =
            std::iter::repeat_n(BLACK_BEAD_CLASS, params.n_black.saturating_sub(bed_black)).chain(
                std::iter::repeat_n(
                    TRANSPARENT_BEAD_CLASS,
                    params.n_transparent.saturating_sub(lodged),
                ),
            );
        let dynamics = Dynamics {
            params: &params,
            surface: creep.surface(),
            top: creep.surface(),
        };
        let last_x = params.width as f64 - 1.0;
        let mut movers: Vec<Mover> = classes
            .enumerate()
            .map(|(i, class)| {
                let x = last_x * start.random::<f64>();
                let u = start.random::<f64>();
                let state = if u < stationary[0] {
                    MotionState::Resting
                } else if u < stationary[0] + stationary[1] {
                    MotionState::Rolling
                } else {
                    MotionState::Saltating
                };
                Mover::new(
                    next_id + i as TrackId,
                    class,
                    x,
                    state,
                    &dynamics,
                    &mut start,
                )
            })
            .collect();
        let proposals: Vec<Proposal> = movers
            .iter()
            .map(|m| Proposal::Drop { x: [m.anchor.x; 2] })
            .collect();
        let mut pile = Pile::new(&params, movers.len());
        pile.settle(&mut movers, &proposals, &dynamics);
        for mover in &mut movers {
            if mover.state == MotionState::Saltating {
                mover.launch(&dynamics, &mut start);
            }
        }
        Ok(Self {
            next_id: next_id + movers.len() as TrackId,
            bed_pos: bed.anchors.iter().map(|&(pos, _)| pos).collect(),
            creep_seen: creep.beads().collect(),
            positions: movers.iter().map(|m| m.anchor).collect(),
            top: creep.surface().clone(),
            deposit_before: creep.surface().clone(),
            creep,
            bed,
            movers,
            pile,
            proposals,
            next_states: Vec::new(),
            previous: Vec::new(),
            motion: rng_stream(params.seed, STREAM_MOTION),
            jitter: rng_stream(params.seed, STREAM_JITTER),
            creep_rng,
            yielded: 0,
            params,
        })
    }

    /// The parameters of the scene.
    pub fn params(&self) -> &BedloadSceneParams {
        &self.params
    }

    /// Number of static bed beads (track ids `0..n`, the first slots of every frame).
    pub fn bed_bead_count(&self) -> usize {
        self.bed_pos.len()
    }

    /// The y of the centre of a bead of `class` resting on the static bed at `x`, px: the
    /// creeping layers and the mobile beads are on it or above (smaller y).
    pub fn surface_y(&self, x: f64, class: ObjectClass) -> f64 {
        self.bed.surface.y(x, class)
    }

    /// The next frame of the sequence, `None` after `n_frames` frames.
    pub fn next_frame(&mut self) -> Option<BedloadFrame> {
        if self.yielded >= self.params.n_frames {
            return None;
        }
        if self.yielded > 0 {
            self.advance();
        }
        let index = self.yielded as FrameIndex;
        self.yielded += 1;
        let bed =
            self.bed_pos.iter().zip(&self.bed.anchors).enumerate().map(
                |(i, (&pos, &(_, class)))| (i as TrackId, class, pos, MotionState::Resting, true),
            );
        let creep = self
            .creep_seen
            .iter()
            .map(|&(id, pos, state)| (id, BLACK_BEAD_CLASS, pos, state, false));
        let movers = self
            .movers
            .iter()
            .zip(&self.positions)
            .map(|(m, &pos)| (m.track_id, m.class, pos, m.label, false));
        let beads: Vec<TrueBead> = bed
            .chain(creep)
            .chain(movers)
            .enumerate()
            .map(|(slot, (track_id, class, pos_px, motion_state, in_bed))| {
                let vel_px_per_frame = match self.previous.get(slot) {
                    Some(&(id, before)) if id == track_id => Some(pos_px - before),
                    _ => None,
                };
                TrueBead {
                    track_id,
                    class,
                    pos_px,
                    vel_px_per_frame,
                    motion_state,
                    in_bed,
                }
            })
            .collect();
        self.previous.clear();
        self.previous
            .extend(beads.iter().map(|bead| (bead.track_id, bead.pos_px)));
        Some(BedloadFrame { index, beads })
    }

    /// Moves every bead one frame, replacing those that leave, and settles the contacts.
    fn advance(&mut self) {
        let half = self.params.resting_jitter_px / 2.0;
        let last = Point2::new(
            self.params.width as f64 - 1.0,
            self.params.height as f64 - 1.0,
        );
        for (pos, &(anchor, _)) in self.bed_pos.iter_mut().zip(&self.bed.anchors) {
            *pos = jittered(&mut self.jitter, anchor, half, last);
        }
        self.deposit_before.clone_from(self.creep.surface());
        self.creep.advance(
            &self.params,
            &self.bed.surface,
            &mut self.creep_rng,
            &mut self.next_id,
        );
        self.creep_seen.clear();
        for (id, anchor, state) in self.creep.beads() {
            let pos = if state == MotionState::Resting {
                jittered(&mut self.jitter, anchor, half, last)
            } else {
                anchor
            };
            self.creep_seen.push((id, pos, state));
        }
        let carry = self.creep.top_shift(&self.params);
        for mover in &mut self.movers {
            mover.carry(carry, &self.deposit_before, self.creep.surface());
        }
        let loads = self.pile.loads();
        self.next_states.clear();
        for mover in &self.movers {
            let next = mover.next_state(&self.params, &mut self.motion);
            self.next_states.push(next);
        }
        // What saltating beads fly over: the deposit and the beads staying on it.
        self.top.clone_from(self.creep.surface());
        for (mover, &next) in self.movers.iter().zip(&self.next_states) {
            if next != MotionState::Saltating {
                self.top.lay(mover.anchor, mover.class, &self.params);
            }
        }
        let dynamics = Dynamics {
            params: &self.params,
            surface: self.creep.surface(),
            top: &self.top,
        };
        let direction = dynamics.direction();
        let (upstream, downstream) = if direction < 0.0 {
            (last.x, 0.0)
        } else {
            (0.0, last.x)
        };
        for (((mover, proposal), loaded), &next) in self
            .movers
            .iter_mut()
            .zip(&mut self.proposals)
            .zip(loads)
            .zip(&self.next_states)
        {
            *proposal = mover.step(next, &dynamics, &mut self.motion, loaded);
            let x = match *proposal {
                Proposal::Ground { dx } => mover.anchor.x + dx,
                Proposal::Drop { x } => x[0],
                Proposal::Air { to, .. } => to.x,
            };
            if direction * (x - downstream) > 0.0 {
                let reach = uniform(
                    &mut self.motion,
                    [0.0, self.params.rolling_speed_px_per_frame[1]],
                );
                let x = (upstream + direction * reach).clamp(0.0, last.x);
                let entry =
                    x + direction * ENTRY_SPAN_BLACK_DIAMETERS * 2.0 * self.params.black_radius_px;
                *mover = Mover::new(
                    self.next_id,
                    mover.class,
                    x,
                    MotionState::Rolling,
                    &dynamics,
                    &mut self.motion,
                );
                *proposal = Proposal::Drop {
                    x: [x, entry.clamp(0.0, last.x)],
                };
                self.next_id += 1;
            }
        }
        self.pile
            .settle(&mut self.movers, &self.proposals, &dynamics);
        for (i, ((mover, proposal), pos)) in self
            .movers
            .iter_mut()
            .zip(&self.proposals)
            .zip(&mut self.positions)
            .enumerate()
        {
            // `pos` is still where it was seen in the last frame.
            let moved = matches!(proposal, Proposal::Ground { .. })
                && mover.anchor.distance(*pos + mover.carried) > half + 1e-9;
            if let Proposal::Air { .. } = proposal {
                mover.end_flight_frame(self.pile.stopped(i));
            }
            mover.settled(moved, half + 1e-9);
            *pos = if mover.label == MotionState::Resting {
                jittered(&mut self.jitter, mover.anchor, half, last)
            } else {
                mover.anchor
            };
        }
    }
}

/// A resting bead's place as seen: `anchor` off by a uniform offset in the disk of radius
/// `half` (half the jitter), kept in the frame (`last` is its last pixel) by a projection,
/// which cannot lengthen a displacement.
fn jittered(jitter: &mut RngStream, anchor: Point2, half: f64, last: Point2) -> Point2 {
    let p = anchor + disk_offset(jitter, half);
    Point2::new(p.x.clamp(0.0, last.x), p.y.clamp(0.0, last.y))
}

impl Iterator for BedloadScene {
    type Item = BedloadFrame;

    fn next(&mut self) -> Option<BedloadFrame> {
        self.next_frame()
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.params.n_frames - self.yielded;
        (left, Some(left))
    }
}

impl ExactSizeIterator for BedloadScene {}

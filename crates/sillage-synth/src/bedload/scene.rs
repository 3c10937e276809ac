//! The true bead motion of the synthetic bedload scene, streamed frame by frame.

use rand::RngExt;
use serde::{Deserialize, Serialize};
use sillage_core::{
    BLACK_BEAD_CLASS, FrameIndex, MotionState, ObjectClass, Point2, Result, RngStream,
    TRANSPARENT_BEAD_CLASS, TrackId, TrackPoint, TruthPoint, Vec2, rng_stream,
};

use super::BedloadSceneParams;
use super::bed::{Bed, BedSurface, disk_offset};
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
    /// True for the beads of the static bed: always resting, outside the Markov chain.
    pub in_bed: bool,
}

/// The true beads of one frame: the bed beads first (fixed order), then the mobile ones
/// (a bead that leaves is replaced in its slot by the newcomer).
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
/// and mobile beads (the black ones beyond the bed, all transparent ones) resting on it or
/// on each other, rolling downstream over the bed and over lower beads, or saltating above
/// them in hops, their states drawn per frame from the transition table.
///
/// The flume is 6.5 mm wide, about one bead (MMPF+ §4.1), so beads do not pass through each
/// other: no two beads come closer than their contact distance (`contact_factors` times the
/// sum of their radii, the real frames' typical distance of touching beads), see
/// [`BedloadSceneParams::contact_factors`]. Each frame, every mobile bead draws its state
/// and its move, then takes its place among the others, bottom first: it lies on the upper
/// envelope of the bed and of the beads below it, is held back where it would have to climb
/// onto a bead not lower than itself (`min_climb_angle_deg`) or run into a bead above, and
/// does not roll while another bead lies on it. Moves are continuous, at most 25 px a frame
/// (below BeadTracking's 31 px search radius, MMPF+ §4.3): a bead that runs off a ledge or
/// loses its support falls under `gravity_px_per_frame2` with a capped speed.
///
/// The motion agrees with the state: a resting bead moves by at most `resting_jitter_px`;
/// a rolling one advances downstream by at most its speed, on the bed or on beads (never
/// upstream, but it may be held back to a standstill); a saltation keeps its horizontal
/// speed and flies in ballistic hops, at least `hop_clearance_px` above the pile's top
/// between contacts, rebounding on the bed or on a bead it meets (Eq. (3)'s
/// saltating-rebound). So that saltations can land, their length is drawn at take-off from
/// the geometric law of the table's saltating row and the hops are fitted to land on the
/// last frame: the transition frequencies are still the table's (the next state after a
/// landing is drawn from the saltating row without its saltating entry).
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
    movers: Vec<Mover>,
    positions: Vec<Point2>,
    pile: Pile,
    proposals: Vec<Proposal>,
    next_states: Vec<MotionState>,
    top: BedSurface,
    previous: Vec<(TrackId, Point2)>,
    motion: RngStream,
    jitter: RngStream,
    next_id: TrackId,
    yielded: usize,
}

impl BedloadScene {
    /// Frame 0 of the scene `params` describe; fails on invalid parameters, naming the key.
    /// Mobile beads are dropped at uniform x, in slot order, on the bed and the beads
    /// already there, in states drawn from the table's stationary distribution.
    pub fn new(params: BedloadSceneParams) -> Result<Self> {
        params.validate()?;
        let bed = Bed::new(&params, &mut rng_stream(params.seed, STREAM_BED));
        let mut start = rng_stream(params.seed, STREAM_START);
        let stationary = params.stationary_distribution();
        let n_bed = bed.anchors.len();
        let classes = std::iter::repeat_n(BLACK_BEAD_CLASS, params.n_black - n_bed).chain(
            std::iter::repeat_n(TRANSPARENT_BEAD_CLASS, params.n_transparent),
        );
        let dynamics = Dynamics {
            params: &params,
            surface: &bed.surface,
            top: &bed.surface,
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
                    (n_bed + i) as TrackId,
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
            next_id: (n_bed + movers.len()) as TrackId,
            bed_pos: bed.anchors.clone(),
            positions: movers.iter().map(|m| m.anchor).collect(),
            top: bed.surface.clone(),
            bed,
            movers,
            pile,
            proposals,
            next_states: Vec::new(),
            previous: Vec::new(),
            motion: rng_stream(params.seed, STREAM_MOTION),
            jitter: rng_stream(params.seed, STREAM_JITTER),
            yielded: 0,
            params,
        })
    }

    /// The parameters of the scene.
    pub fn params(&self) -> &BedloadSceneParams {
        &self.params
    }

    /// Number of bed beads (track ids `0..n`, the first slots of every frame).
    pub fn bed_bead_count(&self) -> usize {
        self.bed_pos.len()
    }

    /// The y of the centre of a bead of `class` resting on the bed at `x`, px: mobile beads
    /// are on it or above (smaller y), on the bed's beads or on other mobile beads.
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
        let bed = self.bed_pos.iter().enumerate().map(|(i, &pos)| {
            (
                i as TrackId,
                BLACK_BEAD_CLASS,
                pos,
                MotionState::Resting,
                true,
            )
        });
        let movers = self
            .movers
            .iter()
            .zip(&self.positions)
            .map(|(m, &pos)| (m.track_id, m.class, pos, m.state, false));
        let beads: Vec<TrueBead> = bed
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
        for (pos, anchor) in self.bed_pos.iter_mut().zip(&self.bed.anchors) {
            let p = *anchor + disk_offset(&mut self.jitter, half);
            *pos = Point2::new(p.x.clamp(0.0, last.x), p.y.clamp(0.0, last.y));
        }
        let loads = self.pile.loads();
        self.next_states.clear();
        for mover in &self.movers {
            let next = mover.next_state(&self.params, &mut self.motion);
            self.next_states.push(next);
        }
        // What saltating beads fly over: the bed and the beads staying on it.
        self.top.clone_from(&self.bed.surface);
        for (mover, &next) in self.movers.iter().zip(&self.next_states) {
            if next != MotionState::Saltating {
                self.top.lay(mover.anchor, mover.class, &self.params);
            }
        }
        let dynamics = Dynamics {
            params: &self.params,
            surface: &self.bed.surface,
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
            match *proposal {
                Proposal::Air { .. } => mover.end_flight_frame(self.pile.stopped(i)),
                // `pos` is still where it was seen in the last frame.
                Proposal::Ground { .. } if mover.anchor.distance(*pos) > half + 1e-9 => {
                    mover.fall()
                }
                _ => {}
            }
            // A resting bead is seen off its place by the jitter, kept in the frame by a
            // projection, which cannot lengthen a displacement.
            *pos = mover.anchor;
            if mover.state == MotionState::Resting {
                let p = mover.anchor + disk_offset(&mut self.jitter, half);
                *pos = Point2::new(p.x.clamp(0.0, last.x), p.y);
            }
        }
    }
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

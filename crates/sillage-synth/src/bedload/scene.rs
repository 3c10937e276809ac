//! The true bead motion of the synthetic bedload scene, streamed frame by frame.

use rand::RngExt;
use serde::{Deserialize, Serialize};
use sillage_core::{
    BLACK_BEAD_CLASS, FrameIndex, MotionState, ObjectClass, Point2, Result, RngStream,
    TRANSPARENT_BEAD_CLASS, TrackId, TrackPoint, TruthPoint, Vec2, rng_stream,
};

use super::BedloadSceneParams;
use super::bed::{Bed, disk_offset};
use super::motion::{Dynamics, Mover, uniform};

/// Stream of the bed's disorder.
pub(crate) const STREAM_BED: u64 = 0xBED0_0001;
/// Stream of the mobile beads' initial positions and states.
pub(crate) const STREAM_START: u64 = 0xBED0_0002;
/// Stream of the state transitions, speeds, hops and births.
pub(crate) const STREAM_MOTION: u64 = 0xBED0_0003;
/// Stream of the resting beads' jitter.
pub(crate) const STREAM_JITTER: u64 = 0xBED0_0004;

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
/// and mobile beads (the black ones beyond the bed, all transparent ones) resting on its
/// surface, rolling along it downstream, or saltating above it in hops, their states drawn
/// per frame from the transition table.
///
/// The motion agrees with the state: a resting bead moves by at most `resting_jitter_px`;
/// a rolling one advances by its speed along x and stays on the surface; a saltation keeps
/// its horizontal speed and flies in ballistic hops, at least `hop_clearance_px` above the
/// surface between contacts, rebounding on it (Eq. (3)'s saltating-rebound). So that
/// saltations can land, their length is drawn at take-off from the geometric law of the
/// table's saltating row and the hops are fitted to land on the last frame: the transition
/// frequencies are still the table's (the next state after a landing is drawn from the
/// saltating row without its saltating entry).
///
/// A mobile bead whose centre passes the downstream edge is replaced by a new bead (a new
/// identity) of the same class entering, rolling, at the upstream edge, so the counts stay
/// constant; centres never leave the frame. Mobile beads pass in front of one another (the
/// paper's flume is 6.5 mm wide: a 2-D projection) and rest on the bed only, not on each
/// other. Streams frames `0..n_frames` in bounded memory.
#[derive(Debug, Clone)]
pub struct BedloadScene {
    params: BedloadSceneParams,
    bed: Bed,
    bed_pos: Vec<Point2>,
    movers: Vec<Mover>,
    previous: Vec<(TrackId, Point2)>,
    motion: RngStream,
    jitter: RngStream,
    next_id: TrackId,
    yielded: usize,
}

impl BedloadScene {
    /// Frame 0 of the scene `params` describe; fails on invalid parameters, naming the key.
    /// Mobile beads start at uniform x on the surface, in states drawn from the table's
    /// stationary distribution.
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
        };
        let last_x = params.width as f64 - 1.0;
        let movers: Vec<Mover> = classes
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
        Ok(Self {
            next_id: (n_bed + movers.len()) as TrackId,
            bed_pos: bed.anchors.clone(),
            bed,
            movers,
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

    /// The y of the centre of a bead of `class` resting on the bed at `x`: rolling beads
    /// are on it, saltating ones on it or above (smaller y), px.
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
            .map(|m| (m.track_id, m.class, m.pos, m.state, false));
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

    /// Moves every bead one frame, replacing those that left.
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
        let dynamics = Dynamics {
            params: &self.params,
            surface: &self.bed.surface,
        };
        let direction = f64::from(self.params.flow_direction);
        let (upstream, downstream) = if direction < 0.0 {
            (last.x, 0.0)
        } else {
            (0.0, last.x)
        };
        for mover in &mut self.movers {
            mover.step(&dynamics, &mut self.motion, &mut self.jitter);
            if direction * (mover.pos.x - downstream) > 0.0 {
                let reach = uniform(
                    &mut self.motion,
                    [0.0, self.params.rolling_speed_px_per_frame[1]],
                );
                let x = (upstream + direction * reach).clamp(0.0, last.x);
                *mover = Mover::new(
                    self.next_id,
                    mover.class,
                    x,
                    MotionState::Rolling,
                    &dynamics,
                    &mut self.motion,
                );
                self.next_id += 1;
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

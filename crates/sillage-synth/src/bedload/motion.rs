//! One mobile bead: its motion state drawn from the transition table, and the move that
//! agrees with it (resting still, rolling downstream, saltating in hops), before the
//! contacts with the other beads ([`super::pile`]) limit it.

use rand::RngExt;
use sillage_core::{MotionState, ObjectClass, Point2, RngStream, TrackId, Vec2};

use super::BedloadSceneParams;
use super::bed::BedSurface;
use super::pile::{MAX_STEP_PX, Proposal};

/// The motion-state order of the transition table's rows and columns.
const STATES: [MotionState; 3] = [
    MotionState::Resting,
    MotionState::Rolling,
    MotionState::Saltating,
];

/// Row or column of `state` in the transition table (`Unknown` never occurs here).
fn index(state: MotionState) -> usize {
    match state {
        MotionState::Rolling => 1,
        MotionState::Saltating => 2,
        _ => 0,
    }
}

/// A state drawn from the weights `row` (not necessarily normalised) with `u` uniform in
/// [0, 1); rounding past the end goes to the last state with a positive weight.
fn draw(row: [f64; 3], u: f64) -> MotionState {
    let total: f64 = row.iter().sum();
    let mut cumulative = 0.0;
    for (i, weight) in row.iter().enumerate() {
        cumulative += weight;
        if *weight > 0.0 && u * total < cumulative {
            return STATES[i];
        }
    }
    let last = row.iter().rposition(|w| *w > 0.0).unwrap_or(0);
    STATES[last]
}

/// Uniform in `[min, max)` (`min` when the range is empty).
pub(crate) fn uniform(rng: &mut RngStream, [min, max]: [f64; 2]) -> f64 {
    min + (max - min) * rng.random::<f64>()
}

/// What the motion needs besides the bead: parameters, the bed surface and the top of the
/// pile on it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Dynamics<'a> {
    /// The scene's parameters.
    pub params: &'a BedloadSceneParams,
    /// The surface of the deposit: the static bed and the creeping layers.
    pub surface: &'a BedSurface,
    /// The surface of the bed and of the mobile beads that stay on it this frame, as they
    /// were at its start: what saltating beads fly over.
    pub top: &'a BedSurface,
}

impl Dynamics<'_> {
    /// −1 or +1, the sign of x downstream.
    pub(crate) fn direction(&self) -> f64 {
        f64::from(self.params.flow_direction)
    }

    /// The point of the surface at `x` for a bead of `class`.
    pub(crate) fn on_surface(&self, x: f64, class: ObjectClass) -> Point2 {
        Point2::new(x, self.surface.y(x, class))
    }
}

/// One ballistic hop from a surface point to another in `frames` frames: the chord plus a
/// parabola of gravity `gravity`, `y(k) = y_a + (y_b − y_a)·k/m − g·k(m − k)/2`.
#[derive(Debug, Clone, Copy, Default)]
struct Hop {
    start: Point2,
    end: Point2,
    frames: u32,
    elapsed: u32,
    gravity: f64,
}

impl Hop {
    /// Position `k` frames after the take-off.
    fn at(&self, k: u32) -> Point2 {
        if k >= self.frames {
            return self.end;
        }
        let (k, m) = (f64::from(k), f64::from(self.frames));
        let chord = self.start + (self.end - self.start) * (k / m);
        Point2::new(chord.x, chord.y - self.gravity * k * (m - k) / 2.0)
    }
}

/// A saltation: its horizontal velocity, the saltating frames still to come, the hop under
/// way.
#[derive(Debug, Clone, Copy, Default)]
struct Flight {
    vel_x: f64,
    frames_left: u64,
    hop: Hop,
}

/// A mobile bead: rests on the bed or on other beads, rolls over them, or saltates above
/// them. Its place among the others is settled by [`super::pile::Pile`] every frame.
#[derive(Debug, Clone)]
pub(crate) struct Mover {
    /// Identity of the bead.
    pub track_id: TrackId,
    /// Its class.
    pub class: ObjectClass,
    /// Its place in contact with the others, px (a resting bead is reported off it by its
    /// jitter).
    pub anchor: Point2,
    /// The state of its last step, drawn from the transition table.
    pub state: MotionState,
    /// The motion state its last step is reported in: its `state`, but rolling where a
    /// resting bead was carried by the creeping layer under it (Eq. (4): it moves).
    pub label: MotionState,
    /// Its place at the start of the frame, before the creeping layer carried it, px: no
    /// bead moves farther than `MAX_STEP_PX` from it in a frame.
    pub origin: Point2,
    /// Whether it lay on the deposit or on beads at the end of the last frame (not in the
    /// air): the creeping layer carries it.
    pub grounded: bool,
    /// How far the creeping layer carried it this frame, px.
    pub carried: Vec2,
    /// Its speed along x while rolling, px/frame.
    rolling_speed: f64,
    /// How far it fell in the last frame while in the air (not in a saltation), px: its
    /// fall speed, which gravity raises in the next frame ([`super::pile::Pile`]).
    pub fall_px: f64,
    flight: Flight,
}

impl Mover {
    /// A bead of `class` on the bed surface at `x` in `state`, before its place among the
    /// others is settled (a saltating one takes off with [`Mover::launch`] once it is).
    pub(crate) fn new(
        track_id: TrackId,
        class: ObjectClass,
        x: f64,
        state: MotionState,
        dynamics: &Dynamics<'_>,
        rng: &mut RngStream,
    ) -> Self {
        Self {
            track_id,
            class,
            anchor: dynamics.on_surface(x, class),
            state,
            label: state,
            origin: dynamics.on_surface(x, class),
            grounded: false,
            carried: Vec2::ZERO,
            rolling_speed: uniform(rng, dynamics.params.rolling_speed_px_per_frame),
            fall_px: 0.0,
            flight: Flight::default(),
        }
    }

    /// The bead's next state, drawn from the transition table (Eq. (3)'s order: state
    /// first, then position, see [`Mover::step`]). A saltation's number of frames is drawn
    /// at its launch from the geometric law the table's saltating row implies (`P(K = k) =
    /// π_ss^(k−1)(1 − π_ss)`), so the per-frame transition frequencies are those of the
    /// table; the state after its last frame is drawn from the saltating row without its
    /// saltating entry.
    pub(crate) fn next_state(
        &self,
        params: &BedloadSceneParams,
        motion: &mut RngStream,
    ) -> MotionState {
        let table = &params.transition_probabilities;
        let u = motion.random::<f64>();
        match self.state {
            MotionState::Saltating if self.flight.frames_left > 0 => MotionState::Saltating,
            MotionState::Saltating => {
                let row = table[2];
                draw([row[0], row[1], 0.0], u)
            }
            state => draw(table[index(state)], u),
        }
    }

    /// Starts a frame: a grounded bead is carried by `dx` along x with the deposit under
    /// it, keeping its height above the deposit's surface (`before` the frame, `after`);
    /// `origin` is where it was.
    pub(crate) fn carry(&mut self, dx: f64, before: &BedSurface, after: &BedSurface) {
        self.origin = self.anchor;
        if self.grounded && dx != 0.0 {
            let x = self.anchor.x + dx;
            let rise = after.y(x, self.class) - before.y(self.anchor.x, self.class);
            self.anchor = Point2::new(x, self.anchor.y + rise);
        }
        self.carried = self.anchor - self.origin;
    }

    /// Ends a frame: a resting bead that the contacts moved (its support went away and it
    /// falls, or it slides off a bead left steep) is set rolling, at the speed of its last
    /// roll; one only carried (by more than `still_px`) is reported rolling.
    pub(crate) fn settled(&mut self, moved_by_contacts: bool, still_px: f64) {
        if moved_by_contacts && self.state == MotionState::Resting {
            self.state = MotionState::Rolling;
        }
        self.label = if self.state == MotionState::Resting && self.carried.norm() > still_px {
            MotionState::Rolling
        } else {
            self.state
        };
    }

    /// Enters state `next` and returns its move, which the pile then limits by the
    /// contacts: resting stays put, rolling advances by its speed along x (a `loaded` bead,
    /// which another lies on, stays put), saltating follows its hop, planned over the pile's
    /// top `dynamics.top` to land on it exactly on the saltation's last frame (or earlier on
    /// a bead that has moved in the way, see [`Mover::end_flight_frame`]). A bead whose
    /// first hop would move it by more than `MAX_STEP_PX` (out of a deep hole), or which
    /// another lies on, does not take off.
    pub(crate) fn step(
        &mut self,
        next: MotionState,
        dynamics: &Dynamics<'_>,
        motion: &mut RngStream,
        loaded: bool,
    ) -> Proposal {
        let mut next = next;
        if next == MotionState::Saltating && self.state != MotionState::Saltating {
            if !loaded {
                self.launch(dynamics, motion);
                let to = self.fly(dynamics, motion);
                if to.distance(self.origin) <= MAX_STEP_PX {
                    self.state = next;
                    return Proposal::Air {
                        to,
                        lands: self.flight.frames_left == 0,
                    };
                }
            }
            // Held down by a bead on it, or too deep in a hole between higher beads to leave
            // it but steeply: it stays in its state.
            next = self.state;
        }
        let proposal = match next {
            MotionState::Resting => Proposal::Ground { dx: 0.0 },
            MotionState::Rolling => {
                if self.state != MotionState::Rolling {
                    self.rolling_speed =
                        uniform(motion, dynamics.params.rolling_speed_px_per_frame);
                }
                let dx = if loaded {
                    0.0
                } else {
                    dynamics.direction() * self.rolling_speed
                };
                Proposal::Ground { dx }
            }
            _ => Proposal::Air {
                to: self.fly(dynamics, motion),
                lands: self.flight.frames_left == 0,
            },
        };
        self.state = next;
        proposal
    }

    /// After a saltating frame: a bead the pile `stopped` on a bead in its way rebounds,
    /// starting a new hop from there on its next frame (Eq. (3)'s saltating-rebound).
    pub(crate) fn end_flight_frame(&mut self, stopped: bool) {
        if stopped {
            self.flight.hop.elapsed = self.flight.hop.frames;
        }
    }

    /// Starts a saltation from the current position: its horizontal velocity and its number
    /// of frames.
    pub(crate) fn launch(&mut self, dynamics: &Dynamics<'_>, rng: &mut RngStream) {
        let params = dynamics.params;
        let speed = uniform(rng, params.saltation_speed_px_per_frame);
        let stay = params.transition_probabilities[2][2];
        let frames = if stay >= 1.0 {
            u64::MAX
        } else if stay <= 0.0 {
            1
        } else {
            // Inversion of the geometric law; `1 − U` is in (0, 1].
            let u = 1.0 - rng.random::<f64>();
            1 + (u.ln() / stay.ln()).floor() as u64
        };
        let hop = Hop {
            start: self.anchor,
            end: self.anchor,
            ..Hop::default()
        };
        self.flight = Flight {
            vel_x: dynamics.direction() * speed,
            frames_left: frames,
            hop,
        };
    }

    /// One saltating frame: the point of the hop under way it aims at, a new hop from the
    /// current position first when the last one has landed or rebounded.
    fn fly(&mut self, dynamics: &Dynamics<'_>, rng: &mut RngStream) -> Point2 {
        if self.flight.hop.elapsed >= self.flight.hop.frames {
            self.flight.hop = self.plan_hop(dynamics, rng);
        }
        let hop = &mut self.flight.hop;
        hop.elapsed += 1;
        self.flight.frames_left = self.flight.frames_left.saturating_sub(1);
        hop.at(hop.elapsed)
    }

    /// A hop from the current position over the pile's top: `round(2v/g)` frames for a
    /// launch speed `v`, its gravity raised where needed to keep every frame in flight
    /// `hop_clearance_px` above the top. Over a pile, a short hop would have to rise and
    /// fall steeply; of the hops of 1 to 3 times that many frames (at most the saltation's
    /// frames left) whose apex stays in the frame, the one closest to it that moves by at
    /// most `MAX_STEP_PX` a frame is taken, else the one that moves least.
    fn plan_hop(&self, dynamics: &Dynamics<'_>, rng: &mut RngStream) -> Hop {
        let params = dynamics.params;
        let g = params.gravity_px_per_frame2;
        let v = uniform(rng, params.launch_speed_px_per_frame);
        let nominal = (2.0 * v / g).round().max(1.0) as u64;
        let longest = (3 * nominal)
            .min(self.flight.frames_left)
            .clamp(1, u64::from(u32::MAX)) as u32;
        let mut best: Option<(bool, u64, f64, Hop)> = None;
        for frames in 1..=longest {
            let hop = self.hop_of(frames, dynamics);
            let apex = (1..frames)
                .map(|k| hop.at(k).y)
                .fold(f64::INFINITY, f64::min);
            if frames > 1 && apex < 0.0 {
                continue;
            }
            let step = (1..=frames)
                .map(|k| hop.at(k).distance(hop.at(k - 1)))
                .fold(0.0, f64::max);
            // Smooth enough first, then closest to the nominal length, then least steep.
            let rank = (
                step > MAX_STEP_PX,
                u64::from(frames).abs_diff(nominal),
                step,
            );
            let better = best.as_ref().is_none_or(|b| {
                (rank.0, rank.1) < (b.0, b.1) || ((rank.0, rank.1) == (b.0, b.1) && rank.2 < b.2)
            });
            if better {
                best = Some((rank.0, rank.1, rank.2, hop));
            }
        }
        best.map_or_else(|| self.hop_of(1, dynamics), |b| b.3)
    }

    /// The hop of `frames` frames from the current position, gravity at least `g`.
    fn hop_of(&self, frames: u32, dynamics: &Dynamics<'_>) -> Hop {
        let params = dynamics.params;
        let start = self.anchor;
        let end_x = start.x + self.flight.vel_x * f64::from(frames);
        let mut hop = Hop {
            start,
            end: Point2::new(end_x, dynamics.top.y(end_x, self.class)),
            frames,
            elapsed: 0,
            gravity: params.gravity_px_per_frame2,
        };
        let m = f64::from(frames);
        for k in (1..frames).map(f64::from) {
            let chord = start.y + (hop.end.y - start.y) * k / m;
            let x = start.x + self.flight.vel_x * k;
            let ceiling = dynamics.top.y(x, self.class) - params.hop_clearance_px;
            hop.gravity = hop.gravity.max(2.0 * (chord - ceiling) / (k * (m - k)));
        }
        hop
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draw_follows_the_cumulative_weights() {
        let row = [0.2, 0.0, 0.8];
        assert_eq!(draw(row, 0.0), MotionState::Resting);
        assert_eq!(draw(row, 0.1999), MotionState::Resting);
        assert_eq!(draw(row, 0.2), MotionState::Saltating);
        assert_eq!(draw(row, 0.999_999_999), MotionState::Saltating);
        // Unnormalised weights (the landing row without its saltating entry).
        assert_eq!(draw([0.0, 0.09, 0.0], 0.5), MotionState::Rolling);
    }

    #[test]
    fn a_hop_starts_and_lands_on_its_end_points() {
        let hop = Hop {
            start: Point2::new(100.0, 50.0),
            end: Point2::new(60.0, 54.0),
            frames: 4,
            elapsed: 0,
            gravity: 2.0,
        };
        assert_eq!(hop.at(0), hop.start);
        assert_eq!(hop.at(4), hop.end);
        // Halfway: the chord's midpoint lifted by g·2·2/2 = 4 px.
        assert_eq!(hop.at(2), Point2::new(80.0, 48.0));
    }
}

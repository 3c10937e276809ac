//! One mobile bead: its motion state drawn from the transition table, and a motion that
//! agrees with it (resting still, rolling along the bed surface, saltating in hops).

use rand::RngExt;
use sillage_core::{MotionState, ObjectClass, Point2, RngStream, TrackId};

use super::BedloadSceneParams;
use super::bed::{BedSurface, disk_offset};

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

/// What the motion needs besides the bead: parameters and the bed surface.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Dynamics<'a> {
    /// The scene's parameters.
    pub params: &'a BedloadSceneParams,
    /// The surface the beads move on.
    pub surface: &'a BedSurface,
}

impl Dynamics<'_> {
    fn direction(&self) -> f64 {
        f64::from(self.params.flow_direction)
    }

    /// The point of the surface at `x` for a bead of `class`.
    fn on_surface(&self, x: f64, class: ObjectClass) -> Point2 {
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

/// A mobile bead: rests on the bed surface, rolls along it, or saltates above it.
#[derive(Debug, Clone)]
pub(crate) struct Mover {
    /// Identity of the bead.
    pub track_id: TrackId,
    /// Its class.
    pub class: ObjectClass,
    /// Its true position, px.
    pub pos: Point2,
    /// The state of its last step.
    pub state: MotionState,
    /// Where it rests (on the surface), while resting.
    rest_point: Point2,
    /// Its speed along x while rolling, px/frame.
    rolling_speed: f64,
    flight: Flight,
}

impl Mover {
    /// A bead of `class` on the surface at `x`, in `state` (saltating: at a take-off).
    pub(crate) fn new(
        track_id: TrackId,
        class: ObjectClass,
        x: f64,
        state: MotionState,
        dynamics: &Dynamics<'_>,
        rng: &mut RngStream,
    ) -> Self {
        let pos = dynamics.on_surface(x, class);
        let mut bead = Self {
            track_id,
            class,
            pos,
            state,
            rest_point: pos,
            rolling_speed: uniform(rng, dynamics.params.rolling_speed_px_per_frame),
            flight: Flight::default(),
        };
        if state == MotionState::Saltating {
            bead.launch(dynamics, rng);
        }
        bead
    }

    /// Moves the bead one frame: a new state from the transition table, then the motion of
    /// that state (Eq. (3)'s order: state first, then position).
    ///
    /// A saltation's number of frames is drawn at its launch from the geometric law the
    /// table's saltating row implies (`P(K = k) = π_ss^(k−1)(1 − π_ss)`), so the per-frame
    /// transition frequencies are those of the table; its hops are planned to land on the
    /// surface exactly on its last frame, and the next state is drawn from the saltating row
    /// without its saltating entry. Saltating frames that fall on a rebound or the landing
    /// are on the surface (a one-frame saltation is a hop between two frames).
    pub(crate) fn step(
        &mut self,
        dynamics: &Dynamics<'_>,
        motion: &mut RngStream,
        jitter: &mut RngStream,
    ) {
        let table = &dynamics.params.transition_probabilities;
        let u = motion.random::<f64>();
        let next = match self.state {
            MotionState::Saltating if self.flight.frames_left > 0 => MotionState::Saltating,
            MotionState::Saltating => {
                let row = table[2];
                draw([row[0], row[1], 0.0], u)
            }
            state => draw(table[index(state)], u),
        };
        let was_resting = self.state == MotionState::Resting;
        if was_resting {
            self.pos = self.rest_point;
        }
        match next {
            MotionState::Resting => {
                if !was_resting {
                    self.rest_point = self.pos;
                }
                // Kept in the frame by a projection, which cannot lengthen a displacement.
                let half = dynamics.params.resting_jitter_px / 2.0;
                let pos = self.rest_point + disk_offset(jitter, half);
                let last_x = dynamics.params.width as f64 - 1.0;
                self.pos = Point2::new(pos.x.clamp(0.0, last_x), pos.y);
            }
            MotionState::Rolling => {
                if self.state != MotionState::Rolling {
                    self.rolling_speed =
                        uniform(motion, dynamics.params.rolling_speed_px_per_frame);
                }
                let x = self.pos.x + dynamics.direction() * self.rolling_speed;
                self.pos = dynamics.on_surface(x, self.class);
            }
            _ => {
                if self.state != MotionState::Saltating {
                    self.launch(dynamics, motion);
                }
                self.fly(dynamics, motion);
            }
        }
        self.state = next;
    }

    /// Starts a saltation from the current (surface) position: its horizontal velocity and
    /// its number of frames.
    fn launch(&mut self, dynamics: &Dynamics<'_>, rng: &mut RngStream) {
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
            start: self.pos,
            end: self.pos,
            ..Hop::default()
        };
        self.flight = Flight {
            vel_x: dynamics.direction() * speed,
            frames_left: frames,
            hop,
        };
    }

    /// One saltating frame: along the hop under way, a new hop from the surface first when
    /// the last one has landed.
    fn fly(&mut self, dynamics: &Dynamics<'_>, rng: &mut RngStream) {
        if self.flight.hop.elapsed >= self.flight.hop.frames {
            self.flight.hop = self.plan_hop(dynamics, rng);
        }
        let hop = &mut self.flight.hop;
        hop.elapsed += 1;
        self.pos = hop.at(hop.elapsed);
        self.flight.frames_left = self.flight.frames_left.saturating_sub(1);
    }

    /// A hop from the current surface point: `round(2v/g)` frames for a launch speed `v`
    /// (at most the saltation's frames left), its gravity raised where needed to keep every
    /// frame in flight `hop_clearance_px` above the surface; shortened while its apex would
    /// leave the top of the frame.
    fn plan_hop(&self, dynamics: &Dynamics<'_>, rng: &mut RngStream) -> Hop {
        let params = dynamics.params;
        let g = params.gravity_px_per_frame2;
        let v = uniform(rng, params.launch_speed_px_per_frame);
        let nominal = (2.0 * v / g).round().max(1.0) as u64;
        let mut frames = nominal
            .min(self.flight.frames_left)
            .min(u64::from(u32::MAX)) as u32;
        loop {
            let hop = self.hop_of(frames, dynamics);
            let top = (1..frames)
                .map(|k| hop.at(k).y)
                .fold(f64::INFINITY, f64::min);
            if frames <= 1 || top >= 0.0 {
                return hop;
            }
            frames -= 1;
        }
    }

    /// The hop of `frames` frames from the current position, gravity at least `g`.
    fn hop_of(&self, frames: u32, dynamics: &Dynamics<'_>) -> Hop {
        let params = dynamics.params;
        let start = self.pos;
        let end_x = start.x + self.flight.vel_x * f64::from(frames);
        let mut hop = Hop {
            start,
            end: dynamics.on_surface(end_x, self.class),
            frames,
            elapsed: 0,
            gravity: params.gravity_px_per_frame2,
        };
        let m = f64::from(frames);
        for k in (1..frames).map(f64::from) {
            let chord = start.y + (hop.end.y - start.y) * k / m;
            let x = start.x + self.flight.vel_x * k;
            let ceiling = dynamics.surface.y(x, self.class) - params.hop_clearance_px;
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

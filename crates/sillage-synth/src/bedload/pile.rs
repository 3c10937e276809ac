//! Contacts between the mobile beads: every frame, each bead takes its new place among the
//! bed and the beads already placed, so that no two beads come closer than their contact
//! distance ([`BedloadSceneParams::contact_distance_px`]). The paper's flume is 6.5 mm wide,
//! about one bead (MMPF+ §4.1): beads pile up on the bed and on each other, roll over lower
//! ones and stop behind higher ones, and saltating beads rebound on them (§3.5.1).
//!
//! The beads on the bed (resting and rolling) are placed bottom first, in the order of their
//! height in the previous frame, each on the upper envelope of the bed surface and of the
//! beads placed before it at its new x (a bead lies on the beads below it, in the dip
//! between two where it can). A moving bead advances by steps of 0.5 px and is held back
//! before a step that would lift it onto a bead not low enough (`min_climb_angle_deg`; the
//! bed itself never holds a bead back) or bring it within contact of a bead not placed yet
//! (which keeps the previous frame's order of the beads one above the other, so that
//! staying put is always a valid place; beads in flight count as not placed yet). Beads
//! that carry another are not moved ([`Pile::loads`]), so a resting bead keeps its place
//! to the last bit. New beads are then dropped from above and slide into a dip, and
//! saltating beads, placed last, rebound where a bead has moved into their hop (see
//! [`Pile::fly`]).
//!
//! Beads move continuously: no bead moves by more than `MAX_STEP_PX` in a frame. A bead
//! that rolls off a ledge, or whose support moves away or takes off, falls under gravity
//! over the next frames ([`Pile::free_fall`]); a saltating bead stops where a bead is in
//! its way. The only exception to the contact distance is a pile reaching the top of the
//! frame, where centres are kept inside it (not with the default parameters).

use sillage_core::{BLACK_BEAD_CLASS, MotionState, Point2, TRANSPARENT_BEAD_CLASS, Vec2};

use super::BedloadSceneParams;
use super::motion::{Dynamics, Mover};

/// Tolerance of the contact tests, px (rounding only).
const EPS_PX: f64 = 1e-9;

/// Most pushes that free a bead from the placed beads it overlaps (each from one of them).
const PUSHES: usize = 4;

/// Tolerance of a flying bead's contacts, px: the bed surface is tabulated within it, and
/// the settling leaves beads in contact off it by less.
const SURFACE_TOLERANCE_PX: f64 = 0.1;

/// A bead lying within this of a bead below it (vertically) is held by it, px: a bead in
/// the dip between two beads, found by steps of 0.5 px, is off the exact contact by less.
const SUPPORT_TOLERANCE_PX: f64 = 0.5;

/// The beads a bead lies on (at most two, in a dip between them; none on the bed alone).
type Supports = [Option<usize>; 2];

/// Largest displacement of a bead in a frame, px (a capped speed): below BeadTracking's
/// search radius (vMax / mByPx / acqFreq = 31 px, MMPF+ §4.3) and above the fastest
/// saltations' 20 px. A bead that would fall further stays in the air on the way, and
/// falls on in the next frame.
pub(crate) const MAX_STEP_PX: f64 = 25.0;

/// Least elevation of the contact through which a bead lies on another, degrees: a bead
/// touching others only from the side (a horizontal chain, a saltating bead stopped against
/// one) falls.
const MIN_SUPPORT_ANGLE_DEG: f64 = 40.0;

/// Step of a bead's advance or slide along the envelope, px.
const SLIDE_STEP_PX: f64 = 0.5;

/// A drop of the envelope by more than this between two steps of 0.5 px is a ledge, px (a
/// slope steeper than 76°): the bead runs off the bead it lay on and falls rather than rolls.
const LEDGE_PX: f64 = 2.0;

/// Where a bead is placed in a frame.
#[derive(Debug, Clone, Copy)]
struct Placement {
    /// Its centre, px.
    pos: Point2,
    /// The placed beads it lies on.
    supports: Supports,
    /// Whether it is in the air, falling (not a saltation's flight).
    airborne: bool,
}

impl Placement {
    /// In the air at `pos`, lying on nothing.
    fn air(pos: Point2) -> Self {
        Self {
            pos,
            supports: [None; 2],
            airborne: true,
        }
    }
}

/// What a mobile bead does this frame, before the contacts limit it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Proposal {
    /// On the bed or on beads: advance by up to `dx` along x from the current place (0 for a
    /// resting or loaded bead).
    Ground {
        /// The free step along x, px.
        dx: f64,
    },
    /// Enter from above at the lowest point of the span `x` (sampled every 0.5 px), then
    /// slide into the dip there (new beads, frame 0).
    Drop {
        /// The span, px, either way round.
        x: [f64; 2],
    },
    /// In flight towards `to`, stopped short where its path would meet a bead.
    Air {
        /// The point of the hop for this frame.
        to: Point2,
        /// Whether this is the saltation's last frame: it then comes down onto the beads
        /// below `to` (where the pile has moved since the hop was planned).
        lands: bool,
    },
}

/// Where a bead is during a settling: not in the grid, at its previous place, or placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Status {
    Away,
    Old,
    New,
}

/// The settling of the mobile beads, with a grid of x cells to find the neighbours and the
/// support of each bead (the bead it lies on) from the last frame.
#[derive(Debug, Clone)]
pub(crate) struct Pile {
    cell_px: f64,
    cells: Vec<Vec<usize>>,
    cell_of: Vec<usize>,
    status: Vec<Status>,
    supports: Vec<Supports>,
    stopped: Vec<bool>,
    order: Vec<usize>,
}

impl Pile {
    /// An empty pile for `n` mobile beads.
    pub(crate) fn new(params: &BedloadSceneParams, n: usize) -> Self {
        let (black, transparent) = (BLACK_BEAD_CLASS, TRANSPARENT_BEAD_CLASS);
        let cell_px = [
            (black, black),
            (black, transparent),
            (transparent, transparent),
        ]
        .map(|(a, b)| params.contact_distance_px(a, b))
        .into_iter()
        .fold(1.0, f64::max);
        let n_cells = (params.width as f64 / cell_px).ceil() as usize + 1;
        Self {
            cell_px,
            cells: vec![Vec::new(); n_cells],
            cell_of: vec![0; n],
            status: vec![Status::Away; n],
            supports: vec![[None; 2]; n],
            stopped: vec![false; n],
            order: Vec::with_capacity(n),
        }
    }

    /// For each bead, whether another one lay on it in the last frame: such a bead must not
    /// move, or the one above would be left in the air.
    pub(crate) fn loads(&self) -> Vec<bool> {
        let mut loaded = vec![false; self.supports.len()];
        for &j in self.supports.iter().flatten().flatten() {
            loaded[j] = true;
        }
        loaded
    }

    fn cell(&self, x: f64) -> usize {
        ((x / self.cell_px).floor().max(0.0) as usize).min(self.cells.len() - 1)
    }

    /// The beads of the cells that can hold a bead within a contact distance of `x`.
    fn near(&self, x: f64) -> impl Iterator<Item = usize> + '_ {
        let c = self.cell(x);
        self.cells[c.saturating_sub(1)..=(c + 1).min(self.cells.len() - 1)]
            .iter()
            .flatten()
            .copied()
    }

    fn insert(&mut self, i: usize, x: f64) {
        let c = self.cell(x);
        self.cells[c].push(i);
        self.cell_of[i] = c;
    }

    fn remove(&mut self, i: usize) {
        let cell = &mut self.cells[self.cell_of[i]];
        if let Some(k) = cell.iter().position(|&j| j == i) {
            cell.swap_remove(k);
        }
    }

    /// The highest place (least y) of bead `i` at `x` that clears the bed and every placed
    /// bead, and the placed beads it lies on there.
    fn envelope(
        &self,
        movers: &[Mover],
        i: usize,
        x: f64,
        dynamics: &Dynamics<'_>,
    ) -> (f64, Supports) {
        let class = movers[i].class;
        // The two highest tops of the placed beads within reach, highest first.
        let mut tops: [Option<(f64, usize)>; 2] = [None; 2];
        for j in self.near(x) {
            if self.status[j] != Status::New || j == i {
                continue;
            }
            let other = movers[j].anchor;
            let d = dynamics.params.contact_distance_px(class, movers[j].class);
            let dx = x - other.x;
            if dx.abs() < d {
                let top = (other.y - (d * d - dx * dx).sqrt(), j);
                if tops[0].is_none_or(|t| top.0 < t.0) {
                    tops = [Some(top), tops[0]];
                } else if tops[1].is_none_or(|t| top.0 < t.0) {
                    tops[1] = Some(top);
                }
            }
        }
        let y = tops[0]
            .map_or(f64::INFINITY, |t| t.0)
            .min(dynamics.surface.y(x, class));
        // A bead touching another from the side (its centre not below by the least support
        // angle) is not held by it.
        let below = |j: usize| {
            let d = dynamics.params.contact_distance_px(class, movers[j].class);
            movers[j].anchor.y - y >= d * MIN_SUPPORT_ANGLE_DEG.to_radians().sin()
        };
        let holds = |t: Option<(f64, usize)>| {
            t.filter(|t| t.0 <= y + SUPPORT_TOLERANCE_PX && below(t.1))
                .map(|t| t.1)
        };
        (y, tops.map(holds))
    }

    /// Whether bead `i` at `p` would come closer than the contact distance to a bead not
    /// placed yet, or rise above one within reach (the beads left at their previous place).
    fn blocked(&self, movers: &[Mover], i: usize, p: Point2, params: &BedloadSceneParams) -> bool {
        self.near(p.x).any(|j| {
            if self.status[j] != Status::Old || j == i {
                return false;
            }
            let other = movers[j].anchor;
            let d = params.contact_distance_px(movers[i].class, movers[j].class);
            let dx = p.x - other.x;
            dx.abs() < d && p.y < other.y + (d * d - dx * dx).sqrt() - EPS_PX
        })
    }

    /// A placed bead that bead `i` at `p` would come closer to than their contact distance.
    fn overlapped(
        &self,
        movers: &[Mover],
        i: usize,
        p: Point2,
        params: &BedloadSceneParams,
    ) -> Option<usize> {
        self.near(p.x).find(|&j| {
            let d = params.contact_distance_px(movers[i].class, movers[j].class);
            self.status[j] == Status::New && j != i && movers[j].anchor.distance(p) < d - EPS_PX
        })
    }

    /// Bead `i` at `place`, pushed straight away from the placed beads it overlaps (one that
    /// a carried bead rose into) to their contact distance, into the air to fall from there.
    fn pushed_out(
        &self,
        movers: &[Mover],
        i: usize,
        place: Placement,
        params: &BedloadSceneParams,
    ) -> Placement {
        let mut pos = place.pos;
        for _ in 0..PUSHES {
            let Some(j) = self.overlapped(movers, i, pos, params) else {
                break;
            };
            let d = params.contact_distance_px(movers[i].class, movers[j].class);
            let away = pos - movers[j].anchor;
            let norm = away.norm();
            let unit = if norm > EPS_PX {
                away * (1.0 / norm)
            } else {
                Vec2::new(0.0, -1.0)
            };
            pos = movers[j].anchor + unit * d;
        }
        if pos == place.pos {
            place
        } else {
            Placement::air(pos)
        }
    }

    /// The place of bead `i` on the envelope at `x` ([`Pile::envelope`]).
    fn on_envelope(
        &self,
        movers: &[Mover],
        i: usize,
        x: f64,
        dynamics: &Dynamics<'_>,
    ) -> Placement {
        let (y, supports) = self.envelope(movers, i, x, dynamics);
        Placement {
            pos: Point2::new(x, y),
            supports,
            airborne: false,
        }
    }

    /// The new place of a bead on the bed that moves by up to `dx` from its place. With
    /// nothing under it (its support moved away or took off, or it rolled off a ledge) it
    /// falls ([`Pile::free_fall`]). Else it advances by steps of at most 0.5 px along the
    /// envelope and stops before the first one that would lift it above the bed surface onto
    /// a bead not low enough (`min_climb_angle_deg`; the bed itself never holds a bead back),
    /// bring it within contact of a bead not placed yet (staying put is always free, see the
    /// module's comment) or take it farther than `MAX_STEP_PX` from its place; at a ledge
    /// it rolls off into the air ([`Pile::roll_to`]). Left hanging on the side of a bead, it
    /// then slides down into the dip.
    fn ground_place(
        &self,
        movers: &[Mover],
        i: usize,
        dx: f64,
        dynamics: &Dynamics<'_>,
    ) -> Placement {
        let from = movers[i].anchor;
        let class = movers[i].class;
        let params = dynamics.params;
        let last_x = params.width as f64 - 1.0;
        let start = self.on_envelope(movers, i, from.x, dynamics);
        let on_bed = dynamics.surface.y(from.x, class) <= start.pos.y + SUPPORT_TOLERANCE_PX;
        let lying = start.pos.y <= from.y + SUPPORT_TOLERANCE_PX;
        if !lying || !(on_bed || start.supports[0].is_some()) {
            return self.free_fall(movers, i, dynamics);
        }
        if dx == 0.0 {
            return if self.steady(movers, i, &start, params) {
                start
            } else {
                self.slide(movers, i, start, true, dynamics)
            };
        }
        let height = |p: Point2| dynamics.surface.y(p.x, class) - p.y;
        let sin_climb = params.min_climb_angle_deg.to_radians().sin();
        // Rising above the bed is climbing onto the bead it lies on, which must lie low.
        let free = |place: &Placement, next: &Placement| {
            let climbs = height(next.pos) - height(place.pos) > EPS_PX;
            let low = next.supports[0].is_some_and(|j| {
                let d = params.contact_distance_px(class, movers[j].class);
                movers[j].anchor.y - next.pos.y >= d * sin_climb
            });
            (!climbs || low) && !self.blocked(movers, i, next.pos, params)
        };
        let mut place = start;
        let steps = (dx.abs() / SLIDE_STEP_PX).ceil() as usize;
        for k in 1..=steps {
            let x = (from.x + dx * k as f64 / steps as f64).clamp(0.0, last_x);
            let next = self.on_envelope(movers, i, x, dynamics);
            if !free(&place, &next) {
                break;
            }
            let (reached, on) = self.roll_to(movers, i, place, next, params);
            place = reached;
            if !on {
                break;
            }
        }
        if !place.airborne && !self.steady(movers, i, &place, params) {
            place = self.slide(movers, i, place, true, dynamics);
        }
        place
    }

    /// Bead `i`, which has got to `place` on the envelope, goes on to `next`, the envelope
    /// 0.5 px further: the place reached and whether it may go on. It stops at `place` where
    /// `next` lies farther than `MAX_STEP_PX` from where the bead started the frame (its
    /// `origin`, a capped speed); where the envelope drops by more than `LEDGE_PX` (a ledge: the bead
    /// runs off the bead it lay on) it leaves the surface, into the air above `next` at
    /// `place`'s height, and falls from there in the next frames.
    fn roll_to(
        &self,
        movers: &[Mover],
        i: usize,
        place: Placement,
        next: Placement,
        params: &BedloadSceneParams,
    ) -> (Placement, bool) {
        if next.pos.distance(movers[i].origin) > MAX_STEP_PX {
            return (place, false);
        }
        if next.pos.y - place.pos.y > LEDGE_PX {
            let edge = Point2::new(next.pos.x, place.pos.y);
            let off = if self.blocked(movers, i, edge, params) {
                place
            } else {
                Placement::air(edge)
            };
            return (off, false);
        }
        (next, true)
    }

    /// Bead `i`, lying neither on the bed nor on a bead below it, falls straight down: by its
    /// fall of the last frame plus `gravity_px_per_frame2` (the fall speed grows under the
    /// buoyancy-reduced gravity), at most `MAX_STEP_PX` (a capped speed), landing on the
    /// first bead or the bed under it when it gets there. Wedged between beads on its sides,
    /// it slides down the envelope where it can (lifted first out of a bead that rose into
    /// it).
    fn free_fall(&self, movers: &[Mover], i: usize, dynamics: &Dynamics<'_>) -> Placement {
        let from = movers[i].anchor;
        let params = dynamics.params;
        let mut room = dynamics.surface.y(from.x, movers[i].class) - from.y;
        let mut hit = None;
        for j in self.near(from.x) {
            let other = movers[j].anchor;
            let d = params.contact_distance_px(movers[i].class, movers[j].class);
            let dx = from.x - other.x;
            if self.status[j] == Status::Away || j == i || dx.abs() >= d || other.y <= from.y {
                continue;
            }
            let gap = other.y - (d * d - dx * dx).sqrt() - from.y;
            if gap < room {
                (room, hit) = (gap, Some(j));
            }
        }
        if room <= SUPPORT_TOLERANCE_PX {
            // Sunk into the bead under it (the deposit rose under that one): lifted onto it,
            // or onto the envelope if a placed bead beside it is in the way.
            let envelope = self.on_envelope(movers, i, from.x, dynamics);
            let lifted = Point2::new(from.x, from.y + room.min(0.0));
            let start = if self.overlapped(movers, i, lifted, params).is_some() {
                envelope
            } else {
                Placement {
                    pos: lifted,
                    ..envelope
                }
            };
            return self.slide(movers, i, start, true, dynamics);
        }
        let fall = (movers[i].fall_px + params.gravity_px_per_frame2).min(MAX_STEP_PX);
        let pos = Point2::new(from.x, from.y + fall.min(room.max(0.0)));
        if fall < room {
            return Placement::air(pos);
        }
        let supports = [hit.filter(|&j| self.status[j] == Status::New), None];
        Placement {
            pos,
            supports,
            airborne: false,
        }
    }

    /// Whether bead `i` can stay at `place`: on the bed, in a dip between two beads, or on a
    /// bead through a contact at least `min_climb_angle_deg` above the horizontal. Else it
    /// hangs on the side of a bead and slides down.
    fn steady(
        &self,
        movers: &[Mover],
        i: usize,
        place: &Placement,
        params: &BedloadSceneParams,
    ) -> bool {
        match place.supports {
            [Some(j), None] => {
                let d = params.contact_distance_px(movers[i].class, movers[j].class);
                let sin_climb = params.min_climb_angle_deg.to_radians().sin();
                movers[j].anchor.y - place.pos.y >= d * sin_climb - EPS_PX
            }
            _ => true,
        }
    }

    /// The place of a bead that slides from `start` down the envelope's slope by steps of 0.5 px
    /// to the bottom of the dip, at most one bead diameter away, stopping before a bead not
    /// placed yet: dropped beads pack as a deposit does rather than stick where they first
    /// touch, and beads left on the side of another slide off. A `moving` bead (not a
    /// newcomer) moves as [`Pile::roll_to`] lets it.
    fn slide(
        &self,
        movers: &[Mover],
        i: usize,
        start: Placement,
        moving: bool,
        dynamics: &Dynamics<'_>,
    ) -> Placement {
        let params = dynamics.params;
        let last_x = params.width as f64 - 1.0;
        let reach = 2.0 * params.radius_px(movers[i].class);
        let x = start.pos.x;
        let mut best = start;
        let (left, right) = (
            self.on_envelope(movers, i, (x - SLIDE_STEP_PX).max(0.0), dynamics),
            self.on_envelope(movers, i, (x + SLIDE_STEP_PX).min(last_x), dynamics),
        );
        let step = if left.pos.y > right.pos.y {
            -SLIDE_STEP_PX
        } else {
            SLIDE_STEP_PX
        };
        while (best.pos.x - x).abs() < reach {
            let x = (best.pos.x + step).clamp(0.0, last_x);
            let next = self.on_envelope(movers, i, x, dynamics);
            if next.pos.y <= best.pos.y || self.blocked(movers, i, next.pos, params) {
                break;
            }
            if !moving {
                best = next;
                continue;
            }
            let (reached, on) = self.roll_to(movers, i, best, next, params);
            best = reached;
            if !on {
                break;
            }
        }
        best
    }

    /// Whether bead `i` at `p` is clear of the bed and of every other bead placed or not
    /// placed yet (a flying bead may pass beside or under a bead, not through it).
    fn clear(&self, movers: &[Mover], i: usize, p: Point2, dynamics: &Dynamics<'_>) -> bool {
        let params = dynamics.params;
        p.y <= dynamics.surface.y(p.x, movers[i].class) + SURFACE_TOLERANCE_PX
            && !self.near(p.x).any(|j| {
                let d = params.contact_distance_px(movers[i].class, movers[j].class);
                self.status[j] != Status::Away
                    && j != i
                    && movers[j].anchor.distance(p) < d - SURFACE_TOLERANCE_PX
            })
    }

    /// The place of a flying bead aimed at `to`, its hop's point for this frame (the frames
    /// are all that is seen of a flight), at most `MAX_STEP_PX` from its place (a capped
    /// speed), and whether it was stopped short. Where a bead has moved into that point since
    /// the hop was planned (over the pile's top), it stops at the last point clear of the
    /// beads on the way there, to rebound from it ([`Pile::stopped`]). On the saltation's
    /// last frame (`lands`) it comes down onto the envelope below that point, or towards it
    /// by what `MAX_STEP_PX` leaves, to fall on in the next frames.
    fn fly(
        &self,
        movers: &[Mover],
        i: usize,
        to: Point2,
        lands: bool,
        dynamics: &Dynamics<'_>,
    ) -> (Placement, bool) {
        let from = movers[i].anchor;
        let length = from.distance(to);
        // What is left of the frame's largest step after the carry of a take-off.
        let budget = MAX_STEP_PX - movers[i].carried.norm();
        let capped = length > budget;
        let end = if capped {
            from + (to - from) * (budget / length)
        } else {
            to
        };
        if !self.clear(movers, i, end, dynamics) {
            let steps = (from.distance(end) / SLIDE_STEP_PX).ceil() as usize;
            let reached = (0..steps)
                .rev()
                .map(|k| from + (end - from) * (k as f64 / steps as f64))
                .find(|&p| self.clear(movers, i, p, dynamics))
                .unwrap_or_else(|| self.lifted(movers, i, budget, dynamics));
            return (Placement::air(reached), true);
        }
        if !lands {
            return (Placement::air(end), capped);
        }
        let below = self.on_envelope(movers, i, end.x, dynamics);
        if below.pos.distance(from) <= budget {
            return (below, false);
        }
        // The lowest point above `below` within reach: `end` is, so the root is real.
        let run = end.x - from.x;
        let y = from.y + (budget * budget - run * run).max(0.0).sqrt();
        let low = Point2::new(end.x, y.max(end.y));
        let place = if self.clear(movers, i, low, dynamics) {
            low
        } else {
            end
        };
        (Placement::air(place), false)
    }

    /// The lowest point above flying bead `i`, by steps of 0.5 px up to `reach`, where it is
    /// clear of the others (a bead carried up by the creeping layer rose into it); its place
    /// if there is none.
    fn lifted(&self, movers: &[Mover], i: usize, reach: f64, dynamics: &Dynamics<'_>) -> Point2 {
        let from = movers[i].anchor;
        let steps = (reach / SLIDE_STEP_PX).floor() as usize;
        (1..=steps)
            .map(|k| Point2::new(from.x, from.y - k as f64 * SLIDE_STEP_PX))
            .find(|&p| self.clear(movers, i, p, dynamics))
            .unwrap_or(from)
    }

    /// Whether flying bead `i` was stopped short of its hop's point in the last settling.
    pub(crate) fn stopped(&self, i: usize) -> bool {
        self.stopped[i]
    }

    /// Settles every mobile bead after its `proposals` (one per bead): see the module's
    /// comment. Sets each bead's `anchor` and remembers the supports for [`Pile::loads`].
    pub(crate) fn settle(
        &mut self,
        movers: &mut [Mover],
        proposals: &[Proposal],
        dynamics: &Dynamics<'_>,
    ) {
        let params = dynamics.params;
        for cell in &mut self.cells {
            cell.clear();
        }
        for (i, proposal) in proposals.iter().enumerate() {
            self.status[i] = Status::Away;
            // Beads in flight are in the way of the others until they are placed.
            if !matches!(proposal, Proposal::Drop { .. }) {
                self.status[i] = Status::Old;
                self.insert(i, movers[i].anchor.x);
            }
        }
        let mut order = std::mem::take(&mut self.order);
        order.clear();
        order.extend(0..movers.len());
        let rank = |p: &Proposal| match p {
            Proposal::Ground { .. } => 0,
            Proposal::Drop { .. } => 1,
            Proposal::Air { .. } => 2,
        };
        order.sort_by(|&a, &b| {
            // Dropped beads: the small ones first, as they fall through the gaps, the ones
            // about to take off last, so that none lies on them.
            let key = |i: usize| {
                let drop = matches!(proposals[i], Proposal::Drop { .. });
                let late = movers[i].state == MotionState::Saltating;
                let sieve = drop && movers[i].class == BLACK_BEAD_CLASS;
                ((rank(&proposals[i]), late, sieve), -movers[i].anchor.y)
            };
            let (ka, kb) = (key(a), key(b));
            ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1)).then(a.cmp(&b))
        });
        for &i in &order {
            self.stopped[i] = false;
            let from = movers[i].anchor;
            let place = match proposals[i] {
                Proposal::Ground { dx } => self.ground_place(movers, i, dx, dynamics),
                Proposal::Drop { x } => {
                    let steps = ((x[1] - x[0]).abs() / SLIDE_STEP_PX).ceil() as usize;
                    // The lowest point clear of the beads in flight.
                    let lowest = (0..=steps)
                        .map(|k| x[0] + (x[1] - x[0]) * k as f64 / steps.max(1) as f64)
                        .map(|x| (self.envelope(movers, i, x, dynamics).0, x))
                        .filter(|&(y, x)| !self.blocked(movers, i, Point2::new(x, y), params))
                        .fold(
                            (f64::NEG_INFINITY, x[0]),
                            |a, b| if b.0 > a.0 { b } else { a },
                        );
                    let start = self.on_envelope(movers, i, lowest.1, dynamics);
                    self.slide(movers, i, start, false, dynamics)
                }
                Proposal::Air { to, lands } => {
                    let (place, stopped) = self.fly(movers, i, to, lands, dynamics);
                    self.stopped[i] = stopped;
                    place
                }
            };
            // Flying beads were kept clear of every bead by `fly`.
            let place = match proposals[i] {
                Proposal::Air { .. } => place,
                _ => self.pushed_out(movers, i, place, params),
            };
            if self.status[i] == Status::Old {
                self.remove(i);
            }
            movers[i].anchor = Point2::new(place.pos.x, place.pos.y.max(0.0));
            // A bead left in the air falls on in the next frame at the speed it had.
            movers[i].fall_px = if place.airborne {
                (movers[i].anchor.y - from.y).max(0.0)
            } else {
                0.0
            };
            movers[i].grounded = !place.airborne;
            self.status[i] = Status::New;
            self.supports[i] = place.supports;
            self.insert(i, place.pos.x);
        }
        self.order = order;
    }
}

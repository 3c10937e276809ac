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
//! bed itself never holds a bead back), drop it by more than its diameter, or bring it
//! within contact of a bead not placed yet (which keeps the previous frame's order of the
//! beads one above the other, so that staying put is always a valid place). Beads that
//! carry another are not moved ([`Pile::loads`]), so a resting bead keeps its place to the
//! last bit. New beads are then dropped from above and slide into a dip, and saltating
//! beads, placed last, rebound where a bead has moved into their hop (see [`Pile::fly`]). The only exception to the contact distance is a pile reaching the top of the
//! frame, where centres are kept inside it (not with the default parameters).

use sillage_core::{BLACK_BEAD_CLASS, MotionState, Point2, TRANSPARENT_BEAD_CLASS};

use super::BedloadSceneParams;
use super::motion::{Dynamics, Mover};

/// Tolerance of the contact tests, px (rounding only).
const EPS_PX: f64 = 1e-9;

/// A bead lying within this of a bead below it (vertically) is held by it, px: a bead in
/// the dip between two beads, found by steps of 0.5 px, is off the exact contact by less.
const SUPPORT_TOLERANCE_PX: f64 = 0.5;

/// The beads a bead lies on (at most two, in a dip between them; none on the bed alone).
type Supports = [Option<usize>; 2];

/// Largest displacement of a bead in a frame that the settling keeps to where it can, px:
/// below BeadTracking's search radius (vMax / mByPx / acqFreq = 31 px, MMPF+ §4.3) and
/// above the fastest saltations' 20 px. A bead that would fall further stays in the air on
/// the way, and falls on in the next frame.
pub(crate) const MAX_STEP_PX: f64 = 25.0;

/// Step of a bead's advance or slide along the envelope, px.
const SLIDE_STEP_PX: f64 = 0.5;

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
        let holds =
            |t: Option<(f64, usize)>| t.filter(|t| t.0 <= y + SUPPORT_TOLERANCE_PX).map(|t| t.1);
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

    /// The new place of a bead on the bed that moves by up to `dx` from its place: it
    /// advances by steps of at most 0.5 px and stops before the first one that would lift it
    /// above the bed surface onto a bead not low enough (`min_climb_angle_deg`), drop it by
    /// more than its diameter, or bring it within contact of a bead not placed yet (staying
    /// put is always free, see the module's comment). Left hanging on the side of a bead, it
    /// then slides down into the dip.
    fn ground_place(
        &self,
        movers: &[Mover],
        i: usize,
        dx: f64,
        dynamics: &Dynamics<'_>,
    ) -> (Point2, Supports) {
        let from = movers[i].anchor;
        let class = movers[i].class;
        let last_x = dynamics.params.width as f64 - 1.0;
        let at = |x: f64| {
            let (y, support) = self.envelope(movers, i, x, dynamics);
            (Point2::new(x, y), support)
        };
        let height = |p: Point2| dynamics.surface.y(p.x, class) - p.y;
        let sin_climb = dynamics.params.min_climb_angle_deg.to_radians().sin();
        // Rising above the bed is climbing onto the bead it lies on, which must lie low.
        let free = |(place, _): &(Point2, Supports), (next, held): &(Point2, Supports)| {
            let climbs = height(*next) - height(*place) > EPS_PX;
            let low = held[0].is_some_and(|j| {
                let d = dynamics.params.contact_distance_px(class, movers[j].class);
                movers[j].anchor.y - next.y >= d * sin_climb
            });
            (!climbs || low) && !self.blocked(movers, i, *next, dynamics.params)
        };
        let mut place = at(from.x);
        if dx == 0.0 {
            return place;
        }
        // It falls by at most its diameter in a frame: it rolls off a bead onto the bed,
        // not off a ledge higher, so that it moves by less than BeadTracking's search radius
        // (31 px for a 5 px roll off a 30 px black bead).
        let fall = 2.0 * dynamics.params.radius_px(class);
        let steps = (dx.abs() / SLIDE_STEP_PX).ceil() as usize;
        for k in 1..=steps {
            let next = at((from.x + dx * k as f64 / steps as f64).clamp(0.0, last_x));
            if !free(&place, &next) || next.0.y - from.y > fall {
                break;
            }
            place = next;
        }
        if !self.steady(movers, i, &place, dynamics.params) {
            place = self.slide(movers, i, place.0.x, dynamics);
        }
        self.within_reach(movers, i, place, dynamics.params)
    }

    /// `place` if bead `i` gets there from its place by at most `MAX_STEP_PX`, else, for a
    /// fall, the point above it that far from its place, in the air (it lies on nothing and
    /// falls on in the next frame), where no bead not placed yet is in the way.
    fn within_reach(
        &self,
        movers: &[Mover],
        i: usize,
        place: (Point2, Supports),
        params: &BedloadSceneParams,
    ) -> (Point2, Supports) {
        let from = movers[i].anchor;
        let run = (place.0.x - from.x).abs();
        if from.distance(place.0) <= MAX_STEP_PX || place.0.y < from.y || run >= MAX_STEP_PX {
            return place;
        }
        // Above the envelope at its x, so clear of the beads placed so far.
        let p = Point2::new(
            place.0.x,
            from.y + (MAX_STEP_PX * MAX_STEP_PX - run * run).sqrt(),
        );
        if self.blocked(movers, i, p, params) {
            place
        } else {
            (p, [None; 2])
        }
    }

    /// Whether bead `i` can stay at `place`: on the bed, in a dip between two beads, or on a
    /// bead through a contact at least `min_climb_angle_deg` above the horizontal. Else it
    /// hangs on the side of a bead and slides down.
    fn steady(
        &self,
        movers: &[Mover],
        i: usize,
        (place, held): &(Point2, Supports),
        params: &BedloadSceneParams,
    ) -> bool {
        match held {
            &[Some(j), None] => {
                let d = params.contact_distance_px(movers[i].class, movers[j].class);
                let sin_climb = params.min_climb_angle_deg.to_radians().sin();
                movers[j].anchor.y - place.y >= d * sin_climb - EPS_PX
            }
            _ => true,
        }
    }

    /// The place of a bead that slides from `x` down the envelope's slope by steps of 0.5 px
    /// to the bottom of the dip, at most one bead diameter away, stopping before a bead not
    /// placed yet: dropped beads pack as a deposit does rather than stick where they first
    /// touch, and beads left on the side of another slide off.
    fn slide(
        &self,
        movers: &[Mover],
        i: usize,
        x: f64,
        dynamics: &Dynamics<'_>,
    ) -> (Point2, Supports) {
        let last_x = dynamics.params.width as f64 - 1.0;
        let reach = 2.0 * dynamics.params.radius_px(movers[i].class);
        let at = |x: f64| {
            let (y, support) = self.envelope(movers, i, x, dynamics);
            (Point2::new(x, y), support)
        };
        let mut best = at(x);
        let (left, right) = (
            at((x - SLIDE_STEP_PX).max(0.0)),
            at((x + SLIDE_STEP_PX).min(last_x)),
        );
        let step = if left.0.y > right.0.y {
            -SLIDE_STEP_PX
        } else {
            SLIDE_STEP_PX
        };
        while (best.0.x - x).abs() < reach {
            let next = at((best.0.x + step).clamp(0.0, last_x));
            if next.0.y <= best.0.y || self.blocked(movers, i, next.0, dynamics.params) {
                break;
            }
            best = next;
        }
        best
    }

    /// The place of a flying bead aimed at `to`, its hop's point for this frame (the frames
    /// are all that is seen of a flight): `to` where it is clear of the placed beads and the
    /// bed, or on the envelope below it when the bead `lands` (falling by `MAX_STEP_PX` at
    /// most in the frame). Where a bead has moved into
    /// it since the hop was planned (over the pile's top), the flying bead is lifted onto the
    /// envelope and rebounds from there ([`Pile::stopped`]).
    fn fly(
        &self,
        movers: &[Mover],
        i: usize,
        to: Point2,
        lands: bool,
        dynamics: &Dynamics<'_>,
    ) -> (Point2, Supports, bool) {
        let (y, held) = self.envelope(movers, i, to.x, dynamics);
        if y < to.y - EPS_PX {
            (Point2::new(to.x, y), held, true)
        } else if lands {
            let (place, held) =
                self.within_reach(movers, i, (Point2::new(to.x, y), held), dynamics.params);
            (place, held, false)
        } else {
            (to, [None; 2], false)
        }
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
        for cell in &mut self.cells {
            cell.clear();
        }
        for (i, proposal) in proposals.iter().enumerate() {
            self.status[i] = Status::Away;
            if matches!(proposal, Proposal::Ground { .. }) {
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
            let (place, support) = match proposals[i] {
                Proposal::Ground { dx } => self.ground_place(movers, i, dx, dynamics),
                Proposal::Drop { x } => {
                    let steps = ((x[1] - x[0]).abs() / SLIDE_STEP_PX).ceil() as usize;
                    let lowest = (0..=steps)
                        .map(|k| x[0] + (x[1] - x[0]) * k as f64 / steps.max(1) as f64)
                        .map(|x| (self.envelope(movers, i, x, dynamics).0, x))
                        .fold(
                            (f64::NEG_INFINITY, x[0]),
                            |a, b| if b.0 > a.0 { b } else { a },
                        );
                    self.slide(movers, i, lowest.1, dynamics)
                }
                Proposal::Air { to, lands } => {
                    let (place, support, stopped) = self.fly(movers, i, to, lands, dynamics);
                    self.stopped[i] = stopped;
                    (place, support)
                }
            };
            if self.status[i] == Status::Old {
                self.remove(i);
            }
            movers[i].anchor = Point2::new(place.x, place.y.max(0.0));
            self.status[i] = Status::New;
            self.supports[i] = support;
            self.insert(i, place.x);
        }
        self.order = order;
    }
}

//! The motion-state measurement of Eq. (4) of the MMPF+ paper: a bead is resting when many
//! beads touch it or it barely moves, saltating when none touches it or it moves fast,
//! rolling otherwise. Contacts are counted with a neighbour grid over the beads of the frame.

use sillage_assoc::PointIndex;
use sillage_core::{MotionState, ObjectClass, Point2};

/// The thresholds of Eq. (4), in px/frame.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct StateRule {
    /// nbN_rest.
    pub neighbours_rest: u32,
    /// nbN_salt.
    pub neighbours_salt: u32,
    /// u_rest, px/frame.
    pub speed_rest_px_per_frame: f64,
    /// u_salt, px/frame.
    pub speed_salt_px_per_frame: f64,
    /// Contact when the centre distance is at most this factor × the sum of the radii.
    pub contact_factor: f64,
}

impl StateRule {
    /// Eq. (4): the state of a bead with `neighbours` beads in contact moving at `speed`
    /// px/frame.
    pub fn state(&self, neighbours: u32, speed: f64) -> MotionState {
        if neighbours >= self.neighbours_rest || speed <= self.speed_rest_px_per_frame {
            MotionState::Resting
        } else if neighbours <= self.neighbours_salt || speed >= self.speed_salt_px_per_frame {
            MotionState::Saltating
        } else {
            MotionState::Rolling
        }
    }
}

/// The beads of one frame, indexed for contact counts (buffers reused frame to frame).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct Contacts {
    positions: Vec<Point2>,
    classes: Vec<ObjectClass>,
    index: PointIndex,
    max_radius_px: f64,
}

impl Contacts {
    /// Indexes the beads `(position, class)` of one frame.
    pub fn rebuild(&mut self, beads: impl Iterator<Item = (Point2, ObjectClass)>, radii: &[f64]) {
        self.positions.clear();
        self.classes.clear();
        for (p, c) in beads {
            self.positions.push(p);
            self.classes.push(c);
        }
        self.index.rebuild(&self.positions);
        self.max_radius_px = radii.iter().copied().fold(0.0, f64::max);
    }

    /// Number of indexed beads in contact with a bead of class `class` at `p`, not counting
    /// the indexed bead `exclude` (the bead itself, when it is in the set).
    pub fn count(
        &self,
        p: Point2,
        class: ObjectClass,
        exclude: Option<usize>,
        radii: &[f64],
        contact_factor: f64,
    ) -> u32 {
        let own = radius_of(radii, class);
        let reach = contact_factor * (own + self.max_radius_px);
        let mut n = 0;
        self.index.for_each_within(p, reach, |j, d2| {
            let touch = contact_factor * (own + radius_of(radii, self.classes[j]));
            if Some(j) != exclude && d2 <= touch * touch {
                n += 1;
            }
        });
        n
    }

    /// The centre distance from a bead of class `class` at `p` to the nearest indexed bead
    /// (not `exclude`) over the sum of their radii (1 = touching), capped at `cap`. Searched
    /// near first (most beads touch one), then out to the cap.
    pub fn nearest_ratio(
        &self,
        p: Point2,
        class: ObjectClass,
        exclude: Option<usize>,
        radii: &[f64],
        cap: f64,
    ) -> f64 {
        const NEAR: f64 = 1.25;
        let near = self.nearest_ratio_within(p, class, exclude, radii, cap.min(NEAR));
        if near < NEAR || cap <= NEAR {
            near
        } else {
            self.nearest_ratio_within(p, class, exclude, radii, cap)
        }
    }

    /// [`Contacts::nearest_ratio`] among the beads within `cap` times the largest contact
    /// distance.
    fn nearest_ratio_within(
        &self,
        p: Point2,
        class: ObjectClass,
        exclude: Option<usize>,
        radii: &[f64],
        cap: f64,
    ) -> f64 {
        let own = radius_of(radii, class);
        let mut best = cap;
        self.index
            .for_each_within(p, cap * (own + self.max_radius_px), |j, d2| {
                if Some(j) != exclude {
                    best = best.min(d2.sqrt() / (own + radius_of(radii, self.classes[j])));
                }
            });
        best
    }
}

/// The radius of `class`, or of the last class listed for classes beyond the list.
pub(crate) fn radius_of(radii: &[f64], class: ObjectClass) -> f64 {
    radii
        .get(class as usize)
        .or(radii.last())
        .copied()
        .unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule() -> StateRule {
        StateRule {
            neighbours_rest: 5,
            neighbours_salt: 0,
            speed_rest_px_per_frame: 0.561,
            speed_salt_px_per_frame: 9.35,
            contact_factor: 1.07,
        }
    }

    #[test]
    fn eq4_orders_its_cases() {
        let r = rule();
        assert_eq!(r.state(5, 20.0), MotionState::Resting);
        assert_eq!(r.state(2, 0.5), MotionState::Resting);
        assert_eq!(r.state(0, 3.0), MotionState::Saltating);
        assert_eq!(r.state(2, 9.35), MotionState::Saltating);
        assert_eq!(r.state(2, 3.0), MotionState::Rolling);
    }

    #[test]
    fn counts_contacts_by_class_pair() {
        let radii = [15.0, 10.0];
        // A black bead at the origin; black at 31 px (≤ 1.07·30 = 32.1), transparent at
        // 26 px (≤ 1.07·25 = 26.75), transparent at 27 px (too far), black at 33 px.
        let beads = [
            (Point2::new(0.0, 0.0), 0),
            (Point2::new(31.0, 0.0), 0),
            (Point2::new(0.0, 26.0), 1),
            (Point2::new(-27.0, 0.0), 1),
            (Point2::new(0.0, -33.0), 0),
        ];
        let mut contacts = Contacts::default();
        contacts.rebuild(beads.iter().copied(), &radii);
        assert_eq!(contacts.count(beads[0].0, 0, Some(0), &radii, 1.07), 2);
        assert_eq!(contacts.count(beads[0].0, 0, None, &radii, 1.07), 3);
        // The transparent bead at (0, 26) touches the black one only.
        assert_eq!(contacts.count(beads[2].0, 1, Some(2), &radii, 1.07), 1);
        // Nearest to the black bead at the origin by ratio: the black one at 31 px, 31/30
        // (the transparent one at 26 px is 26/25).
        let ratio = contacts.nearest_ratio(beads[0].0, 0, Some(0), &radii, 2.0);
        assert!((ratio - 31.0 / 30.0).abs() < 1e-12, "{ratio}");
        // Alone, the cap.
        let mut alone = Contacts::default();
        alone.rebuild([(Point2::new(0.0, 0.0), 0)].into_iter(), &radii);
        assert_eq!(
            alone.nearest_ratio(Point2::new(0.0, 0.0), 0, Some(0), &radii, 2.0),
            2.0
        );
    }
}

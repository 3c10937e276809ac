//! Each window's share of the stitched run — the frames from the cut with the window before
//! to the cut with the window after — planned from the seams and the windows' track ids
//! alone, then made where the window's points are.

use sillage_core::{Error, FrameIndex, Result, TrackId, TrackPoint};

use super::ids::{IdMap, Numbering};
use super::seam::Seam;
use super::{SeamReport, WindowTracks, sort_points};

/// What one window's share of the stitched run needs besides the window's own points.
#[derive(Debug, Clone, PartialEq)]
pub struct PartPlan {
    /// The share starts at this frame: the cut with the window before (the window's first
    /// frame for the first window).
    pub from: FrameIndex,
    /// The share ends before this frame, the cut with the window after (`None`: the last
    /// window, to its end).
    pub to: Option<FrameIndex>,
    /// The window's ids → global ids.
    pub ids: IdMap,
    /// The points the window before kept from its cut on, in global ids.
    pub carried: Vec<TrackPoint>,
    /// The points the window after kept before its cut, in global ids.
    pub head: Vec<TrackPoint>,
}

impl PartPlan {
    /// The window's share: its own points of frames `from..to` under their global ids, then
    /// `carried` and `head`, in frame order (within a frame, the window's own points first).
    /// `window` must be the one planned for, its points in frame order; its points are
    /// reused, not copied.
    pub fn apply(self, window: WindowTracks) -> Result<Vec<TrackPoint>> {
        let mut share = window.points;
        let end = self
            .to
            .map_or(share.len(), |to| share.partition_point(|p| p.frame < to));
        share.truncate(end);
        share.drain(..share.partition_point(|p| p.frame < self.from));
        self.ids.renumber(&mut share)?;
        share.extend(self.carried);
        share.extend(self.head);
        sort_points(&mut share);
        Ok(share)
    }
}

/// Plans the windows' shares in window order from each window's first frame, its track ids
/// ([`WindowEdges::ids`](super::WindowEdges::ids)) and the seam before it: the global ids are
/// handed out here, and nothing else of the windows needs to come here.
#[derive(Debug, Default)]
pub struct PartPlanner {
    numbering: Numbering,
    /// The last window pushed: its map, where its share starts, what it carries.
    last: Option<(IdMap, FrameIndex, Vec<TrackPoint>)>,
    seams: Vec<SeamReport>,
}

impl PartPlanner {
    /// A planner for a run's first window.
    pub fn new() -> Self {
        Self::default()
    }

    /// Global identities handed out so far: the trajectories of the stitched run.
    pub fn tracks(&self) -> TrackId {
        self.numbering.tracks()
    }

    /// Adds the next window: its first frame, its `ids` and the `seam` with the window before
    /// (`None` for the first window only). Returns the plan of the window before, now
    /// complete. On an error nothing changes: the window can be pushed again, corrected.
    pub fn push(
        &mut self,
        first: FrameIndex,
        ids: &[TrackId],
        seam: Option<Seam>,
    ) -> Result<Option<PartPlan>> {
        let mut numbering = self.numbering.clone();
        match (self.last.take(), seam) {
            (None, None) => {
                let map = numbering.window(ids, &[], None)?;
                self.numbering = numbering;
                self.last = Some((map, first, Vec::new()));
                Ok(None)
            }
            (Some((previous, from, carried)), Some(seam)) => {
                match Self::follow(&mut numbering, &previous, ids, seam) {
                    Ok((map, report, earlier_tail, head)) => {
                        self.numbering = numbering;
                        self.last = Some((map, report.cut, earlier_tail));
                        let to = Some(report.cut);
                        self.seams.push(report);
                        Ok(Some(PartPlan {
                            from,
                            to,
                            ids: previous,
                            carried,
                            head,
                        }))
                    }
                    Err(error) => {
                        self.last = Some((previous, from, carried));
                        Err(error)
                    }
                }
            }
            (None, Some(_)) => Err(Error::input(
                "the first window has no seam before it; pass None for it",
            )),
            (Some(last), None) => {
                self.last = Some(last);
                Err(Error::input(format!(
                    "the window from frame {first} follows another: pass the seam between them"
                )))
            }
        }
    }

    /// The ids of a window that follows the one mapped by `previous` across `seam`, the
    /// seam's report, and the points each side keeps of the other's, in global ids.
    fn follow(
        numbering: &mut Numbering,
        previous: &IdMap,
        ids: &[TrackId],
        seam: Seam,
    ) -> Result<(IdMap, SeamReport, Vec<TrackPoint>, Vec<TrackPoint>)> {
        let map = numbering.window(ids, &seam.joined, Some(previous))?;
        let Seam {
            report,
            mut earlier_tail,
            mut later_head,
            ..
        } = seam;
        map.renumber(&mut later_head)?;
        previous.renumber(&mut earlier_tail)?;
        Ok((map, report, earlier_tail, later_head))
    }

    /// The last window's plan (`None` when no window was pushed) and every seam's report.
    pub fn finish(self) -> (Option<PartPlan>, Vec<SeamReport>) {
        let plan = self.last.map(|(ids, from, carried)| PartPlan {
            from,
            to: None,
            ids,
            carried,
            head: Vec::new(),
        });
        (plan, self.seams)
    }
}

#[cfg(test)]
mod tests {
    use sillage_core::Point2;

    use super::*;

    fn seam(cut: FrameIndex, joined: Vec<(TrackId, TrackId)>, head: Vec<TrackPoint>) -> Seam {
        Seam {
            report: SeamReport {
                cut,
                ..SeamReport::default()
            },
            joined,
            earlier_tail: Vec::new(),
            later_head: head,
        }
    }

    #[test]
    fn a_wrong_push_is_refused_and_changes_nothing() {
        let mut planner = PartPlanner::new();
        let err = planner.push(0, &[4, 9], Some(seam(5, vec![], vec![])));
        assert!(
            err.unwrap_err()
                .to_string()
                .contains("first window has no seam")
        );
        assert_eq!(planner.push(0, &[4, 9], None).unwrap(), None);
        let err = planner.push(10, &[0, 1], None).unwrap_err().to_string();
        assert!(err.contains("pass the seam between them"), "{err}");
        // A seam joining a track the window before never had, or keeping a point of a track
        // the later window has no id for.
        let err = planner.push(10, &[0, 1], Some(seam(15, vec![(0, 77)], vec![])));
        assert!(err.unwrap_err().to_string().contains("track 77"));
        let stray = TrackPoint::at(12, 5, Point2::new(1.0, 1.0));
        let err = planner.push(10, &[0, 1], Some(seam(15, vec![], vec![stray])));
        assert!(err.unwrap_err().to_string().contains("track 5 of frame 12"));
        assert_eq!(planner.tracks(), 2, "failed pushes hand out no ids");
        // The same window, pushed right: track 0 continues window 0's track 9 (global 1).
        let plan = planner
            .push(10, &[0, 1], Some(seam(15, vec![(0, 9)], vec![])))
            .unwrap()
            .unwrap();
        assert_eq!((plan.from, plan.to), (0, Some(15)));
        assert_eq!(plan.ids.pairs(), [(4, 0), (9, 1)]);
        let (last, seams) = planner.finish();
        let last = last.unwrap();
        assert_eq!((last.from, last.to), (15, None));
        assert_eq!(last.ids.pairs(), [(0, 1), (1, 2)]);
        assert_eq!(seams.len(), 1);
    }
}

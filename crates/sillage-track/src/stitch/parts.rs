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
    /// complete.
    pub fn push(
        &mut self,
        first: FrameIndex,
        ids: &[TrackId],
        seam: Option<Seam>,
    ) -> Result<Option<PartPlan>> {
        let (last, seam) = match (self.last.take(), seam) {
            (None, None) => {
                let map = self.numbering.window(ids, &[], None)?;
                self.last = Some((map, first, Vec::new()));
                return Ok(None);
            }
            (Some(last), Some(seam)) => (last, seam),
            (None, Some(_)) => {
                return Err(Error::input(
                    "the first window has no seam before it; pass None for it",
                ));
            }
            (Some(_), None) => {
                return Err(Error::input(format!(
                    "the window from frame {first} follows another: pass the seam between them"
                )));
            }
        };
        let (previous, from, carried) = last;
        let map = self.numbering.window(ids, &seam.joined, Some(&previous))?;
        let Seam {
            report,
            mut earlier_tail,
            mut later_head,
            ..
        } = seam;
        map.renumber(&mut later_head)?;
        previous.renumber(&mut earlier_tail)?;
        self.last = Some((map, report.cut, earlier_tail));
        self.seams.push(report);
        Ok(Some(PartPlan {
            from,
            to: Some(self.seams.last().expect("pushed above").cut),
            ids: previous,
            carried,
            head: later_head,
        }))
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

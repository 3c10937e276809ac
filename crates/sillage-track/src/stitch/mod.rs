//! Joins the tracks of overlapping time windows, each tracked on its own, into one set of
//! trajectories (a long run split over workers; the overlapping-windows scheme of Ultrack).
//!
//! Consecutive windows share `O` frames. At each seam the tracks of both windows that have
//! points in the overlap are paired by the assignment solver ([`SparseLapSolver`], as many
//! pairs as possible, then the least total cost): a pair's cost is the median distance between
//! their points over the overlap frames where both have one, and pairs whose median exceeds
//! [`StitchParams::join_px`] are not allowed. Trackers that see identical detections in both
//! windows (PTV) pair at cost 0; particle filters, whose estimates differ by their random
//! draws, pair at their small residual distance.
//!
//! The seam is cut at the overlap's middle frame `c`: the earlier window gives the frames
//! before `c` (its end has no look-ahead, yet it has run long enough to forget its own start),
//! the later window `c` onwards (by then its warm-up is over). A paired track keeps the
//! earlier window's identity, and takes its partner's point where it has none on its own side
//! of the cut; the points an unpaired track has on the other side of the cut are kept unless
//! the other window has a point within [`StitchParams::same_px`] in that frame (the overlap's
//! duplicates). A track of the later window that ends before the cut lived only in that
//! window's warm-up and is dropped. Identities are renumbered globally, in order of the
//! windows and, within one, of the window's own ids.
//!
//! A seam needs only the two windows' points in the overlap ([`WindowEdges`]); the global ids
//! only the seams and each window's track ids ([`PartPlanner`]). So a distributed run joins each
//! seam, and makes each window's share of the result ([`PartPlan::apply`]), where the windows
//! are, and sends one place only the ids; [`Stitcher`] does the same in one process, window
//! by window as they come.

mod ids;
mod parts;
mod seam;

pub use ids::IdMap;
pub use parts::{PartPlan, PartPlanner};
pub use seam::{Seam, WindowEdges, join_seam};

use serde::{Deserialize, Serialize};
use sillage_assoc::SparseLapSolver;
use sillage_core::{Error, FrameIndex, Result, TrackId, TrackPoint};

/// How close points must be to count as one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StitchParams {
    /// Two points of one frame closer than this, px, are the same object (a duplicate of the
    /// overlap). Default 0.01 px: PTV's windows give bit-identical positions for one detection.
    pub same_px: f64,
    /// Largest median distance, px, between two tracks over their shared overlap frames for
    /// them to be joined. Default 1 px (PTV); the facade widens it for particle filters.
    pub join_px: f64,
}

impl Default for StitchParams {
    fn default() -> Self {
        Self {
            same_px: 0.01,
            join_px: 1.0,
        }
    }
}

impl StitchParams {
    /// Checks that both distances are finite and positive.
    pub fn validate(&self) -> Result<()> {
        for (name, value) in [("same_px", self.same_px), ("join_px", self.join_px)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::parameter(
                    format!("stitch.{name}"),
                    value,
                    "give a distance > 0 px",
                ));
            }
        }
        Ok(())
    }
}

/// The points one window's tracker gave, with the window's frames `first..=last`; ids are the
/// window's own.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct WindowTracks {
    /// First frame of the window.
    pub first: FrameIndex,
    /// Last frame of the window.
    pub last: FrameIndex,
    /// Its track points, any order.
    pub points: Vec<TrackPoint>,
}

impl WindowTracks {
    /// The same window with its points in frame order (kept within a frame), as its edges
    /// and its share are cut from: nothing moves when a tracker gave them so.
    pub fn in_frame_order(mut self) -> Self {
        sort_points(&mut self.points);
        self
    }
}

/// What happened at one seam.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SeamReport {
    /// The cut: frames before it come from the earlier window, from it on the later one.
    pub cut: FrameIndex,
    /// Tracks of the earlier window present at the frame before the cut.
    pub earlier_at_cut: usize,
    /// Tracks of the later window present at the cut.
    pub later_at_cut: usize,
    /// Pairs joined across the seam.
    pub joined: usize,
    /// Joined pairs whose shared points all coincide (within `same_px`).
    pub identical: usize,
    /// Points of unpaired tracks dropped as duplicates of the other window's.
    pub duplicates: usize,
    /// Points of the later window's tracks that ended before the cut, dropped as its
    /// warm-up.
    pub warm_up: usize,
}

/// Joins windows pushed in order, handing back the points that became final: the same
/// seams, identities and shares as a run stitched apart, in one process.
#[derive(Debug)]
pub struct Stitcher {
    params: StitchParams,
    planner: PartPlanner,
    /// The last window pushed (its points in frame order).
    pending: Option<WindowTracks>,
    solver: SparseLapSolver,
}

impl Stitcher {
    /// A stitcher with `params` (validated).
    pub fn new(params: StitchParams) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            params,
            planner: PartPlanner::new(),
            pending: None,
            solver: SparseLapSolver::new(),
        })
    }

    /// Global identities handed out so far: the trajectories of the stitched run.
    pub fn tracks(&self) -> TrackId {
        self.planner.tracks()
    }

    /// Adds the next window (windows come in order, each overlapping the previous by at most
    /// half its length); returns the points now final, in frame order (within a frame, in the
    /// windows' own order).
    pub fn push(&mut self, window: WindowTracks) -> Result<Vec<TrackPoint>> {
        if window.first > window.last {
            return Err(Error::input(format!(
                "a window from frame {} to frame {} is empty",
                window.first, window.last
            )));
        }
        let window = window.in_frame_order();
        let Some(earlier) = self.pending.take() else {
            let ids = window.edges(None, None).ids;
            self.planner.push(window.first, &ids, None)?;
            self.pending = Some(window);
            return Ok(Vec::new());
        };
        let later = window.edges(Some(earlier.last), None);
        // As the earlier window of this seam only its tail counts (its ids came with it).
        let earlier_edges = WindowEdges {
            first: earlier.first,
            last: earlier.last,
            tail: earlier.tail(window.first),
            ..WindowEdges::default()
        };
        let seam = join_seam(&self.params, &mut self.solver, &earlier_edges, &later)?;
        let plan = self.planner.push(window.first, &later.ids, Some(seam))?;
        let finished = plan.expect("a window came before").apply(earlier)?;
        self.pending = Some(window);
        Ok(finished)
    }

    /// Hands back the last window's remaining points (in frame order) and the seams.
    pub fn finish(self) -> Result<(Vec<TrackPoint>, Vec<SeamReport>)> {
        let (plan, seams) = self.planner.finish();
        let points = match (plan, self.pending) {
            (Some(plan), Some(window)) => plan.apply(window)?,
            _ => Vec::new(),
        };
        Ok((points, seams))
    }
}

/// Sorts `points` by frame, keeping the order within a frame (stable): nothing to move when
/// they already are (a tracker's output), and only the overlap's points when a window's
/// sorted points are joined by a few of the other window's.
fn sort_points(points: &mut [TrackPoint]) {
    if !points.is_sorted_by_key(|p| p.frame) {
        points.sort_by_key(|p| p.frame);
    }
}

/// Stitches `windows` (in order) in one go: every point, in frame order, and the
/// seams.
pub fn stitch(
    windows: impl IntoIterator<Item = WindowTracks>,
    params: StitchParams,
) -> Result<(Vec<TrackPoint>, Vec<SeamReport>)> {
    let mut stitcher = Stitcher::new(params)?;
    let mut points = Vec::new();
    for window in windows {
        points.extend(stitcher.push(window)?);
    }
    let (rest, seams) = stitcher.finish()?;
    points.extend(rest);
    Ok((points, seams))
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;

    use sillage_core::Point2;

    use super::*;

    /// A track `id` from `from` to `to` along x = x0 + frame, y = y.
    fn track(id: TrackId, from: FrameIndex, to: FrameIndex, x0: f64, y: f64) -> Vec<TrackPoint> {
        (from..=to)
            .map(|f| TrackPoint::at(f, id, Point2::new(x0 + f as f64, y)))
            .collect()
    }

    fn window(first: FrameIndex, last: FrameIndex, tracks: Vec<Vec<TrackPoint>>) -> WindowTracks {
        WindowTracks {
            first,
            last,
            points: tracks.into_iter().flatten().collect(),
        }
    }

    #[test]
    fn identical_tracks_keep_one_identity_and_lose_no_point() {
        // Frames 0–19 then 10–29 (overlap 10–19, cut 15); the window-local ids differ.
        let earlier = window(
            0,
            19,
            vec![track(7, 1, 18, 0.0, 5.0), track(3, 1, 12, 0.0, 50.0)],
        );
        let later = window(
            10,
            29,
            vec![track(0, 11, 28, 0.0, 5.0), track(1, 20, 28, 0.0, 90.0)],
        );
        let (points, seams) = stitch([earlier, later], StitchParams::default()).unwrap();
        let ids_at_y = |y: f64| -> BTreeSet<TrackId> {
            points
                .iter()
                .filter(|p| p.pos_px.y == y)
                .map(|p| p.track_id)
                .collect()
        };
        assert_eq!(ids_at_y(5.0).len(), 1, "the crossing track keeps one id");
        let frames: Vec<FrameIndex> = points
            .iter()
            .filter(|p| p.pos_px.y == 5.0)
            .map(|p| p.frame)
            .collect();
        assert_eq!(frames, (1..=28).collect::<Vec<_>>(), "each frame once");
        assert_eq!(ids_at_y(50.0).len(), 1);
        assert_eq!(points.iter().filter(|p| p.pos_px.y == 50.0).count(), 12);
        assert_eq!(ids_at_y(90.0).len(), 1);
        // Ids: the earlier window's in its order (3 → 0, 7 → 1), then the later's new one.
        assert_eq!(ids_at_y(5.0), BTreeSet::from([1]));
        assert_eq!(ids_at_y(50.0), BTreeSet::from([0]));
        assert_eq!(ids_at_y(90.0), BTreeSet::from([2]));
        assert_eq!(seams[0].cut, 15);
        assert_eq!((seams[0].joined, seams[0].identical), (1, 1));
        assert!(points.is_sorted_by_key(|p| p.frame));
    }

    #[test]
    fn unpaired_tracks_keep_their_points_without_duplicates() {
        // The later window lost the track at 50 px, which ends in the overlap at frame 17;
        // the earlier lost the one at 90 px, which starts at frame 13 in the later window.
        // A track of the later window's warm-up (frames 11–13, before the cut) is dropped.
        let earlier = window(0, 19, vec![track(0, 1, 17, 0.0, 50.0)]);
        let later = window(
            10,
            29,
            vec![track(0, 13, 28, 0.0, 90.0), track(1, 11, 13, 0.0, 130.0)],
        );
        let (points, seams) = stitch([earlier, later], StitchParams::default()).unwrap();
        assert_eq!(points.iter().filter(|p| p.pos_px.y == 50.0).count(), 17);
        assert_eq!(points.iter().filter(|p| p.pos_px.y == 90.0).count(), 16);
        assert!(!points.iter().any(|p| p.pos_px.y == 130.0));
        assert_eq!((seams[0].joined, seams[0].warm_up), (0, 3));
        // An unpaired track's points that the other window also has are dropped once.
        let earlier = window(
            0,
            19,
            vec![track(0, 1, 18, 0.0, 5.0), track(1, 14, 18, 0.0, 70.0)],
        );
        let later = window(
            10,
            29,
            vec![track(0, 11, 28, 0.0, 5.0), track(1, 16, 28, 0.3, 70.0)],
        );
        let (points, seams) = stitch([earlier, later], StitchParams::default()).unwrap();
        assert_eq!(seams[0].joined, 2, "{:?}", seams[0]);
        let at_70: Vec<_> = points.iter().filter(|p| p.pos_px.y == 70.0).collect();
        let frames: BTreeSet<FrameIndex> = at_70.iter().map(|p| p.frame).collect();
        assert_eq!(frames.len(), at_70.len(), "one point per frame");
        assert_eq!(frames, (14..=28).collect());
    }

    #[test]
    fn pairs_follow_the_nearest_tracks_and_respect_the_gate() {
        // Particle-filter estimates: the later window's are 0.4 px off, one track 3 px off.
        let earlier = window(
            0,
            39,
            vec![track(0, 0, 39, 0.0, 10.0), track(1, 0, 39, 0.0, 20.0)],
        );
        let later = window(
            20,
            59,
            vec![track(5, 20, 59, 0.4, 10.0), track(6, 20, 59, 3.0, 20.0)],
        );
        let params = StitchParams {
            same_px: 0.01,
            join_px: 1.0,
        };
        let (points, seams) = stitch([earlier.clone(), later.clone()], params).unwrap();
        assert_eq!((seams[0].joined, seams[0].identical), (1, 0));
        let ids: BTreeSet<TrackId> = points.iter().map(|p| p.track_id).collect();
        assert_eq!(ids.len(), 3, "the 3-px track is a new one at 1 px");
        let wide = StitchParams {
            join_px: 4.0,
            ..params
        };
        let (points, seams) = stitch([earlier, later], wide).unwrap();
        assert_eq!(seams[0].joined, 2);
        let ids: BTreeSet<TrackId> = points.iter().map(|p| p.track_id).collect();
        assert_eq!(ids.len(), 2);
        assert_eq!(points.len(), 120, "each track once per frame");
    }

    /// `windows` stitched as a distributed run does: edges, seams and shares each made on
    /// their own (as on the workers), only ids and seams through the planner.
    fn stitch_apart(windows: &[WindowTracks], params: StitchParams) -> Vec<TrackPoint> {
        let edges: Vec<WindowEdges> = (0..windows.len())
            .map(|k| {
                let previous = k.checked_sub(1).map(|j| windows[j].last);
                windows[k].edges(previous, windows.get(k + 1).map(|w| w.first))
            })
            .collect();
        let mut solver = SparseLapSolver::new();
        let mut planner = PartPlanner::new();
        let mut plans = Vec::new();
        for (k, window) in edges.iter().enumerate() {
            let seam = k
                .checked_sub(1)
                .map(|j| join_seam(&params, &mut solver, &edges[j], window).unwrap());
            plans.extend(planner.push(window.first, &window.ids, seam).unwrap());
        }
        plans.extend(planner.finish().0);
        plans
            .into_iter()
            .zip(windows)
            .flat_map(|(plan, window)| plan.apply(window.clone()).unwrap())
            .collect()
    }

    #[test]
    fn windows_stitched_apart_give_the_stitchers_points() {
        // Three windows of 30 frames overlapping by 10; tracks that cross both seams, some
        // broken or jittered in one window, one that starts in a warm-up, one that only the
        // middle window sees; local ids shuffled per window.
        let spans = [(0, 29), (20, 49), (40, 69)];
        let windows: Vec<WindowTracks> = spans
            .iter()
            .enumerate()
            .map(|(k, &(first, last))| {
                let shift = 0.02 * k as f64;
                let mut tracks = vec![
                    track(10 - k as u64, first.max(1), last, shift, 5.0),
                    track(20 + 3 * k as u64, first, last.min(first + 17), 0.0, 40.0),
                    track(7, first + 2, first + 4, 0.0, 130.0),
                ];
                if k == 1 {
                    tracks.push(track(3, 21, 47, 0.5, 80.0));
                }
                window(first, last, tracks).in_frame_order()
            })
            .collect();
        for params in [
            StitchParams::default(),
            StitchParams {
                same_px: 0.5,
                join_px: 3.0,
            },
        ] {
            let (points, seams) = stitch(windows.clone(), params).unwrap();
            assert_eq!(seams.len(), 2);
            let rows = |points: &[TrackPoint]| -> Vec<(FrameIndex, TrackId, f64, f64)> {
                points
                    .iter()
                    .map(|p| (p.frame, p.track_id, p.pos_px.x, p.pos_px.y))
                    .collect()
            };
            assert_eq!(rows(&stitch_apart(&windows, params)), rows(&points));
            assert_eq!(stitch_apart(&windows, params), points);
        }
    }

    #[test]
    fn windows_out_of_order_or_overlapping_too_much_are_refused() {
        let mut stitcher = Stitcher::new(StitchParams::default()).unwrap();
        stitcher.push(window(10, 29, vec![])).unwrap();
        let err = stitcher
            .push(window(0, 19, vec![]))
            .unwrap_err()
            .to_string();
        assert!(err.contains("in order"), "{err}");
        let mut stitcher = Stitcher::new(StitchParams::default()).unwrap();
        stitcher.push(window(0, 19, vec![])).unwrap();
        let err = stitcher
            .push(window(5, 24, vec![]))
            .unwrap_err()
            .to_string();
        assert!(err.contains("more than half"), "{err}");
        let err = Stitcher::new(StitchParams {
            same_px: 0.0,
            join_px: 1.0,
        })
        .unwrap_err()
        .to_string();
        assert!(err.contains("same_px"), "{err}");
    }
}

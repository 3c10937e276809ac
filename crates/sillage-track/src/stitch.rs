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

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};

use serde::{Deserialize, Serialize};
use sillage_assoc::{Pairing, PointIndex, SparseLapSolver};
use sillage_core::{Error, FrameIndex, Point2, Result, TrackId, TrackPoint};

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

/// Joins windows pushed in order, handing back the points that became final.
#[derive(Debug)]
pub struct Stitcher {
    params: StitchParams,
    next_id: TrackId,
    /// The last window's points not yet handed back (global ids), and its extent.
    pending: Option<Pending>,
    seams: Vec<SeamReport>,
    solver: SparseLapSolver,
}

#[derive(Debug)]
struct Pending {
    first: FrameIndex,
    last: FrameIndex,
    points: Vec<TrackPoint>,
}

/// The points of the tracks of one window in the overlap: by track, sorted by frame.
type OverlapTracks = BTreeMap<TrackId, Vec<(FrameIndex, Point2)>>;

/// The points of one window in one overlap frame, with their tracks, indexed.
#[derive(Debug)]
struct FramePoints {
    tracks: Vec<TrackId>,
    positions: Vec<Point2>,
    index: PointIndex,
}

/// The points of one window in the overlap, by frame.
type OverlapFrames = BTreeMap<FrameIndex, FramePoints>;

impl Stitcher {
    /// A stitcher with `params` (validated).
    pub fn new(params: StitchParams) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            params,
            next_id: 0,
            pending: None,
            seams: Vec::new(),
            solver: SparseLapSolver::new(),
        })
    }

    /// Global identities handed out so far: the trajectories of the stitched run.
    pub fn tracks(&self) -> TrackId {
        self.next_id
    }

    /// Adds the next window (windows come in order, each overlapping the previous by at most
    /// half its length); returns the points now final, in frame order (within a frame, in the
    /// windows' own order).
    pub fn push(&mut self, window: WindowTracks) -> Result<Vec<TrackPoint>> {
        let WindowTracks {
            first,
            last,
            mut points,
        } = window;
        if first > last {
            return Err(Error::input(format!(
                "a window from frame {first} to frame {last} is empty"
            )));
        }
        sort_points(&mut points);
        let Some(pending) = self.pending.take() else {
            let ids = self.new_ids(points.iter().map(|p| p.track_id));
            for p in &mut points {
                p.track_id = ids.get(p.track_id);
            }
            self.pending = Some(Pending {
                first,
                last,
                points,
            });
            return Ok(Vec::new());
        };
        let overlap_frames = pending.last.saturating_sub(first) + 1;
        if first <= pending.first || first > pending.last || last <= pending.last {
            return Err(Error::input(format!(
                "windows must come in order and overlap: frames {}–{} then {first}–{last}",
                pending.first, pending.last
            )));
        }
        if 2 * overlap_frames > last - first + 1 {
            return Err(Error::input(format!(
                "the overlap of frames {first}–{} is more than half the window {first}–{last}",
                pending.last
            )));
        }
        let cut = first + overlap_frames / 2;
        let (finished, kept) = self.seam(pending, points, first, cut);
        self.pending = Some(Pending {
            first,
            last,
            points: kept,
        });
        Ok(finished)
    }

    /// Hands back the last window's remaining points (in frame order) and the seams.
    pub fn finish(mut self) -> (Vec<TrackPoint>, Vec<SeamReport>) {
        let points = self.pending.take().map(|p| p.points).unwrap_or_default();
        (points, self.seams)
    }

    /// Fresh global ids for the distinct `local` ids, in increasing local order.
    fn new_ids<I: Iterator<Item = TrackId> + Clone>(&mut self, local: I) -> IdMap {
        let (count, max) = local
            .clone()
            .fold((0usize, None), |(n, max), id| (n + 1, max.max(Some(id))));
        let mut ids = IdMap::for_ids(max, count);
        match &mut ids {
            IdMap::Dense(table) => {
                for id in local {
                    table[id as usize] = 0;
                }
                for slot in table.iter_mut().filter(|slot| **slot == 0) {
                    *slot = self.next_id;
                    self.next_id += 1;
                }
            }
            IdMap::Sparse(map) => {
                let mut distinct: Vec<TrackId> = local.collect();
                distinct.sort_unstable();
                distinct.dedup();
                for id in distinct {
                    map.insert(id, self.next_id);
                    self.next_id += 1;
                }
            }
        }
        ids
    }

    /// Joins `pending` (global ids, sorted) and the later window's sorted `later` points (its
    /// own ids), whose overlap starts at `first`, at `cut`: returns the points final now and
    /// those kept for the next seam, both sorted. Only the overlap's points are looked at one
    /// by one; the rest are moved in bulk.
    fn seam(
        &mut self,
        pending: Pending,
        mut later: Vec<TrackPoint>,
        first: FrameIndex,
        cut: FrameIndex,
    ) -> (Vec<TrackPoint>, Vec<TrackPoint>) {
        let mut earlier = pending.points;
        let earlier_overlap = &earlier[earlier.partition_point(|p| p.frame < first)..];
        let later_overlap = &later[..later.partition_point(|p| p.frame <= pending.last)];
        let later_overlap_len = later_overlap.len();
        let earlier_tracks = overlap_tracks(earlier_overlap);
        let later_tracks = overlap_tracks(later_overlap);
        let earlier_frames = points_by_frame(earlier_overlap);
        let later_frames = points_by_frame(later_overlap);

        let mut report = SeamReport {
            cut,
            earlier_at_cut: present_at(&earlier_tracks, cut - 1),
            later_at_cut: present_at(&later_tracks, cut),
            ..SeamReport::default()
        };
        let joined = self.pair(
            &earlier_tracks,
            &later_tracks,
            &earlier_frames,
            &later_frames,
            cut,
        );
        report.joined = joined.len();
        report.identical = joined.values().filter(|(_, identical)| *identical).count();
        let partner_of: HashMap<TrackId, TrackId> = joined
            .iter()
            .map(|(&later, &(earlier, _))| (earlier, later))
            .collect();

        let same = self.params.same_px;
        let duplicate = |frames: &OverlapFrames, p: &TrackPoint| {
            frames.get(&p.frame).is_some_and(|others| {
                let mut found = false;
                others
                    .index
                    .for_each_within(p.pos_px, same, |_, _| found = true);
                found
            })
        };
        // The earlier window's points from the cut on: kept where its track has no partner
        // there and the later window has no duplicate.
        let earlier_cut = earlier.partition_point(|p| p.frame < cut);
        let mut earlier_tail = Vec::new();
        for p in earlier.drain(earlier_cut..) {
            let keep = match partner_of.get(&p.track_id) {
                Some(partner) => !has_point(&later_tracks, *partner, p.frame),
                None => !duplicate(&later_frames, &p),
            };
            if keep {
                earlier_tail.push(p);
            } else if !partner_of.contains_key(&p.track_id) {
                report.duplicates += 1;
            }
        }
        // The later window's points before the cut: the same rule the other way round, for
        // tracks that go on past the cut; a track that ends before it lived only in the
        // window's warm-up (a detector's background still learning, a motion model still
        // empty) and is dropped.
        let later_cut = later.partition_point(|p| p.frame < cut);
        let goes_on: HashSet<TrackId> = later[later_cut..].iter().map(|p| p.track_id).collect();
        let mut later_head = Vec::new();
        for p in later.drain(..later_cut) {
            let keep = match joined.get(&p.track_id) {
                Some((partner, _)) => !has_point(&earlier_tracks, *partner, p.frame),
                None if !goes_on.contains(&p.track_id) => {
                    report.warm_up += 1;
                    false
                }
                None => !duplicate(&earlier_frames, &p),
            };
            if keep {
                later_head.push(p);
            } else if !joined.contains_key(&p.track_id) && goes_on.contains(&p.track_id) {
                report.duplicates += 1;
            }
        }
        let mut ids = self.new_ids(
            later_head
                .iter()
                .chain(&later)
                .map(|p| p.track_id)
                .filter(|id| !joined.contains_key(id)),
        );
        for (&later, &(earlier, _)) in &joined {
            ids.insert(later, earlier);
        }
        for p in later_head.iter_mut().chain(later.iter_mut()) {
            p.track_id = ids.get(p.track_id);
        }
        let mut finished = earlier;
        finished.append(&mut later_head);
        let mut kept = later;
        // Room for the next seam's additions, so that they do not move the window's points.
        kept.reserve(earlier_tail.len() + 2 * later_overlap_len);
        kept.append(&mut earlier_tail);
        sort_points(&mut finished);
        sort_points(&mut kept);
        self.seams.push(report);
        (finished, kept)
    }

    /// Pairs earlier and later tracks by the assignment solver on their median distance over
    /// shared frames: for each joined later track, its earlier partner and whether all their
    /// shared points coincide.
    fn pair(
        &mut self,
        earlier: &OverlapTracks,
        later: &OverlapTracks,
        earlier_frames: &OverlapFrames,
        later_frames: &OverlapFrames,
        cut: FrameIndex,
    ) -> BTreeMap<TrackId, (TrackId, bool)> {
        let earlier_ids: Vec<TrackId> = earlier.keys().copied().collect();
        let later_ids: Vec<TrackId> = later.keys().copied().collect();
        let earlier_row: BTreeMap<TrackId, usize> = earlier_ids
            .iter()
            .enumerate()
            .map(|(i, &id)| (id, i))
            .collect();
        let later_col: BTreeMap<TrackId, usize> = later_ids
            .iter()
            .enumerate()
            .map(|(j, &id)| (id, j))
            .collect();
        // Candidate pairs: a point of each within `join_px` in some frame.
        let mut candidates: BTreeSet<(usize, usize)> = BTreeSet::new();
        for (frame, later_points) in later_frames {
            let Some(earlier_points) = earlier_frames.get(frame) else {
                continue;
            };
            let earlier_at = earlier_points.tracks.iter().zip(&earlier_points.positions);
            for (owner, &p) in earlier_at {
                later_points
                    .index
                    .for_each_within(p, self.params.join_px, |k, _| {
                        candidates.insert((earlier_row[owner], later_col[&later_points.tracks[k]]));
                    });
            }
        }
        // Sparse rows of the allowed pairs and their costs.
        let mut row_start = vec![0];
        let (mut col_index, mut costs, mut identical) = (Vec::new(), Vec::new(), Vec::new());
        let mut candidates = candidates.into_iter().peekable();
        for row in 0..earlier_ids.len() {
            while let Some(&(r, col)) = candidates.peek()
                && r == row
            {
                candidates.next();
                let shared = shared_distances(&earlier[&earlier_ids[row]], &later[&later_ids[col]]);
                if let Some(cost) = self.pair_cost(&shared, cut) {
                    col_index.push(col as u32);
                    costs.push(cost);
                    identical.push(shared.iter().all(|&(_, d)| d <= self.params.same_px));
                }
            }
            row_start.push(col_index.len());
        }
        let assignment = self.solver.solve(
            earlier_ids.len(),
            later_ids.len(),
            &row_start,
            &col_index,
            &costs,
            Pairing::Optional,
        );
        let mut joined = BTreeMap::new();
        for (row, col) in assignment.iter().enumerate() {
            if let Some(col) = *col {
                let entry = (row_start[row]..row_start[row + 1])
                    .find(|&k| col_index[k] as usize == col)
                    .expect("the solver pairs allowed entries only");
                joined.insert(later_ids[col], (earlier_ids[row], identical[entry]));
            }
        }
        joined
    }
}

impl Stitcher {
    /// The cost of joining two tracks whose `shared` frames are at these distances, `None`
    /// when not allowed: their median distance from the frame before the cut on (where the
    /// later window has warmed up; over every shared frame when they share none there) must
    /// be within `join_px`. The cost, `median / join_px − close` with `close` the shared
    /// frames within `join_px`, prefers the partner followed the longest, so that a track the
    /// later window broke in its first frames is joined to its settled part.
    fn pair_cost(&self, shared: &[(FrameIndex, f64)], cut: FrameIndex) -> Option<f64> {
        let settled: Vec<f64> = shared
            .iter()
            .filter(|&&(frame, _)| frame + 1 >= cut)
            .map(|&(_, d)| d)
            .collect();
        let all: Vec<f64> = shared.iter().map(|&(_, d)| d).collect();
        let median = median(if settled.is_empty() { &all } else { &settled });
        let join = self.params.join_px;
        let close = all.iter().filter(|&&d| d <= join).count();
        (median <= join).then(|| median / join - close as f64)
    }
}

/// Window ids → global ids: a table when the window's ids are dense (PTV numbers its tracks
/// from 0), else a hash map.
enum IdMap {
    Dense(Vec<TrackId>),
    Sparse(HashMap<TrackId, TrackId>),
}

impl IdMap {
    /// A map for the `count` ids (repeats included) of largest `max`: a table of `max + 1`
    /// unset slots when that is at most twice `count` (plus a little), else a hash map.
    fn for_ids(max: Option<TrackId>, count: usize) -> Self {
        match max {
            Some(max) if max < 2 * count as u64 + 1024 => {
                IdMap::Dense(vec![TrackId::MAX; max as usize + 1])
            }
            _ => IdMap::Sparse(HashMap::with_capacity(count.min(1 << 16))),
        }
    }

    fn insert(&mut self, local: TrackId, global: TrackId) {
        match self {
            IdMap::Dense(table) => {
                if local as usize >= table.len() {
                    table.resize(local as usize + 1, TrackId::MAX);
                }
                table[local as usize] = global;
            }
            IdMap::Sparse(map) => {
                map.insert(local, global);
            }
        }
    }

    /// The global id of `local` (every id of the window was inserted).
    fn get(&self, local: TrackId) -> TrackId {
        match self {
            IdMap::Dense(table) => table[local as usize],
            IdMap::Sparse(map) => map[&local],
        }
    }
}

/// The overlap points of `points` grouped by track, each sorted by frame.
fn overlap_tracks(points: &[TrackPoint]) -> OverlapTracks {
    let mut tracks = OverlapTracks::new();
    for p in points {
        tracks
            .entry(p.track_id)
            .or_default()
            .push((p.frame, p.pos_px));
    }
    for points in tracks.values_mut() {
        points.sort_by_key(|&(frame, _)| frame);
    }
    tracks
}

/// The positions of `points` by frame, each with its track.
fn points_by_frame(points: &[TrackPoint]) -> OverlapFrames {
    let mut frames: BTreeMap<FrameIndex, (Vec<TrackId>, Vec<Point2>)> = BTreeMap::new();
    for p in points {
        let (tracks, positions) = frames.entry(p.frame).or_default();
        tracks.push(p.track_id);
        positions.push(p.pos_px);
    }
    frames
        .into_iter()
        .map(|(frame, (tracks, positions))| {
            let index = PointIndex::new(&positions);
            (
                frame,
                FramePoints {
                    tracks,
                    positions,
                    index,
                },
            )
        })
        .collect()
}

/// Whether track `id` of `tracks` has a point in `frame`.
fn has_point(tracks: &OverlapTracks, id: TrackId, frame: FrameIndex) -> bool {
    tracks
        .get(&id)
        .is_some_and(|points| points.binary_search_by_key(&frame, |&(f, _)| f).is_ok())
}

/// How many of `tracks` have a point in `frame`.
fn present_at(tracks: &OverlapTracks, frame: FrameIndex) -> usize {
    tracks
        .values()
        .filter(|points| points.binary_search_by_key(&frame, |&(f, _)| f).is_ok())
        .count()
}

/// The distances between two tracks' points in the frames both have one, with the frame.
fn shared_distances(
    a: &[(FrameIndex, Point2)],
    b: &[(FrameIndex, Point2)],
) -> Vec<(FrameIndex, f64)> {
    let (mut i, mut j, mut distances) = (0, 0, Vec::new());
    while i < a.len() && j < b.len() {
        match a[i].0.cmp(&b[j].0) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                distances.push((a[i].0, a[i].1.distance(b[j].1)));
                i += 1;
                j += 1;
            }
        }
    }
    distances
}

/// The median of `values` (the mean of the middle two for an even count); infinite when
/// empty.
fn median(values: &[f64]) -> f64 {
    if values.is_empty() {
        return f64::INFINITY;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
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
    let (rest, seams) = stitcher.finish();
    points.extend(rest);
    Ok((points, seams))
}

#[cfg(test)]
mod tests {
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

//! One seam: the tracks two consecutive windows have in their shared frames paired, and what
//! each window keeps of the other's side of the cut. A seam needs only the windows' points in
//! the overlap ([`WindowEdges`]), so it can be joined wherever those are, apart from the
//! windows' other points.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use serde::{Deserialize, Serialize};
use sillage_assoc::{Pairing, PointIndex, SparseLapSolver};
use sillage_core::{Error, FrameIndex, Point2, Result, TrackId, TrackPoint};

use super::{SeamReport, StitchParams, WindowTracks, sort_points};

/// What the seams on either side of one window look at: its points in the frames it shares
/// with its neighbours, and its tracks that go on past the cut with the window before. Ids
/// are the window's own.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct WindowEdges {
    /// First frame of the window.
    pub first: FrameIndex,
    /// Last frame of the window.
    pub last: FrameIndex,
    /// Its points in the frames shared with the window before (none for the first window),
    /// in frame order.
    pub head: Vec<TrackPoint>,
    /// Its points in the frames shared with the window after (none for the last window), in
    /// frame order.
    pub tail: Vec<TrackPoint>,
    /// Its tracks with a point at or after the cut with the window before (every track of
    /// the first window), ascending: each gets an identity of its own unless the seam joins
    /// it to a track of the window before.
    pub ids: Vec<TrackId>,
}

impl WindowTracks {
    /// The window's edges, for the window before ending at `previous_last` and the one after
    /// starting at `next_first` (`None` where there is none). Its points must be in frame
    /// order (as a tracker gives them).
    pub fn edges(
        &self,
        previous_last: Option<FrameIndex>,
        next_first: Option<FrameIndex>,
    ) -> WindowEdges {
        let points = &self.points;
        let (head, from_cut) = match previous_last {
            Some(previous_last) => (
                &points[..points.partition_point(|p| p.frame <= previous_last)],
                &points
                    [points.partition_point(|p| p.frame < seam_cut(self.first, previous_last))..],
            ),
            None => (&points[..0], &points[..]),
        };
        WindowEdges {
            first: self.first,
            last: self.last,
            head: head.to_vec(),
            tail: next_first.map(|next| self.tail(next)).unwrap_or_default(),
            ids: distinct_ids(from_cut),
        }
    }

    /// Its points from frame `next_first` on (those shared with a window starting there), in
    /// frame order: what the seam with that window needs of this one as the earlier.
    pub(super) fn tail(&self, next_first: FrameIndex) -> Vec<TrackPoint> {
        let points = &self.points;
        points[points.partition_point(|p| p.frame < next_first)..].to_vec()
    }
}

/// The cut of the seam between a window ending at `earlier_last` and one starting at
/// `later_first`: the overlap's middle frame. Frames before it come from the earlier window
/// (its end has no look-ahead, yet it has run long enough to forget its own start), the cut
/// and after from the later one (by then its warm-up is over).
fn seam_cut(later_first: FrameIndex, earlier_last: FrameIndex) -> FrameIndex {
    later_first + (earlier_last + 1).saturating_sub(later_first) / 2
}

/// Checks that a window of frames `later_first..=later_last` may follow one of frames
/// `earlier_first..=earlier_last` (in order, overlapping, by at most half the later window);
/// returns their seam's cut.
fn check_order(
    (earlier_first, earlier_last): (FrameIndex, FrameIndex),
    (later_first, later_last): (FrameIndex, FrameIndex),
) -> Result<FrameIndex> {
    if later_first <= earlier_first || later_first > earlier_last || later_last <= earlier_last {
        return Err(Error::input(format!(
            "windows must come in order and overlap: frames \
             {earlier_first}–{earlier_last} then {later_first}–{later_last}"
        )));
    }
    let overlap_frames = earlier_last - later_first + 1;
    if 2 * overlap_frames > later_last - later_first + 1 {
        return Err(Error::input(format!(
            "the overlap of frames {later_first}–{earlier_last} is more than half the window \
             {later_first}–{later_last}"
        )));
    }
    Ok(seam_cut(later_first, earlier_last))
}

/// What one seam decided, in the two windows' own ids.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Seam {
    /// The seam's figures.
    pub report: SeamReport,
    /// The joined pairs `(later window's id, earlier window's id)`, by the later id.
    pub joined: Vec<(TrackId, TrackId)>,
    /// The earlier window's points from the cut on that stay, in frame order.
    pub earlier_tail: Vec<TrackPoint>,
    /// The later window's points before the cut that stay, in frame order.
    pub later_head: Vec<TrackPoint>,
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

/// Joins the windows whose edges are `earlier` and `later` at their seam: pairs the tracks of
/// the overlap by `solver` (as many pairs as allowed, then the least total cost; see
/// `pair_cost`) and decides which points of each window stay on the other's side of the
/// cut. A paired track keeps its partner's point where it has none on its own side; an
/// unpaired track's points there stay unless the other window has a point within
/// [`StitchParams::same_px`] in that frame (the overlap's duplicates); a track of the later
/// window that ends before the cut lived only in that window's warm-up (a background still
/// learning, a motion model still empty) and is dropped.
pub fn join_seam(
    params: &StitchParams,
    solver: &mut SparseLapSolver,
    earlier: &WindowEdges,
    later: &WindowEdges,
) -> Result<Seam> {
    let cut = check_order((earlier.first, earlier.last), (later.first, later.last))?;
    let earlier_overlap = &earlier.tail[earlier.tail.partition_point(|p| p.frame < later.first)..];
    let later_overlap = &later.head[..later.head.partition_point(|p| p.frame <= earlier.last)];
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
    let joined = pair(
        params,
        solver,
        (&earlier_tracks, &earlier_frames),
        (&later_tracks, &later_frames),
        cut,
    );
    report.joined = joined.len();
    report.identical = joined.values().filter(|(_, identical)| *identical).count();
    let partner_of: HashMap<TrackId, TrackId> = joined
        .iter()
        .map(|(&later, &(earlier, _))| (earlier, later))
        .collect();

    let duplicate = |frames: &OverlapFrames, p: &TrackPoint| {
        frames.get(&p.frame).is_some_and(|others| {
            let mut found = false;
            others
                .index
                .for_each_within(p.pos_px, params.same_px, |_, _| found = true);
            found
        })
    };
    // The earlier window's points from the cut on: kept where its track has no partner
    // there and the later window has no duplicate.
    let mut earlier_tail = Vec::new();
    for p in earlier_overlap.iter().filter(|p| p.frame >= cut) {
        let keep = match partner_of.get(&p.track_id) {
            Some(partner) => !has_point(&later_tracks, *partner, p.frame),
            None => !duplicate(&later_frames, p),
        };
        if keep {
            earlier_tail.push(*p);
        } else if !partner_of.contains_key(&p.track_id) {
            report.duplicates += 1;
        }
    }
    // The later window's points before the cut: the same rule the other way round, for
    // tracks that go on past the cut; the others lived only in the warm-up.
    let goes_on = |id: TrackId| later.ids.binary_search(&id).is_ok();
    let mut later_head = Vec::new();
    for p in later_overlap.iter().filter(|p| p.frame < cut) {
        let keep = match joined.get(&p.track_id) {
            Some((partner, _)) => !has_point(&earlier_tracks, *partner, p.frame),
            None if !goes_on(p.track_id) => {
                report.warm_up += 1;
                false
            }
            None => !duplicate(&earlier_frames, p),
        };
        if keep {
            later_head.push(*p);
        } else if !joined.contains_key(&p.track_id) && goes_on(p.track_id) {
            report.duplicates += 1;
        }
    }
    sort_points(&mut earlier_tail);
    sort_points(&mut later_head);
    Ok(Seam {
        report,
        joined: joined
            .into_iter()
            .map(|(later, (earlier, _))| (later, earlier))
            .collect(),
        earlier_tail,
        later_head,
    })
}

/// Pairs earlier and later tracks by the assignment solver on their median distance over
/// shared frames: for each joined later track, its earlier partner and whether all their
/// shared points coincide.
fn pair(
    params: &StitchParams,
    solver: &mut SparseLapSolver,
    (earlier, earlier_frames): (&OverlapTracks, &OverlapFrames),
    (later, later_frames): (&OverlapTracks, &OverlapFrames),
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
                .for_each_within(p, params.join_px, |k, _| {
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
            if let Some(cost) = pair_cost(params, &shared, cut) {
                col_index.push(col as u32);
                costs.push(cost);
                identical.push(shared.iter().all(|&(_, d)| d <= params.same_px));
            }
        }
        row_start.push(col_index.len());
    }
    let assignment = solver.solve(
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

/// The cost of joining two tracks whose `shared` frames are at these distances, `None` when
/// not allowed: their median distance from the frame before the cut on (where the later
/// window has warmed up; over every shared frame when they share none there) must be within
/// `join_px`. The cost, `median / join_px − close` with `close` the shared frames within
/// `join_px`, prefers the partner followed the longest, so that a track the later window
/// broke in its first frames is joined to its settled part.
fn pair_cost(params: &StitchParams, shared: &[(FrameIndex, f64)], cut: FrameIndex) -> Option<f64> {
    let settled: Vec<f64> = shared
        .iter()
        .filter(|&&(frame, _)| frame + 1 >= cut)
        .map(|&(_, d)| d)
        .collect();
    let all: Vec<f64> = shared.iter().map(|&(_, d)| d).collect();
    let median = median(if settled.is_empty() { &all } else { &settled });
    let join = params.join_px;
    let close = all.iter().filter(|&&d| d <= join).count();
    (median <= join).then(|| median / join - close as f64)
}

/// The distinct track ids of `points`, ascending (a table when ids are dense, as PTV's are).
fn distinct_ids(points: &[TrackPoint]) -> Vec<TrackId> {
    let Some(max) = points.iter().map(|p| p.track_id).max() else {
        return Vec::new();
    };
    if max < 2 * points.len() as u64 + 1024 {
        let mut seen = vec![false; max as usize + 1];
        for p in points {
            seen[p.track_id as usize] = true;
        }
        (0..=max).filter(|&id| seen[id as usize]).collect()
    } else {
        let mut ids: Vec<TrackId> = points.iter().map(|p| p.track_id).collect();
        ids.sort_unstable();
        ids.dedup();
        ids
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

//! Track points grouped by track, to find what each frame of an overlay shows: the tracks
//! present at that frame and their recent points.

use std::collections::HashMap;

use sillage_core::{FrameIndex, TrackPoint, Vec2};

/// Every track's points in frame order.
#[derive(Debug, Clone, Default)]
pub struct TrackHistory {
    /// One track per entry, points sorted by frame; tracks sorted by their first frame.
    tracks: Vec<Vec<TrackPoint>>,
}

impl TrackHistory {
    /// Groups `points` (any order) by track.
    pub fn new(points: impl IntoIterator<Item = TrackPoint>) -> Self {
        let mut by_track: HashMap<u64, Vec<TrackPoint>> = HashMap::new();
        for point in points {
            by_track.entry(point.track_id).or_default().push(point);
        }
        let mut tracks: Vec<Vec<TrackPoint>> = by_track.into_values().collect();
        for track in &mut tracks {
            track.sort_by_key(|p| p.frame);
        }
        tracks.sort_by_key(|t| (t[0].frame, t[0].track_id));
        Self { tracks }
    }

    /// Keeps only the tracks of at least `min_points` points.
    pub fn with_min_points(mut self, min_points: usize) -> Self {
        self.tracks.retain(|t| t.len() >= min_points);
        self
    }

    /// Every track's points in frame order, tracks by their first frame.
    pub fn tracks(&self) -> impl Iterator<Item = &[TrackPoint]> {
        self.tracks.iter().map(Vec::as_slice)
    }

    /// Number of tracks.
    pub fn len(&self) -> usize {
        self.tracks.len()
    }

    /// Whether there is no track.
    pub fn is_empty(&self) -> bool {
        self.tracks.is_empty()
    }

    /// The tails of the tracks that have a point at `frame`: their points from frames
    /// `frame - tail_frames + 1 ..= frame`, oldest first, the last one at `frame`.
    pub fn tails_at(
        &self,
        frame: FrameIndex,
        tail_frames: u64,
    ) -> impl Iterator<Item = &[TrackPoint]> {
        let started = self.tracks.partition_point(|t| t[0].frame <= frame);
        let first = frame.saturating_sub(tail_frames.saturating_sub(1));
        self.tracks[..started].iter().filter_map(move |track| {
            let end = track.partition_point(|p| p.frame <= frame);
            if end == 0 || track[end - 1].frame != frame {
                return None;
            }
            let begin = track[..end].partition_point(|p| p.frame < first);
            Some(&track[begin..end])
        })
    }
}

/// The velocity of `track[i]` (a track's points in frame order), px/frame: the point's own
/// when the table has one, else the finite difference of its neighbours' positions over
/// their frame gap (central inside the track, one-sided at its ends); `None` for a track of
/// one point or an `i` beyond it.
pub fn velocity_px_per_frame(track: &[TrackPoint], i: usize) -> Option<Vec2> {
    let point = track.get(i)?;
    if let Some(v) = point.vel_px_per_frame.filter(|v| v.is_finite()) {
        return Some(v);
    }
    let before = &track[i.saturating_sub(1)];
    let after = track.get(i + 1).unwrap_or(point);
    let frames = after.frame.checked_sub(before.frame).filter(|&n| n > 0)?;
    Some((after.pos_px - before.pos_px) / frames as f64)
}

#[cfg(test)]
mod tests {
    use sillage_core::Point2;

    use super::*;

    fn point(frame: u64, track_id: u64) -> TrackPoint {
        TrackPoint::at(frame, track_id, Point2::new(frame as f64, track_id as f64))
    }

    #[test]
    fn tails_hold_the_last_frames_of_present_tracks_only() {
        let points = [
            point(3, 1),
            point(1, 1),
            point(2, 1),
            point(2, 2),
            point(5, 3),
            point(4, 1),
        ];
        let history = TrackHistory::new(points);
        assert_eq!(history.len(), 3);
        let frames = |frame, length| -> Vec<Vec<(u64, u64)>> {
            history
                .tails_at(frame, length)
                .map(|t| t.iter().map(|p| (p.track_id, p.frame)).collect())
                .collect()
        };
        assert_eq!(frames(3, 2), vec![vec![(1, 2), (1, 3)]]);
        assert_eq!(frames(2, 10), vec![vec![(1, 1), (1, 2)], vec![(2, 2)]]);
        assert_eq!(frames(4, 1), vec![vec![(1, 4)]]);
        assert_eq!(frames(5, 3), vec![vec![(3, 5)]]);
        assert!(frames(6, 3).is_empty());
        assert!(frames(0, 3).is_empty());
        assert_eq!(history.with_min_points(2).len(), 1);
    }

    #[test]
    fn velocities_are_the_tables_or_finite_differences() {
        let mut track: Vec<TrackPoint> = [(0, 0.0), (1, 2.0), (3, 10.0)]
            .map(|(frame, x)| TrackPoint::at(frame, 1, Point2::new(x, 5.0)))
            .to_vec();
        let vx = |track: &[TrackPoint], i| velocity_px_per_frame(track, i).map(|v| v.x);
        // One-sided at the ends, central (over the 3-frame gap) inside.
        assert_eq!(vx(&track, 0), Some(2.0));
        assert_eq!(vx(&track, 1), Some(10.0 / 3.0));
        assert_eq!(vx(&track, 2), Some(4.0));
        assert_eq!(vx(&track, 3), None);
        track[1].vel_px_per_frame = Some(Vec2::new(-1.0, 0.0));
        assert_eq!(vx(&track, 1), Some(-1.0));
        assert_eq!(vx(&track[..1], 0), None);
    }
}

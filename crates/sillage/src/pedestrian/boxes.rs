//! The box-tracking baselines on a MOTChallenge detection file (`det.txt`): SORT and
//! ByteTrack, which the pedestrian benches compare with (`sillage track boxes`).

use std::collections::BTreeMap;
use std::path::Path;

use sillage_core::{Error, Result};
use sillage_io::{MotRow, read_mot_rows};
use sillage_track::bytetrack::{ByteTrackParams, ByteTracker, ScoredBox};
use sillage_track::sort::{SortParams, SortTracker};

/// Which baseline runs, with its parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BoxTracker {
    /// SORT (Bewley et al. 2016): the filters' boxes are written.
    Sort(SortParams),
    /// ByteTrack (Zhang et al. 2022) as `supervision` 0.30.9: the detections matched to the
    /// tracks are written.
    ByteTrack(ByteTrackParams),
}

impl BoxTracker {
    /// The name `--tracker` takes.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Sort(_) => "sort",
            Self::ByteTrack(_) => "bytetrack",
        }
    }

    /// The name tables print.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Sort(_) => "SORT",
            Self::ByteTrack(_) => "ByteTrack",
        }
    }
}

/// Tracks the boxes of `detections` (a MOTChallenge `det.txt`; rows scoring below
/// `min_score` dropped) with `tracker`, one step per frame from the first to the last
/// detection's frame (frames without detections included); the result rows (confidence 1) in
/// frame and id order. Errors name the file.
pub fn track_boxes(
    detections: &Path,
    tracker: BoxTracker,
    min_score: Option<f64>,
) -> Result<Vec<MotRow>> {
    let rows = read_mot_rows(detections)?;
    let mut by_frame: BTreeMap<u64, Vec<ScoredBox>> = BTreeMap::new();
    for r in &rows {
        let score = r.confidence.unwrap_or(1.0);
        if !min_score.is_some_and(|s| score < s) {
            by_frame.entry(r.frame).or_default().push(ScoredBox {
                bbox: r.bbox(),
                score,
            });
        }
    }
    let named = |e: Error| Error::input(format!("{}: {e}", detections.display()));
    let frames = rows
        .iter()
        .map(|r| r.frame)
        .max()
        .map_or(0..0, |last| 0..last + 1);
    let mut out = Vec::new();
    match tracker {
        BoxTracker::Sort(params) => {
            let mut sort = SortTracker::new(params)?;
            for frame in frames {
                let boxes: Vec<_> = by_frame
                    .get(&frame)
                    .map_or(Vec::new(), |d| d.iter().map(|d| d.bbox).collect());
                let tracked = sort.step(&boxes).map_err(named)?;
                out.extend(tracked.iter().map(|t| MotRow::result(frame, t.id, &t.bbox)));
            }
        }
        BoxTracker::ByteTrack(params) => {
            let mut byte = ByteTracker::new(params)?;
            for frame in frames {
                let boxes = by_frame.get(&frame).map_or(&[][..], Vec::as_slice);
                let mut tracked = byte.step(boxes);
                tracked.sort_by_key(|t| t.id);
                out.extend(tracked.iter().map(|t| MotRow::result(frame, t.id, &t.bbox)));
            }
        }
    }
    Ok(out)
}

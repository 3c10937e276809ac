//! SORT on a MOTChallenge detection file (`det.txt`): the box-tracking baseline the pedestrian
//! benches compare with (`sillage track boxes`).

use std::collections::BTreeMap;
use std::path::Path;

use sillage_core::{BoundingBox, Error, Result};
use sillage_io::{MotRow, read_mot_rows};
use sillage_track::sort::{SortParams, SortTracker};

/// Tracks the boxes of `detections` (a MOTChallenge `det.txt`; rows scoring below
/// `min_score` dropped) with SORT, one step per frame from the first to the last detection's
/// frame (frames without detections included, as SORT requires); the result rows (the
/// filters' boxes, confidence 1) in frame and id order. Errors name the file.
pub fn track_boxes_with_sort(
    detections: &Path,
    params: SortParams,
    min_score: Option<f64>,
) -> Result<Vec<MotRow>> {
    let rows = read_mot_rows(detections)?;
    let mut tracker = SortTracker::new(params)?;
    let mut by_frame: BTreeMap<u64, Vec<BoundingBox>> = BTreeMap::new();
    for r in &rows {
        if !min_score.is_some_and(|s| r.confidence.is_some_and(|c| c < s)) {
            by_frame.entry(r.frame).or_default().push(r.bbox());
        }
    }
    let last = rows.iter().map(|r| r.frame).max();
    let mut out = Vec::new();
    for frame in last.map_or(0..0, |last| 0..last + 1) {
        let boxes = by_frame.get(&frame).map_or(&[][..], Vec::as_slice);
        let tracked = tracker
            .step(boxes)
            .map_err(|e| Error::input(format!("{}: {e}", detections.display())))?;
        out.extend(tracked.iter().map(|t| MotRow::result(frame, t.id, &t.bbox)));
    }
    Ok(out)
}

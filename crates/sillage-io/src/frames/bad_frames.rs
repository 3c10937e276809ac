//! Frames that cannot be tracked: files that do not decode, frames of the wrong size, and
//! frames missing from a numbered sequence (`img_0001.tif`, `img_0002.tif`, `img_0004.tif`).
//! [`BadFramePolicy::Stop`] stops the run at the first one with an error naming it;
//! [`BadFramePolicy::Skip`] records it in a [`SkippedFrames`] log and goes on, the frame's
//! index left unused so that the trackers see a missed frame.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use serde::{Deserialize, Serialize};
use sillage_core::{Error, FrameIndex, Result};

/// What a run does with a frame it cannot track (`--on-bad-frame`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BadFramePolicy {
    /// Stop with an error naming the frame (the default).
    #[default]
    Stop,
    /// Record the frame as skipped and go on; its index stays unused (a missed frame).
    Skip,
}

/// One frame a run skipped.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct SkippedFrame {
    /// The index the frame has (had) in the sequence.
    pub index: FrameIndex,
    /// Its file (the stack or video for a page or video frame; for a frame missing from a
    /// numbered sequence, the file after the gap).
    pub path: PathBuf,
    /// Why it was skipped.
    pub reason: String,
}

/// The frames skipped so far by a frame source; a handle shared with its reading thread, so
/// it can be read after the source has been consumed.
#[derive(Debug, Clone, Default)]
pub struct SkippedFrames(Arc<Mutex<Vec<SkippedFrame>>>);

impl SkippedFrames {
    /// Records `frame`.
    pub(crate) fn push(&self, frame: SkippedFrame) {
        // A poisoned lock means a reader thread panicked, which `FrameSource` passes on.
        if let Ok(mut list) = self.0.lock() {
            list.push(frame);
        }
    }

    /// The frames skipped so far, in sequence order.
    pub fn list(&self) -> Vec<SkippedFrame> {
        let mut list = self.0.lock().map(|l| l.clone()).unwrap_or_default();
        list.sort_by_key(|f| f.index);
        list
    }
}

/// The frame indices of an ordered list of files: their positions, or, when every name
/// carries a frame number (the last run of digits of the file stem, the rest of the names
/// equal), the number's offset from the first file's in units of the sequence's step (the
/// smallest difference between consecutive numbers, so a sequence saved every other frame
/// has no gap). Returns the indices and the gaps: `(index of the first missing frame, how
/// many, the file after the gap)`.
pub(crate) fn frame_indices(files: &[PathBuf]) -> (Vec<FrameIndex>, Vec<(FrameIndex, u64, &Path)>) {
    let positions = || (0..files.len() as FrameIndex).collect();
    let Some(numbers) = frame_numbers(files) else {
        return (positions(), Vec::new());
    };
    let Some(step) = numbers.windows(2).map(|w| w[1] - w[0]).min() else {
        return (positions(), Vec::new());
    };
    if step == 0 {
        return (positions(), Vec::new());
    }
    let indices: Vec<FrameIndex> = numbers.iter().map(|n| (n - numbers[0]) / step).collect();
    let gaps = indices
        .windows(2)
        .zip(&files[1..])
        .filter(|(w, _)| w[1] > w[0] + 1)
        .map(|(w, path)| (w[0] + 1, w[1] - w[0] - 1, path.as_path()))
        .collect();
    (indices, gaps)
}

/// The frame number of every file, when each stem ends its last run of digits with the same
/// text around it, and the numbers increase.
fn frame_numbers(files: &[PathBuf]) -> Option<Vec<u64>> {
    let mut pattern: Option<(String, String)> = None;
    let mut numbers = Vec::with_capacity(files.len());
    for path in files {
        let name = path.file_name()?.to_str()?;
        let end = name.rfind(|c: char| c.is_ascii_digit())? + 1;
        let start = name[..end]
            .rfind(|c: char| !c.is_ascii_digit())
            .map_or(0, |i| i + 1);
        let around = (name[..start].to_string(), name[end..].to_string());
        match &pattern {
            Some(p) if *p != around => return None,
            Some(_) => {}
            None => pattern = Some(around),
        }
        let number: u64 = name[start..end].parse().ok()?;
        if numbers.last().is_some_and(|&last| number <= last) {
            return None;
        }
        numbers.push(number);
    }
    Some(numbers)
}

/// The frame indices of `files` under `policy`: with [`BadFramePolicy::Skip`] the gaps of a
/// numbered sequence are recorded in `skipped` and their indices left unused; with
/// [`BadFramePolicy::Stop`] a gap is an error naming the missing frames.
pub(crate) fn indices_under(
    files: &[PathBuf],
    policy: BadFramePolicy,
    skipped: &SkippedFrames,
) -> Result<Vec<FrameIndex>> {
    let (indices, gaps) = frame_indices(files);
    for (first, count, after) in gaps {
        let reason = format!(
            "missing from the numbered sequence: {count} frame(s) before {}",
            after.display()
        );
        match policy {
            BadFramePolicy::Stop => {
                return Err(Error::frame(
                    after,
                    first,
                    format!(
                        "{reason}; the trackers would link across the gap as if no time had \
                         passed. Pass `--on-bad-frame skip` to track across it as missed frames"
                    ),
                ));
            }
            BadFramePolicy::Skip => {
                for index in first..first + count {
                    skipped.push(SkippedFrame {
                        index,
                        path: after.to_path_buf(),
                        reason: reason.clone(),
                    });
                }
            }
        }
    }
    Ok(indices)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paths(names: &[&str]) -> Vec<PathBuf> {
        names.iter().map(|n| PathBuf::from("dir").join(n)).collect()
    }

    #[test]
    fn a_missing_number_is_a_gap_and_a_regular_step_is_not() {
        let files = paths(&["img_0001.tif", "img_0002.tif", "img_0005.tif"]);
        let (indices, gaps) = frame_indices(&files);
        assert_eq!(indices, [0, 1, 4]);
        assert_eq!(gaps.len(), 1);
        assert_eq!((gaps[0].0, gaps[0].1), (2, 2));
        assert_eq!(gaps[0].2, Path::new("dir/img_0005.tif"));
        // Every other frame saved: the step is 2, no gap.
        let files = paths(&["a10.png", "a12.png", "a14.png"]);
        let (indices, gaps) = frame_indices(&files);
        assert_eq!((indices, gaps.len()), (vec![0, 1, 2], 0));
    }

    #[test]
    fn names_without_one_numbering_keep_their_positions() {
        for names in [
            &["a1.tif", "b2.tif", "a4.tif"][..],
            &["x.tif", "y.tif"],
            &["only7.tif"],
        ] {
            let files = paths(names);
            let (indices, gaps) = frame_indices(&files);
            assert_eq!(indices, (0..names.len() as u64).collect::<Vec<_>>());
            assert!(gaps.is_empty());
        }
    }

    #[test]
    fn stop_names_the_gap_and_skip_records_each_missing_frame() {
        let files = paths(&["f1.png", "f2.png", "f4.png", "f5.png"]);
        let log = SkippedFrames::default();
        let err = indices_under(&files, BadFramePolicy::Stop, &log)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("f4.png") && err.contains("--on-bad-frame skip"),
            "{err}"
        );
        let indices = indices_under(&files, BadFramePolicy::Skip, &log).unwrap();
        assert_eq!(indices, [0, 1, 3, 4]);
        let skipped = log.list();
        assert_eq!(skipped.len(), 1);
        assert_eq!(skipped[0].index, 2);
    }
}

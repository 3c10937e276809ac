//! What the MOTChallenge paper benches (`bench immpf`, `bench siftpf`) share: a sequence
//! folder's name, frames and ground truth, and the matching of box estimates to it
//! (IoU ≥ 0.5).

use std::path::Path;

use sillage_core::BoundingBox;
use sillage_core::{Error, FrameIndex, Result};
use sillage_eval::MotData;
use sillage_eval::mot::{MatchRule, MotChallengeProtocol, MotEstimate, MotTruth, Shape};

use crate::evaluate::load_truth;

use crate::pedestrian::within;

/// Boxes match when their IoU is at least 0.5 (CLEAR MOT's usual rule, and the papers').
const BOX_MATCH: MatchRule = MatchRule::Iou { threshold: 0.5 };

/// A sequence folder's name: its last path component.
pub fn sequence_name(folder: &Path) -> String {
    folder
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| folder.display().to_string())
}

/// The ground truth of a MOTChallenge sequence folder (`gt/gt.txt`, MOT15 rows).
pub struct SequenceTruth {
    truth: Vec<MotTruth>,
    /// `seqLength` of `seqinfo.ini`, when there is one.
    frame_count: Option<u64>,
}

impl SequenceTruth {
    /// Reads `folder/gt/gt.txt` (and the `seqinfo.ini` beside it) as `sillage eval mot`
    /// reads it: the boxes of every row, scored or skipped by the MOT15 protocol.
    pub fn load(folder: &Path) -> Result<Self> {
        let gt = folder.join("gt").join("gt.txt");
        let (truth, frame_count) = load_truth(&gt, BOX_MATCH, MotChallengeProtocol::Mot15)
            .map_err(|e| {
                let what = format!(
                    "cannot read the ground truth of {}; a sequence folder holds gt/gt.txt",
                    folder.display()
                );
                within(what, e)
            })?;
        Ok(Self { truth, frame_count })
    }

    /// The evaluation data of `boxes` (`(frame, id, box)`, 0-based frames) against the
    /// truth of the first `frames` frames, matched by box IoU.
    pub fn data(
        &self,
        boxes: impl IntoIterator<Item = (FrameIndex, u64, BoundingBox)>,
        frames: u64,
    ) -> Result<MotData> {
        let truth: Vec<MotTruth> = self
            .truth
            .iter()
            .filter(|t| t.frame < frames)
            .cloned()
            .collect();
        let estimates: Vec<MotEstimate> = boxes
            .into_iter()
            .map(|(frame, id, bbox)| MotEstimate {
                frame,
                id,
                shape: Shape::Box(bbox),
            })
            .collect();
        MotData::new(
            &truth,
            &estimates,
            BOX_MATCH.similarity(),
            self.frame_count.map(|n| n.min(frames)),
        )
    }
}

/// The frames of a sequence folder, as `open_frames` reads them: `img1/` or, when there is
/// no `img1/`, the one video `video/*.mp4`.
pub fn sequence_frames(folder: &Path) -> Result<String> {
    let images = folder.join("img1");
    if images.is_dir() {
        return Ok(images.to_string_lossy().into_owned());
    }
    let videos_dir = folder.join("video");
    let mut videos: Vec<_> = std::fs::read_dir(&videos_dir)
        .into_iter()
        .flatten()
        .filter_map(|entry| Some(entry.ok()?.path()))
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("mp4")))
        .collect();
    videos.sort();
    match videos.as_slice() {
        [video] => Ok(video.to_string_lossy().into_owned()),
        [] => Err(Error::input(format!(
            "{} has no frames: neither an img1/ folder of images nor a video/*.mp4; put the \
             frames in img1/ (MOTChallenge layout) or one video in video/",
            folder.display()
        ))),
        _ => Err(Error::input(format!(
            "{} holds {} videos; keep one, or put the frames in img1/",
            videos_dir.display(),
            videos.len()
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_eval::mot::TruthRole;

    #[test]
    fn the_truth_of_a_folder_keeps_every_box_and_skips_flag_0() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("gt")).unwrap();
        std::fs::write(
            dir.path().join("gt").join("gt.txt"),
            "1,1,10,20,30,60,1,-1,-1,-1\n2,1,12,20,30,60,0,-1,-1,-1\n",
        )
        .unwrap();
        std::fs::write(dir.path().join("seqinfo.ini"), "[Sequence]\nseqLength=5\n").unwrap();
        let truth = SequenceTruth::load(dir.path()).unwrap();
        assert_eq!(truth.frame_count, Some(5));
        let roles: Vec<TruthRole> = truth.truth.iter().map(|t| t.role).collect();
        assert_eq!(roles, [TruthRole::Scored, TruthRole::Skipped]);
        assert_eq!(truth.truth[1].frame, 1);
        assert_eq!(sequence_name(dir.path().join("PETS").as_path()), "PETS");
    }
}

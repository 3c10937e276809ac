//! What the MOTChallenge paper benches (`bench immpf`, `bench siftpf`) share: a sequence
//! folder's name and ground truth, and the matching of box estimates to it (IoU ≥ 0.5).

use std::path::Path;

use anyhow::{Context, Result, bail};
use sillage::core::FrameIndex;
use sillage::eval::MotData;
use sillage::eval::mot::{BoundingBox, MotChallengeProtocol, MotEstimate, MotTruth, Shape};

use crate::cli::MatchRule;
use sillage::evaluate::load_truth;

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
    /// Reads `folder/gt/gt.txt` (and the `seqinfo.ini` beside it).
    pub fn load(folder: &Path) -> Result<Self> {
        let gt = folder.join("gt").join("gt.txt");
        let (truth, frame_count) = load_truth(&gt, BOX_MATCH, MotChallengeProtocol::Mot15)
            .with_context(|| {
                format!(
                    "cannot read the ground truth of {}; a sequence folder holds gt/gt.txt",
                    folder.display()
                )
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
        Ok(MotData::new(
            &truth,
            &estimates,
            BOX_MATCH.similarity(),
            self.frame_count.map(|n| n.min(frames)),
        )?)
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
        [] => bail!(
            "{} has no frames: neither an img1/ folder of images nor a video/*.mp4; put the \
             frames in img1/ (MOTChallenge layout) or one video in video/",
            folder.display()
        ),
        _ => bail!(
            "{} holds {} videos; keep one, or put the frames in img1/",
            videos_dir.display(),
            videos.len()
        ),
    }
}

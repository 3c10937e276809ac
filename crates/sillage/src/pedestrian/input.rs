//! The inputs of the pedestrian tracker, frame by frame: colour frames binned for the
//! observation model with their motion blobs as birth candidates, or MOTChallenge detections
//! (beside the frames, as measurements or as birth candidates, or alone in the
//! detections-only mode).

use std::collections::BTreeMap;
use std::path::Path;

use sillage_core::{Error, FrameIndex, GrayImage, Result, RgbImage};
use sillage_detect::motion::{MotionBlob, MotionDetector, MotionParams, blob_box};
use sillage_io::{FrameOptions, FrameSource, open_frames, read_mot_rows};
use sillage_track::immpf::{AppearanceParams, Candidate, FrameCues, PedestrianParams};

use super::within;

/// One frame ready for the tracker.
pub struct PreparedFrame {
    /// 0-based frame index.
    pub frame: FrameIndex,
    /// Colour and motion bins (image mode).
    pub cues: Option<FrameCues>,
    /// Birth candidates (and, without cues, the measurements).
    pub candidates: Vec<Candidate>,
    /// Whether the candidates are detections (from `--detections`) rather than motion blobs.
    pub candidates_are_detections: bool,
    /// The colour frame, kept only when asked for (`keep_colour`, for overlays).
    pub colour: Option<RgbImage>,
}

/// Where the frames and candidates come from.
pub struct PedestrianInput {
    frames: Option<FrameSource>,
    detections: Option<BTreeMap<FrameIndex, Vec<Candidate>>>,
    motion: Option<MotionDetector>,
    appearance: AppearanceParams,
    /// Whether the frames' colour and motion bins are computed: not when detections drive
    /// the trackers without colour in the assignment, which then ignores them.
    binned: bool,
    /// Spare buffers for the next frame's bins (see [`PedestrianInput::recycle`]).
    cues: FrameCues,
    /// The previous frame's grey levels, for the motion histogram.
    previous: Option<GrayImage>,
    keep_colour: bool,
    /// Frames in the detections-only mode: 0 to the last detection frame (or `frame_count`).
    next_frame: FrameIndex,
    end_frame: FrameIndex,
    /// (width, height), px.
    pub frame_size_px: (usize, usize),
    /// Frames to expect, when known.
    pub len: Option<usize>,
}

/// Reads a MOTChallenge detections file as candidates by 0-based frame.
pub fn read_candidates(path: &Path) -> Result<BTreeMap<FrameIndex, Vec<Candidate>>> {
    let rows = read_mot_rows(path)?;
    if rows.is_empty() {
        return Err(Error::input(format!(
            "{} holds no detection; give a MOTChallenge file with rows \
             `frame,-1,left,top,width,height,score,...`",
            path.display()
        )));
    }
    let mut frames: BTreeMap<FrameIndex, Vec<Candidate>> = BTreeMap::new();
    for row in rows {
        frames.entry(row.frame).or_default().push(Candidate {
            bbox: row.bbox(),
            score: row.confidence.unwrap_or(1.0),
        });
    }
    Ok(frames)
}

/// The frame size (width, height), px, of a MOTChallenge sequence, from the `seqinfo.ini`
/// beside the folder of `file` (`SEQ/det/det.txt` → `SEQ/seqinfo.ini`).
pub fn frame_size_beside(file: &Path) -> Option<(usize, usize)> {
    let sequence = file.parent()?.parent()?;
    let info = sillage_io::read_seqinfo(sequence.join("seqinfo.ini")).ok()?;
    Some((info.image_width? as usize, info.image_height? as usize))
}

/// The frames of `input` opened with `options`; a MOTChallenge image folder (`SEQ/img1`) is
/// first checked against its sequence's `SEQ/seqinfo.ini` when there is one
/// ([`sillage_io::check_seqinfo_frames`]: the frame count when the whole folder is read, the
/// frame size always).
pub(super) fn open_sequence_frames(input: &str, options: &FrameOptions) -> Result<FrameSource> {
    let frames = open_frames(input, options)?;
    let folder = Path::new(input);
    let (Some(name), Some(sequence)) = (folder.file_name(), folder.parent()) else {
        return Ok(frames);
    };
    let ini = sequence.join("seqinfo.ini");
    if folder.is_dir() && ini.is_file() {
        let whole =
            options.max_frames.is_none() && options.start_at == 0 && options.stop_at.is_none();
        let count = frames.len().filter(|_| whole).map(|n| n as u64);
        let name = name.to_string_lossy();
        sillage_io::check_seqinfo_frames(&ini, &name, count, frames.dimensions())?;
    }
    Ok(frames)
}

impl PedestrianInput {
    /// Colour frames of `input` (motion blobs as candidates unless `detections` is given),
    /// or, without `input`, the detections alone over frames of `frame_size_px`; `frames`
    /// selects the frames (`start_at`, `stop_at`, `max_frames`; colour is always decoded);
    /// `keep_colour` keeps each colour frame in [`PreparedFrame::colour`]. `params` (the
    /// tracker's) says what the frames are for: with detections as measurements
    /// (`detection.with_frames`) no motion detector runs, and the frames are binned only
    /// for a colour weight above 0.
    pub fn open(
        input: Option<&str>,
        detections: Option<&Path>,
        frame_size_px: Option<(usize, usize)>,
        motion: &MotionParams,
        params: &PedestrianParams,
        frames: &FrameOptions,
        keep_colour: bool,
    ) -> Result<Self> {
        let detections_drive =
            input.is_some() && params.detection.drive_trackers(true, detections.is_some());
        let max_frames = frames.max_frames;
        let detections = detections.map(read_candidates).transpose()?;
        let (start, options) = (frames.start_at, frames);
        let (frames, size, len, end) = match input {
            Some(input) => {
                let options = FrameOptions {
                    colour: true,
                    ..options.clone()
                };
                let frames = open_sequence_frames(input, &options)?;
                let size = frames.dimensions();
                let len = frames.len();
                (Some(frames), size, len, 0)
            }
            None => {
                let Some(found) = &detections else {
                    return Err(Error::input(
                        "give frames to track, or --detections FILE for the detections-only mode",
                    ));
                };
                let Some(size) = frame_size_px else {
                    return Err(Error::input(
                        "the detections-only mode needs the frame size: give --size WxH, or keep \
                         the MOTChallenge layout SEQ/det/det.txt with SEQ/seqinfo.ini",
                    ));
                };
                let last = found.keys().next_back().copied().unwrap_or(0) + 1;
                let end = max_frames.map_or(last, |m| last.min(m as u64));
                let end = options.stop_at.map_or(end, |stop| end.min(stop));
                (None, size, Some(end.saturating_sub(start) as usize), end)
            }
        };
        // With frames, the motion detector gives the foreground mask of the likelihood, and
        // the birth candidates unless detections are given.
        let motion = match &frames {
            Some(_) if !detections_drive => Some(MotionDetector::new(motion, size.0, size.1)?),
            _ => None,
        };
        Ok(Self {
            frames,
            detections,
            motion,
            appearance: params.appearance.clone(),
            binned: !detections_drive || params.detection.colour_weight > 0.0,
            cues: FrameCues::default(),
            previous: None,
            keep_colour,
            next_frame: start,
            end_frame: end,
            frame_size_px: size,
            len,
        })
    }

    /// The next frame, `None` at the end.
    pub fn next_frame(&mut self) -> Result<Option<PreparedFrame>> {
        let Some(frames) = &mut self.frames else {
            if self.next_frame >= self.end_frame {
                return Ok(None);
            }
            let frame = self.next_frame;
            self.next_frame += 1;
            let candidates = self.candidates_of(frame);
            return Ok(Some(PreparedFrame {
                frame,
                cues: None,
                candidates,
                candidates_are_detections: true,
                colour: None,
            }));
        };
        let Some(frame) = frames.next() else {
            return Ok(None);
        };
        let mut frame = frame?;
        let colour = frame
            .colour
            .as_ref()
            .ok_or_else(|| Error::input("the frame source gave no colour pixels"))?;
        let context = |e| {
            within(
                format_args!("{}: frame {}", frame.path.display(), frame.index + 1),
                e,
            )
        };
        let mut blobs = Vec::new();
        let foreground = match &mut self.motion {
            Some(detector) => {
                detector.detect(&frame.image, &mut blobs).map_err(context)?;
                Some(detector.foreground())
            }
            None => None,
        };
        let cues = if self.binned {
            // The buffers the consumer gave back (`recycle`), or new ones.
            let mut cues = std::mem::take(&mut self.cues);
            cues.update(
                &self.appearance,
                colour,
                &frame.image,
                self.previous.as_ref(),
                foreground,
            )
            .map_err(context)?;
            Some(cues)
        } else {
            None
        };
        let candidates = match &self.detections {
            Some(_) => self.candidates_of(frame.index),
            None => blobs.iter().map(blob_candidate).collect(),
        };
        let prepared = PreparedFrame {
            frame: frame.index,
            cues,
            candidates,
            candidates_are_detections: self.detections.is_some(),
            colour: if self.keep_colour {
                frame.colour.take()
            } else {
                None
            },
        };
        self.previous = Some(frame.image);
        Ok(Some(prepared))
    }

    /// Gives a frame's buffers back once it is tracked, so that streaming allocates nothing
    /// per frame (a cache of prepared frames simply keeps them).
    pub fn recycle(&mut self, frame: PreparedFrame) {
        if let Some(cues) = frame.cues {
            self.cues = cues;
        }
    }

    fn candidates_of(&self, frame: FrameIndex) -> Vec<Candidate> {
        self.detections
            .as_ref()
            .and_then(|d| d.get(&frame))
            .cloned()
            .unwrap_or_default()
    }
}

/// A motion blob as a birth candidate (score 1).
fn blob_candidate(blob: &MotionBlob) -> Candidate {
    Candidate {
        bbox: blob_box(blob),
        score: 1.0,
    }
}

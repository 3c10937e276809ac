//! The learned motion prior of the IMM-PF paper (§5.1) as `sillage fit motion-prior` learns
//! it from trajectories (MOTChallenge files) and writes it (JSON), and as `track immpf
//! --motion-prior` reads it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use sillage_core::{Error, FrameIndex, Point2, Result};
use sillage_filter::{MotionPrior, MotionPriorParams};
use sillage_io::{MotFileRole, MotRow, read_mot_sequence};

use super::{foot_px, within};

/// One trajectory: its foot points by frame.
type Track = Vec<(FrameIndex, Point2)>;

/// What [`fit_motion_prior`] learned, and from what.
pub struct MotionPriorFit {
    /// The file the trajectories came from.
    pub tracks_file: PathBuf,
    /// Image width, px.
    pub width_px: u32,
    /// Image height, px.
    pub height_px: u32,
    /// Trajectories used.
    pub tracks: usize,
    /// Rows with flag (7th column) 0, ignored.
    pub ignored_rows: usize,
    /// The prior.
    pub prior: MotionPrior,
}

/// Learns a motion prior from the trajectories of `tracks_file` (a MOTChallenge `gt.txt` or
/// tracker output) over an image of `width` × `height` px, each taken from its
/// `seqinfo.ini` when not given.
pub fn fit_motion_prior(
    tracks_file: &Path,
    width: Option<u32>,
    height: Option<u32>,
    params: &MotionPriorParams,
) -> Result<MotionPriorFit> {
    params
        .validate()
        .map_err(|e| within("invalid option (--cell, --min-speed, --smoothing)", e))?;
    let sequence = read_mot_sequence(tracks_file, MotFileRole::GroundTruth).map_err(|e| {
        within(
            "cannot read the trajectories (a MOTChallenge gt.txt or tracker output)",
            e,
        )
    })?;
    let path = &sequence.path;
    let seqinfo = sequence.seqinfo.as_ref();
    let size = |given: Option<u32>, from_ini: Option<u32>, option: &str| {
        given.or(from_ini).ok_or_else(|| {
            Error::input(format!(
                "{}: the image size is unknown; give {option} (no seqinfo.ini with imWidth and \
                 imHeight beside the file or in the folder above)",
                path.display()
            ))
        })
    };
    let width_px = size(width, seqinfo.and_then(|s| s.image_width), "--width")?;
    let height_px = size(height, seqinfo.and_then(|s| s.image_height), "--height")?;
    let (tracks, ignored_rows) = group_tracks(path, &sequence.rows)?;
    let prior = MotionPrior::fit(&tracks, width_px, height_px, params).map_err(|e| {
        within(
            format_args!("cannot learn a motion prior from {}", path.display()),
            e,
        )
    })?;
    Ok(MotionPriorFit {
        tracks_file: sequence.path.clone(),
        width_px,
        height_px,
        tracks: tracks.len(),
        ignored_rows,
        prior,
    })
}

/// The foot-point trajectories of the rows, by id then frame; rows with flag (7th column) 0
/// are ignored and counted. Rows without an id (detections) or an id twice in one frame are
/// errors naming the file.
fn group_tracks(path: &Path, rows: &[MotRow]) -> Result<(Vec<Track>, usize)> {
    let mut by_id: BTreeMap<u64, Track> = BTreeMap::new();
    let mut ignored = 0;
    for (k, row) in rows.iter().enumerate() {
        if row.confidence == Some(0.0) {
            ignored += 1;
            continue;
        }
        let Some(id) = row.id else {
            return Err(Error::input(format!(
                "{}: row {} has no track id (-1): these are detections; give ground truth or \
                 tracker output, whose rows carry track ids",
                path.display(),
                k + 1
            )));
        };
        by_id.entry(id).or_default().push((row.frame, foot_px(row)));
    }
    let mut tracks = Vec::with_capacity(by_id.len());
    for (id, mut points) in by_id {
        points.sort_by_key(|p| p.0);
        if let Some(pair) = points.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(Error::input(format!(
                "{}: track id {id} appears twice in frame {} (the file's numbering); keep one \
                 row per id and frame",
                path.display(),
                pair[0].0 + 1
            )));
        }
        tracks.push(points);
    }
    Ok((tracks, ignored))
}

/// Writes `prior` as JSON at `path` (a partial file renamed when complete).
pub fn write_motion_prior(path: &Path, prior: &MotionPrior) -> Result<()> {
    sillage_io::write_text(path, &format!("{}\n", prior.to_json()))
}

/// Reads a motion prior written by `sillage fit motion-prior`; errors name the file.
pub fn read_motion_prior(path: &Path) -> Result<MotionPrior> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Error::input(format!(
            "cannot read the motion prior {}; write it with `sillage fit motion-prior`: {e}",
            path.display()
        ))
    })?;
    MotionPrior::from_json(path, &text)
}

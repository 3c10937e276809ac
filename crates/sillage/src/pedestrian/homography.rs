//! `sillage fit homography`: the image ↔ ground homography and the adult's box size in metres
//! (IMM-PF paper §4: "the real dimensions (h, w) of the bounding box ... are fixed to the
//! average size of an adult"), from a MOT15 ground truth with world coordinates or from
//! point pairs.

use std::path::Path;

use sillage_core::{Error, Homography, PedestrianSize, Point2, Result};
use sillage_io::{MotRow, read_mot_rows};

use super::ground_plane::{FitTable, GroundPlaneFile};
use super::{foot_px, within};
use crate::experiments::median;

/// An image point (px) and its ground point (m).
type PointPair = (Point2, Point2);

/// Where the point pairs of a fit come from.
pub enum HomographySource<'a> {
    /// A MOT15 ground truth: foot points ↔ `(world_x, world_y)`, and the adult's box.
    GroundTruth(&'a Path),
    /// `u,v,x,y` lines (image px, ground m).
    Points(&'a Path),
}

/// A fitted ground plane and the number of boxes its adult size is the median of.
pub struct HomographyFit {
    /// The file to write (`[homography]`, `[pedestrian]` for a ground truth, `[fit]`).
    pub file: GroundPlaneFile,
    /// Boxes measured for `[pedestrian]` (0 for point pairs).
    pub boxes: usize,
}

/// Fits the homography of `source`, and from a ground truth the adult's box: the medians of
/// box height and width over the local scale.
pub fn fit_homography(source: HomographySource) -> Result<HomographyFit> {
    let (path, pairs, boxes) = match source {
        HomographySource::Points(path) => (path, read_point_pairs(path)?, Vec::new()),
        HomographySource::GroundTruth(path) => {
            let (pairs, boxes) = ground_truth_pairs(path)?;
            (path, pairs, boxes)
        }
    };
    let homography = Homography::fit(&pairs).map_err(|e| {
        within(
            format_args!("{}: cannot fit a homography", path.display()),
            e,
        )
    })?;
    let rms = homography.rms_reprojection_px(&pairs);
    let pedestrian = if boxes.is_empty() {
        None
    } else {
        Some(pedestrian_size(&homography, &boxes).ok_or_else(|| {
            Error::input(format!(
                "{}: no box lies where the ground scale is defined",
                path.display()
            ))
        })?)
    };
    Ok(HomographyFit {
        file: GroundPlaneFile {
            homography,
            pedestrian,
            fit: Some(FitTable {
                source: path.display().to_string(),
                pairs: pairs.len(),
                rms_reprojection_px: rms,
            }),
        },
        boxes: boxes.len(),
    })
}

/// Foot point ↔ (world_x, world_y) of every row with world coordinates, and those rows'
/// boxes; none is an error naming the file.
fn ground_truth_pairs(path: &Path) -> Result<(Vec<PointPair>, Vec<MotRow>)> {
    let rows = read_mot_rows(path).map_err(|e| {
        within(
            "cannot read the ground truth (MOT15: frame,id,box,flag,world_x,world_y,z)",
            e,
        )
    })?;
    let with_world: Vec<MotRow> = rows.into_iter().filter(|r| r.world.is_some()).collect();
    if with_world.is_empty() {
        return Err(Error::input(format!(
            "{}: no row has world coordinates (columns 8 and 9 are -1 or absent); give a MOT15 \
             ground truth with world_x, world_y, or four image ↔ ground pairs with --points",
            path.display()
        )));
    }
    let pairs = with_world
        .iter()
        .filter_map(|r| r.world.map(|w| (foot_px(r), Point2::new(w[0], w[1]))))
        .collect();
    Ok((pairs, with_world))
}

/// The medians of box height and width over the local scale: the adult size in metres.
fn pedestrian_size(homography: &Homography, boxes: &[MotRow]) -> Option<PedestrianSize> {
    let mut heights = Vec::with_capacity(boxes.len());
    let mut widths = Vec::with_capacity(boxes.len());
    for row in boxes {
        if let Some(scale) = homography.px_per_metre_across(foot_px(row)) {
            heights.push(row.height_px / scale);
            widths.push(row.width_px / scale);
        }
    }
    Some(PedestrianSize {
        height_m: median(&mut heights)?,
        width_m: median(&mut widths)?,
    })
}

/// `u,v,x,y` lines (image px, ground m; commas or spaces; `#` comments and blank lines
/// skipped); a bad line is an error naming the file and the line.
fn read_point_pairs(path: &Path) -> Result<Vec<PointPair>> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Error::input(format!(
            "{}: cannot read the point pairs: {e}",
            path.display()
        ))
    })?;
    let mut pairs = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let values: Vec<f64> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .map(|s| s.parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect::<Option<_>>()
            .unwrap_or_default();
        if values.len() != 4 {
            return Err(Error::format(
                path,
                Some(index + 1),
                format!(
                    "`{line}` is not four numbers `u,v,x,y` (image px, ground m); fix or \
                     remove the line"
                ),
            ));
        }
        pairs.push((
            Point2::new(values[0], values[1]),
            Point2::new(values[2], values[3]),
        ));
    }
    Ok(pairs)
}

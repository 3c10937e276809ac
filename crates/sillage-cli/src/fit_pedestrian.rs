//! `sillage fit motion-prior` and `sillage fit homography`: what the pedestrian IMM particle
//! filter of Madrigal & Hayet learns before tracking, from MOTChallenge files. The learned
//! motion prior (§5.1) is written as JSON; the image ↔ ground homography and the adult's box
//! size in metres (§4: "the real dimensions (h, w) of the bounding box ... are fixed to the
//! average size of an adult") as TOML.
//!
//! A box's position is its foot point, the bottom centre `(bb_left + w/2, bb_top + h)`, in the
//! file's own pixel numbering (MOTChallenge boxes are kept as written, see
//! `sillage_io::mot`), so the prior, the homography and a tracker's MOTChallenge output agree.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result, bail};
use serde::Serialize;
use sillage::core::{FrameIndex, Homography, PedestrianSize, Point2};
use sillage::filter::{MotionPrior, MotionPriorParams};
use sillage::io::{MotFileRole, MotRow, read_mot_rows, read_mot_sequence};

use crate::cli::{FitHomographyArgs, FitMotionPriorArgs};
use crate::fit::write_config;
use crate::ground_plane::{FitTable, GroundPlaneFile};

/// One trajectory: its foot points by frame.
type Track = Vec<(FrameIndex, Point2)>;

/// An image point (px) and its ground point (m).
type PointPair = (Point2, Point2);

/// The foot point of a box: its bottom centre.
fn foot_px(row: &MotRow) -> Point2 {
    Point2::new(row.left_px + 0.5 * row.width_px, row.top_px + row.height_px)
}

/// `--json` of `fit motion-prior`.
#[derive(Serialize)]
struct MotionPriorSummary<'a> {
    tracks_file: &'a Path,
    out: &'a Path,
    width_px: u32,
    height_px: u32,
    params: MotionPriorParams,
    tracks: usize,
    moves: u64,
    cells: usize,
    cells_with_data: usize,
    ignored_rows: usize,
}

/// `sillage fit motion-prior TRACKS --out prior.json`.
pub fn run_motion_prior(args: &FitMotionPriorArgs) -> Result<()> {
    let params = MotionPriorParams {
        cell_px: args.cell,
        min_speed_px_per_frame: args.min_speed,
        smoothing: args.smoothing,
    };
    params
        .validate()
        .context("invalid option (--cell, --min-speed, --smoothing)")?;
    let sequence = read_mot_sequence(&args.tracks, MotFileRole::GroundTruth)
        .context("cannot read the trajectories (a MOTChallenge gt.txt or tracker output)")?;
    let path = &sequence.path;
    let seqinfo = sequence.seqinfo.as_ref();
    let size = |given: Option<u32>, from_ini: Option<u32>, option: &str| {
        given.or(from_ini).with_context(|| {
            format!(
                "{}: the image size is unknown; give {option} (no seqinfo.ini with imWidth and \
                 imHeight beside the file or in the folder above)",
                path.display()
            )
        })
    };
    let width = size(args.width, seqinfo.and_then(|s| s.image_width), "--width")?;
    let height = size(
        args.height,
        seqinfo.and_then(|s| s.image_height),
        "--height",
    )?;
    let (tracks, ignored_rows) = group_tracks(path, &sequence.rows)?;
    let prior = MotionPrior::fit(&tracks, width, height, &params)
        .with_context(|| format!("cannot learn a motion prior from {}", path.display()))?;
    sillage::io::write_text(&args.out, &format!("{}\n", prior.to_json()))?;
    let (columns, rows) = prior.grid_size();
    let summary = MotionPriorSummary {
        tracks_file: path,
        out: &args.out,
        width_px: width,
        height_px: height,
        params,
        tracks: tracks.len(),
        moves: prior.moves(),
        cells: columns * rows,
        cells_with_data: prior.cells_with_data(),
        ignored_rows,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        println!(
            "{} tracks, {} moves ({} rows with flag 0 ignored) from {} → {}",
            summary.tracks,
            summary.moves,
            ignored_rows,
            path.display(),
            args.out.display()
        );
        println!(
            "{width} × {height} px in {columns} × {rows} cells of {} px: {} cells with data",
            params.cell_px, summary.cells_with_data
        );
    }
    Ok(())
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
            bail!(
                "{}: row {} has no track id (-1): these are detections; give ground truth or \
                 tracker output, whose rows carry track ids",
                path.display(),
                k + 1
            );
        };
        by_id.entry(id).or_default().push((row.frame, foot_px(row)));
    }
    let mut tracks = Vec::with_capacity(by_id.len());
    for (id, mut points) in by_id {
        points.sort_by_key(|p| p.0);
        if let Some(pair) = points.windows(2).find(|w| w[0].0 == w[1].0) {
            bail!(
                "{}: track id {id} appears twice in frame {} (the file's numbering); keep one \
                 row per id and frame",
                path.display(),
                pair[0].0 + 1
            );
        }
        tracks.push(points);
    }
    Ok((tracks, ignored))
}

/// `sillage fit homography (GT | --points FILE) --out ground.toml`.
pub fn run_homography(args: &FitHomographyArgs) -> Result<()> {
    let (source, pairs, boxes) = match (&args.gt, &args.points) {
        (_, Some(points)) => (points, read_point_pairs(points)?, Vec::new()),
        (Some(gt), None) => {
            let (pairs, boxes) = ground_truth_pairs(gt)?;
            (gt, pairs, boxes)
        }
        (None, None) => bail!("give a ground truth file or --points FILE"),
    };
    let homography = Homography::fit(&pairs)
        .with_context(|| format!("{}: cannot fit a homography", source.display()))?;
    let rms = homography.rms_reprojection_px(&pairs);
    let pedestrian = if boxes.is_empty() {
        None
    } else {
        Some(pedestrian_size(&homography, &boxes).with_context(|| {
            format!(
                "{}: no box lies where the ground scale is defined",
                source.display()
            )
        })?)
    };
    let file = GroundPlaneFile {
        homography,
        pedestrian,
        fit: Some(FitTable {
            source: source.display().to_string(),
            pairs: pairs.len(),
            rms_reprojection_px: rms,
        }),
    };
    let mut text = String::new();
    let _ = writeln!(
        text,
        "# Image <-> ground-plane homography (image px from ground m), by `sillage fit \
         homography` (sillage {}).",
        env!("CARGO_PKG_VERSION")
    );
    let _ = writeln!(
        text,
        "# {} pairs from {}; RMS reprojection error {rms:.3} px.",
        pairs.len(),
        source.display()
    );
    if pedestrian.is_some() {
        let _ = writeln!(
            text,
            "# [pedestrian]: medians of bb_height and bb_width / px_per_metre_across(foot \
             point), the adult box of Madrigal & Hayet §4."
        );
    }
    text.push('\n');
    text.push_str(&toml::to_string(&file).context("cannot write the homography as TOML")?);
    write_config(&args.out, &text)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&file)?);
    } else {
        println!(
            "{} pairs from {} → {}",
            pairs.len(),
            source.display(),
            args.out.display()
        );
        println!("RMS reprojection error: {rms:.3} px");
        if let Some(p) = pedestrian {
            println!(
                "adult box (median over {} boxes): height {:.3} m, width {:.3} m",
                boxes.len(),
                p.height_m,
                p.width_m
            );
        }
    }
    Ok(())
}

/// Foot point ↔ (world_x, world_y) of every row with world coordinates, and those rows'
/// boxes; none is an error naming the file.
fn ground_truth_pairs(path: &Path) -> Result<(Vec<PointPair>, Vec<MotRow>)> {
    let rows = read_mot_rows(path)
        .context("cannot read the ground truth (MOT15: frame,id,box,flag,world_x,world_y,z)")?;
    let with_world: Vec<MotRow> = rows.into_iter().filter(|r| r.world.is_some()).collect();
    if with_world.is_empty() {
        bail!(
            "{}: no row has world coordinates (columns 8 and 9 are -1 or absent); give a MOT15 \
             ground truth with world_x, world_y, or four image ↔ ground pairs with --points",
            path.display()
        );
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

/// The median of `values` (sorted in place); `None` when empty.
pub(crate) fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    })
}

/// `u,v,x,y` lines (image px, ground m; commas or spaces; `#` comments and blank lines
/// skipped); a bad line is an error naming the file and the line.
fn read_point_pairs(path: &Path) -> Result<Vec<PointPair>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read the point pairs", path.display()))?;
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
            bail!(
                "{}:{}: `{line}` is not four numbers `u,v,x,y` (image px, ground m); fix or \
                 remove the line",
                path.display(),
                index + 1
            );
        }
        pairs.push((
            Point2::new(values[0], values[1]),
            Point2::new(values[2], values[3]),
        ));
    }
    Ok(pairs)
}

/// Reads a motion prior written by `sillage fit motion-prior`; errors name the file.
pub fn read_motion_prior(path: &Path) -> Result<MotionPrior> {
    let text = std::fs::read_to_string(path).with_context(|| {
        format!(
            "cannot read the motion prior {}; write it with `sillage fit motion-prior`",
            path.display()
        )
    })?;
    Ok(MotionPrior::from_json(path, &text)?)
}

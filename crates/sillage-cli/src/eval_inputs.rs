//! The inputs of `sillage eval mot`: the sequences of `--gt` and `--pred` paired by name, and
//! each file read in its format (told from its extension and first line) and turned into
//! the evaluation's objects under the matching rule.

use std::io::BufRead;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use sillage::core::{BoundingBox, FrameIndex, Point2};
use sillage::eval::mot::{MotChallengeProtocol, MotEstimate, MotTruth, Shape, TruthRole};
use sillage::eval::papers::StateLabel;
use sillage::io::{
    BEAD_HEADER, BeadPoint, BeadSequenceParams, MotFileRole, MotRow, TRACK_COLUMNS, TRUTH_HEADER,
    TrackFormat, TrackLayout, read_bead_csv, read_bead_sequence_params, read_mot_rows,
    read_mot_sequence, read_track_table, read_truth_csv,
};

use crate::cli::MatchRule;

/// Extensions of the files taken as sequences in a folder.
const SEQUENCE_EXTENSIONS: [&str; 5] = ["txt", "csv", "parquet", "h5", "hdf5"];

/// One sequence to score: its name and its ground-truth and prediction files.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SequencePaths {
    /// The name shown in the tables.
    pub name: String,
    /// The ground-truth file.
    pub gt: PathBuf,
    /// The prediction file.
    pub pred: PathBuf,
}

/// The sequences of `gt` (a file, a sequence folder, or a folder of them) paired with the
/// predictions in `pred` (a file, or a folder of files named `<sequence>.<ext>`).
pub fn pair_sequences(gt: &Path, pred: &Path) -> Result<Vec<SequencePaths>> {
    let truths = gt_sequences(gt)?;
    if !pred.exists() {
        bail!("--pred {} does not exist", pred.display());
    }
    if !pred.is_dir() {
        return match truths.as_slice() {
            [(name, file)] => Ok(vec![SequencePaths {
                name: name.clone(),
                gt: file.clone(),
                pred: pred.to_path_buf(),
            }]),
            _ => bail!(
                "--gt {} holds {} sequences but --pred {} is one file; give a folder of \
                 predictions named <sequence>.txt",
                gt.display(),
                truths.len(),
                pred.display()
            ),
        };
    }
    let preds = files_by_stem(pred)?;
    let mut pairs = Vec::with_capacity(truths.len());
    let mut missing = Vec::new();
    for (name, file) in &truths {
        match preds.iter().find(|(stem, _)| stem == name) {
            Some((_, pred_file)) => pairs.push(SequencePaths {
                name: name.clone(),
                gt: file.clone(),
                pred: pred_file.clone(),
            }),
            None => missing.push(name.as_str()),
        }
    }
    let extra: Vec<&str> = preds
        .iter()
        .map(|(stem, _)| stem.as_str())
        .filter(|stem| truths.iter().all(|(name, _)| name != stem))
        .collect();
    if missing.is_empty() && extra.is_empty() {
        return Ok(pairs);
    }
    let mut problems = Vec::new();
    if !missing.is_empty() {
        problems.push(format!(
            "no prediction in {} for the ground-truth sequence(s) {}",
            pred.display(),
            missing.join(", ")
        ));
    }
    if !extra.is_empty() {
        problems.push(format!(
            "no ground truth in {} for the prediction(s) {}",
            gt.display(),
            extra.join(", ")
        ));
    }
    bail!(
        "{}; sequences pair by name (SEQ/gt/gt.txt with SEQ.txt): rename or remove the \
         unpaired files, or score one pair with --gt FILE --pred FILE",
        problems.join("; ")
    )
}

/// The ground-truth sequences of `gt` by name: a file; a sequence folder (`gt/gt.txt` or
/// `gt.txt` in it); or a folder of sequence folders and ground-truth files.
fn gt_sequences(gt: &Path) -> Result<Vec<(String, PathBuf)>> {
    if !gt.exists() {
        bail!("--gt {} does not exist", gt.display());
    }
    if !gt.is_dir() {
        return Ok(vec![(file_sequence_name(gt), gt.to_path_buf())]);
    }
    if let Some(file) = sequence_folder_gt(gt) {
        return Ok(vec![(file_name(gt), file)]);
    }
    let mut sequences = Vec::new();
    for path in folder_entries(gt)? {
        if path.is_dir() {
            if let Some(file) = sequence_folder_gt(&path) {
                sequences.push((file_name(&path), file));
            }
        } else if has_extension(&path, &["txt", "csv"]) {
            sequences.push((file_stem(&path), path));
        }
    }
    if sequences.is_empty() {
        bail!(
            "--gt {} holds no sequence: expected sequence folders (SEQ/gt/gt.txt) or \
             ground-truth files (.txt, .csv)",
            gt.display()
        );
    }
    Ok(sequences)
}

/// The ground-truth file of a MOTChallenge sequence folder, if it is one.
fn sequence_folder_gt(folder: &Path) -> Option<PathBuf> {
    [
        folder.join(MotFileRole::GroundTruth.path_in_sequence()),
        folder.join("gt.txt"),
    ]
    .into_iter()
    .find(|p| p.is_file())
}

/// The files of a prediction folder by stem (`SEQ.txt` → `SEQ`); a stem twice is an error.
fn files_by_stem(folder: &Path) -> Result<Vec<(String, PathBuf)>> {
    let mut files: Vec<(String, PathBuf)> = Vec::new();
    for path in folder_entries(folder)? {
        if path.is_dir() || !has_extension(&path, &SEQUENCE_EXTENSIONS) {
            continue;
        }
        let stem = file_stem(&path);
        if let Some((_, other)) = files.iter().find(|(s, _)| *s == stem) {
            bail!(
                "{} and {} are both predictions for sequence {stem}; keep one",
                other.display(),
                path.display()
            );
        }
        files.push((stem, path));
    }
    Ok(files)
}

/// The entries of `folder` in name order, hidden ones left out.
fn folder_entries(folder: &Path) -> Result<Vec<PathBuf>> {
    let mut paths = Vec::new();
    let entries =
        std::fs::read_dir(folder).with_context(|| format!("cannot list {}", folder.display()))?;
    for entry in entries {
        let path = entry
            .with_context(|| format!("cannot list {}", folder.display()))?
            .path();
        if !file_name(&path).starts_with('.') {
            paths.push(path);
        }
    }
    paths.sort();
    Ok(paths)
}

/// The last component of `path` (empty for none).
fn file_name(path: &Path) -> String {
    path.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// The file name of `path` without its extension.
fn file_stem(path: &Path) -> String {
    path.file_stem()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// Whether `path` ends in one of `extensions` (any case).
fn has_extension(path: &Path, extensions: &[&str]) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| extensions.iter().any(|x| x.eq_ignore_ascii_case(e)))
}

/// The sequence a ground-truth file is named after: the folder of a `gt.txt` (above a `gt`
/// folder, as in `SEQ/gt/gt.txt`), else the file's stem.
fn file_sequence_name(path: &Path) -> String {
    if !file_name(path).eq_ignore_ascii_case("gt.txt") {
        return file_stem(path);
    }
    let mut folder = path.parent();
    if folder.is_some_and(|f| file_name(f).eq_ignore_ascii_case("gt")) {
        folder = folder.and_then(Path::parent);
    }
    folder
        .map(file_name)
        .filter(|name| !name.is_empty())
        .unwrap_or_else(|| file_stem(path))
}

/// The objects a file holds.
enum Objects {
    /// MOTChallenge rows (boxes).
    Boxes(Vec<MotRow>),
    /// Beads with categories and motion states.
    Beads(Vec<BeadPoint>),
    /// Points: truth CSV or sillage tracks.
    Points(Vec<(FrameIndex, u64, Point2)>),
}

/// Reads `path` in the format its extension and first line tell; for ground truth
/// (`with_seqinfo`), a MOTChallenge file comes with the `seqLength` of its `seqinfo.ini`
/// (beside it or one folder up), when there is one.
fn read_objects(path: &Path, with_seqinfo: bool) -> Result<(Objects, Option<u64>)> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let points = |points: Vec<(FrameIndex, u64, Point2)>| Ok((Objects::Points(points), None));
    // Tables with motion states (bedload trackers) are beads; the others points.
    let tracks = |format: TrackFormat| {
        let table = read_track_table(path, format)?;
        if table.layout == TrackLayout::WithStates {
            let beads = table
                .points
                .iter()
                .map(|p| {
                    BeadPoint::from_track_point(p).ok_or_else(|| {
                        anyhow!(
                            "{}: track {} at frame {} has class {}; bead tracks have class 0 \
                             (black) or 1 (transparent)",
                            path.display(),
                            p.track_id,
                            p.frame,
                            p.class
                        )
                    })
                })
                .collect::<Result<_>>()?;
            return Ok((Objects::Beads(beads), None));
        }
        points(
            table
                .points
                .iter()
                .map(|p| (p.frame, p.track_id, p.pos_px))
                .collect(),
        )
    };
    match extension.as_deref() {
        Some("parquet" | "h5" | "hdf5") => tracks(TrackFormat::from_path(path)?),
        Some("csv") => {
            let header = first_line(path)?;
            let columns: Vec<String> = header
                .split(',')
                .map(|c| c.trim().to_ascii_lowercase())
                .collect();
            let has = |name: &str| columns.iter().any(|c| c == name);
            if has("category") {
                Ok((Objects::Beads(read_bead_csv(path)?), None))
            } else if has("track_id") {
                let truth = read_truth_csv(path)?;
                points(
                    truth
                        .iter()
                        .map(|p| (p.frame, p.track_id, p.pos_px))
                        .collect(),
                )
            } else if has("particle") {
                tracks(TrackFormat::Csv)
            } else {
                bail!(
                    "{}: a CSV with the header `{header}` is none of the tables `eval mot` \
                     reads: bead ground truth ({BEAD_HEADER}), truth ({TRUTH_HEADER}) or tracks \
                     ({})",
                    path.display(),
                    TRACK_COLUMNS.join(",")
                )
            }
        }
        _ if first_line(path)?.starts_with('#') => tracks(TrackFormat::Tractrac),
        _ if with_seqinfo => {
            let file = read_mot_sequence(path, MotFileRole::GroundTruth)?;
            let frame_count = file.seqinfo.and_then(|info| info.frame_count);
            Ok((Objects::Boxes(file.rows), frame_count))
        }
        _ => Ok((Objects::Boxes(read_mot_rows(path)?), None)),
    }
}

/// The first non-blank line of `path` (empty for an empty file), trimmed.
pub(crate) fn first_line(path: &Path) -> Result<String> {
    let file = std::fs::File::open(path).map_err(|e| sillage::core::Error::io(path, e))?;
    let mut reader = std::io::BufReader::new(file);
    let mut line = Vec::new();
    loop {
        line.clear();
        let read = reader
            .read_until(b'\n', &mut line)
            .map_err(|e| sillage::core::Error::io(path, e))?;
        let text = String::from_utf8_lossy(&line).trim().to_owned();
        if read == 0 || !text.is_empty() {
            return Ok(text);
        }
    }
}

/// One sequence read and converted for [`MotData::new`](sillage::eval::mot::MotData::new).
pub struct LoadedSequence {
    /// The true objects.
    pub truth: Vec<MotTruth>,
    /// The predictions.
    pub estimates: Vec<MotEstimate>,
    /// `seqLength` of the ground truth's `seqinfo.ini`, when there is one.
    pub frame_count: Option<u64>,
    /// True and estimated motion states, when both files are bead files.
    pub states: Option<(Vec<StateLabel>, Vec<StateLabel>)>,
}

/// Reads the ground truth and predictions of `paths` and gives them the shapes `rule`
/// compares.
pub fn load_sequence(
    paths: &SequencePaths,
    rule: MatchRule,
    protocol: MotChallengeProtocol,
) -> Result<LoadedSequence> {
    let (gt_objects, frame_count) = read_objects(&paths.gt, true)?;
    let (shapes, truth) = truth_of(&gt_objects, &paths.gt, rule, protocol)?;
    let (pred_objects, _) = read_objects(&paths.pred, false)?;
    let estimates = shapes
        .of(&pred_objects, &paths.pred)?
        .into_iter()
        .map(|(frame, id, shape)| MotEstimate { frame, id, shape })
        .collect();
    let states = match (&gt_objects, &pred_objects) {
        (Objects::Beads(truth), Objects::Beads(pred)) => Some((labels(truth), labels(pred))),
        _ => None,
    };
    Ok(LoadedSequence {
        truth,
        estimates,
        frame_count,
        states,
    })
}

/// The shapes `rule` compares and the true objects of `objects`, read from `gt`.
fn truth_of(
    objects: &Objects,
    gt: &Path,
    rule: MatchRule,
    protocol: MotChallengeProtocol,
) -> Result<(Shapes, Vec<MotTruth>)> {
    let bead_params = match (rule, objects) {
        (MatchRule::Disc { .. }, Objects::Beads(_)) => Some(bead_params(gt)?),
        _ => None,
    };
    let shapes = Shapes { rule, bead_params };
    let truth = shapes
        .of(objects, gt)?
        .into_iter()
        .zip(roles(objects, protocol))
        .map(|((frame, id, shape), role)| MotTruth {
            frame,
            id,
            shape,
            role,
        })
        .collect();
    Ok((shapes, truth))
}

/// The roles of ground-truth objects: MOTChallenge rows by `protocol`, the rest scored.
fn roles(objects: &Objects, protocol: MotChallengeProtocol) -> Vec<TruthRole> {
    match objects {
        Objects::Boxes(rows) => rows
            .iter()
            .map(|r| protocol.truth_role(r.confidence.unwrap_or(1.0), r.class))
            .collect(),
        Objects::Beads(beads) => vec![TruthRole::Scored; beads.len()],
        Objects::Points(points) => vec![TruthRole::Scored; points.len()],
    }
}

/// The motion states of bead points.
fn labels(beads: &[BeadPoint]) -> Vec<StateLabel> {
    beads
        .iter()
        .map(|b| StateLabel {
            frame: b.frame,
            id: b.id,
            state: b.motion_state,
        })
        .collect()
}

/// BeadTracking's `sequence_param.txt` (bead sizes), beside the ground truth or one folder
/// up (`ground_truth/truth.csv` in a sequence folder).
fn bead_params(gt: &Path) -> Result<BeadSequenceParams> {
    let folder = gt.parent().unwrap_or(Path::new(""));
    let candidates = [
        Some(folder.join("sequence_param.txt")),
        folder
            .parent()
            .map(|above| above.join("sequence_param.txt")),
    ];
    match candidates.into_iter().flatten().find(|p| p.is_file()) {
        Some(path) => Ok(read_bead_sequence_params(path)?),
        None => bail!(
            "disc matching needs the bead radii: put BeadTracking's sequence_param.txt \
             (diamBlackBead, diamTransBead, mByPx) beside {} or in the folder above, or match \
             by distance (--match dist:R)",
            gt.display()
        ),
    }
}

/// The shapes a matching rule compares.
struct Shapes {
    rule: MatchRule,
    bead_params: Option<BeadSequenceParams>,
}

impl Shapes {
    /// `(frame, id, shape)` of every object of `objects`, read from `path`.
    fn of(&self, objects: &Objects, path: &Path) -> Result<Vec<(FrameIndex, u64, Shape)>> {
        let (what, rules) = match objects {
            Objects::Boxes(_) => ("boxes", "iou[:T] or dist:R"),
            Objects::Beads(_) => ("beads", "disc[:T] or dist:R"),
            Objects::Points(_) => ("points", "dist:R (centres at most R px apart)"),
        };
        let refuse = |needs: &str| {
            anyhow!(
                "{}: --match {} compares {needs}, and this file holds {what}; match {what} with \
                 --match {rules}",
                path.display(),
                self.rule
            )
        };
        match (self.rule, objects) {
            (MatchRule::Disc { .. }, Objects::Beads(beads)) => {
                let params = self
                    .bead_params
                    .ok_or_else(|| refuse("beads, sized by a bead ground truth"))?;
                Ok(beads
                    .iter()
                    .map(|b| {
                        let shape = Shape::Disc {
                            centre_px: b.pos_px,
                            radius_px: params.radius_px(b.category),
                        };
                        (b.frame, b.id, shape)
                    })
                    .collect())
            }
            (MatchRule::Disc { .. }, _) => Err(refuse("beads (bead CSV files)")),
            (MatchRule::Iou { .. } | MatchRule::Distance { .. }, Objects::Boxes(rows)) => rows
                .iter()
                .map(|r| {
                    let id = r.id.ok_or_else(|| {
                        anyhow!(
                            "{}: a row of frame {} has id -1; every row needs an object or \
                             track id in column 2",
                            path.display(),
                            r.frame + 1
                        )
                    })?;
                    let shape = Shape::Box(BoundingBox {
                        left_px: r.left_px,
                        top_px: r.top_px,
                        width_px: r.width_px,
                        height_px: r.height_px,
                    });
                    Ok((r.frame, id, shape))
                })
                .collect(),
            (MatchRule::Iou { .. }, _) => Err(refuse("boxes (MOTChallenge files)")),
            (MatchRule::Distance { .. }, Objects::Beads(beads)) => Ok(beads
                .iter()
                .map(|b| (b.frame, b.id, Shape::Point(b.pos_px)))
                .collect()),
            (MatchRule::Distance { .. }, Objects::Points(points)) => Ok(points
                .iter()
                .map(|&(frame, id, pos)| (frame, id, Shape::Point(pos)))
                .collect()),
        }
    }
}

//! One sequence's ground truth and predictions given the shapes a [`MatchRule`] compares:
//! boxes, bead discs sized by BeadTracking's `sequence_param.txt`, or points.

use std::path::Path;

use sillage_core::{Error, FrameIndex, Result};
use sillage_eval::mot::{MatchRule, MotChallengeProtocol, MotEstimate, MotTruth, Shape, TruthRole};
use sillage_eval::papers::StateLabel;
use sillage_io::{BeadPoint, BeadSequenceParams, read_bead_sequence_params};

use super::objects::{Objects, read_objects};
use super::pairing::SequencePaths;

/// One sequence read and converted for [`MotData::new`](sillage_eval::mot::MotData::new).
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

/// Reads the ground truth `gt` alone, as [`load_sequence`] does: the true objects and the
/// `seqLength` of its `seqinfo.ini`, when there is one.
pub fn load_truth(
    gt: &Path,
    rule: MatchRule,
    protocol: MotChallengeProtocol,
) -> Result<(Vec<MotTruth>, Option<u64>)> {
    let (objects, frame_count) = read_objects(gt, true)?;
    let (_, truth) = truth_of(&objects, gt, rule, protocol)?;
    Ok((truth, frame_count))
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
        Some(path) => read_bead_sequence_params(path),
        None => Err(Error::input(format!(
            "disc matching needs the bead radii: put BeadTracking's sequence_param.txt \
             (diamBlackBead, diamTransBead, mByPx) beside {} or in the folder above, or match \
             by distance (--match dist:R)",
            gt.display()
        ))),
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
            Error::format(
                path,
                None,
                format!(
                    "--match {} compares {needs}, and this file holds {what}; match {what} \
                     with --match {rules}",
                    self.rule
                ),
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
                        Error::format(
                            path,
                            None,
                            format!(
                                "a row of frame {} has id -1; every row needs an object or \
                                 track id in column 2",
                                r.frame + 1
                            ),
                        )
                    })?;
                    let shape = Shape::Box(r.bbox());
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

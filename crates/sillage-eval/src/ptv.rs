//! The PTV accuracy indexes of the TracTrac paper (§4.1.2, Fig. 4): true and false
//! recovery rates, mean position and displacement errors.

use std::fmt;

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result, TrackPoint, TruthPoint, Vec2};

use crate::matching::{by_frame, check_finite, check_radius, greedy_match};
use crate::summary::{Mean, percent, px};

/// Parameters of [`ptv_accuracy`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PtvAccuracyParams {
    /// The paper's `d`: largest position error of a true recovery, px (exclusive). The paper
    /// does not give its value; the default 1 px is five times the errors it reports at
    /// SNR ≥ 4 and well below the particle spacing.
    pub max_position_error_px: f64,
}

impl Default for PtvAccuracyParams {
    fn default() -> Self {
        Self {
            max_position_error_px: 1.0,
        }
    }
}

impl PtvAccuracyParams {
    /// Checks `max_position_error_px` (finite, > 0).
    pub fn validate(&self) -> Result<()> {
        check_radius("max_position_error_px", self.max_position_error_px)
    }
}

/// The accuracy of a PTV result against the truth (see [`ptv_accuracy`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PtvAccuracy {
    /// The `d` used, px.
    pub max_position_error_px: f64,
    /// Truth points with a velocity: the denominator of the true recovery rate.
    pub n_truth: usize,
    /// Estimated points evaluated: the denominator of the false recovery rate.
    pub n_estimated: usize,
    /// Estimated points left out: without a velocity, or in a frame where no truth point has
    /// one (e.g. the first and last frames of a sequence).
    pub n_not_evaluated: usize,
    /// True recoveries: position error < d and displacement error < |v_true| / 2.
    pub n_true: usize,
    /// False recoveries: every other evaluated estimated point.
    pub n_false: usize,
    /// `n_true / n_truth`; `None` when there is no truth point with a velocity.
    pub true_recovery_rate: Option<f64>,
    /// `n_false / n_estimated`; `None` when no estimated point was evaluated.
    pub false_recovery_rate: Option<f64>,
    /// Mean Euclidean position error over true recoveries, px.
    pub mean_position_error_px: Option<f64>,
    /// Mean Euclidean displacement error |v_est − v_true| over true recoveries, px/frame.
    pub mean_displacement_error_px: Option<f64>,
    /// Root-mean-square position error per axis over true recoveries, px.
    pub rms_position_error_px: Option<Vec2>,
}

/// Scores PTV `tracks` against `truth` with the criteria of the TracTrac paper (Fig. 4).
///
/// Per frame, the estimated points with a velocity are matched one-to-one to the truth
/// points of that frame by position (greedy by ascending distance, pairs closer than `d`).
/// A matched point is a **true recovery** when its true point has a velocity `v_true` and
/// `|v_est − v_true| < |v_true| / 2` (Euclidean norms, strict: an error of exactly
/// `|v_true| / 2` is false); every other evaluated estimate (unmatched, matched to a truth
/// point without velocity, or with a bad displacement) is a **false recovery**.
///
/// Frames that count are those where some truth point has a velocity: a truth generator
/// that gives central-difference velocities (as `sillage_synth::VortexTruth`) leaves
/// the first and last frames without, like TracTrac's output, which covers frames
/// `1..n−2`. Inputs need not be sorted. Non-finite positions or velocities are rejected,
/// naming the frame and the id.
pub fn ptv_accuracy(
    truth: &[TruthPoint],
    tracks: &[TrackPoint],
    params: &PtvAccuracyParams,
) -> Result<PtvAccuracy> {
    params.validate()?;
    check_inputs(truth, tracks)?;
    let d = params.max_position_error_px;
    let with_velocity = tracks.iter().filter(|p| p.vel_px_per_frame.is_some());
    let frames = by_frame(
        truth.iter().map(|p| (p.frame, p)),
        with_velocity.map(|p| (p.frame, p)),
    );
    let mut counts = Counts {
        not_evaluated: tracks.len(),
        ..Default::default()
    };
    for pair in frames.values() {
        let n_truth = pair
            .truth
            .iter()
            .filter(|p| p.vel_px_per_frame.is_some())
            .count();
        if n_truth == 0 {
            continue;
        }
        counts.truth += n_truth;
        counts.estimated += pair.estimates.len();
        counts.not_evaluated -= pair.estimates.len();
        let truth_pos: Vec<_> = pair.truth.iter().map(|p| p.pos_px).collect();
        let estimate_pos: Vec<_> = pair.estimates.iter().map(|p| p.pos_px).collect();
        for m in greedy_match(&truth_pos, &estimate_pos, d) {
            let (t, e) = (pair.truth[m.truth], pair.estimates[m.estimate]);
            if let (Some(v_true), Some(v_est)) = (t.vel_px_per_frame, e.vel_px_per_frame) {
                let displacement_error = (v_est - v_true).norm();
                if displacement_error < v_true.norm() / 2.0 {
                    counts.add_true(e.pos_px - t.pos_px, displacement_error);
                }
            }
        }
    }
    Ok(counts.finish(d))
}

/// Rejects non-finite positions and velocities, naming the frame and the id.
fn check_inputs(truth: &[TruthPoint], tracks: &[TrackPoint]) -> Result<()> {
    let velocity_ok = |v: Option<Vec2>| v.is_none_or(Vec2::is_finite);
    for p in truth {
        check_finite("truth point", p.frame, p.track_id, p.pos_px)?;
        if !velocity_ok(p.vel_px_per_frame) {
            return Err(non_finite_velocity("truth point", p.frame, p.track_id));
        }
    }
    for p in tracks {
        check_finite("track point", p.frame, p.track_id, p.pos_px)?;
        if !velocity_ok(p.vel_px_per_frame) {
            return Err(non_finite_velocity("track point", p.frame, p.track_id));
        }
    }
    Ok(())
}

fn non_finite_velocity(what: &str, frame: u64, id: u64) -> Error {
    Error::input(format!(
        "{what} of frame {frame}, id {id}: velocity is not finite; remove or fix this point"
    ))
}

/// Running counts and error sums of [`ptv_accuracy`].
#[derive(Default)]
struct Counts {
    truth: usize,
    estimated: usize,
    not_evaluated: usize,
    position_error: Mean,
    displacement_error: Mean,
    squared_x: Mean,
    squared_y: Mean,
}

impl Counts {
    fn add_true(&mut self, position_error: Vec2, displacement_error: f64) {
        self.position_error.add(position_error.norm());
        self.displacement_error.add(displacement_error);
        self.squared_x.add(position_error.x * position_error.x);
        self.squared_y.add(position_error.y * position_error.y);
    }

    fn finish(self, d: f64) -> PtvAccuracy {
        let n_true = self.position_error.count();
        let rate = |count: usize, total: usize| (total > 0).then(|| count as f64 / total as f64);
        let rms = self
            .squared_x
            .value()
            .zip(self.squared_y.value())
            .map(|(x, y)| Vec2::new(x.sqrt(), y.sqrt()));
        PtvAccuracy {
            max_position_error_px: d,
            n_truth: self.truth,
            n_estimated: self.estimated,
            n_not_evaluated: self.not_evaluated,
            n_true,
            n_false: self.estimated - n_true,
            true_recovery_rate: rate(n_true, self.truth),
            false_recovery_rate: rate(self.estimated - n_true, self.estimated),
            mean_position_error_px: self.position_error.value(),
            mean_displacement_error_px: self.displacement_error.value(),
            rms_position_error_px: rms,
        }
    }
}

impl fmt::Display for PtvAccuracy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "PTV accuracy (d = {} px)", self.max_position_error_px)?;
        writeln!(
            f,
            "  true recoveries:  {} ({} of {} true points with a velocity)",
            percent(self.true_recovery_rate),
            self.n_true,
            self.n_truth
        )?;
        writeln!(
            f,
            "  false recoveries: {} ({} of {} estimated points; {} not evaluated)",
            percent(self.false_recovery_rate),
            self.n_false,
            self.n_estimated,
            self.n_not_evaluated
        )?;
        writeln!(
            f,
            "  mean position error:     {}",
            px(self.mean_position_error_px)
        )?;
        writeln!(
            f,
            "  mean displacement error: {}",
            px(self.mean_displacement_error_px)
        )?;
        let rms = self.rms_position_error_px;
        write!(
            f,
            "  RMS position error:      x {}, y {}",
            px(rms.map(|v| v.x)),
            px(rms.map(|v| v.y))
        )
    }
}

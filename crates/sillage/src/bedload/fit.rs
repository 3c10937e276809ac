//! The bedload particle filter's motion parameters learnt from BeadTracking ground truth
//! (the transition table of the MMPF+ paper's Eqs. (11)-(12) and the process noises of
//! Eq. (3), §4.3), the evidence model of the motion-state smoother learnt from a tracker's
//! output paired with that truth, and the TOML config text that records them under `[motion]`
//! and `[smoother.emission]`, which the trackers read.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;
use sillage_core::{Error, MotionState, Result, Vec2};
use sillage_filter::fit::STATE_NAMES;
use sillage_filter::{BedloadFit, BedloadParams, FitOptions, StatePoint, StateTrack, fit_bedload};
use sillage_io::read_bead_csv;
use sillage_track::bedload::{
    BedloadTrackerParams, EmissionParams, EmissionReport, LabelledPoint, fit_emission,
};

/// The config file: the fitted parameters under `[motion]`, and the smoother's evidence
/// model under `[smoother.emission]` when it was fitted.
#[derive(Serialize)]
struct ConfigFile<'a> {
    motion: &'a BedloadParams,
    #[serde(skip_serializing_if = "Option::is_none")]
    smoother: Option<SmootherSection<'a>>,
}

/// `[smoother]` with its evidence model and the window it was learnt over (the lag keeps its
/// default).
#[derive(Serialize)]
struct SmootherSection<'a> {
    half_window: u32,
    emission: &'a EmissionParams,
}

/// The points of a BeadTracking CSV (a truth or `sillage track bedload`'s output) as the
/// smoother's fit reads them: the velocity is the file's `vx, vy`.
pub fn read_labelled_points(path: &Path) -> Result<Vec<LabelledPoint>> {
    Ok(read_bead_csv(path)?
        .iter()
        .map(|p| LabelledPoint::of(&p.track_point()))
        .collect())
}

/// The smoother's evidence model learnt from a tracker's output (`tracks`) and the truth
/// with states (`truth`) over the training frames `frames`, with the bead radii and the
/// calibration of `params`; a state with fewer than `min_samples` samples keeps the default.
pub fn fit_smoother(
    truth: &Path,
    tracks: &Path,
    frames: [u64; 2],
    params: &BedloadTrackerParams,
    min_samples: u64,
) -> Result<(EmissionParams, EmissionReport)> {
    let truth_points = read_labelled_points(truth)?;
    let track_points = read_labelled_points(tracks)?;
    fit_emission(
        &track_points,
        &truth_points,
        frames,
        &params.radius_px,
        &params.calibration,
        &params.smoother,
        min_samples,
    )
    .map_err(|e| Error::input(format!("{}: {e}", truth.display())))
}

/// Reads a BeadTracking CSV and groups its points by bead id, frames increasing; an id given
/// twice in one frame is an error naming the file.
fn read_state_tracks(path: &Path) -> Result<Vec<StateTrack>> {
    let points = read_bead_csv(path)?;
    let mut by_id: BTreeMap<u64, Vec<StatePoint>> = BTreeMap::new();
    for p in points {
        by_id.entry(p.id).or_default().push(StatePoint {
            frame: p.frame,
            pos_px: p.pos_px,
            motion_state: p.motion_state,
        });
    }
    by_id
        .into_iter()
        .map(|(track_id, mut points)| {
            points.sort_by_key(|p| p.frame);
            if let Some(pair) = points.windows(2).find(|w| w[0].frame == w[1].frame) {
                return Err(Error::format(
                    path,
                    None,
                    format!(
                        "bead id {track_id} appears twice in frame {} (the file's numbering); \
                         keep one row per id and frame",
                        pair[0].frame + 1
                    ),
                ));
            }
            Ok(StateTrack { track_id, points })
        })
        .collect()
}

/// How many of `tracks` carry no motion state at all (they add no transition).
fn tracks_without_state(tracks: &[StateTrack]) -> usize {
    tracks
        .iter()
        .filter(|t| {
            t.points
                .iter()
                .all(|p| p.motion_state == MotionState::Unknown)
        })
        .count()
}

/// Everything `sillage fit bedload` learns from its files, and the config text recording it.
#[derive(Debug, Clone)]
pub struct BedloadFitFile {
    /// The motion parameters (`[motion]`) and their report.
    pub fit: BedloadFit,
    /// The smoother's evidence model (`[smoother.emission]`) and its samples, when a tracker's
    /// output was given.
    pub emission: Option<(EmissionParams, EmissionReport)>,
    /// Trajectories in the truth.
    pub tracks: usize,
    /// Trajectories without any motion state.
    pub tracks_without_state: usize,
    /// The TOML text to write.
    pub text: String,
}

/// Learns the motion parameters from `truth` (a BeadTracking CSV with states) and, with
/// `tracks` (`sillage track bedload`'s output on the same frames), the smoother's evidence
/// model on the same training frames, its features averaged over `half_window`
/// (`smoother.half_window`, written beside the model); errors name the file.
pub fn fit_bedload_files(
    truth: &Path,
    tracks: Option<&Path>,
    options: &FitOptions,
    half_window: u32,
) -> Result<BedloadFitFile> {
    let mut params = BedloadTrackerParams::default();
    params.smoother.half_window = half_window;
    let truth_tracks = read_state_tracks(truth)?;
    let without = tracks_without_state(&truth_tracks);
    let fit = fit_bedload(&truth_tracks, &BedloadParams::default(), options)
        .map_err(|e| Error::input(format!("{}: {e}", truth.display())))?;
    let emission = tracks
        .map(|path| {
            fit_smoother(
                truth,
                path,
                fit.report.training_frames,
                &params,
                options.min_samples,
            )
        })
        .transpose()?;
    let text = config_text(
        truth,
        options,
        &fit,
        truth_tracks.len(),
        without,
        tracks
            .zip(emission.as_ref())
            .map(|(p, (m, r))| (p, half_window, m, r)),
    )?;
    Ok(BedloadFitFile {
        fit,
        emission,
        tracks: truth_tracks.len(),
        tracks_without_state: without,
        text,
    })
}

/// The TOML file of `fit`: comment lines saying where the values come from (the `truth`
/// file, its `tracks`, the fit `options`), then `[motion]`.
fn config_text(
    truth: &Path,
    options: &FitOptions,
    fit: &BedloadFit,
    tracks: usize,
    tracks_without_state: usize,
    emission: Option<(&Path, u32, &EmissionParams, &EmissionReport)>,
) -> Result<String> {
    let r = &fit.report;
    let mut text = String::new();
    let mut line = |s: String| {
        text.push_str("# ");
        text.push_str(&s);
        text.push('\n');
    };
    line(format!(
        "Bedload motion parameters (MMPF+ Eq. (3) process noises, Eqs. (11)-(12) transition \
         table), by `sillage fit bedload` (sillage {}).",
        env!("CARGO_PKG_VERSION")
    ));
    line(format!("source: {}", truth.display()));
    line(format!(
        "{tracks} tracks ({tracks_without_state} without any motion state); frames {}..={} \
         (0-based), trained on {}..={} (--train-fraction {})",
        r.frame_range[0],
        r.frame_range[1],
        r.training_frames[0],
        r.training_frames[1],
        options.train_fraction
    ));
    line(format!(
        "--min-probability {} (each fitted row floored, then renormalised); --min-samples {}",
        options.min_probability, options.min_samples
    ));
    line(format!(
        "residuals per state (step t-1 -> t, by the state at t): {} (saltating: {} rebound)",
        per_state(|s| r.samples[s].to_string()),
        r.rebound_samples
    ));
    line(format!(
        "mean residual, px (zero-mean noises expected): {}",
        per_state(|s| r.mean_residual_px[s].map_or("none".into(), show_vec))
    ));
    line("transition counts, rows from / columns to (resting, rolling, saltating):".into());
    for (s, row) in r.transition_counts.iter().enumerate() {
        line(format!("  {:<9} {row:?}", STATE_NAMES[s]));
    }
    line(if r.kept.is_empty() {
        "kept from the defaults: none".into()
    } else {
        format!(
            "kept from the defaults (fewer than {} samples): {}",
            options.min_samples,
            r.kept.join(", ")
        )
    });
    line(
        "velocity noises equal the position noises (finite-difference velocities); the other \
         keys are the defaults: set flow_vel_px_per_frame for your sequence"
            .into(),
    );
    if let Some((tracks_file, half_window, _, report)) = emission {
        line(format!(
            "[smoother.emission] from the tracker's points of {} paired with the truth in the \
             training frames, averaged over ±{half_window} frames: {} ({} unpaired)",
            tracks_file.display(),
            per_state(|s| report.samples[s].to_string()),
            report.unpaired
        ));
    }
    let body = toml::to_string(&ConfigFile {
        motion: &fit.params,
        smoother: emission.map(|(_, half_window, emission, _)| SmootherSection {
            half_window,
            emission,
        }),
    })
    .map_err(|e| Error::input(format!("cannot write the fitted parameters as TOML: {e}")))?;
    Ok(format!("{text}\n{body}"))
}

/// `resting A, rolling B, saltating C`.
fn per_state(value: impl Fn(usize) -> String) -> String {
    (0..3)
        .map(|s| format!("{} {}", STATE_NAMES[s], value(s)))
        .collect::<Vec<_>>()
        .join(", ")
}

fn show_vec(v: Vec2) -> String {
    format!("({:.3}, {:.3})", v.x, v.y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_id_twice_in_a_frame_is_refused_and_stateless_tracks_counted() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("truth.csv");
        let header = "frame,id,x,y,category,vx,vy,motion_state\n";
        std::fs::write(
            &path,
            format!("{header}1,1,5,5,0,0,0,0\n2,1,6,5,0,0,0,1\n1,2,9,9,1,0,0,3\n"),
        )
        .unwrap();
        let tracks = read_state_tracks(&path).unwrap();
        assert_eq!(tracks.len(), 2);
        assert_eq!(tracks_without_state(&tracks), 1);
        std::fs::write(&path, format!("{header}1,4,5,5,0,0,0,0\n1,4,6,5,0,0,0,0\n")).unwrap();
        let err = read_state_tracks(&path).unwrap_err().to_string();
        assert!(err.contains("bead id 4 appears twice in frame 1"), "{err}");
    }
}

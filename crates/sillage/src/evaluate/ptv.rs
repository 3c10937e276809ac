//! The TracTrac paper's accuracy indexes of a track table against a truth CSV.

use std::path::Path;

use sillage_core::Result;
use sillage_eval::ptv::{PtvAccuracy, PtvAccuracyParams, ptv_accuracy};
use sillage_io::{TrackFormat, read_tracks, read_truth_csv};

/// The true and false recovery rates and the position and displacement errors (TracTrac
/// §4.1.2, Fig. 4) of the tracks in `tracks` (format from its extension) against the truth
/// CSV `truth`.
pub fn ptv_accuracy_of_files(
    truth: &Path,
    tracks: &Path,
    params: &PtvAccuracyParams,
) -> Result<PtvAccuracy> {
    let truth = read_truth_csv(truth)?;
    let tracks = read_tracks(tracks, TrackFormat::from_path(tracks)?)?;
    ptv_accuracy(&truth, &tracks, params)
}

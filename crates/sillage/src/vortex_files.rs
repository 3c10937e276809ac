//! The synthetic vortex flow of the TracTrac paper (Eqs. 13-16) written to disk: frames as
//! 16-bit PNG and the ground truth as CSV (`sillage synth vortex`, `sillage demo`).

use std::path::{Path, PathBuf};

use sillage_core::Result;
use sillage_io::{TruthCsvWriter, write_png16};
use sillage_synth::vortex::{VortexParams, VortexSequence};

use crate::folders::create_folder;

/// Where frame `index` of a generated sequence is written.
fn frame_path(dir: &Path, index: u64) -> PathBuf {
    dir.join(format!("frame_{index:05}.png"))
}

/// Writes the sequence of `params` into `dir`: `frame_NNNNN.png` and `truth.csv`; `on_frame`
/// is called after each frame (progress bars). Returns the truth file's path.
pub fn write_vortex(
    params: &VortexParams,
    dir: &Path,
    on_frame: &mut dyn FnMut(),
) -> Result<PathBuf> {
    create_folder(dir)?;
    let truth_path = dir.join("truth.csv");
    let mut truth = TruthCsvWriter::create(&truth_path)?;
    for frame in VortexSequence::new(params.clone())? {
        write_png16(frame_path(dir, frame.index), &frame.image)?;
        truth.push(&frame.truth)?;
        on_frame();
    }
    truth.finish()?;
    Ok(truth_path)
}

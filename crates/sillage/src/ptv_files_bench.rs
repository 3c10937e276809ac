//! `sillage bench ptv --files`: the whole path from frame files to a track file, per stage —
//! decoding, detection, tracking, writing — and the wall time of the whole run, for each
//! output format, so that the budget of a real run can be watched (issue "Speed end to end").

use std::path::Path;
use std::time::Instant;

use serde::Serialize;
use sillage_core::{Error, Result, TrackPoint};
use sillage_io::{FrameOptions, TrackFileHeader, TrackFormat, create_track_writer, open_frames};

use crate::config::PipelineConfig;
use crate::ptv_run::PtvRun;

/// The stages of one run from files to files, ms per frame.
#[derive(Debug, Clone, Serialize)]
pub struct PtvFilesRow {
    /// The output format.
    pub format: &'static str,
    /// Frames run.
    pub frames: u64,
    /// Track points written.
    pub points: u64,
    /// Decoding the frames alone (one reading thread, nothing else running), ms per frame.
    pub decode_ms: f64,
    /// Detection (pre-processing included) in the run, ms per frame: wall time on its own
    /// thread, overlapped with tracking, so the two can add up to more than the wall.
    pub detect_ms: f64,
    /// Tracking in the run, ms per frame (handing the points to the writing thread included;
    /// overlapped with the next frame's detection).
    pub track_ms: f64,
    /// Writing the run's points alone in this format (formatting, compressing, the file),
    /// ms per frame.
    pub write_ms: f64,
    /// The whole run: opening (the first frame measured), decoding, detection, tracking and
    /// writing overlapped on their threads, until the file is complete, ms per frame.
    pub wall_ms: f64,
}

/// Runs the PTV pipeline of `config` on the frames of `input` into a file of each of
/// `formats`, and times each stage. The runs are whole runs as `sillage ptv` makes them, into
/// a scratch folder of the system's temporary folder removed afterwards; decoding and writing
/// are also timed alone, on the same frames and points.
pub fn bench_ptv_files(
    config: &PipelineConfig,
    input: &str,
    formats: &[TrackFormat],
) -> Result<Vec<PtvFilesRow>> {
    let scratch = std::env::temp_dir().join(format!("sillage-bench-ptv-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).map_err(|e| {
        Error::input(format!(
            "{}: cannot create the scratch folder: {e}",
            scratch.display()
        ))
    })?;
    let rows = bench_into(config, input, &scratch, formats);
    // The runs' files are removed with their folder, whatever the outcome.
    let _ = std::fs::remove_dir_all(&scratch);
    rows
}

/// [`bench_ptv_files`] with its files in `out_dir`.
fn bench_into(
    config: &PipelineConfig,
    input: &str,
    out_dir: &Path,
    formats: &[TrackFormat],
) -> Result<Vec<PtvFilesRow>> {
    let start = Instant::now();
    let mut decoded = 0u64;
    for frame in open_frames(input, &FrameOptions::default())? {
        frame?;
        decoded += 1;
    }
    let decode_ms = ms_per_frame(start.elapsed().as_secs_f64(), decoded);
    let mut points: Vec<TrackPoint> = Vec::new();
    let collect = PtvRun::open(config, input)?;
    let header = collect.header().clone();
    collect.run(&mut points, &mut |_| {})?;
    let mut rows = Vec::new();
    for &format in formats {
        let out = out_dir.join(format!("bench_tracks.{}", format.extension()));
        let write_ms = time_writing(&points, &out, format, &header, decoded)?;
        let start = Instant::now();
        let run = PtvRun::open(config, input)?.run_to_file(&out, format, &mut |_| {})?;
        let wall = start.elapsed().as_secs_f64();
        rows.push(PtvFilesRow {
            format: format.name(),
            frames: run.summary.frames,
            points: run.written.rows,
            decode_ms,
            detect_ms: run.summary.detect_ms_per_frame,
            track_ms: run.summary.track_ms_per_frame,
            write_ms,
            wall_ms: ms_per_frame(wall, run.summary.frames),
        });
    }
    Ok(rows)
}

/// Writes `points` frame by frame (the batches a run hands over) to `out` on this thread;
/// ms per frame of `frames`.
fn time_writing(
    points: &[TrackPoint],
    out: &Path,
    format: TrackFormat,
    header: &TrackFileHeader,
    frames: u64,
) -> Result<f64> {
    let start = Instant::now();
    let mut writer = create_track_writer(out, format, header)?;
    for batch in points.chunk_by(|a, b| a.frame == b.frame) {
        writer.accept(batch)?;
    }
    writer.finish()?;
    Ok(ms_per_frame(start.elapsed().as_secs_f64(), frames))
}

fn ms_per_frame(seconds: f64, frames: u64) -> f64 {
    1e3 * seconds / frames.max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vortex_files::write_vortex;
    use sillage_synth::vortex::VortexParams;

    #[test]
    fn every_stage_is_timed_for_every_format() {
        let dir = tempfile::tempdir().unwrap();
        let frames = dir.path().join("frames");
        let params = VortexParams {
            width: 128,
            height: 128,
            n_particles: 60,
            n_frames: 6,
            ..VortexParams::default()
        };
        write_vortex(&params, &frames, &mut || {}).unwrap();
        let formats = [TrackFormat::Tractrac, TrackFormat::Csv];
        let input = format!("{}/*.png", frames.display());
        let rows = bench_ptv_files(&PipelineConfig::default(), &input, &formats).unwrap();
        assert_eq!(rows.len(), 2);
        for row in &rows {
            assert_eq!(row.frames, 6);
            assert!(row.points > 0);
            for ms in [
                row.decode_ms,
                row.detect_ms,
                row.track_ms,
                row.write_ms,
                row.wall_ms,
            ] {
                assert!(ms.is_finite() && ms > 0.0, "{row:?}");
            }
        }
        // The scratch folder is gone; the frames stay.
        let scratch =
            std::env::temp_dir().join(format!("sillage-bench-ptv-{}", std::process::id()));
        assert!(!scratch.exists());
        assert!(frames.exists());
    }
}

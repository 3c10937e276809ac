//! `sillage bench ptv`: detection and tracking time per frame on synthetic vortex frames, and
//! the process's peak memory, for one (frame size, particle count) case at a time; and a long
//! streaming run that shows the memory stays flat.

use std::path::PathBuf;

use serde::Serialize;
use sillage_core::{DiscardSink, Result};
use sillage_io::Frame;
use sillage_synth::vortex::{VortexParams, VortexSequence};
use sillage_track::ptv::DEFAULT_WARM_UP_FRAMES;

use crate::config::PipelineConfig;
use crate::pipeline::{FrameInput, Pipeline};
use crate::process_memory::{peak_rss_mib, rss_mib};

/// Frames run before timing starts: the tracker's warm-up (its first frames tracked twice,
/// [`DEFAULT_WARM_UP_FRAMES`], a cost paid once per run) and three more, so that the timed
/// frames are the steady state of a long run.
const WARM_UP_FRAMES: usize = DEFAULT_WARM_UP_FRAMES + 3;

/// One row of the table.
#[derive(Debug, Clone, Serialize)]
pub struct PtvBenchRow {
    /// Frame width and height, px.
    pub size_px: usize,
    /// Particles in the flow.
    pub particles: usize,
    /// Frames timed (after the warm-up).
    pub frames_timed: usize,
    /// Mean detections per timed frame.
    pub detections_per_frame: f64,
    /// Mean track points emitted per timed frame.
    pub points_per_frame: f64,
    /// Mean detection time, ms.
    pub detect_ms_per_frame: f64,
    /// Mean tracking time, ms.
    pub track_ms_per_frame: f64,
    /// Their sum, ms.
    pub total_ms_per_frame: f64,
    /// Peak resident memory of the process so far, MiB (Linux only).
    pub peak_rss_mib: Option<f64>,
}

/// Synthetic vortex frames rendered on the fly, as the pipeline's frame stream.
fn vortex_frames(
    size: usize,
    particles: usize,
    frames: usize,
) -> Result<impl Iterator<Item = Result<Frame>>> {
    let params = VortexParams {
        width: size,
        height: size,
        n_particles: particles,
        n_frames: frames,
        ..VortexParams::default()
    };
    Ok(VortexSequence::new(params)?.map(|f| {
        Ok(Frame {
            index: f.index,
            path: PathBuf::from(format!("synthetic:{}", f.index)),
            image: f.image,
            colour: None,
        })
    }))
}

/// Times one (size, particles) case over `frames` frames. Frames are rendered on the fly
/// (rendering is not timed), so the peak memory is that of a streaming run. Track points are
/// dropped, so "track" times the linking itself, not the growth of an in-memory table (which
/// cost ~5 ms per frame at 25,000 particles when the points were collected into a `Vec`).
/// Frames are stepped one by one ([`Pipeline::step`]), so each stage is timed alone; a whole
/// run ([`Pipeline::run`]) overlaps them.
pub fn bench_ptv_case(size: usize, particles: usize, frames: usize) -> Result<PtvBenchRow> {
    let mut pipeline = Pipeline::from_config(&PipelineConfig::default())?;
    let (mut detect_ms, mut track_ms, mut detections, mut points) = (0.0, 0.0, 0usize, 0usize);
    for frame in vortex_frames(size, particles, frames + WARM_UP_FRAMES)? {
        let report = pipeline.step(&FrameInput::Image(frame?), &mut DiscardSink)?;
        if report.frame as usize >= WARM_UP_FRAMES {
            detect_ms += report.detect_time.as_secs_f64() * 1e3;
            track_ms += report.track_time.as_secs_f64() * 1e3;
            detections += report.detections;
            points += report.points_emitted;
        }
    }
    pipeline.finish(&mut DiscardSink)?;
    let n = frames.max(1) as f64;
    Ok(PtvBenchRow {
        size_px: size,
        particles,
        frames_timed: frames,
        detections_per_frame: detections as f64 / n,
        points_per_frame: points as f64 / n,
        detect_ms_per_frame: detect_ms / n,
        track_ms_per_frame: track_ms / n,
        total_ms_per_frame: (detect_ms + track_ms) / n,
        peak_rss_mib: peak_rss_mib(),
    })
}

/// A long streaming run of `frames` frames whose track points are dropped (as a file writer
/// would after writing); every tenth of the way `on_sample(frames done, resident MiB)` is
/// called, to show the memory stays flat whatever the sequence length.
pub fn stream_memory(
    size: usize,
    particles: usize,
    frames: usize,
    on_sample: &mut dyn FnMut(usize, Option<f64>),
) -> Result<()> {
    let mut pipeline = Pipeline::from_config(&PipelineConfig::default())?;
    let step = (frames / 10).max(1);
    pipeline.run(
        vortex_frames(size, particles, frames)?,
        &mut DiscardSink,
        &mut |report| {
            let done = report.frame as usize + 1;
            if done.is_multiple_of(step) {
                on_sample(done, rss_mib());
            }
        },
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_case_is_timed_and_a_stream_is_sampled_every_tenth() {
        let row = bench_ptv_case(128, 50, 2).unwrap();
        assert_eq!((row.size_px, row.particles, row.frames_timed), (128, 50, 2));
        assert!(row.detections_per_frame > 0.0, "{row:?}");
        assert!(
            (row.total_ms_per_frame - row.detect_ms_per_frame - row.track_ms_per_frame).abs()
                < 1e-9
        );
        let mut samples = Vec::new();
        stream_memory(128, 50, 20, &mut |done, _| samples.push(done)).unwrap();
        assert_eq!(samples, (1..=10).map(|i| 2 * i).collect::<Vec<_>>());
    }
}

//! A million frames without files: a synthetic source streamed through PTV (the paper's
//! vortex, its particles' positions as detections) or MMPF+ (the synthetic bedload scene
//! through its detector model, candidates included), with the resident memory and the
//! throughput sampled along the way and every track id checked never to come back once its
//! trajectory has ended (`sillage bench stream`).

use std::collections::HashMap;
use std::time::Instant;

use serde::Serialize;
use sillage_core::{Detection, Error, FrameIndex, Result, TrackPoint, TrackSink};
use sillage_synth::bedload::{BedloadDetectionParams, BedloadSceneParams, BedloadSequence};
use sillage_synth::vortex::{VortexFlow, VortexParams};

use crate::config::{PipelineConfig, TrackerConfig};
use crate::pipeline::{FrameInput, Pipeline};
use crate::process_memory::rss_mib;

/// The tracker a stream runs through.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum StreamTracker {
    /// PTV on 500 particles of the paper's vortex (512² px), fed their positions.
    Ptv,
    /// MMPF+ on the synthetic bedload scene's detections and candidates.
    Bedload,
}

/// One sample of a stream.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct StreamSample {
    /// Frames tracked so far.
    pub frames: u64,
    /// Resident memory now, MiB (`None` off Linux).
    pub rss_mib: Option<f64>,
    /// Frames per second since the previous sample.
    pub frames_per_s: f64,
    /// Track points emitted so far.
    pub points: u64,
    /// Distinct track ids so far.
    pub tracks: u64,
}

/// Track ids that end never come back: a point's id is one seen within the last
/// [`ID_GAP_FRAMES`] frames (at a later frame than its last point), or one never seen. Ids
/// are handed out in increasing order, so "never seen" is checked against the highest id of
/// the trajectories that ended (silent for [`ID_GAP_FRAMES`]), in bounded memory; the
/// smoother's lag may emit a new trajectory's first point a few frames late, far within it.
struct IdCheck {
    last_frame: HashMap<u64, FrameIndex>,
    max_ended_id: Option<u64>,
    points: u64,
    tracks: u64,
    latest_frame: FrameIndex,
}

/// Frames after which a silent id counts as ended (the bedload trackers coast through at
/// most a few tens of missed frames; PTV ids end at their first missing frame).
const ID_GAP_FRAMES: u64 = 1_000;

impl IdCheck {
    fn new() -> Self {
        Self {
            last_frame: HashMap::new(),
            max_ended_id: None,
            points: 0,
            tracks: 0,
            latest_frame: 0,
        }
    }

    /// Forgets the ids silent for [`ID_GAP_FRAMES`]: memory stays bounded.
    fn forget_ended(&mut self) {
        let horizon = self.latest_frame.saturating_sub(ID_GAP_FRAMES);
        let max_ended = &mut self.max_ended_id;
        self.last_frame.retain(|&id, &mut last| {
            let active = last >= horizon;
            if !active {
                *max_ended = Some(max_ended.map_or(id, |m| m.max(id)));
            }
            active
        });
    }
}

impl TrackSink for IdCheck {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        for p in points {
            self.latest_frame = self.latest_frame.max(p.frame);
            match self.last_frame.get_mut(&p.track_id) {
                Some(last) if p.frame > *last => *last = p.frame,
                Some(last) => {
                    return Err(Error::input(format!(
                        "track {} has a point at frame {} after one at frame {last}",
                        p.track_id, p.frame
                    )));
                }
                None if self.max_ended_id.is_none_or(|m| p.track_id > m) => {
                    self.tracks += 1;
                    self.last_frame.insert(p.track_id, p.frame);
                }
                None => {
                    return Err(Error::input(format!(
                        "track id {} came back at frame {} after its trajectory ended",
                        p.track_id, p.frame
                    )));
                }
            }
        }
        self.points += points.len() as u64;
        Ok(())
    }
}

/// The frames of `tracker`'s synthetic source, as pipeline inputs.
fn source(tracker: StreamTracker, frames: usize) -> Result<Box<dyn Iterator<Item = FrameInput>>> {
    Ok(match tracker {
        StreamTracker::Ptv => {
            let params = VortexParams {
                n_particles: 500,
                width: 512,
                height: 512,
                ..VortexParams::default()
            };
            let mut flow = VortexFlow::new(&params)?;
            let mut first = true;
            Box::new((0..frames).map(move |_| {
                if !std::mem::take(&mut first) {
                    flow.advance();
                }
                FrameInput::Detections {
                    frame: flow.frame(),
                    detections: flow
                        .positions()
                        .iter()
                        .map(|&p| Detection::new(p, 1.0))
                        .collect(),
                    candidates: Vec::new(),
                }
            }))
        }
        StreamTracker::Bedload => {
            // Half the default flume's width, half its bed layers, a quarter of its
            // transparent beads (the scene's minimum for these layers).
            let scene = BedloadSceneParams {
                n_frames: frames,
                width: 640,
                bed_layers: 4,
                n_black: 110,
                n_transparent: 25,
                ..BedloadSceneParams::default()
            };
            let sequence = BedloadSequence::new(scene, BedloadDetectionParams::default())?;
            Box::new(sequence.enumerate().map(|(frame, sample)| {
                let observed = sample.observation.observations();
                FrameInput::Detections {
                    frame: frame as FrameIndex,
                    detections: observed.detections.to_vec(),
                    candidates: observed.candidates.to_vec(),
                }
            }))
        }
    })
}

/// Streams `frames` frames through `tracker`, calling `on_sample` `samples` times evenly
/// along the way (and at the end); errors if a track id comes back after its trajectory
/// ended.
pub fn stream_frames(
    tracker: StreamTracker,
    frames: usize,
    samples: usize,
    on_sample: &mut dyn FnMut(&StreamSample),
) -> Result<StreamSample> {
    let config = PipelineConfig {
        tracker: match tracker {
            StreamTracker::Ptv => PipelineConfig::default().tracker,
            StreamTracker::Bedload => TrackerConfig::Bedload(Box::default()),
        },
        ..PipelineConfig::default()
    };
    let mut pipeline = Pipeline::from_config(&config)?;
    let every = (frames / samples.max(1)).max(1) as u64;
    let mut ids = IdCheck::new();
    let mut since = (Instant::now(), 0u64);
    let mut last = None;
    for (n, input) in source(tracker, frames)?.enumerate() {
        pipeline.step(&input, &mut ids)?;
        let done = n as u64 + 1;
        if done.is_multiple_of(ID_GAP_FRAMES) {
            ids.forget_ended();
        }
        if done.is_multiple_of(every) || done == frames as u64 {
            let seconds = since.0.elapsed().as_secs_f64();
            let sample = StreamSample {
                frames: done,
                rss_mib: rss_mib(),
                frames_per_s: (done - since.1) as f64 / seconds.max(1e-9),
                points: ids.points,
                tracks: ids.tracks,
            };
            on_sample(&sample);
            last = Some(sample);
            since = (Instant::now(), done);
        }
    }
    pipeline.finish(&mut ids)?;
    last.ok_or_else(|| Error::parameter("frames", 0, "stream at least one frame"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_streams_sample_evenly_and_ids_are_checked() {
        for tracker in [StreamTracker::Ptv, StreamTracker::Bedload] {
            let mut seen = Vec::new();
            let last = stream_frames(tracker, 60, 3, &mut |s| seen.push(s.frames)).unwrap();
            assert_eq!(seen, [20, 40, 60], "{tracker:?}");
            assert!(last.points > 0 && last.tracks > 0, "{last:?}");
        }
        let mut check = IdCheck::new();
        let at = |frame, id| TrackPoint::at(frame, id, sillage_core::Point2::new(0.0, 0.0));
        check.accept(&[at(0, 1), at(0, 2), at(1, 2)]).unwrap();
        check.latest_frame = 5_000;
        check.forget_ended();
        let err = check.accept(&[at(5_000, 1)]).unwrap_err().to_string();
        assert!(err.contains("came back"), "{err}");
    }
}

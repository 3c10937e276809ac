//! The output pass with detection running ahead of tracking: a thread of its own
//! pre-processes and detects the next frames (at most [`AHEAD`] beyond the one in hand) while
//! the tracker steps through the current one, so that the two stages share the cores instead
//! of taking turns. Each stage still sees the frames one by one in their order, as in the
//! frame-by-frame pass ([`Pipeline::step`](super::Pipeline::step)), so the points are the same
//! byte for byte, whatever the number of threads (tests in `tests/pipeline.rs`).

use std::sync::mpsc::{Receiver, Sender, SyncSender, channel, sync_channel};
use std::time::{Duration, Instant};

use sillage_core::{Detection, FrameIndex, FrameObservations, GrayImage, Result, TrackSink};
use sillage_io::Frame;

use super::{AnyTracker, FrameInput, FrameObserver, RunTally, Timings, track_frame};
use crate::detection_stage::DetectionStage;

/// Frames handed to the detection thread beyond the one being tracked, at most: each holds
/// its decoded image (16 MB for a 2048² frame), so memory stays bounded.
const AHEAD: usize = 1;

/// One frame as the detection thread hands it over.
struct Detected {
    index: FrameIndex,
    /// The decoded frame (`None` for detections given as a table).
    frame: Option<Frame>,
    detections: Vec<Detection>,
    candidates: Vec<Detection>,
    /// The pre-processed copy the detector saw (`None`: it saw the frame itself).
    preprocessed: Option<GrayImage>,
    detect_time: Duration,
}

/// Buffers the tracking side hands back to the detection thread for reuse.
#[derive(Default)]
struct Spare {
    detections: Vec<Detection>,
    candidates: Vec<Detection>,
    image: GrayImage,
}

/// Runs the output pass over `inputs` with `stage` detecting on a thread of its own and
/// `tracker` stepping on this one; counts in `tally` and returns the stages' times. An error
/// (of an input, the detection or the tracker) ends the run after the frames before it were
/// tracked, as the frame-by-frame pass does.
pub(super) fn run<S: TrackSink + ?Sized>(
    stage: &mut DetectionStage,
    tracker: &mut AnyTracker,
    inputs: impl Iterator<Item = Result<FrameInput>>,
    sink: &mut S,
    tally: &mut RunTally,
    on_frame: &mut FrameObserver<'_>,
) -> Result<Timings> {
    let (to_detect, frames) = sync_channel(AHEAD);
    let (send_detected, detected) = sync_channel(AHEAD);
    let (give_back, spares) = channel();
    std::thread::scope(|scope| {
        scope.spawn(move || detect_frames(stage, &frames, &send_detected, &spares));
        // The channels' ends move into the tracking side, so that its return closes them and
        // the detection thread stops.
        let ends = Ends {
            to_detect,
            detected,
            give_back,
        };
        ends.track_frames(tracker, inputs, sink, tally, on_frame)
    })
}

/// Detects each frame `frames` delivers and sends it on, until `frames` closes, the tracking
/// side hangs up, or a frame fails (its error is sent).
fn detect_frames(
    stage: &mut DetectionStage,
    frames: &Receiver<FrameInput>,
    detected: &SyncSender<Result<Detected>>,
    spares: &Receiver<Spare>,
) {
    for input in frames {
        let spare = spares.try_recv().unwrap_or_default();
        let result = detect_one(stage, input, spare);
        let failed = result.is_err();
        if detected.send(result).is_err() || failed {
            return;
        }
    }
}

/// Pre-processes and detects one frame (a table's detections pass through as they are).
fn detect_one(stage: &mut DetectionStage, input: FrameInput, spare: Spare) -> Result<Detected> {
    let Spare {
        mut detections,
        mut candidates,
        image,
    } = spare;
    match input {
        FrameInput::Image(frame) => {
            let start = Instant::now();
            stage.detect(&frame, &mut detections)?;
            candidates.clear();
            candidates.extend_from_slice(stage.candidates());
            Ok(Detected {
                index: frame.index,
                preprocessed: stage.take_preprocessed(image),
                frame: Some(frame),
                detections,
                candidates,
                detect_time: start.elapsed(),
            })
        }
        FrameInput::Detections {
            frame,
            detections,
            candidates,
        } => Ok(Detected {
            index: frame,
            frame: None,
            detections,
            candidates,
            preprocessed: None,
            detect_time: Duration::ZERO,
        }),
    }
}

/// The tracking side's ends of the channels.
struct Ends {
    to_detect: SyncSender<FrameInput>,
    detected: Receiver<Result<Detected>>,
    give_back: Sender<Spare>,
}

impl Ends {
    /// Feeds `inputs` to the detection thread, keeping it up to [`AHEAD`] frames ahead, and
    /// tracks what comes back in order.
    fn track_frames<S: TrackSink + ?Sized>(
        self,
        tracker: &mut AnyTracker,
        inputs: impl Iterator<Item = Result<FrameInput>>,
        sink: &mut S,
        tally: &mut RunTally,
        on_frame: &mut FrameObserver<'_>,
    ) -> Result<Timings> {
        let mut inputs = inputs.fuse();
        let mut timings = Timings::default();
        let (mut in_flight, mut input_error, mut detecting) = (0, None, true);
        loop {
            while detecting && in_flight <= AHEAD && input_error.is_none() {
                match inputs.next() {
                    // A closed channel: the detection thread stopped at an error, which
                    // waits among the results.
                    Some(Ok(input)) => match self.to_detect.send(input) {
                        Ok(()) => in_flight += 1,
                        Err(_) => detecting = false,
                    },
                    Some(Err(e)) => input_error = Some(e),
                    None => break,
                }
            }
            if in_flight == 0 {
                break;
            }
            in_flight -= 1;
            let Ok(next) = self.detected.recv() else {
                break;
            };
            let Detected {
                index,
                frame,
                detections,
                candidates,
                preprocessed,
                detect_time,
            } = next?;
            let image = frame
                .as_ref()
                .map(|f| preprocessed.as_ref().unwrap_or(&f.image));
            let observations = FrameObservations {
                frame: index,
                detections: &detections,
                image,
                candidates: &candidates,
            };
            let report = track_frame(tracker, &observations, detect_time, sink, tally, on_frame)?;
            timings.add(&report);
            // Reused when the detection thread is still running; dropped otherwise.
            let _ = self.give_back.send(Spare {
                detections,
                candidates,
                image: preprocessed.unwrap_or_default(),
            });
        }
        input_error.map_or(Ok(timings), Err)
    }
}

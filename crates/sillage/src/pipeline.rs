//! The composition root: frames → pre-processing → detector → tracker → sink.

use std::time::{Duration, Instant};

use sillage_core::{
    Detection, DiscardSink, Error, FrameIndex, FrameObservations, Result, TrackPoint, TrackSink,
    Tracker,
};
use sillage_io::Frame;
use sillage_track::ptv::{PassDirection, PtvTracker};

use crate::config::{PipelineConfig, TrackerConfig};
use crate::detection_stage::DetectionStage;

/// The built-in trackers, chosen by [`TrackerConfig`].
enum AnyTracker {
    Ptv(PtvTracker),
}

impl AnyTracker {
    fn as_tracker(&mut self) -> &mut dyn Tracker {
        match self {
            AnyTracker::Ptv(t) => t,
        }
    }

    fn start_pass(&mut self, direction: PassDirection) {
        match self {
            AnyTracker::Ptv(t) => t.start_pass(direction),
        }
    }
}

/// One frame given to [`Pipeline::step`]: an image to detect in, or detections made
/// elsewhere.
#[derive(Debug, Clone)]
pub enum FrameInput {
    /// A decoded frame: pre-processed, detected, and shown to the tracker.
    Image(Frame),
    /// The detections of one frame (a detections table): tracked as they are.
    Detections {
        /// The frame's index.
        frame: FrameIndex,
        /// Its detections.
        detections: Vec<Detection>,
    },
}

impl FrameInput {
    /// The frame's index.
    pub fn index(&self) -> FrameIndex {
        match self {
            FrameInput::Image(frame) => frame.index,
            FrameInput::Detections { frame, .. } => *frame,
        }
    }
}

/// What one frame cost and produced.
#[derive(Debug, Clone, Copy, Default)]
pub struct FrameReport {
    /// The frame's index.
    pub frame: FrameIndex,
    /// Objects detected in it.
    pub detections: usize,
    /// Track points emitted while processing it (points of earlier frames that became final).
    pub points_emitted: usize,
    /// Wall time of pre-processing and detection.
    pub detect_time: Duration,
    /// Wall time of the tracker's step.
    pub track_time: Duration,
}

/// Totals of a whole run.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct RunSummary {
    /// Frames processed in the output pass.
    pub frames: u64,
    /// Detections over all frames.
    pub detections: u64,
    /// Track points written.
    pub points: u64,
    /// Distinct trajectories among them.
    pub tracks: u64,
    /// Mean wall time of pre-processing + detection per frame, ms.
    pub detect_ms_per_frame: f64,
    /// Mean wall time of tracking per frame, ms.
    pub track_ms_per_frame: f64,
}

/// A configured detector and tracker, fed one frame at a time.
pub struct Pipeline {
    stage: DetectionStage,
    tracker: AnyTracker,
    training_passes: usize,
    detections: Vec<Detection>,
}

/// Counts what passes through to the real sink, so the run summary needs no second look.
struct CountingSink<'a> {
    inner: &'a mut dyn TrackSink,
    points: u64,
    max_track_id: Option<u64>,
    track_ids_seen: u64,
}

impl<'a> CountingSink<'a> {
    fn new(inner: &'a mut dyn TrackSink) -> Self {
        Self {
            inner,
            points: 0,
            max_track_id: None,
            track_ids_seen: 0,
        }
    }
}

impl TrackSink for CountingSink<'_> {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        for p in points {
            // Track ids are handed out in increasing order, so a new maximum is a new track.
            if self.max_track_id.is_none_or(|m| p.track_id > m) {
                self.max_track_id = Some(p.track_id);
                self.track_ids_seen += 1;
            }
        }
        self.points += points.len() as u64;
        self.inner.accept(points)
    }
}

impl Pipeline {
    /// Builds the pipeline of `config` (validated here; the mask image is read here).
    pub fn from_config(config: &PipelineConfig) -> Result<Self> {
        config.validate()?;
        let tracker = match &config.tracker {
            TrackerConfig::Ptv(params) => AnyTracker::Ptv(PtvTracker::new(params.clone())?),
        };
        Ok(Self {
            stage: DetectionStage::from_config(config)?,
            tracker,
            training_passes: config.training_passes,
            detections: Vec::new(),
        })
    }

    /// How many leading frames [`Pipeline::prime_background`] wants (0 without background
    /// subtraction).
    pub fn background_init_frames(&self) -> usize {
        self.stage.background_init_frames()
    }

    /// Initialises the background model from the mean of the first frames, as TracTrac does
    /// (Eq. (2)), before [`Pipeline::run`]. Pass the sequence's leading frames (a second
    /// opening of the source); at most [`Pipeline::background_init_frames`] are read, one at a
    /// time. Returns how many were used. Without priming, the background starts as the running
    /// mean of the frames seen so far.
    pub fn prime_background(
        &mut self,
        frames: impl Iterator<Item = Result<Frame>>,
    ) -> Result<usize> {
        let mut used = 0;
        for frame in frames.take(self.background_init_frames()) {
            let frame = frame?;
            used += self.stage.prime_background(std::iter::once(&frame.image))?;
        }
        Ok(used)
    }

    /// Pre-processes and detects one frame; the detections stay in `self.detections`.
    fn detect(&mut self, frame: &Frame) -> Result<Duration> {
        let start = Instant::now();
        self.stage.detect(frame, &mut self.detections)?;
        Ok(start.elapsed())
    }

    /// Pre-processes and detects one frame without tracking it (`sillage detect`, Python's
    /// `locate`): the detections, valid until the next call. Background subtraction, when
    /// configured, learns from the frames in the order they are given.
    pub fn locate(&mut self, frame: &Frame) -> Result<&[Detection]> {
        self.detect(frame)?;
        Ok(&self.detections)
    }

    /// Fills `self.detections` from `input`: detected in its image, or copied from it.
    fn observe(&mut self, input: &FrameInput) -> Result<Duration> {
        match input {
            FrameInput::Image(frame) => self.detect(frame),
            FrameInput::Detections { detections, .. } => {
                self.detections.clone_from(detections);
                Ok(Duration::ZERO)
            }
        }
    }

    /// Runs the whole sequence: training passes first if configured, then the output pass that
    /// feeds `sink`. `on_frame` is called after every frame of the output pass (progress bars).
    pub fn run(
        &mut self,
        frames: impl Iterator<Item = Result<Frame>>,
        sink: &mut dyn TrackSink,
        on_frame: &mut dyn FnMut(&FrameReport),
    ) -> Result<RunSummary> {
        self.run_inputs(frames.map(|f| f.map(FrameInput::Image)), sink, on_frame)
    }

    /// [`Pipeline::run`] on detections made elsewhere (a detections table): the configured
    /// detector and pre-processing are skipped, the tracker sees no image. Frames are tracked
    /// in the order given; leave an empty frame where a frame has no detection, or the tracker
    /// links across the gap.
    pub fn run_detections(
        &mut self,
        frames: impl Iterator<Item = Result<(FrameIndex, Vec<Detection>)>>,
        sink: &mut dyn TrackSink,
        on_frame: &mut dyn FnMut(&FrameReport),
    ) -> Result<RunSummary> {
        let inputs = frames
            .map(|f| f.map(|(frame, detections)| FrameInput::Detections { frame, detections }));
        self.run_inputs(inputs, sink, on_frame)
    }

    /// The shared body of [`Pipeline::run`] and [`Pipeline::run_detections`].
    fn run_inputs(
        &mut self,
        inputs: impl Iterator<Item = Result<FrameInput>>,
        sink: &mut dyn TrackSink,
        on_frame: &mut dyn FnMut(&FrameReport),
    ) -> Result<RunSummary> {
        let mut counting = CountingSink::new(sink);
        let mut totals = RunSummary::default();
        let (mut detect_time, mut track_time) = (Duration::ZERO, Duration::ZERO);
        let mut add = |report: &FrameReport| {
            detect_time += report.detect_time;
            track_time += report.track_time;
            totals.frames += 1;
            totals.detections += report.detections as u64;
            on_frame(report);
        };
        if self.training_passes == 0 {
            for input in inputs {
                add(&self.step_output_pass(&input?, &mut counting)?);
            }
        } else {
            let cached = self.detect_all(inputs)?;
            self.train(&cached)?;
            self.tracker.start_pass(PassDirection::Forward);
            for (index, detections, detect) in &cached {
                self.detections.clone_from(detections);
                add(&self.track(*index, None, *detect, &mut counting)?);
            }
        }
        self.tracker.as_tracker().finish(&mut counting)?;
        totals.points = counting.points;
        totals.tracks = counting.track_ids_seen;
        if totals.frames > 0 {
            totals.detect_ms_per_frame = detect_time.as_secs_f64() * 1e3 / totals.frames as f64;
            totals.track_ms_per_frame = track_time.as_secs_f64() * 1e3 / totals.frames as f64;
        }
        Ok(totals)
    }

    /// Detects (or takes the detections of) one frame and tracks it, streaming: the points
    /// that became final go to `sink` now, the rest at [`Pipeline::finish`]. For runs that
    /// never hold the whole sequence (Python's `ptv_iter`); training passes need the whole
    /// sequence, so a configuration with `training_passes` > 0 is refused here (use
    /// [`Pipeline::run`]).
    pub fn step(&mut self, input: &FrameInput, sink: &mut dyn TrackSink) -> Result<FrameReport> {
        if self.training_passes > 0 {
            return Err(Error::parameter(
                "training_passes",
                self.training_passes,
                "a streamed run has a single pass; set it to 0 or run the whole sequence at once",
            ));
        }
        self.step_output_pass(input, &mut CountingSink::new(sink))
    }

    /// Flushes the points the tracker still holds at the end of a streamed run
    /// ([`Pipeline::step`]).
    pub fn finish(&mut self, sink: &mut dyn TrackSink) -> Result<()> {
        self.tracker.as_tracker().finish(sink)
    }

    /// One frame of the output pass: observe, then track.
    fn step_output_pass(
        &mut self,
        input: &FrameInput,
        sink: &mut CountingSink<'_>,
    ) -> Result<FrameReport> {
        let detect = self.observe(input)?;
        let frame = match input {
            FrameInput::Image(frame) => Some(frame),
            FrameInput::Detections { .. } => None,
        };
        self.track(input.index(), frame, detect, sink)
    }

    /// Feeds `self.detections` of frame `index` to the tracker, with the image the detector saw
    /// when `frame` is at hand (not in replayed training passes).
    fn track(
        &mut self,
        index: FrameIndex,
        frame: Option<&Frame>,
        detect_time: Duration,
        sink: &mut CountingSink<'_>,
    ) -> Result<FrameReport> {
        let before = sink.points;
        let start = Instant::now();
        let image = frame.map(|frame| self.stage.detector_input(frame));
        let observations = FrameObservations {
            frame: index,
            detections: &self.detections,
            image,
            candidates: &[],
        };
        self.tracker.as_tracker().step(&observations, sink)?;
        Ok(FrameReport {
            frame: index,
            detections: self.detections.len(),
            points_emitted: (sink.points - before) as usize,
            detect_time,
            track_time: start.elapsed(),
        })
    }

    /// First (forward) pass of a trained run: detects every frame, keeps the detections and
    /// trains the tracker on them.
    fn detect_all(
        &mut self,
        inputs: impl Iterator<Item = Result<FrameInput>>,
    ) -> Result<Vec<(FrameIndex, Vec<Detection>, Duration)>> {
        let mut cached = Vec::new();
        self.tracker.start_pass(PassDirection::Forward);
        for input in inputs {
            let input = input?;
            let detect = self.observe(&input)?;
            let observations = FrameObservations::from_detections(input.index(), &self.detections);
            self.tracker
                .as_tracker()
                .step(&observations, &mut DiscardSink)?;
            cached.push((input.index(), self.detections.clone(), detect));
        }
        Ok(cached)
    }

    /// The extra training passes of TracTrac's `vid_loop`: alternately backward and forward
    /// over the cached detections, the motion model carried from pass to pass.
    fn train(&mut self, cached: &[(FrameIndex, Vec<Detection>, Duration)]) -> Result<()> {
        for pass in 1..self.training_passes {
            let backward = pass % 2 == 1;
            let direction = if backward {
                PassDirection::Backward
            } else {
                PassDirection::Forward
            };
            self.tracker.start_pass(direction);
            let mut feed = |(index, detections, _): &(FrameIndex, Vec<Detection>, Duration)| {
                let observations = FrameObservations::from_detections(*index, detections);
                self.tracker
                    .as_tracker()
                    .step(&observations, &mut DiscardSink)
            };
            if backward {
                cached.iter().rev().try_for_each(&mut feed)?;
            } else {
                cached.iter().try_for_each(&mut feed)?;
            }
        }
        Ok(())
    }
}

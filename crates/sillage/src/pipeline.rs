//! The composition root: frames → pre-processing → detector → tracker → sink.

mod overlap;

use std::time::{Duration, Instant};

use sillage_core::{
    Detection, DiscardSink, Error, FrameIndex, FrameObservations, Result, TrackPoint, TrackSink,
    Tracker,
};
use sillage_detect::blob::Calibration;
use sillage_detect::{ParticleImages, Preprocessor};
use sillage_io::Frame;
use sillage_track::bedload::{BedloadStats, BedloadTracker};
use sillage_track::ptv::{PassDirection, PtvTracker};

use crate::config::{PipelineConfig, TrackerConfig};
use crate::detection_stage::DetectionStage;

/// The built-in trackers, chosen by [`TrackerConfig`].
#[derive(Clone, serde::Serialize, serde::Deserialize)]
enum AnyTracker {
    Ptv(PtvTracker),
    Bedload(BedloadTracker),
}

impl AnyTracker {
    fn as_tracker(&mut self) -> &mut dyn Tracker {
        match self {
            AnyTracker::Ptv(t) => t,
            AnyTracker::Bedload(t) => t,
        }
    }

    /// Starts a training pass; only PTV trains (the configuration refuses training passes
    /// for the others).
    fn start_pass(&mut self, direction: PassDirection) {
        match self {
            AnyTracker::Ptv(t) => t.start_pass(direction),
            AnyTracker::Bedload(_) => {}
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
        /// Its detector-confidence candidates (Eq. (1) of the MMPF+ paper), empty when the
        /// detector made none.
        candidates: Vec<Detection>,
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
    /// Detector-confidence candidates shown to the tracker with them.
    pub candidates: usize,
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
    /// Detector-confidence candidates over all frames (bedload trackers).
    pub candidates: u64,
    /// Track points written.
    pub points: u64,
    /// Distinct trajectories among them.
    pub tracks: u64,
    /// Mean wall time of pre-processing + detection per frame, ms (in a whole run, on its own
    /// thread while the previous frame is tracked: the two stages overlap).
    pub detect_ms_per_frame: f64,
    /// Mean wall time of tracking per frame, ms.
    pub track_ms_per_frame: f64,
    /// The blob detector's scale and polarity and, when `"auto"`, what was measured on the
    /// first frame to choose them; `None` for other detectors.
    pub detector: Option<Calibration>,
    /// PTV with `vote_search_px = "auto"`: the displacement measured on the first two frames
    /// (95th percentile, px).
    pub measured_displacement_px: Option<f64>,
    /// PTV with `vote_search_px = "auto"`: the share of the points whose cell of that first
    /// vote found its own displacement; below `AUTO_VOTE_MIN_VALID_SHARE` (0.5) the vote was
    /// used only if the displacements reached a spacing.
    pub vote_valid_share: Option<f64>,
    /// PTV: displacement voting's search radius in use at the end of the run (`None`: off).
    pub vote_search_px: Option<f64>,
    /// PTV: the points among `points` that the outlier test rejected and that were written
    /// because their trajectories vouch for them (`tracker.restore_flanked`); `None` for
    /// other trackers.
    pub restored_points: Option<u64>,
}

/// Wall time spent per stage over the frames of a run.
#[derive(Debug, Default)]
struct Timings {
    frames: u64,
    detect: Duration,
    track: Duration,
}

impl Timings {
    fn add(&mut self, report: &FrameReport) {
        self.frames += 1;
        self.detect += report.detect_time;
        self.track += report.track_time;
    }
}

/// A configured detector and tracker, fed one frame at a time.
pub struct Pipeline {
    stage: DetectionStage,
    tracker: AnyTracker,
    training_passes: usize,
    detections: Vec<Detection>,
    /// The candidates of a frame given as detections ([`FrameInput::Detections`]); those of
    /// a detected frame stay in the detection stage.
    candidates: Vec<Detection>,
}

/// What [`Pipeline::run_inputs`] shows its caller after each frame: the frame's report and
/// what the tracker saw.
pub type FrameObserver<'a> = dyn FnMut(&FrameReport, &FrameObservations<'_>) + 'a;

/// The counts of a run so far (frames, detections, points, tracks): the totals of its
/// summary, carried in a checkpoint so that a resumed run reports the same ones.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct RunTally {
    /// Frames of the output pass tracked.
    pub frames: u64,
    /// The last of them (`None` before the first).
    pub last_frame: Option<FrameIndex>,
    /// Detections over those frames.
    pub detections: u64,
    /// Detector-confidence candidates shown to the tracker with them.
    pub candidates: u64,
    /// Track points handed to the sink.
    pub points: u64,
    /// Distinct trajectories among them.
    pub tracks: u64,
    /// The highest track id seen.
    max_track_id: Option<u64>,
}

/// The state of a pipeline between two frames, for checkpoints: the tracker's (its
/// particles and random streams included) and the pre-processing's (the background model).
/// Detector scratch and settings are rebuilt from the configuration.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct PipelineState {
    tracker: AnyTracker,
    preprocessor: Preprocessor,
}

/// Counts what passes through to the real sink, so the run summary needs no second look.
struct CountingSink<'a, S: ?Sized> {
    inner: &'a mut S,
    tally: &'a mut RunTally,
}

impl<S: TrackSink + ?Sized> TrackSink for CountingSink<'_, S> {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        let tally = &mut *self.tally;
        for p in points {
            // Track ids are handed out in increasing order, so a new maximum is a new track.
            if tally.max_track_id.is_none_or(|m| p.track_id > m) {
                tally.max_track_id = Some(p.track_id);
                tally.tracks += 1;
            }
        }
        tally.points += points.len() as u64;
        self.inner.accept(points)
    }
}

impl Pipeline {
    /// Builds the pipeline of `config` (validated here; the mask image is read here).
    pub fn from_config(config: &PipelineConfig) -> Result<Self> {
        config.validate()?;
        let tracker = match &config.tracker {
            TrackerConfig::Ptv(params) => AnyTracker::Ptv(PtvTracker::new(params.clone())?),
            TrackerConfig::Bedload(params) => AnyTracker::Bedload(BedloadTracker::new(params)?),
        };
        Ok(Self {
            stage: DetectionStage::from_config(config)?,
            tracker,
            training_passes: config.training_passes,
            detections: Vec::new(),
            candidates: Vec::new(),
        })
    }

    /// The bedload tracker's counts so far (frames, confirmed tracks, predictions through
    /// misses); `None` for the other trackers.
    pub fn bedload_stats(&self) -> Option<BedloadStats> {
        match &self.tracker {
            AnyTracker::Bedload(tracker) => Some(tracker.stats()),
            AnyTracker::Ptv(_) => None,
        }
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

    /// Measures the particle images on `frame` before the run when the blob detector's scale
    /// or polarity is `"auto"` (see [`DetectionStage::calibrate`]); otherwise the first frame
    /// detected is measured.
    pub fn calibrate(&mut self, frame: &Frame) -> Result<()> {
        self.stage.calibrate(frame)
    }

    /// Adopts particle images measured on another run's first frame instead of measuring
    /// (the windows of one sequence, see [`crate::windows`]).
    pub fn calibrate_with(&mut self, measured: ParticleImages) -> Result<()> {
        self.stage.calibrate_with(measured)
    }

    /// PTV with `vote_search_px = "auto"`: links the first frames as the automatic decision
    /// does, then follows `radius` (voting on with it, or off for `None`) decided on another
    /// run's first frames (see `PtvTracker::follow_vote_decision`); nothing for the bedload
    /// trackers.
    pub fn follow_vote_decision(&mut self, radius: Option<f64>) {
        if let AnyTracker::Ptv(tracker) = &mut self.tracker {
            tracker.follow_vote_decision(radius);
        }
    }

    /// The blob detector's scale and polarity in use and what was measured to choose them.
    pub fn calibration(&self) -> Option<Calibration> {
        self.stage.calibration()
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

    /// Fills `self.detections` from `input`: detected in its image, or copied from it with
    /// its candidates.
    fn observe(&mut self, input: &FrameInput) -> Result<Duration> {
        match input {
            FrameInput::Image(frame) => self.detect(frame),
            FrameInput::Detections {
                detections,
                candidates,
                ..
            } => {
                self.detections.clone_from(detections);
                self.candidates.clone_from(candidates);
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
        self.run_inputs(
            frames.map(|f| f.map(FrameInput::Image)),
            sink,
            &mut |report, _| on_frame(report),
        )
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
        let inputs = frames.map(|f| {
            f.map(|(frame, detections)| FrameInput::Detections {
                frame,
                detections,
                candidates: Vec::new(),
            })
        });
        self.run_inputs(inputs, sink, &mut |report, _| on_frame(report))
    }

    /// The body of [`Pipeline::run`] and [`Pipeline::run_detections`], on frames of either
    /// kind (detections with their candidates: the bedload trackers' tables). `on_frame` sees
    /// each frame's report and the observations the tracker was given (overlays keep the
    /// detections from there).
    pub fn run_inputs(
        &mut self,
        inputs: impl Iterator<Item = Result<FrameInput>>,
        sink: &mut dyn TrackSink,
        on_frame: &mut FrameObserver<'_>,
    ) -> Result<RunSummary> {
        if self.training_passes == 0 {
            let mut tally = RunTally::default();
            let run = overlap::run(
                &mut self.stage,
                &mut self.tracker,
                inputs,
                &mut *sink,
                &mut tally,
                on_frame,
            );
            let timings = match run {
                Ok(timings) => timings,
                Err(error) => {
                    // The points the tracker still holds (a warm-up's, those waiting for
                    // their velocity windows) are of frames before the error: they are
                    // written too, so that nothing tracked is lost. The error is the run's.
                    let _ = self.tracker.as_tracker().finish(&mut CountingSink {
                        inner: &mut *sink,
                        tally: &mut tally,
                    });
                    return Err(error);
                }
            };
            return self.finish_run(sink, tally, timings);
        }
        let mut tally = RunTally::default();
        let mut timings = Timings::default();
        let cached = self.detect_all(inputs)?;
        self.train(&cached)?;
        self.tracker.start_pass(PassDirection::Forward);
        // Training passes replay detections only: PTV, the tracker that trains, takes no
        // candidates.
        self.candidates.clear();
        for (index, detections, detect) in &cached {
            self.detections.clone_from(detections);
            let report = self.track(*index, None, *detect, sink, &mut tally, on_frame)?;
            timings.add(&report);
        }
        self.finish_run(sink, tally, timings)
    }

    /// The output pass of a run without training passes, from `tally` on: a fresh run starts
    /// from [`RunTally::default`], a resumed one from its checkpoint's tally with the state
    /// of [`Pipeline::restore`] and the frames after the checkpoint's last. After every
    /// frame `after_frame` gets the pipeline, the tally and the sink (a checkpoint is saved
    /// there); an error from it ends the run.
    pub fn run_resumable<S: TrackSink + ?Sized>(
        &mut self,
        inputs: impl Iterator<Item = Result<FrameInput>>,
        sink: &mut S,
        mut tally: RunTally,
        on_frame: &mut FrameObserver<'_>,
        after_frame: &mut dyn FnMut(&Self, &RunTally, &mut S) -> Result<()>,
    ) -> Result<RunSummary> {
        if self.training_passes > 0 {
            return Err(Error::parameter(
                "training_passes",
                self.training_passes,
                "training passes replay the whole sequence, which a run that can be resumed \
                 does not keep; set it to 0",
            ));
        }
        let mut timings = Timings::default();
        for input in inputs {
            let report = self.step_output_pass(&input?, &mut *sink, &mut tally, on_frame)?;
            timings.add(&report);
            after_frame(self, &tally, sink)?;
        }
        self.finish_run(sink, tally, timings)
    }

    /// Flushes the tracker and turns the tally and timings into the run's summary.
    fn finish_run<S: TrackSink + ?Sized>(
        &mut self,
        sink: &mut S,
        mut tally: RunTally,
        timings: Timings,
    ) -> Result<RunSummary> {
        self.tracker.as_tracker().finish(&mut CountingSink {
            inner: &mut *sink,
            tally: &mut tally,
        })?;
        let mut totals = RunSummary {
            frames: tally.frames,
            detections: tally.detections,
            candidates: tally.candidates,
            points: tally.points,
            tracks: tally.tracks,
            detector: self.stage.calibration(),
            ..RunSummary::default()
        };
        if let AnyTracker::Ptv(tracker) = &self.tracker {
            totals.measured_displacement_px = tracker.measured_displacement();
            totals.vote_valid_share = tracker.measured_vote_valid_share();
            totals.vote_search_px = tracker.vote_radius();
            totals.restored_points = Some(tracker.restored_points());
        }
        if timings.frames > 0 {
            let per_frame = |d: Duration| d.as_secs_f64() * 1e3 / timings.frames as f64;
            totals.detect_ms_per_frame = per_frame(timings.detect);
            totals.track_ms_per_frame = per_frame(timings.track);
        }
        Ok(totals)
    }

    /// The tracker's and the pre-processing's state now (see [`PipelineState`]).
    pub fn state(&self) -> PipelineState {
        PipelineState {
            tracker: self.tracker.clone(),
            preprocessor: self.stage.preprocessor().clone(),
        }
    }

    /// Continues from `state`, saved by a pipeline of the same configuration; a state of
    /// another tracker is refused.
    pub fn restore(&mut self, state: PipelineState) -> Result<()> {
        let same_kind = matches!(
            (&self.tracker, &state.tracker),
            (AnyTracker::Ptv(_), AnyTracker::Ptv(_))
                | (AnyTracker::Bedload(_), AnyTracker::Bedload(_))
        );
        if !same_kind {
            return Err(Error::input(
                "the saved state is of another tracker than the configuration's",
            ));
        }
        self.tracker = state.tracker;
        self.stage.set_preprocessor(state.preprocessor);
        Ok(())
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
        self.step_output_pass(input, sink, &mut RunTally::default(), &mut |_, _| {})
    }

    /// Flushes the points the tracker still holds at the end of a streamed run
    /// ([`Pipeline::step`]).
    pub fn finish(&mut self, sink: &mut dyn TrackSink) -> Result<()> {
        self.tracker.as_tracker().finish(sink)
    }

    /// One frame of the output pass: observe, then track.
    fn step_output_pass<S: TrackSink + ?Sized>(
        &mut self,
        input: &FrameInput,
        sink: &mut S,
        tally: &mut RunTally,
        on_frame: &mut FrameObserver<'_>,
    ) -> Result<FrameReport> {
        let detect = self.observe(input)?;
        let frame = match input {
            FrameInput::Image(frame) => Some(frame),
            FrameInput::Detections { .. } => None,
        };
        self.track(input.index(), frame, detect, sink, tally, on_frame)
    }

    /// Feeds `self.detections` of frame `index` to the tracker, with the image the detector saw
    /// and its candidates when `frame` is at hand (not in replayed training passes), else the
    /// candidates given with the detections (see [`track_frame`]).
    fn track<S: TrackSink + ?Sized>(
        &mut self,
        index: FrameIndex,
        frame: Option<&Frame>,
        detect_time: Duration,
        sink: &mut S,
        tally: &mut RunTally,
        on_frame: &mut FrameObserver<'_>,
    ) -> Result<FrameReport> {
        let (image, candidates) = match frame {
            Some(frame) => (
                Some(self.stage.detector_input(frame)),
                self.stage.candidates(),
            ),
            None => (None, self.candidates.as_slice()),
        };
        let observations = FrameObservations {
            frame: index,
            detections: &self.detections,
            image,
            candidates,
        };
        track_frame(
            &mut self.tracker,
            &observations,
            detect_time,
            sink,
            tally,
            on_frame,
        )
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

/// Shows one frame's `observations` to `tracker`, its points to `sink`; counts the frame and
/// its points in `tally`, then shows the report to `on_frame`.
fn track_frame<S: TrackSink + ?Sized>(
    tracker: &mut AnyTracker,
    observations: &FrameObservations<'_>,
    detect_time: Duration,
    sink: &mut S,
    tally: &mut RunTally,
    on_frame: &mut FrameObserver<'_>,
) -> Result<FrameReport> {
    let before = tally.points;
    let start = Instant::now();
    let mut counting = CountingSink {
        inner: &mut *sink,
        tally: &mut *tally,
    };
    tracker.as_tracker().step(observations, &mut counting)?;
    tally.frames += 1;
    tally.last_frame = Some(observations.frame);
    tally.detections += observations.detections.len() as u64;
    tally.candidates += observations.candidates.len() as u64;
    let report = FrameReport {
        frame: observations.frame,
        detections: observations.detections.len(),
        candidates: observations.candidates.len(),
        points_emitted: (tally.points - before) as usize,
        detect_time,
        track_time: start.elapsed(),
    };
    on_frame(&report, observations);
    Ok(report)
}

#[cfg(test)]
mod tests {
    use sillage_core::{Point2, TRANSPARENT_BEAD_CLASS};

    use super::*;

    /// Candidates given with the detections reach the tracker and the observer, frame by
    /// frame; training passes are refused for the bedload tracker.
    #[test]
    fn detections_tables_carry_their_candidates_to_the_bedload_tracker() {
        let config = PipelineConfig {
            tracker: TrackerConfig::Bedload(Box::default()),
            ..PipelineConfig::default()
        };
        let mut pipeline = Pipeline::from_config(&config).unwrap();
        let bead = |x: f64| Detection::of_class(Point2::new(x, 50.0), 0.5, TRANSPARENT_BEAD_CLASS);
        let inputs = (0..4).map(|frame| {
            Ok(FrameInput::Detections {
                frame,
                detections: vec![bead(100.0 + 4.0 * frame as f64)],
                candidates: vec![bead(100.0 + 4.0 * frame as f64); frame as usize],
            })
        });
        let mut seen = Vec::new();
        let mut points: Vec<TrackPoint> = Vec::new();
        let summary = pipeline
            .run_inputs(inputs, &mut points, &mut |report, observations| {
                assert_eq!(report.candidates, observations.candidates.len());
                seen.push(report.candidates);
            })
            .unwrap();
        assert_eq!(seen, [0, 1, 2, 3]);
        assert_eq!(summary.frames, 4);
        assert_eq!(pipeline.bedload_stats().unwrap().tracks, 1);
        assert_eq!(points.len(), 4);
        let trained = PipelineConfig {
            training_passes: 1,
            ..config
        };
        let err = Pipeline::from_config(&trained).err().unwrap().to_string();
        assert!(err.contains("training_passes"), "{err}");
    }
}

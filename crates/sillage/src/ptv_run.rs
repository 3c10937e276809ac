//! A PTV run from files to files: the configuration assembled as `sillage ptv` and
//! `sillage config` assemble it, the track-file header that records it, and a whole run from a
//! frame source into one track file (or any sink).

use std::path::Path;

use sillage_core::{Error, FrameIndex, Result, TrackSink};
use sillage_io::{
    BadFramePolicy, FrameOptions, SkippedFrame, TrackFileHeader, TrackFormat, TrackWriter,
    WrittenSummary, create_track_writer, open_frames, read_tractrac_par, write_in_background,
};

use sillage_detect::blob::Calibration;

use crate::checkpoint::RunIdentity;
use crate::config::{DetectorConfig, PipelineConfig};
use crate::long_run::{Inputs, LongRunOptions, LongRunOutput, run_long};
use crate::pipeline::{FrameInput, FrameReport, Pipeline, RunSummary};
use crate::toml_config::{Settings, dotted_keys, load_unvalidated, set_key};
use crate::tracking::Tracking;
use crate::tractrac::apply_par;
use crate::windows::{Window, WindowPlan, WindowedRun, WindowedSummary};

/// Fewest frames from which PTV forms tracks: a particle is linked over three frames (the
/// paper's three-frame nearest-neighbour association).
pub const MIN_PTV_FRAMES: usize = 3;

/// A warning for run summaries when `frames` is fewer than [`MIN_PTV_FRAMES`], from which no
/// track can form (a PIV image pair, say); `None` otherwise.
pub fn too_few_frames_warning(frames: usize) -> Option<String> {
    (frames < MIN_PTV_FRAMES).then(|| {
        format!(
            "{frames} frame(s): PTV links each particle over {MIN_PTV_FRAMES} frames (the \
             paper's three-frame association), so no track can form; give at least \
             {MIN_PTV_FRAMES} frames, or measure an image pair by cross-correlation (PIV)"
        )
    })
}

impl Settings for PipelineConfig {
    fn validate(&self) -> Result<()> {
        PipelineConfig::validate(self)
    }
}

/// The configuration of a PTV run: the defaults, then the TOML `file`, then the TracTrac
/// `*_par.txt` at `tractrac_par`, then each `key=value` of `overrides`; validated.
pub fn load_ptv_config(
    file: Option<&Path>,
    tractrac_par: Option<&Path>,
    overrides: &[String],
) -> Result<PipelineConfig> {
    let mut config: PipelineConfig = load_unvalidated(file, &[])?;
    if let Some(path) = tractrac_par {
        let par = read_tractrac_par(path)?;
        apply_par(&mut config, &par)
            .map_err(|e| Error::input(format!("in {}: {e}", path.display())))?;
    }
    for assignment in overrides {
        set_key(&mut config, assignment)?;
    }
    Settings::validate(&config)?;
    Ok(config)
}

/// The header written into track files: our version and every parameter of `config` under
/// its dotted key (`detector.scale_px`, `tracker.motion_av`), the keys `--set` takes; then,
/// when the blob detector's scale or polarity was measured, the values in use and the
/// measurement (`detector.measured.*`).
pub fn track_header(
    config: &PipelineConfig,
    calibration: Option<&Calibration>,
) -> Result<TrackFileHeader> {
    let mut parameters = dotted_keys(config)?;
    if let Some(calibration) = calibration
        && let Some(measured) = &calibration.measured
    {
        parameters.extend([
            (
                "detector.measured.particle_sigma_px".to_string(),
                format!("{:.3}", measured.sigma_px),
            ),
            (
                "detector.measured.scale_px".to_string(),
                format!("{:.3}", calibration.scale_px),
            ),
            (
                "detector.measured.polarity".to_string(),
                calibration.polarity.name().to_string(),
            ),
            (
                "detector.measured.source_density".to_string(),
                format!("{:.3}", measured.source_density),
            ),
        ]);
    }
    Ok(TrackFileHeader {
        program_version: format!("sillage {}", env!("CARGO_PKG_VERSION")),
        parameters,
        ..TrackFileHeader::default()
    })
}

/// A pipeline ready to track a frame source: built, its background primed, the scale of
/// its particles measured.
pub struct PtvRun {
    pipeline: Pipeline,
    input: String,
    config: PipelineConfig,
    header: TrackFileHeader,
    background_frames: Option<usize>,
    frame_count: Option<usize>,
    /// The frames to track (their span and the bad-frame policy).
    frames: FrameOptions,
}

/// What [`PtvRun::run_to_file`] did.
#[derive(Debug, Clone)]
pub struct PtvFileRun {
    /// Frames, detections, points and timings.
    pub summary: RunSummary,
    /// The file written and its rows.
    pub written: WrittenSummary,
    /// The frames skipped (`--on-bad-frame skip`), in order.
    pub skipped: Vec<SkippedFrame>,
    /// The last frame of the checkpoint the run resumed from (`None`: from the start).
    pub resumed_after: Option<FrameIndex>,
}

impl PtvRun {
    /// Builds the pipeline of `config` for the frames of `input` (folder, glob, TIFF stack or
    /// video); with background subtraction, the model starts as the mean of the first frames
    /// (TracTrac's Eq. (2)), read from a first opening of the source.
    /// An `"auto"` blob scale or polarity is measured on the first frame here, so that the
    /// header records it. Bad frames stop the run ([`PtvRun::open_with`] to skip them).
    pub fn open(config: &PipelineConfig, input: &str) -> Result<Self> {
        Self::open_with(config, input, BadFramePolicy::Stop)
    }

    /// [`PtvRun::open`] with frames that cannot be read handled by `on_bad_frame`.
    pub fn open_with(
        config: &PipelineConfig,
        input: &str,
        on_bad_frame: BadFramePolicy,
    ) -> Result<Self> {
        let frames = FrameOptions {
            on_bad_frame,
            ..FrameOptions::default()
        };
        Self::open_frames(config, input, frames)
    }

    /// [`PtvRun::open`] on the frames `frames` selects (a time window: its `start_at`,
    /// `stop_at`, `max_frames`; its bad-frame policy). The background model starts from the
    /// selected frames; an `"auto"` blob scale or polarity is measured on the sequence's first
    /// frame, whatever the selection.
    pub fn open_frames(config: &PipelineConfig, input: &str, frames: FrameOptions) -> Result<Self> {
        let mut pipeline = Pipeline::from_config(config)?;
        let background_frames = if pipeline.background_init_frames() > 0 {
            Some(pipeline.prime_background(open_frames(input, &frames)?)?)
        } else {
            None
        };
        let frame_count = open_frames(input, &frames)?.len();
        if let DetectorConfig::Blob(_) = config.detector {
            let first_frame = FrameOptions {
                on_bad_frame: frames.on_bad_frame,
                ..FrameOptions::default()
            };
            if let Some(first) = open_frames(input, &first_frame)?.next() {
                pipeline.calibrate(&first?)?;
            }
        }
        Ok(Self {
            header: track_header(config, pipeline.calibration().as_ref())?,
            pipeline,
            input: input.to_string(),
            config: config.clone(),
            background_frames,
            frame_count,
            frames,
        })
    }

    /// The blob detector's scale and polarity in use and what was measured to choose them.
    pub fn calibration(&self) -> Option<Calibration> {
        self.pipeline.calibration()
    }

    /// How many frames the background model was initialised from (`None` without one).
    pub fn background_frames(&self) -> Option<usize> {
        self.background_frames
    }

    /// Number of frames to track, when the source knows it (not for every video).
    pub fn frame_count(&self) -> Option<usize> {
        self.frame_count
    }

    /// [`too_few_frames_warning`] for this run's source, when it knows its length.
    pub fn too_few_frames_warning(&self) -> Option<String> {
        self.frame_count.and_then(too_few_frames_warning)
    }

    /// The header of the track files of this run ([`track_header`]).
    pub fn header(&self) -> &TrackFileHeader {
        &self.header
    }

    /// The frame options of this run's source, from frame `start_at` on.
    fn frame_options(&self, start_at: FrameIndex) -> FrameOptions {
        FrameOptions {
            start_at: start_at.max(self.frames.start_at),
            ..self.frames.clone()
        }
    }

    /// Tracks every frame into `sink`; `on_frame` is called after each (progress bars).
    pub fn run(
        mut self,
        sink: &mut dyn TrackSink,
        on_frame: &mut dyn FnMut(&FrameReport),
    ) -> Result<RunSummary> {
        let frames = open_frames(&self.input, &self.frame_options(0))?;
        self.pipeline.run(frames, sink, on_frame)
    }

    /// Tracks every frame into the track file `out` in `format`. Rows written before an error
    /// stay valid: the file is completed either way, then the error is returned.
    pub fn run_to_file(
        self,
        out: &Path,
        format: TrackFormat,
        on_frame: &mut dyn FnMut(&FrameReport),
    ) -> Result<PtvFileRun> {
        let options = LongRunOptions {
            on_bad_frame: self.frames.on_bad_frame,
            ..LongRunOptions::default()
        };
        self.run_long(out, format, &options, on_frame)
    }

    /// [`PtvRun::run_to_file`] with checkpoints and resume (see [`crate::long_run`]);
    /// `options.on_bad_frame` must be the policy the run was opened with.
    pub fn run_long(
        mut self,
        out: &Path,
        format: TrackFormat,
        options: &LongRunOptions,
        on_frame: &mut dyn FnMut(&FrameReport),
    ) -> Result<PtvFileRun> {
        if options.on_bad_frame != self.frames.on_bad_frame {
            return Err(Error::input(
                "the bad-frame policy differs from the one the run was opened with",
            ));
        }
        let mut settings = dotted_keys(&self.config)?;
        settings.push(("format".to_string(), format.name().to_string()));
        settings.extend(options.settings());
        let identity = RunIdentity::new("ptv", &self.input, out, settings);
        let header = self.header.clone();
        let mut create_writer = || create_track_writer(out, format, &header);
        let output = LongRunOutput {
            path: out,
            create_writer: &mut create_writer,
            identity,
        };
        let (input, frame_options) = (self.input.clone(), self.frame_options(0));
        let mut open_inputs = move |start_at: FrameIndex| -> Result<Inputs<'static>> {
            let frames = open_frames(
                &input,
                &FrameOptions {
                    start_at,
                    ..frame_options.clone()
                },
            )?;
            let log = frames.skipped();
            Ok((
                Box::new(frames.map(|f| f.map(FrameInput::Image))),
                Some(log),
            ))
        };
        let outcome = run_long(
            &mut self.pipeline,
            &mut open_inputs,
            output,
            options,
            &mut |report, _| on_frame(report),
        )?;
        Ok(PtvFileRun {
            summary: outcome.summary,
            written: outcome.written,
            skipped: outcome.skipped,
            resumed_after: outcome.resumed_after,
        })
    }
}

impl PtvRun {
    /// Tracks the sequence in the time windows of `plan`, `jobs` at once, stitched into the
    /// track file `out` ([`crate::windows`]); `on_window` is called as each window is
    /// stitched. Rows written before an error stay valid: the file is completed either way,
    /// then the error is returned.
    pub fn run_windowed(
        self,
        out: &Path,
        format: TrackFormat,
        plan: WindowPlan,
        jobs: usize,
        on_window: &mut dyn FnMut(&Window),
    ) -> Result<(WindowedSummary, WrittenSummary)> {
        if self.frames.on_bad_frame != BadFramePolicy::Stop {
            return Err(Error::input(
                "windows read every frame: skipping bad frames is not available with windows",
            ));
        }
        let tracking = Tracking::Pipeline(Box::new(self.config));
        // Formatting rows takes a core's share: on a thread of its own, as in a single run.
        let mut writer = write_in_background(create_track_writer(out, format, &self.header)?)?;
        let run = WindowedRun::new(&tracking, plan).jobs(jobs);
        let summary = run.run(&self.input, &mut writer, on_window);
        let written = Box::new(writer).finish()?;
        Ok((summary?, written))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_header_names_nested_keys_with_their_sections() {
        let header = track_header(&PipelineConfig::default(), None).unwrap();
        let keys: Vec<&str> = header.parameters.iter().map(|(k, _)| k.as_str()).collect();
        assert!(keys.contains(&"tracker.motion_av"), "{keys:?}");
        assert!(
            keys.iter().any(|k| k.starts_with("detector.threshold.")),
            "{keys:?}"
        );
        assert!(keys.contains(&"training_passes"), "{keys:?}");
        assert!(header.program_version.starts_with("sillage "));
    }

    #[test]
    fn overrides_come_after_the_file_and_are_validated() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("ptv.toml");
        std::fs::write(&file, "training_passes = 1\n").unwrap();
        let config = load_ptv_config(Some(&file), None, &["training_passes=2".into()]).unwrap();
        assert_eq!(config.training_passes, 2);
        let err = load_ptv_config(None, None, &["tracker.motion_av=0".into()])
            .unwrap_err()
            .to_string();
        assert!(err.contains("motion_av"), "{err}");
    }
}

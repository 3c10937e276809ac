//! A PTV run from files to files: the configuration assembled as `sillage ptv` and
//! `sillage config` assemble it, the track-file header that records it, and a whole run from a
//! frame source into one track file (or any sink).

use std::path::Path;

use sillage_core::{Error, Result, TrackSink};
use sillage_io::{
    FrameOptions, FrameSource, TrackFileHeader, TrackFormat, TrackWriter, WrittenSummary,
    create_track_writer, open_frames, read_tractrac_par, write_in_background,
};

use sillage_detect::blob::Calibration;

use crate::config::{DetectorConfig, PipelineConfig};
use crate::pipeline::{FrameReport, Pipeline, RunSummary};
use crate::toml_config::{Settings, dotted_keys, load_unvalidated, set_key};
use crate::tractrac::apply_par;

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
        ]);
    }
    Ok(TrackFileHeader {
        program_version: format!("sillage {}", env!("CARGO_PKG_VERSION")),
        parameters,
        ..TrackFileHeader::default()
    })
}

/// A pipeline ready to track a frame source: built, its background primed, the frames open.
pub struct PtvRun {
    pipeline: Pipeline,
    frames: FrameSource,
    header: TrackFileHeader,
    background_frames: Option<usize>,
}

/// What [`PtvRun::run_to_file`] did.
#[derive(Debug, Clone)]
pub struct PtvFileRun {
    /// Frames, detections, points and timings.
    pub summary: RunSummary,
    /// The file written and its rows.
    pub written: WrittenSummary,
}

impl PtvRun {
    /// Builds the pipeline of `config` for the frames of `input` (folder, glob, TIFF stack or
    /// video); with background subtraction, the model starts as the mean of the first frames
    /// (TracTrac's Eq. (2)), read from a first opening of the source.
    /// An `"auto"` blob scale or polarity is measured on the first frame here, so that the
    /// header records it.
    pub fn open(config: &PipelineConfig, input: &str) -> Result<Self> {
        let mut pipeline = Pipeline::from_config(config)?;
        let background_frames = if pipeline.background_init_frames() > 0 {
            Some(pipeline.prime_background(open_frames(input, &FrameOptions::default())?)?)
        } else {
            None
        };
        if let DetectorConfig::Blob(_) = config.detector
            && let Some(first) = open_frames(input, &FrameOptions::default())?.next()
        {
            pipeline.calibrate(&first?)?;
        }
        Ok(Self {
            header: track_header(config, pipeline.calibration().as_ref())?,
            pipeline,
            frames: open_frames(input, &FrameOptions::default())?,
            background_frames,
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
        self.frames.len()
    }

    /// The header of the track files of this run ([`track_header`]).
    pub fn header(&self) -> &TrackFileHeader {
        &self.header
    }

    /// Tracks every frame into `sink`; `on_frame` is called after each (progress bars).
    pub fn run(
        mut self,
        sink: &mut dyn TrackSink,
        on_frame: &mut dyn FnMut(&FrameReport),
    ) -> Result<RunSummary> {
        self.pipeline.run(self.frames, sink, on_frame)
    }

    /// Tracks every frame into the track file `out` in `format`. Rows written before an error
    /// stay valid: the file is completed either way, then the error is returned.
    pub fn run_to_file(
        self,
        out: &Path,
        format: TrackFormat,
        on_frame: &mut dyn FnMut(&FrameReport),
    ) -> Result<PtvFileRun> {
        // Rows are formatted and written on a thread of their own while tracking goes on.
        let mut writer = Box::new(write_in_background(create_track_writer(
            out,
            format,
            &self.header,
        )?)?);
        let outcome = self.run(writer.as_mut(), on_frame);
        let written = writer.finish()?;
        Ok(PtvFileRun {
            summary: outcome?,
            written,
        })
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

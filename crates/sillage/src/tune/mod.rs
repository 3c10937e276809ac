//! The detector-tuning page of `sillage tune`: the first frames of a sequence held in memory,
//! and the answers to the page's requests. Each change on the page posts the whole
//! configuration back, and the frame's detections, their count, the threshold and a histogram
//! of the band-passed image's local maxima are computed by the same [`DetectionStage`] a
//! tracking run uses, so what the page shows is what `sillage ptv` will see; the band-passed
//! image the threshold applies to can be shown instead of the frame. "Save" writes the
//! configuration as TOML for `sillage ptv --config`. The server ([`http`]) runs on the
//! standard library alone.

pub mod http;

use std::net::TcpListener;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use serde::{Deserialize, Serialize};
use sillage_core::{Detection, Error, GrayImage, Result};
use sillage_detect::blob::{BlobParams, Calibration, Scale};
use sillage_image::{Peak, PeakFinder, Roi};
use sillage_io::{Frame, FrameOptions, open_frames, write_text};

use crate::config::{DetectorConfig, PipelineConfig};
use crate::detection_stage::DetectionStage;
use http::{Request, Response, serve};

/// The page, served as it is; it asks `/api/state` for everything else.
const PAGE: &str = include_str!("../../assets/tune.html");

/// Bins of the local-maxima histogram.
const HISTOGRAM_BINS: usize = 64;

/// Everything the server answers from: the loaded frames and where "save" writes.
pub struct TuneSession {
    /// The frames, in order (the first `--max-frames` of the sequence).
    frames: Vec<Frame>,
    /// The configuration the page starts from.
    initial: PipelineConfig,
    /// The scale and polarity measured on the first frame for an `"auto"` configuration.
    measured: Option<Calibration>,
    /// Where "save" writes the configuration.
    save_path: PathBuf,
}

/// What `/api/state` tells the page.
#[derive(Debug, Serialize)]
struct StateReply<'a> {
    /// Number of frames loaded.
    frames: usize,
    /// Frame width and height, px.
    width: usize,
    height: usize,
    /// File of each frame.
    files: Vec<String>,
    /// The configuration to start from (JSON form of the TOML file), `"auto"` scale and
    /// polarity replaced by the values measured on the first frame.
    config: &'a PipelineConfig,
    /// What was measured on the first frame, when the configuration asked for it.
    measured: Option<&'a Calibration>,
    /// Where "save" writes.
    save_path: String,
}

/// A detection request: the frame and the whole configuration.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct DetectRequest {
    /// Index of the frame among those loaded.
    frame: usize,
    /// The configuration to run.
    config: serde_json::Value,
}

/// A save request.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SaveRequest {
    /// The configuration to write.
    config: serde_json::Value,
}

/// Histogram of the strengths of every local maximum of the band-passed image: the noise
/// maxima and the objects' peaks, with the threshold between them.
#[derive(Debug, Serialize)]
struct StrengthHistogram {
    /// Lower edge of the first bin.
    lo: f32,
    /// Upper edge of the last bin.
    hi: f32,
    /// Maxima per bin, [`HISTOGRAM_BINS`] equal bins.
    counts: Vec<u32>,
}

/// What one detection run found.
#[derive(Debug, Serialize)]
struct DetectReply {
    /// The frame.
    frame: usize,
    /// Number of detections.
    count: usize,
    /// The threshold applied to the band-passed image.
    threshold: Option<f32>,
    /// Detections as `[x, y, strength]`, positions rounded to 0.01 px.
    detections: Vec<[f32; 3]>,
    /// Local maxima strengths.
    histogram: StrengthHistogram,
    /// Wall time of pre-processing and detection, ms.
    detect_ms: f64,
}

/// The first `max_frames` frames of `input`; `on_frame` is called after each with the number
/// of frames when the source knows it (progress bars).
pub fn load_frames(
    input: &str,
    max_frames: usize,
    on_frame: &mut dyn FnMut(Option<usize>),
) -> Result<Vec<Frame>> {
    let options = FrameOptions {
        max_frames: Some(max_frames),
        ..FrameOptions::default()
    };
    let source = open_frames(input, &options)?;
    let total = source.len();
    let mut frames = Vec::new();
    for frame in source {
        frames.push(frame?);
        on_frame(total);
    }
    Ok(frames)
}

/// Answers every connection of `listener` from `session`, each on its own thread; returns
/// only if accepting fails.
pub fn serve_session(listener: &TcpListener, session: TuneSession) -> std::io::Result<()> {
    let session = Arc::new(session);
    serve(listener, Arc::new(move |request| session.answer(request)))
}

impl TuneSession {
    /// A session on `frames` (at least one), starting from `initial`, saving to `save_path`.
    /// An `"auto"` blob scale or polarity is measured on the first frame and the page starts
    /// from the measured values (errors when the frame has no particles to measure).
    pub fn new(
        frames: Vec<Frame>,
        mut initial: PipelineConfig,
        save_path: PathBuf,
    ) -> Result<Self> {
        let Some(first) = frames.first() else {
            return Err(Error::input("no frame to tune on; check the input"));
        };
        let mut stage = DetectionStage::from_config(&initial)?;
        stage.calibrate(first)?;
        let measured = stage.calibration().filter(|c| c.measured.is_some());
        if let (Some(calibration), DetectorConfig::Blob(blob)) = (&measured, &mut initial.detector)
        {
            blob.scale_px = Scale::Px((calibration.scale_px * 100.0).round() / 100.0);
            blob.polarity = calibration.polarity.into();
        }
        Ok(Self {
            frames,
            initial,
            measured,
            save_path,
        })
    }

    /// The scale and polarity measured on the first frame, when the configuration asked for
    /// them.
    pub fn measured(&self) -> Option<&Calibration> {
        self.measured.as_ref()
    }

    /// Number of frames loaded.
    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }

    /// Where "save" writes the configuration.
    pub fn save_path(&self) -> &std::path::Path {
        &self.save_path
    }

    /// Routes one request.
    pub fn answer(&self, request: &Request) -> Response {
        let outcome = match (request.method.as_str(), request.path.as_str()) {
            ("GET", "/") => Ok(Response::bytes(
                "text/html; charset=utf-8",
                PAGE.as_bytes().to_vec(),
            )),
            ("GET", "/api/state") => Ok(Response::json(&self.state())),
            ("POST", "/api/detect") => parse_json(&request.body)
                .and_then(|r: DetectRequest| self.detect(r.frame, r.config))
                .map(|reply| Response::json(&reply)),
            ("POST", "/api/band-passed") => parse_json(&request.body)
                .and_then(|r: DetectRequest| self.band_passed_png(r.frame, r.config)),
            ("POST", "/api/save") => parse_json(&request.body)
                .and_then(|r: SaveRequest| self.save(r.config))
                .map(|path| Response::json(&serde_json::json!({ "path": path }))),
            ("GET", path) if path.starts_with("/frame/") => self.frame_png(path),
            (_, "/" | "/api/state" | "/api/detect" | "/api/band-passed" | "/api/save") => {
                return Response::error(405, format!("{} is not allowed here", request.method));
            }
            _ => return Response::error(404, format!("no page at {}", request.path)),
        };
        outcome.unwrap_or_else(|error| Response::error(400, error.to_string()))
    }

    /// The page's starting point.
    fn state(&self) -> StateReply<'_> {
        let (width, height) = self.frames[0].image.dimensions();
        StateReply {
            frames: self.frames.len(),
            width,
            height,
            files: self
                .frames
                .iter()
                .map(|f| f.path.display().to_string())
                .collect(),
            config: &self.initial,
            measured: self.measured.as_ref(),
            save_path: self.save_path.display().to_string(),
        }
    }

    /// The stage of `config`, primed and run on frame `index`, with its detections and the
    /// time detection took, ms.
    fn run_stage(
        &self,
        index: usize,
        config: &PipelineConfig,
    ) -> Result<(DetectionStage, Vec<Detection>, f64)> {
        let frame = self.frame(index)?;
        let mut stage = DetectionStage::from_config(config)?;
        let init = stage.background_init_frames().min(self.frames.len());
        stage.prime_background(self.frames[..init].iter().map(|f| &f.image))?;
        let mut detections: Vec<Detection> = Vec::new();
        let start = Instant::now();
        stage.detect(frame, &mut detections)?;
        Ok((stage, detections, start.elapsed().as_secs_f64() * 1e3))
    }

    /// Runs pre-processing and detection of `config` on frame `index`.
    fn detect(&self, index: usize, config: serde_json::Value) -> Result<DetectReply> {
        let config = parse_config(config)?;
        let (stage, detections, detect_ms) = self.run_stage(index, &config)?;
        let threshold = stage.last_threshold();
        Ok(DetectReply {
            frame: index,
            count: detections.len(),
            threshold,
            detections: detections
                .iter()
                .map(|d| [round_centi(d.pos_px.x), round_centi(d.pos_px.y), d.strength])
                .collect(),
            histogram: maxima_histogram(
                band_passed(&stage)?,
                blob_params(&config)?.neighbourhood,
                threshold,
            ),
            detect_ms,
        })
    }

    /// The band-passed image of frame `index` under `config`, frame-sized (outside the ROI at
    /// its minimum), as a PNG stretched to its range: what the threshold is applied to.
    fn band_passed_png(&self, index: usize, config: serde_json::Value) -> Result<Response> {
        let config = parse_config(config)?;
        let (stage, _, _) = self.run_stage(index, &config)?;
        let (width, height) = self.frames[index].image.dimensions();
        let filtered = band_passed(&stage)?;
        let placed = place_in_frame(filtered, blob_params(&config)?.roi, width, height);
        Ok(Response::bytes("image/png", encode_png(&placed)?))
    }

    /// Validates `config` and writes it as TOML to the save path (through a temporary file).
    fn save(&self, config: serde_json::Value) -> Result<String> {
        let config = parse_config(config)?;
        write_text(&self.save_path, &config.to_toml_string()?)?;
        Ok(self.save_path.display().to_string())
    }

    /// `/frame/{i}.png`: the frame as 8-bit grey, its grey levels stretched to their range.
    fn frame_png(&self, path: &str) -> Result<Response> {
        let index = path
            .strip_prefix("/frame/")
            .and_then(|rest| rest.strip_suffix(".png"))
            .and_then(|i| i.parse::<usize>().ok())
            .ok_or_else(|| Error::input(format!("{path}: expected /frame/<index>.png")))?;
        let png = encode_png(&self.frame(index)?.image)?;
        Ok(Response::bytes("image/png", png))
    }

    /// Frame `index`, or an error naming the loaded range.
    fn frame(&self, index: usize) -> Result<&Frame> {
        self.frames.get(index).ok_or_else(|| {
            Error::input(format!(
                "frame {index} is not loaded; frames 0..={} are (raise --max-frames for more)",
                self.frames.len() - 1
            ))
        })
    }
}

/// Parses a JSON request body.
fn parse_json<T: for<'de> Deserialize<'de>>(body: &[u8]) -> Result<T> {
    serde_json::from_slice(body).map_err(|e| Error::input(format!("malformed request: {e}")))
}

/// The configuration the page sent, validated (errors name the key and its range).
fn parse_config(value: serde_json::Value) -> Result<PipelineConfig> {
    let config: PipelineConfig = serde_json::from_value(value)
        .map_err(|e| Error::input(format!("the configuration does not parse: {e}")))?;
    config.validate()?;
    blob_params(&config)?;
    Ok(config)
}

/// The blob detector's parameters of `config`, the one detector `sillage tune` tunes.
fn blob_params(config: &PipelineConfig) -> Result<&BlobParams> {
    match &config.detector {
        DetectorConfig::Blob(params) => Ok(params),
        _ => Err(Error::input(
            "`sillage tune` tunes the blob detector; set detector.kind = \"blob\"",
        )),
    }
}

/// The band-passed image the blob detector thresholded in the last frame of `stage`.
fn band_passed(stage: &DetectionStage) -> Result<&GrayImage> {
    stage
        .filtered()
        .ok_or_else(|| Error::input("no band-passed image: `sillage tune` tunes the blob detector"))
}

/// `filtered`, the band-passed image of `roi` (the whole frame when `None`), placed in a
/// `width × height` image whose pixels outside the ROI take its minimum value.
fn place_in_frame(
    filtered: &GrayImage,
    roi: Option<Roi>,
    width: usize,
    height: usize,
) -> GrayImage {
    let Some(roi) = roi else {
        return filtered.clone();
    };
    let floor = filtered
        .as_slice()
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(f32::INFINITY, f32::min);
    let floor = if floor.is_finite() { floor } else { 0.0 };
    let mut placed = GrayImage::from_vec(width, height, vec![floor; width * height])
        .expect("the buffer has the frame's size");
    let (w, h) = filtered.dimensions();
    for y in 0..h.min(height.saturating_sub(roi.y0)) {
        let columns = w.min(width.saturating_sub(roi.x0));
        placed.row_mut(roi.y0 + y)[roi.x0..roi.x0 + columns]
            .copy_from_slice(&filtered.row(y)[..columns]);
    }
    placed
}

/// Histogram of the values of every local maximum (window `2n+1`) of `filtered`, over the
/// range of those values and the threshold.
fn maxima_histogram(filtered: &GrayImage, n: usize, threshold: Option<f32>) -> StrengthHistogram {
    let mut peaks: Vec<Peak> = Vec::new();
    PeakFinder::new().find(filtered, n, f32::NEG_INFINITY, &mut peaks);
    let values: Vec<f32> = peaks
        .iter()
        .map(|p| filtered.get(p.x, p.y))
        .filter(|v| v.is_finite())
        .collect();
    let (mut lo, mut hi) = values
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if let Some(t) = threshold.filter(|t| t.is_finite()) {
        (lo, hi) = (lo.min(t), hi.max(t));
    }
    let mut counts = vec![0u32; HISTOGRAM_BINS];
    if !(lo.is_finite() && hi.is_finite()) {
        return StrengthHistogram {
            lo: 0.0,
            hi: 1.0,
            counts,
        };
    }
    if hi <= lo {
        hi = lo + 1e-6;
    }
    let scale = HISTOGRAM_BINS as f32 / (hi - lo);
    for v in values {
        let bin = (((v - lo) * scale) as usize).min(HISTOGRAM_BINS - 1);
        counts[bin] += 1;
    }
    StrengthHistogram { lo, hi, counts }
}

/// `v` rounded to 0.01 (sub-pixel positions; the page needs no more).
fn round_centi(v: f64) -> f32 {
    ((v * 100.0).round() / 100.0) as f32
}

/// `image` as an 8-bit grey PNG, grey levels stretched from their minimum to their maximum.
fn encode_png(image: &GrayImage) -> Result<Vec<u8>> {
    let (lo, hi) = image
        .as_slice()
        .iter()
        .filter(|v| v.is_finite())
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let span = if hi > lo { hi - lo } else { 1.0 };
    let bytes: Vec<u8> = image
        .as_slice()
        .iter()
        .map(|&v| (((v - lo) / span).clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect();
    let (width, height) = image.dimensions();
    let grey = ::image::GrayImage::from_raw(width as u32, height as u32, bytes)
        .ok_or_else(|| Error::input("frame buffer of the wrong size"))?;
    let mut png = Vec::new();
    grey.write_to(
        &mut std::io::Cursor::new(&mut png),
        ::image::ImageFormat::Png,
    )
    .map_err(|e| Error::input(format!("cannot encode the frame as PNG: {e}")))?;
    Ok(png)
}

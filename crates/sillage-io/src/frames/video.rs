//! Video files read through the `ffmpeg` program as a subprocess (no FFmpeg library is
//! linked, so the default build stays pure Rust). Frames are decoded as 16-bit grey
//! (`-pix_fmt gray16le`), so 8-bit and 16-bit videos both land in `[0, 1]`; colour video
//! is converted to grey by FFmpeg's scaler. When colour is requested they are decoded as
//! 8-bit RGB (`-pix_fmt rgb24`) instead, and grey is derived from it with the Rec. 601 luma
//! of [`super::decode`], as for colour image files.

use std::io::Read;
use std::path::Path;
use std::process::{Child, Command, Stdio};

use sillage_core::{Error, GrayImage, Result, RgbImage};

use super::decode::{DecodeResult, Decoded, to_luma, u8_unit};

/// Size and (when the container records it) frame count of a video's first video stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct VideoInfo {
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) frames: Option<usize>,
}

/// The error of a failed start of `program` (`ffmpeg`, `ffprobe`): when it is not installed,
/// what needs it (`purpose`), how to install it and what to do instead (`otherwise`).
pub(super) fn missing_program(
    program: &Path,
    source: std::io::Error,
    purpose: &str,
    otherwise: &str,
) -> Error {
    if source.kind() == std::io::ErrorKind::NotFound {
        Error::MissingProgram {
            program: program.display().to_string(),
            hint: format!(
                "{purpose} through FFmpeg: install it (`apt-get install ffmpeg` on \
                 Debian/Ubuntu, `brew install ffmpeg` on macOS), or {otherwise}"
            ),
        }
    } else {
        Error::io(program, source)
    }
}

/// [`missing_program`] for reading videos.
fn missing_reader(program: &Path, source: std::io::Error) -> Error {
    missing_program(
        program,
        source,
        "videos are read",
        "convert the video to an image sequence",
    )
}

/// Reads the size and frame count of `video` with `ffprobe`.
pub(crate) fn probe(ffprobe: &Path, video: &Path) -> Result<VideoInfo> {
    let output = Command::new(ffprobe)
        .args(["-v", "error", "-select_streams", "v:0"])
        .args(["-show_entries", "stream=width,height,nb_frames"])
        .args(["-of", "csv=p=0"])
        .arg(video)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| missing_reader(ffprobe, e))?;
    let bad = |why: String| {
        Error::format(
            video,
            None,
            format!("{why}; check that it is a video file, or convert it to an image sequence"),
        )
    };
    if !output.status.success() {
        return Err(bad(format!(
            "ffprobe cannot read it ({})",
            String::from_utf8_lossy(&output.stderr).trim()
        )));
    }
    let text = String::from_utf8_lossy(&output.stdout);
    let line = text.lines().next().unwrap_or("").trim();
    let fields: Vec<&str> = line.split(',').map(str::trim).collect();
    let size = |i: usize| fields.get(i).and_then(|f| f.parse::<usize>().ok());
    match (size(0), size(1)) {
        (Some(width), Some(height)) if width > 0 && height > 0 => Ok(VideoInfo {
            width,
            height,
            frames: size(2).filter(|&n| n > 0),
        }),
        _ => Err(bad(format!(
            "ffprobe found no video stream (it said `{line}`)"
        ))),
    }
}

/// A running `ffmpeg` that writes raw frames on its stdout: 16-bit grey, or 8-bit RGB when
/// colour was requested.
#[derive(Debug)]
pub(crate) struct FfmpegDecoder {
    child: Child,
    colour: bool,
}

impl FfmpegDecoder {
    /// Starts `ffmpeg` on `video`, asking for RGB frames when `colour` is true.
    pub(crate) fn spawn(ffmpeg: &Path, video: &Path, colour: bool) -> Result<Self> {
        let pixel_format = if colour { "rgb24" } else { "gray16le" };
        let child = Command::new(ffmpeg)
            .args(["-v", "error", "-nostdin", "-i"])
            .arg(video)
            .args(["-f", "rawvideo", "-pix_fmt", pixel_format, "-"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| missing_reader(ffmpeg, e))?;
        Ok(Self { child, colour })
    }

    /// Hands the frames to `emit` in order until it returns `false` or the video ends; a
    /// failure is handed over as `Err(message)` and ends the reading.
    pub(crate) fn read_frames(
        mut self,
        info: VideoInfo,
        mut emit: impl FnMut(DecodeResult<Decoded>) -> bool,
    ) {
        let (Some(mut stdout), Some(mut stderr)) =
            (self.child.stdout.take(), self.child.stderr.take())
        else {
            emit(Err("ffmpeg started without its output pipes".into()));
            return;
        };
        // Drained on its own thread so a chatty ffmpeg never blocks on a full stderr pipe.
        let stderr_reader = std::thread::spawn(move || {
            let mut text = String::new();
            let _ = stderr.read_to_string(&mut text);
            text
        });
        let bytes_per_pixel = if self.colour { 3 } else { 2 };
        let mut bytes = vec![0u8; info.width * info.height * bytes_per_pixel];
        let finished = loop {
            match read_full(&mut stdout, &mut bytes) {
                Ok(0) => break true,
                Ok(n) if n < bytes.len() => {
                    emit(Err(format!(
                        "the video ended in the middle of a frame ({n} of {} bytes)",
                        bytes.len()
                    )));
                    break false;
                }
                Ok(_) => {
                    if !emit(raw_frame(&bytes, info, self.colour)) {
                        break false;
                    }
                }
                Err(e) => {
                    emit(Err(format!("cannot read ffmpeg's output: {e}")));
                    break false;
                }
            }
        };
        if !finished {
            // Stopped early (consumer gone or error): ffmpeg is no longer needed.
            let _ = self.child.kill();
        }
        drop(stdout);
        let status = self.child.wait();
        let messages = stderr_reader.join().unwrap_or_default();
        if finished {
            match status {
                Ok(s) if s.success() => {}
                Ok(s) => {
                    emit(Err(format!("ffmpeg failed ({s}): {}", messages.trim())));
                }
                Err(e) => {
                    emit(Err(format!("cannot wait for ffmpeg: {e}")));
                }
            }
        }
    }
}

impl Drop for FfmpegDecoder {
    fn drop(&mut self) {
        // Never leave a running or zombie ffmpeg behind; both calls are no-ops once it exited.
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// One raw frame from ffmpeg: little-endian 16-bit grey, or (`colour`) 8-bit RGB whose grey
/// is its Rec. 601 luma.
fn raw_frame(bytes: &[u8], info: VideoInfo, colour: bool) -> DecodeResult<Decoded> {
    let (w, h) = (info.width, info.height);
    if colour {
        let grey = to_luma(bytes, 3, u8_unit);
        let pixels = bytes.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        Ok(Decoded {
            grey: GrayImage::from_vec(w, h, grey).map_err(|e| e.to_string())?,
            colour: Some(RgbImage::from_vec(w, h, pixels).map_err(|e| e.to_string())?),
        })
    } else {
        let pixels = bytes
            .chunks_exact(2)
            .map(|b| f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0)
            .collect();
        Ok(Decoded {
            grey: GrayImage::from_vec(w, h, pixels).map_err(|e| e.to_string())?,
            colour: None,
        })
    }
}

/// Reads until `buf` is full or the stream ends; returns the number of bytes read.
fn read_full(reader: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match reader.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

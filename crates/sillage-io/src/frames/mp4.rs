//! Videos written through the `ffmpeg` program: raw RGB frames piped to its standard input
//! and encoded as H.264 (`libx264`) in an MP4, or as MPEG-4 part 2 where this FFmpeg has no
//! `libx264`. The file is written as `.NAME.partial` and renamed when complete.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::thread::JoinHandle;

use sillage_core::{Error, Result, RgbImage};

use super::video::missing_program;
use crate::WrittenSummary;
use crate::partial::write_target;

/// A running `ffmpeg` encoding the frames it is given into an MP4.
#[derive(Debug)]
pub struct Mp4Writer {
    child: Child,
    stdin: Option<ChildStdin>,
    stderr: Option<JoinHandle<String>>,
    final_path: PathBuf,
    partial_path: PathBuf,
    size: (usize, usize),
    codec: &'static str,
    frames: u64,
    finished: bool,
}

impl Mp4Writer {
    /// Starts `ffmpeg` (a name looked up on `PATH`, or a path) writing `path` at `fps` frames
    /// per second from frames of `width × height` px; odd sizes get one black row or column
    /// more, as H.264 in 4:2:0 needs even sizes.
    pub fn create(
        path: &Path,
        width: usize,
        height: usize,
        fps: f64,
        ffmpeg: &Path,
    ) -> Result<Self> {
        if !(fps.is_finite() && fps > 0.0) {
            return Err(Error::parameter(
                "fps",
                fps,
                "give a frame rate > 0, e.g. 10",
            ));
        }
        if width == 0 || height == 0 {
            return Err(Error::input(format!(
                "{}: cannot encode {width}x{height} frames",
                path.display()
            )));
        }
        let codec = if has_encoder(ffmpeg, "libx264")? {
            "libx264"
        } else {
            "mpeg4"
        };
        let partial_path = write_target(path)?;
        let mut child = Command::new(ffmpeg)
            .args([
                "-y", "-v", "error", "-nostdin", "-f", "rawvideo", "-pix_fmt", "rgb24",
            ])
            .args([
                "-s",
                &format!("{width}x{height}"),
                "-r",
                &fps.to_string(),
                "-i",
                "-",
            ])
            .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", codec])
            .args(if codec == "mpeg4" {
                ["-q:v", "3"]
            } else {
                ["-crf", "20"]
            })
            .args(["-pix_fmt", "yuv420p", "-f", "mp4"])
            .arg(&partial_path)
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| missing(ffmpeg, e))?;
        let stdin = child.stdin.take();
        let stderr = child.stderr.take().map(|mut pipe| {
            // Drained on its own thread so a chatty ffmpeg never blocks on a full pipe.
            std::thread::spawn(move || {
                let mut text = String::new();
                let _ = pipe.read_to_string(&mut text);
                text
            })
        });
        Ok(Self {
            child,
            stdin,
            stderr,
            final_path: path.to_path_buf(),
            partial_path,
            size: (width, height),
            codec,
            frames: 0,
            finished: false,
        })
    }

    /// The encoder in use: `libx264`, or `mpeg4` where FFmpeg has no `libx264`.
    pub fn codec(&self) -> &'static str {
        self.codec
    }

    /// Encodes `frame`, which must have the size given to [`Mp4Writer::create`].
    pub fn push(&mut self, frame: &RgbImage) -> Result<()> {
        if frame.dimensions() != self.size {
            return Err(Error::input(format!(
                "{}: frame {} is {}x{} px, the video {}x{} px; every frame must have the size \
                 of the first",
                self.final_path.display(),
                self.frames,
                frame.width(),
                frame.height(),
                self.size.0,
                self.size.1
            )));
        }
        let stdin = self.stdin.as_mut().expect("stdin is held until finish");
        if let Err(e) = stdin.write_all(frame.as_slice().as_flattened()) {
            let said = self.stop();
            return Err(Error::input(format!(
                "{}: ffmpeg stopped at frame {} ({e}): {said}",
                self.final_path.display(),
                self.frames
            )));
        }
        self.frames += 1;
        Ok(())
    }

    /// Closes the input, waits for `ffmpeg` and renames the file; returns the number of
    /// frames (as `rows`) and the final path.
    pub fn finish(mut self) -> Result<WrittenSummary> {
        drop(self.stdin.take());
        let status = self
            .child
            .wait()
            .map_err(|e| Error::io(&self.partial_path, e))?;
        let said = self
            .stderr
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        if !status.success() {
            return Err(Error::input(format!(
                "{}: ffmpeg failed ({status}): {}",
                self.final_path.display(),
                said.trim()
            )));
        }
        if self.partial_path != self.final_path {
            std::fs::rename(&self.partial_path, &self.final_path)
                .map_err(|e| Error::io(&self.final_path, e))?;
        }
        self.finished = true;
        Ok(WrittenSummary {
            rows: self.frames,
            path: self.final_path.clone(),
        })
    }

    /// Ends `ffmpeg` after a failed write; returns what it said.
    fn stop(&mut self) -> String {
        drop(self.stdin.take());
        let _ = self.child.wait();
        let said = self
            .stderr
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        said.trim().to_owned()
    }
}

impl Drop for Mp4Writer {
    fn drop(&mut self) {
        if !self.finished {
            // Abandoned (an error upstream): no ffmpeg left running, no partial file kept.
            let _ = self.child.kill();
            let _ = self.child.wait();
            if self.partial_path != self.final_path {
                let _ = std::fs::remove_file(&self.partial_path);
            }
        }
    }
}

/// Whether `ffmpeg -encoders` lists `encoder`.
fn has_encoder(ffmpeg: &Path, encoder: &str) -> Result<bool> {
    let output = Command::new(ffmpeg)
        .args(["-hide_banner", "-encoders"])
        .stdin(Stdio::null())
        .output()
        .map_err(|e| missing(ffmpeg, e))?;
    let text = String::from_utf8_lossy(&output.stdout);
    Ok(text
        .lines()
        .any(|line| line.split_whitespace().nth(1) == Some(encoder)))
}

/// [`missing_program`] for writing videos.
fn missing(ffmpeg: &Path, source: std::io::Error) -> Error {
    missing_program(
        ffmpeg,
        source,
        "MP4 videos are written",
        "leave out the video and use the PNG frames",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_ffmpeg_says_how_to_install_it() {
        let dir = tempfile::tempdir().unwrap();
        let e = Mp4Writer::create(
            &dir.path().join("a.mp4"),
            4,
            4,
            10.0,
            Path::new("/nonexistent/ffmpeg"),
        )
        .unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("apt-get install ffmpeg") && text.contains("PNG frames"),
            "{text}"
        );
    }

    #[test]
    fn frames_become_an_mp4_of_their_size() {
        let ffmpeg = Path::new("ffmpeg");
        if Command::new(ffmpeg).arg("-version").output().is_err() {
            eprintln!("skipped: ffmpeg is not installed (apt-get install ffmpeg)");
            return;
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("clip.mp4");
        let mut writer = Mp4Writer::create(&path, 33, 20, 5.0, ffmpeg).unwrap();
        for k in 0..6u8 {
            let frame =
                RgbImage::from_vec(33, 20, vec![[40 * k, 0, 255 - 40 * k]; 33 * 20]).unwrap();
            writer.push(&frame).unwrap();
        }
        let wrong = RgbImage::new(8, 8);
        assert!(writer.push(&wrong).unwrap_err().to_string().contains("8x8"));
        let summary = writer.finish().unwrap();
        assert_eq!(summary.rows, 6);
        let info = super::super::video::probe(Path::new("ffprobe"), &path).unwrap();
        // Padded to even sizes.
        assert_eq!((info.width, info.height), (34, 20));
        assert_eq!(info.frames, Some(6));
        // No partial file left beside it.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}

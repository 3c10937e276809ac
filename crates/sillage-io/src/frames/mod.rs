//! Frame sources: image folders, glob patterns, single images, multi-page TIFF stacks and
//! videos (through the `ffmpeg` program), decoded on a background thread with a bounded
//! read-ahead queue so memory stays bounded whatever the length of the sequence.

mod bad_frames;
mod ccitt;
mod decode;
mod encode;
mod input;
mod lzw;
mod mp4;
mod strips;
mod tiff_stack;
mod video;

use std::path::{Path, PathBuf};
use std::thread::JoinHandle;

use crossbeam_channel::{Receiver, Sender};
use sillage_core::{Error, FrameIndex, GrayImage, Result, RgbImage};

pub use bad_frames::{BadFramePolicy, SkippedFrame, SkippedFrames};
pub use decode::{read_image, read_image_from_bytes};
pub use encode::{write_png_rgb, write_png16, write_text};
pub use mp4::Mp4Writer;

use decode::Decoded;
use input::InputKind;
use video::{FfmpegDecoder, VideoInfo};

/// How frames are read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameOptions {
    /// Frames decoded ahead of the consumer (the bounded queue's capacity); default 4.
    pub read_ahead: usize,
    /// Stop after this many frames (`None`: read them all).
    pub max_frames: Option<usize>,
    /// The `ffmpeg` program used for videos (a name looked up on `PATH`, or a path).
    pub ffmpeg: PathBuf,
    /// The `ffprobe` program used to read a video's size.
    pub ffprobe: PathBuf,
    /// Also decode each frame's 8-bit colour into [`Frame::colour`] (for colour-histogram
    /// observation models); default false, so grey-only pipelines pay nothing for it.
    pub colour: bool,
    /// What to do with a frame that cannot be read or is missing from a numbered sequence
    /// (see [`BadFramePolicy`]); default: stop.
    pub on_bad_frame: BadFramePolicy,
    /// Frames of a lower index are passed over (a resumed run): files are not even decoded,
    /// pages and video frames are decoded and dropped. Default 0.
    pub start_at: FrameIndex,
    /// Frames of this index and above are not read (a time window of a longer run); `None`:
    /// read to the end.
    pub stop_at: Option<FrameIndex>,
}

impl Default for FrameOptions {
    fn default() -> Self {
        Self {
            read_ahead: 4,
            max_frames: None,
            ffmpeg: "ffmpeg".into(),
            ffprobe: "ffprobe".into(),
            colour: false,
            on_bad_frame: BadFramePolicy::Stop,
            start_at: 0,
            stop_at: None,
        }
    }
}

/// One decoded frame.
#[derive(Debug, Clone)]
pub struct Frame {
    /// 0-based index in the sequence.
    pub index: FrameIndex,
    /// The file it was read from (the stack or video file for pages and video frames).
    pub path: PathBuf,
    /// Grey levels in `[0, 1]`.
    pub image: GrayImage,
    /// 8-bit colour (16-bit samples rounded to 8 bits, grey replicated into the three
    /// channels), present when [`FrameOptions::colour`] was set.
    pub colour: Option<RgbImage>,
}

/// A sequence of frames, decoded ahead on a background thread.
///
/// Iterate it to get `Result<Frame>` in order; after the first error it ends. Dropping it
/// early stops the reading thread (and `ffmpeg`, for a video).
#[derive(Debug)]
pub struct FrameSource {
    receiver: Option<Receiver<Result<Frame>>>,
    worker: Option<JoinHandle<()>>,
    len: Option<usize>,
    dimensions: (usize, usize),
    paths: Vec<PathBuf>,
    skipped: SkippedFrames,
    ended: bool,
}

/// Opens `input`: a folder (its .tif/.tiff/.png/.jpg/.jpeg/.bmp files in natural name order),
/// a glob pattern (`"dir/*.tif"`), a single image, a multi-page TIFF (one frame per page) or a
/// video (.avi/.mp4/.mov/.mkv, read through `ffmpeg`).
///
/// Pixels become grey levels in `[0, 1]`: 8-bit values / 255, 16-bit / 65535, 32-bit float
/// grey TIFF kept as is; colour is converted with the Rec. 601 luma weights
/// `0.299 R + 0.587 G + 0.114 B` (as OpenCV's, so frames match TracTrac's) and alpha is
/// dropped. In a folder or glob every file is one frame (a TIFF's first page).
///
/// With [`FrameOptions::colour`] each frame also carries its 8-bit colour; a video is then
/// decoded as RGB and its grey derived with the same Rec. 601 weights.
///
/// A frame's index is its position in the sequence; in a folder or glob whose names are
/// numbered (`img_0001.tif` …), the frame number's offset from the first one's, so that a
/// frame missing from the numbering is a gap: an error with [`BadFramePolicy::Stop`], a
/// skipped index with [`BadFramePolicy::Skip`], which also goes on past frames that do not
/// decode or have the wrong size ([`FrameSource::skipped`] lists them).
///
/// The first frame's size is read here, so a missing or unreadable input fails now rather
/// than on the first iteration.
pub fn open_frames(input: &str, options: &FrameOptions) -> Result<FrameSource> {
    let limit = |n: usize| options.max_frames.map_or(n, |m| m.min(n));
    let colour = options.colour;
    let skipped = SkippedFrames::default();
    let (sender, receiver) = crossbeam_channel::bounded(options.read_ahead);
    let reading = Reading {
        sender,
        max_frames: options.max_frames,
        policy: options.on_bad_frame,
        skipped: skipped.clone(),
        start_at: options.start_at,
        stop_at: options.stop_at,
    };
    let (len, dimensions, paths, worker) = match input::resolve(input)? {
        InputKind::Files(mut files) => {
            let first = &files[0];
            let dimensions = decode::file_dimensions(first)
                .map_err(|message| Error::frame(first, 0, decode_failure(&message)))?;
            files.truncate(limit(files.len()));
            let mut indices = bad_frames::indices_under(&files, options.on_bad_frame, &skipped)?;
            let passed_over = indices.partition_point(|&i| i < options.start_at);
            files.drain(..passed_over);
            indices.drain(..passed_over);
            if let Some(stop_at) = options.stop_at {
                let kept = indices.partition_point(|&i| i < stop_at);
                files.truncate(kept);
                indices.truncate(kept);
            }
            let len = files.len();
            let worker_files = files.clone();
            let worker = spawn(reading, dimensions, Some(indices), move |emitter| {
                read_files(&worker_files, colour, emitter);
            })?;
            (Some(len), dimensions, files, worker)
        }
        InputKind::TiffStack { path, pages } => {
            let dimensions = decode::file_dimensions(&path)
                .map_err(|message| Error::frame(&path, 0, decode_failure(&message)))?;
            let stack = path.clone();
            let worker = spawn(reading, dimensions, None, move |emitter| {
                tiff_stack::read_pages(&stack, colour, |page| match page {
                    Ok(image) => emitter.frame(&stack, image),
                    Err(message) => emitter.fail(&stack, decode_failure(&message)),
                });
            })?;
            (Some(limit(pages)), dimensions, vec![path], worker)
        }
        InputKind::Video(path) => {
            let info = video::probe(&options.ffprobe, &path)?;
            let decoder = FfmpegDecoder::spawn(&options.ffmpeg, &path, colour)?;
            let video = path.clone();
            let dimensions = (info.width, info.height);
            let worker = spawn(reading, dimensions, None, move |emitter| {
                read_video(decoder, info, &video, emitter);
            })?;
            (info.frames.map(limit), dimensions, vec![path], worker)
        }
    };
    Ok(FrameSource {
        receiver: Some(receiver),
        worker: Some(worker),
        len,
        dimensions,
        paths,
        skipped,
        ended: false,
    })
}

fn decode_failure(message: &str) -> String {
    format!("cannot decode: {message}; remove or replace the file")
}

/// Files decoded at once by the reading thread's helpers: a compressed TIFF decodes on one
/// core, so a few frames decode side by side; they are emitted in order.
const PARALLEL_DECODES: usize = 2;

fn read_files(files: &[PathBuf], colour: bool, emitter: &mut Emitter) {
    for group in files.chunks(PARALLEL_DECODES) {
        let decoded: Vec<_> = std::thread::scope(|scope| {
            let helpers: Vec<_> = group[1..]
                .iter()
                .map(|path| scope.spawn(move || decode::decode_file(path, colour)))
                .collect();
            let first = decode::decode_file(&group[0], colour);
            std::iter::once(first)
                .chain(helpers.into_iter().map(|helper| {
                    helper
                        .join()
                        .unwrap_or_else(|_| Err("the decoder stopped unexpectedly".to_string()))
                }))
                .collect()
        });
        for (path, result) in group.iter().zip(decoded) {
            let keep_going = match result {
                Ok(image) => emitter.frame(path, image),
                Err(message) => emitter.fail(path, decode_failure(&message)),
            };
            if !keep_going {
                return;
            }
        }
    }
}

fn read_video(decoder: FfmpegDecoder, info: VideoInfo, path: &Path, emitter: &mut Emitter) {
    decoder.read_frames(info, |frame| match frame {
        Ok(image) => emitter.frame(path, image),
        Err(message) => emitter.fail(
            path,
            format!(
                "cannot decode: {message}; check the video with `ffprobe`, or convert it to \
                 an image sequence"
            ),
        ),
    });
}

/// How the reading thread hands frames over: the queue, the frame limit, and what to do with
/// bad frames.
struct Reading {
    sender: Sender<Result<Frame>>,
    max_frames: Option<usize>,
    policy: BadFramePolicy,
    skipped: SkippedFrames,
    start_at: FrameIndex,
    stop_at: Option<FrameIndex>,
}

/// Starts the reading thread, which runs `read` with an [`Emitter`]; `indices` are the frame
/// indices of the files read in order (`None`: positions).
fn spawn(
    reading: Reading,
    dimensions: (usize, usize),
    indices: Option<Vec<FrameIndex>>,
    read: impl FnOnce(&mut Emitter) + Send + 'static,
) -> Result<JoinHandle<()>> {
    std::thread::Builder::new()
        .name("sillage-frames".into())
        .spawn(move || {
            let mut emitter = Emitter {
                reading,
                dimensions,
                indices,
                position: 0,
            };
            read(&mut emitter);
        })
        .map_err(|e| Error::input(format!("cannot start the frame-reading thread: {e}")))
}

/// The reading thread's end of the queue: numbers frames, checks their size, and tells the
/// reader when to stop (consumer gone, frame limit reached, or an error sent).
struct Emitter {
    reading: Reading,
    dimensions: (usize, usize),
    indices: Option<Vec<FrameIndex>>,
    /// Frames read so far, good or bad.
    position: usize,
}

impl Emitter {
    /// The index of the frame at the current position.
    fn index(&self) -> FrameIndex {
        self.indices
            .as_ref()
            .and_then(|indices| indices.get(self.position).copied())
            .unwrap_or(self.position as FrameIndex)
    }

    /// Whether the position is past the frame limit, or its index past the last to read.
    fn past_limit(&self) -> bool {
        self.reading.max_frames.is_some_and(|m| self.position >= m)
            || self
                .reading
                .stop_at
                .is_some_and(|stop| self.index() >= stop)
    }

    /// Sends one decoded frame; `false` means stop reading.
    fn frame(&mut self, path: &Path, decoded: Decoded) -> bool {
        let Decoded {
            grey: image,
            colour,
        } = decoded;
        if self.past_limit() {
            return false;
        }
        let index = self.index();
        if index < self.reading.start_at {
            self.position += 1;
            return true;
        }
        if image.dimensions() != self.dimensions {
            let (w0, h0) = self.dimensions;
            let (w, h) = image.dimensions();
            return self.fail(
                path,
                format!(
                    "frame is {w}×{h} pixels but the first frame is {w0}×{h0}; all frames of a \
                     sequence must have the same size (crop or resize them, or split the sequence)"
                ),
            );
        }
        let frame = Frame {
            index,
            path: path.to_path_buf(),
            image,
            colour,
        };
        self.position += 1;
        self.reading.sender.send(Ok(frame)).is_ok() && !self.past_limit()
    }

    /// The current frame is bad: with [`BadFramePolicy::Stop`] sends its error and returns
    /// `false` (stop reading); with [`BadFramePolicy::Skip`] records it and goes on.
    fn fail(&mut self, path: &Path, message: String) -> bool {
        let index = self.index();
        match self.reading.policy {
            BadFramePolicy::Stop => {
                // If the consumer is gone nobody needs the error.
                let _ = self
                    .reading
                    .sender
                    .send(Err(Error::frame(path, index, message)));
                false
            }
            BadFramePolicy::Skip => {
                self.reading.skipped.push(SkippedFrame {
                    index,
                    path: path.to_path_buf(),
                    reason: message,
                });
                self.position += 1;
                !self.past_limit()
            }
        }
    }
}

impl FrameSource {
    /// Number of frames, when known in advance (image files, TIFF pages, and videos whose
    /// container records it): for progress bars.
    #[expect(
        clippy::len_without_is_empty,
        reason = "a length hint for progress bars; an opened source always has a first frame"
    )]
    pub fn len(&self) -> Option<usize> {
        self.len
    }

    /// `(width, height)` of the first frame; every frame must have this size.
    pub fn dimensions(&self) -> (usize, usize) {
        self.dimensions
    }

    /// The files read, in order: every image of a folder or glob, or the one stack or video.
    pub fn paths(&self) -> &[PathBuf] {
        &self.paths
    }

    /// The frames skipped under [`BadFramePolicy::Skip`]: a handle that stays readable after
    /// the source is consumed.
    pub fn skipped(&self) -> SkippedFrames {
        self.skipped.clone()
    }
}

impl Iterator for FrameSource {
    type Item = Result<Frame>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.ended {
            return None;
        }
        let received = self.receiver.as_ref().map(Receiver::recv);
        match received {
            Some(Ok(Ok(frame))) => Some(Ok(frame)),
            Some(Ok(Err(error))) => {
                self.ended = true;
                Some(Err(error))
            }
            Some(Err(_)) | None => {
                self.ended = true;
                self.stop();
                None
            }
        }
    }
}

impl FrameSource {
    /// Closes the queue (which makes the reader's next send fail) and joins the thread; a
    /// panic there is a bug and is passed on.
    fn stop(&mut self) {
        self.receiver = None;
        if let Some(worker) = self.worker.take()
            && let Err(panic) = worker.join()
            && !std::thread::panicking()
        {
            std::panic::resume_unwind(panic);
        }
    }
}

impl Drop for FrameSource {
    fn drop(&mut self) {
        self.stop();
    }
}

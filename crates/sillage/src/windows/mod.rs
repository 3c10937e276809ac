//! Time windows: a long sequence split into overlapping windows of `W` frames, each tracked on
//! its own (on local threads here, on Dask workers from Python), then joined by the stitcher
//! ([`sillage_track::stitch`]) into one set of trajectories.
//!
//! Every window runs the same configuration. What a run decides once on its first frames
//! (the blob scale and polarity, PTV's displacement voting, under `"auto"`) is decided once
//! on the sequence's first frames and given to every window ([`Measured`]), so that all
//! windows detect and link alike; the background model starts from each window's own first
//! frames; particle filters draw from seeds derived from the window's index
//! ([`window_seed`]), window 0 keeping the run's seed. The result depends on `W`, the overlap
//! and the seed, never on how many windows run at once.
//!
//! ```no_run
//! use sillage::windows::{WindowPlan, WindowedRun};
//! use sillage::Tracking;
//! use sillage::core::TrackPoint;
//!
//! let tracking = Tracking::Pipeline(Box::default());
//! let plan = WindowPlan::for_source("experiment/*.tif", 500, 20, &tracking)?;
//! let mut points: Vec<TrackPoint> = Vec::new();
//! let run = WindowedRun::new(&tracking, plan).jobs(4);
//! let summary = run.run("experiment/*.tif", &mut points, &mut |_| {})?;
//! println!("{} windows, {} tracks", summary.windows, summary.tracks);
//! # Ok::<(), sillage::core::Error>(())
//! ```

mod agreement;
mod measured;
mod run;
mod wire;

pub use agreement::{WindowAgreement, agreement};
pub use measured::{Measured, Voting};
pub use run::{WindowedRun, WindowedSummary};
pub use wire::{
    decode_edges, decode_ids, decode_plan, decode_seam, decode_window, encode_edges, encode_ids,
    encode_plan, encode_seam, encode_window,
};

use serde::Serialize;
use sillage_core::{Error, FrameIndex, Result, TrackPoint};
use sillage_io::{Frame, FrameOptions, open_frames};
use sillage_track::stitch::{StitchParams, WindowTracks};

use crate::config::{PipelineConfig, TrackerConfig};
use crate::pipeline::Pipeline;
use crate::tracking::{Tracking, track_source};

/// One window: its place in the plan and its frames `first..=last`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Window {
    /// 0-based position in the plan (also what its seed derives from).
    pub index: usize,
    /// First frame.
    pub first: FrameIndex,
    /// Last frame.
    pub last: FrameIndex,
}

impl Window {
    /// The frame options that read this window's frames.
    pub fn frame_options(&self) -> FrameOptions {
        FrameOptions {
            start_at: self.first,
            stop_at: Some(self.last + 1),
            ..FrameOptions::default()
        }
    }
}

/// How a sequence of `frames` frames is cut: windows of `window` frames, consecutive ones
/// sharing `overlap` frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct WindowPlan {
    /// Frames in the sequence.
    pub frames: u64,
    /// Frames per window (the last may be longer, up to `window + window / 2`).
    pub window: usize,
    /// Frames shared by consecutive windows.
    pub overlap: usize,
}

/// The overlap the command line and Python use when none is given, frames. Chosen on the
/// vortex seeds 21–22 (512², 1,500 particles, windows of 60 frames, overlaps 4–20 tried):
/// 16 frames kept one identity for 99.96 % and 99.64 % of the trajectories crossing a seam
/// (6–12 frames: 99.2–99.7 %; 4: 96.7–97.0 %). On the unseen seed 11 (`tests/windows.rs`):
/// 99.91 % of 2,225 trajectories keep one identity, 99.9997 % of the points are found.
pub const DEFAULT_OVERLAP: usize = 16;

/// Fewest frames an overlap may have: the stitcher pairs tracks on the frames both windows
/// have points in, and PTV's windows have none in their first and last frame.
pub const MIN_OVERLAP: usize = 4;

impl WindowPlan {
    /// The plan for `frames` frames with windows of `window` frames overlapping by `overlap`;
    /// refused, with the fix, when the overlap is below [`MIN_OVERLAP`] or above half the
    /// window (seams would overlap each other), or a window is shorter than
    /// `min_window` frames (the tracker's least, [`min_window`]).
    pub fn new(frames: u64, window: usize, overlap: usize, min_window: usize) -> Result<Self> {
        if window < min_window {
            return Err(Error::parameter(
                "window",
                window,
                format!("this tracker needs windows of at least {min_window} frames"),
            ));
        }
        if overlap >= window {
            return Err(Error::parameter(
                "overlap",
                overlap,
                format!(
                    "the overlap must be shorter than the window ({window} frames); at most \
                     half of it ({})",
                    window / 2
                ),
            ));
        }
        if 2 * overlap > window {
            return Err(Error::parameter(
                "overlap",
                overlap,
                format!(
                    "at most half the window ({} of {window} frames), or seams would overlap; \
                     lengthen the window or shorten the overlap",
                    window / 2
                ),
            ));
        }
        if overlap < MIN_OVERLAP {
            return Err(Error::parameter(
                "overlap",
                overlap,
                format!("give at least {MIN_OVERLAP} frames, so that tracks can be joined"),
            ));
        }
        if frames < min_window as u64 {
            return Err(Error::input(format!(
                "the sequence has {frames} frames; this tracker needs at least {min_window}"
            )));
        }
        Ok(Self {
            frames,
            window,
            overlap,
        })
    }

    /// [`WindowPlan::new`] for the frames of `source` ([`frame_count`]) and the least window
    /// of `tracking`.
    pub fn for_source(
        source: &str,
        window: usize,
        overlap: usize,
        tracking: &Tracking,
    ) -> Result<Self> {
        Self::new(frame_count(source)?, window, overlap, min_window(tracking))
    }

    /// The windows, in order: they start every `window − overlap` frames; a last window
    /// shorter than half a window (or than its overlap allows) is merged into the one before.
    pub fn windows(&self) -> Vec<Window> {
        let step = (self.window - self.overlap) as u64;
        let shortest = (self.window as u64)
            .div_ceil(2)
            .max(2 * self.overlap as u64);
        let mut windows: Vec<Window> = Vec::new();
        let mut first = 0;
        loop {
            let last = (first + self.window as u64 - 1).min(self.frames - 1);
            match windows.last_mut() {
                Some(previous) if last - first + 1 < shortest => previous.last = last,
                _ => windows.push(Window {
                    index: windows.len(),
                    first,
                    last,
                }),
            }
            if last + 1 >= self.frames {
                return windows;
            }
            first += step;
        }
    }
}

/// The number of frames of `source` (a folder, glob, TIFF stack or video), which windows
/// need; an error naming the fix for a video that does not record it.
pub fn frame_count(source: &str) -> Result<u64> {
    let frames = open_frames(source, &FrameOptions::default())?.len();
    frames.map(|n| n as u64).ok_or_else(|| {
        Error::input(format!(
            "{source}: the number of frames is unknown (a video without a frame count); \
             windows need it: convert the video to an image sequence"
        ))
    })
}

/// Fewest frames a window of `tracking` may have: 3 for PTV (a point is the middle of three
/// linked frames), 2 for the others.
pub fn min_window(tracking: &Tracking) -> usize {
    match tracking {
        Tracking::Pipeline(config) if matches!(config.tracker, TrackerConfig::Ptv(_)) => 3,
        _ => 2,
    }
}

/// Frames a window of `tracking` is run for before its first frame, its output there dropped:
/// the pedestrian trackers' motion detector learns its background over its start-up phase
/// (`bootstrap_frames`, 20 for the IMM-PF), and a window starting with it empty reports the
/// people standing in its first frame as ghosts. PTV and the bedload trackers start from their
/// first frames (their warm-up is a few frames, inside the overlap).
pub fn lead_in(tracking: &Tracking) -> u64 {
    let mixture = match tracking {
        Tracking::Pipeline(_) => return 0,
        Tracking::Immpf(setup) => &setup.settings.motion_detector.detector.mixture,
        Tracking::Siftpf(setup) => &setup.settings.motion_detector.mixture,
    };
    mixture.bootstrap_frames as u64
}

/// How the stitcher joins `tracking`'s windows. PTV's windows see identical detections: tracks
/// join within 1 px and a point is a duplicate within 0.01 px. The particle filters' estimates
/// of one object differ between windows by their random draws, so both distances are one
/// radius of agreement: 3 px for beads (a fifth of a bead's radius; set before measuring),
/// 15 px for people (half a person's width at PETS 2009's scale; raised from a first 10 px
/// after PETS windows joined few people, with no measurable change: `docs/scale.md`). Not
/// tuned on any figure reported.
pub fn stitch_params(tracking: &Tracking) -> StitchParams {
    let agree_px = match tracking {
        Tracking::Pipeline(config) => match config.tracker {
            TrackerConfig::Ptv(_) => return StitchParams::default(),
            TrackerConfig::Bedload(_) => 3.0,
        },
        Tracking::Immpf(_) | Tracking::Siftpf(_) => 15.0,
    };
    StitchParams {
        same_px: agree_px,
        join_px: agree_px,
    }
}

/// The seed of window `index` of a run seeded `seed`: `seed` itself for window 0 (so that it
/// matches the single run), else SplitMix64 of `seed` and the index.
pub fn window_seed(seed: u64, index: usize) -> u64 {
    if index == 0 {
        return seed;
    }
    let mut z = seed.wrapping_add((index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// `tracking` with its particle filters seeded for window `index` ([`window_seed`]).
pub fn for_window(tracking: &Tracking, index: usize) -> Tracking {
    let mut tracking = tracking.clone();
    match &mut tracking {
        Tracking::Pipeline(config) => seed_for_window(config, index),
        Tracking::Immpf(setup) => setup.seed = window_seed(setup.seed, index),
        Tracking::Siftpf(setup) => setup.seed = window_seed(setup.seed, index),
    }
    tracking
}

/// Seeds the bedload tracker of `config` for window `index` (PTV draws nothing at random).
fn seed_for_window(config: &mut PipelineConfig, index: usize) {
    if let TrackerConfig::Bedload(params) = &mut config.tracker {
        params.seed = window_seed(params.seed, index);
    }
}

/// Tracks one window of `source`: its points with the window's own ids, for the stitcher.
/// `measured` is what the run decided on the sequence's first frames ([`Measured`]); with
/// [`Measured::default`] a window decides on its own.
pub fn track_window(
    source: &str,
    tracking: &Tracking,
    window: &Window,
    measured: &Measured,
) -> Result<WindowTracks> {
    if let Tracking::Pipeline(config) = tracking {
        return track_window_frames(config, window, measured, || {
            open_frames(source, &window.frame_options())
        });
    }
    // The pedestrian trackers' motion detector learns its background from a lead-in before
    // the window; what the tracker reports there is dropped.
    let pedestrians = for_window(tracking, window.index);
    let frames = FrameOptions {
        start_at: window.first.saturating_sub(lead_in(&pedestrians)),
        ..window.frame_options()
    };
    let mut points: Vec<TrackPoint> = Vec::new();
    track_source(source, &pedestrians, &frames, &mut points, &mut || {})?;
    points.retain(|p| p.frame >= window.first);
    Ok(WindowTracks {
        first: window.first,
        last: window.last,
        points,
    })
}

/// Tracks one window with PTV or a bedload tracker, its frames opened by `frames` (a file
/// source, or the frames of a numpy array on a Dask worker), indexed as in the sequence
/// (opened twice with background subtraction: once to start the model); `measured` as for
/// [`track_window`].
pub fn track_window_frames<I>(
    config: &PipelineConfig,
    window: &Window,
    measured: &Measured,
    frames: impl Fn() -> Result<I>,
) -> Result<WindowTracks>
where
    I: Iterator<Item = Result<Frame>>,
{
    let mut config = config.clone();
    seed_for_window(&mut config, window.index);
    let mut pipeline = Pipeline::from_config(&config)?;
    if pipeline.background_init_frames() > 0 {
        pipeline.prime_background(frames()?)?;
    }
    measured.adopt(&mut pipeline)?;
    let mut points = Vec::new();
    pipeline.run(frames()?, &mut points, &mut |_| {})?;
    Ok(WindowTracks {
        first: window.first,
        last: window.last,
        points,
    })
}

/// Runs `f` with its parallel kernels on `threads` threads of their own (a window's share of
/// the cores), or on the global pool for `None`.
pub fn on_threads<T: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> Result<T> + Send,
) -> Result<T> {
    match threads {
        None => f(),
        Some(threads) => rayon::ThreadPoolBuilder::new()
            .num_threads(threads.max(1))
            .build()
            .map_err(|e| Error::input(format!("cannot start {threads} threads: {e}")))?
            .install(f),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spans(plan: WindowPlan) -> Vec<(FrameIndex, FrameIndex)> {
        plan.windows().iter().map(|w| (w.first, w.last)).collect()
    }

    #[test]
    fn windows_cover_the_sequence_with_the_overlap() {
        let plan = WindowPlan::new(200, 60, 10, 3).unwrap();
        assert_eq!(spans(plan), [(0, 59), (50, 109), (100, 159), (150, 199)]);
        // A short last window joins the one before.
        let plan = WindowPlan::new(212, 60, 10, 3).unwrap();
        assert_eq!(spans(plan), [(0, 59), (50, 109), (100, 159), (150, 211)]);
        let plan = WindowPlan::new(40, 60, 10, 3).unwrap();
        assert_eq!(spans(plan), [(0, 39)]);
        for (frames, window, overlap) in [(1000, 37, 9), (97, 8, 4), (500, 100, 50)] {
            let windows = WindowPlan::new(frames, window, overlap, 3)
                .unwrap()
                .windows();
            assert_eq!(windows[0].first, 0);
            assert_eq!(windows.last().unwrap().last, frames - 1);
            for pair in windows.windows(2) {
                assert_eq!(pair[0].last + 1 - pair[1].first, overlap as u64);
                assert!(2 * overlap as u64 <= pair[1].last - pair[1].first + 1);
            }
        }
    }

    #[test]
    fn bad_plans_are_refused_with_the_fix() {
        let err = WindowPlan::new(100, 20, 20, 3).unwrap_err().to_string();
        assert!(
            err.contains("overlap") && err.contains("shorter than the window"),
            "{err}"
        );
        let err = WindowPlan::new(100, 20, 11, 3).unwrap_err().to_string();
        assert!(err.contains("at most half"), "{err}");
        let err = WindowPlan::new(100, 2, 1, 3).unwrap_err().to_string();
        assert!(err.contains("at least 3 frames"), "{err}");
        let err = WindowPlan::new(100, 20, 2, 3).unwrap_err().to_string();
        assert!(err.contains("at least 4"), "{err}");
        let err = WindowPlan::new(2, 20, 4, 3).unwrap_err().to_string();
        assert!(err.contains("2 frames"), "{err}");
    }

    #[test]
    fn window_seeds_are_distinct_and_the_first_is_the_run_seed() {
        assert_eq!(window_seed(7, 0), 7);
        let seeds: std::collections::BTreeSet<u64> = (0..1000).map(|k| window_seed(7, k)).collect();
        assert_eq!(seeds.len(), 1000);
    }
}

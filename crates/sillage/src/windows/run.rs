//! Windows tracked at once on local threads, stitched in order as they finish.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;

use serde::Serialize;
use sillage_core::{Result, TrackSink};
use sillage_track::stitch::{SeamReport, StitchParams, Stitcher, WindowTracks};

use super::{Measured, Window, WindowPlan, on_threads, stitch_params, track_window};
use crate::tracking::Tracking;

/// What a windowed run did.
#[derive(Debug, Clone, Serialize)]
pub struct WindowedSummary {
    /// Windows tracked.
    pub windows: usize,
    /// Windows tracked at once.
    pub jobs: usize,
    /// Track points written.
    pub points: u64,
    /// Trajectories (global identities).
    pub tracks: u64,
    /// Each seam's joins and duplicates.
    pub seams: Vec<SeamReport>,
}

/// A windowed run: a tracking, its plan, how many windows run at once and how they are
/// stitched.
#[derive(Debug, Clone)]
pub struct WindowedRun<'a> {
    tracking: &'a Tracking,
    plan: WindowPlan,
    jobs: usize,
    stitch: StitchParams,
}

impl<'a> WindowedRun<'a> {
    /// `tracking` over the windows of `plan`, one at a time, stitched with
    /// [`stitch_params`].
    pub fn new(tracking: &'a Tracking, plan: WindowPlan) -> Self {
        Self {
            tracking,
            plan,
            jobs: 1,
            stitch: stitch_params(tracking),
        }
    }

    /// Runs `jobs` windows at once (at least 1), each on its share of the cores for its
    /// parallel kernels (the last windows, fewer than `jobs`, on a larger share).
    pub fn jobs(mut self, jobs: usize) -> Self {
        self.jobs = jobs.max(1);
        self
    }

    /// Stitches with `params` instead of the tracker's defaults.
    pub fn stitch_params(mut self, params: StitchParams) -> Self {
        self.stitch = params;
        self
    }

    /// Tracks every window of `source`, handing the stitched points to `sink` in frame order
    /// as each seam is joined; `on_window` is called once per window stitched. The first
    /// error of any window stops the run (windows already running finish first).
    pub fn run(
        &self,
        source: &str,
        sink: &mut dyn TrackSink,
        on_window: &mut dyn FnMut(&Window),
    ) -> Result<WindowedSummary> {
        let windows = self.plan.windows();
        let jobs = self.jobs.min(windows.len());
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let next = AtomicUsize::new(0);
        let stop = AtomicBool::new(false);
        let mut stitcher = Stitcher::new(self.stitch)?;
        let measured = Measured::on_source(source, self.tracking)?;
        let mut points = 0u64;
        std::thread::scope(|scope| -> Result<()> {
            let (sender, receiver) = mpsc::channel();
            for _ in 0..jobs {
                let sender = sender.clone();
                let (windows, next, stop) = (&windows, &next, &stop);
                scope.spawn(move || {
                    loop {
                        let k = next.fetch_add(1, Ordering::SeqCst);
                        if k >= windows.len() || stop.load(Ordering::SeqCst) {
                            return;
                        }
                        // The cores shared by the windows still running: the last ones get
                        // more when fewer windows than jobs remain.
                        let running = jobs.min(windows.len() - k);
                        let threads = (cores / running).max(1);
                        let tracked = on_threads(Some(threads), || {
                            track_window(source, self.tracking, &windows[k], &measured)
                        });
                        if sender.send((k, tracked)).is_err() {
                            return;
                        }
                    }
                });
            }
            drop(sender);
            let result = (|| {
                let mut ready: BTreeMap<usize, WindowTracks> = BTreeMap::new();
                let mut stitched = 0;
                for (k, tracked) in &receiver {
                    ready.insert(k, tracked?);
                    while let Some(window) = ready.remove(&stitched) {
                        let finished = stitcher.push(window)?;
                        points += finished.len() as u64;
                        sink.accept(&finished)?;
                        on_window(&windows[stitched]);
                        stitched += 1;
                    }
                }
                Ok(())
            })();
            if result.is_err() {
                stop.store(true, Ordering::SeqCst);
            }
            result
        })?;
        let tracks = stitcher.tracks();
        let (rest, seams) = stitcher.finish()?;
        points += rest.len() as u64;
        sink.accept(&rest)?;
        Ok(WindowedSummary {
            windows: windows.len(),
            jobs,
            points,
            tracks,
            seams,
        })
    }
}

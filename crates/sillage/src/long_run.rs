//! Long runs of the pipeline trackers (PTV, bedload) into a track file: bad frames skipped
//! or stopped at (`--on-bad-frame`), a checkpoint every N frames and when a signal asks the
//! run to stop (`--checkpoint-every`), and a run continued from its last checkpoint
//! (`--resume`) into a file byte for byte the one an uninterrupted run writes.
//!
//! With checkpoints the rows go to a spool beside the output ([`sillage_io::SpoolWriter`]),
//! cut back to the checkpoint's length on resume, and are replayed into the real writer at
//! the end; the checkpoint ([`crate::checkpoint`]) holds the tracker's state. Both files are
//! removed once the output is complete.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use sillage_core::{Error, FrameIndex, Result};
use sillage_io::{
    BadFramePolicy, SkippedFrame, SkippedFrames, SpoolWriter, TrackWriter, WrittenSummary,
    replay_spool, spool_path, write_in_background,
};

use crate::checkpoint::{
    Checkpoint, RunIdentity, checkpoint_path, read_checkpoint, write_checkpoint,
};
use crate::pipeline::{FrameInput, FrameObserver, Pipeline, RunSummary, RunTally};

/// How a long run treats bad frames, saves checkpoints and resumes.
#[derive(Debug, Clone, Default)]
pub struct LongRunOptions {
    /// Stop at a frame that cannot be read (the default), or skip it as a missed frame.
    pub on_bad_frame: BadFramePolicy,
    /// Save a checkpoint every this many frames (`None`: no checkpoint, no spool).
    pub checkpoint_every: Option<u64>,
    /// Continue from the output's checkpoint when there is one.
    pub resume: bool,
    /// Set (by a signal handler) to stop after the current frame, saving a checkpoint first.
    pub stop: Option<Arc<AtomicBool>>,
}

impl LongRunOptions {
    /// Checks the options (a checkpoint every 0 frames, `--resume` without checkpoints).
    pub fn validate(&self) -> Result<()> {
        if self.checkpoint_every == Some(0) {
            return Err(Error::parameter(
                "checkpoint_every",
                0,
                "give a number of frames of at least 1 (e.g. 1000)",
            ));
        }
        if self.resume && self.checkpoint_every.is_none() {
            return Err(Error::input(
                "--resume continues a run saved by --checkpoint-every; give the same \
                 --checkpoint-every as the interrupted run",
            ));
        }
        Ok(())
    }

    /// The settings of these options that change the output, for the run's identity.
    pub fn settings(&self) -> Vec<(String, String)> {
        let policy = match self.on_bad_frame {
            BadFramePolicy::Stop => "stop",
            BadFramePolicy::Skip => "skip",
        };
        vec![("on_bad_frame".to_string(), policy.to_string())]
    }
}

/// What a long run did.
#[derive(Debug, Clone)]
pub struct LongRunOutcome {
    /// Frames, detections, points and timings (the whole run's counts, resumed or not).
    pub summary: RunSummary,
    /// The file written and its rows.
    pub written: WrittenSummary,
    /// The frames skipped (`--on-bad-frame skip`), in order.
    pub skipped: Vec<SkippedFrame>,
    /// The last frame of the checkpoint this run resumed from (`None`: from the start).
    pub resumed_after: Option<FrameIndex>,
}

/// The frames to track, from `start_at` on, as pipeline inputs, and the log of the frames
/// their source skips (`None` for sources that skip none).
pub type Inputs<'a> = (
    Box<dyn Iterator<Item = Result<FrameInput>> + 'a>,
    Option<SkippedFrames>,
);

/// Opens the frames to track from a frame index on.
pub type OpenInputs<'a> = dyn FnMut(FrameIndex) -> Result<Inputs<'a>> + 'a;

/// Creates the output's writer.
pub type CreateWriter<'a> = dyn FnMut() -> Result<Box<dyn TrackWriter + Send>> + 'a;

/// Where a long run writes: the output file, its writer, and the run's identity.
pub struct LongRunOutput<'a> {
    /// The output file.
    pub path: &'a Path,
    /// Creates its writer (at the start, or at the end of a checkpointed run).
    pub create_writer: &'a mut CreateWriter<'a>,
    /// What a checkpoint of this run must match.
    pub identity: RunIdentity,
}

/// Runs `pipeline` over the frames `open_inputs` gives into `output`, under `options`
/// (checkpoints refuse a pipeline with training passes: those replay the whole sequence);
/// `on_frame` sees every frame tracked by this process.
pub fn run_long(
    pipeline: &mut Pipeline,
    open_inputs: &mut OpenInputs<'_>,
    output: LongRunOutput<'_>,
    options: &LongRunOptions,
    on_frame: &mut FrameObserver<'_>,
) -> Result<LongRunOutcome> {
    options.validate()?;
    let Some(every) = options.checkpoint_every else {
        let (inputs, log) = open_inputs(0)?;
        // Rows are written on a thread of their own while tracking goes on; rows written
        // before an error stay valid: the file is completed either way.
        let mut writer = write_in_background((output.create_writer)()?)?;
        let outcome = pipeline.run_inputs(inputs, &mut writer, on_frame);
        let written = Box::new(writer).finish()?;
        return Ok(LongRunOutcome {
            summary: outcome?,
            written,
            skipped: log.map(|l| l.list()).unwrap_or_default(),
            resumed_after: None,
        });
    };
    let checkpoint_file = checkpoint_path(output.path);
    let spool_file = spool_path(output.path)?;
    let resumed = if options.resume && checkpoint_file.exists() {
        Some(read_checkpoint(&checkpoint_file)?)
    } else {
        None
    };
    let (mut spool, tally, skipped_before) = match resumed {
        Some(saved) => {
            if let Some(difference) = output.identity.difference(&saved.identity) {
                return Err(Error::input(format!(
                    "{}: the checkpoint is of another run ({difference}); run the same \
                     command as the interrupted one, or without --resume to start again",
                    checkpoint_file.display()
                )));
            }
            pipeline.restore(saved.state)?;
            (
                SpoolWriter::resume(&spool_file, saved.spool_bytes)?,
                saved.tally,
                saved.skipped,
            )
        }
        None => {
            // A fresh run: an older checkpoint of this output would not match its new spool.
            if checkpoint_file.exists() {
                std::fs::remove_file(&checkpoint_file)
                    .map_err(|e| Error::io(&checkpoint_file, e))?;
            }
            (
                SpoolWriter::create(&spool_file)?,
                RunTally::default(),
                Vec::new(),
            )
        }
    };
    let resumed_after = tally.last_frame;
    let start_at = resumed_after.map_or(0, |f| f + 1);
    let (inputs, log) = open_inputs(start_at)?;
    let skipped_from = |up_to: Option<FrameIndex>| {
        let mut all = skipped_before.clone();
        if let Some(log) = &log {
            all.extend(
                log.list()
                    .into_iter()
                    .filter(|f| f.index >= start_at && up_to.is_none_or(|last| f.index <= last)),
            );
        }
        all
    };
    let mut save = |pipeline: &Pipeline, tally: &RunTally, spool: &mut SpoolWriter| {
        let stop = options
            .stop
            .as_ref()
            .is_some_and(|flag| flag.load(Ordering::Relaxed));
        if !tally.frames.is_multiple_of(every) && !stop {
            return Ok(());
        }
        let checkpoint = Checkpoint {
            identity: output.identity.clone(),
            tally: *tally,
            spool_bytes: spool.commit()?,
            skipped: skipped_from(tally.last_frame),
            state: pipeline.state(),
        };
        write_checkpoint(&checkpoint_file, &checkpoint)?;
        if stop {
            return Err(Error::input(format!(
                "stopped after frame {}; the run so far is saved in {}: run the same command \
                 with --resume to go on",
                tally.last_frame.unwrap_or_default(),
                checkpoint_file.display()
            )));
        }
        Ok(())
    };
    let summary = pipeline.run_resumable(inputs, &mut spool, tally, on_frame, &mut save)?;
    let spooled = spool.commit()?;
    let spool_path = spool.path().to_path_buf();
    drop(spool);
    let mut writer = write_in_background((output.create_writer)()?)?;
    let replayed = replay_spool(&spool_path, spooled, &mut writer);
    let written = Box::new(writer).finish()?;
    replayed?;
    for done in [&spool_path, &checkpoint_file] {
        std::fs::remove_file(done).map_err(|e| Error::io(done, e))?;
    }
    Ok(LongRunOutcome {
        summary,
        written,
        skipped: skipped_from(None),
        resumed_after,
    })
}

//! A track writer on its own thread: the tracking thread hands each batch over a bounded
//! queue and goes on while the rows are formatted and written, so writing overlaps tracking
//! (issue "Speed end to end"). Batches keep their order, so the file is byte for byte the one
//! the writer makes on the calling thread; at most [`QUEUED_BATCHES`] batches wait (memory
//! stays bounded: a slow disk slows the tracker down rather than filling memory).

use std::thread::JoinHandle;

use crossbeam_channel::{Receiver, Sender};
use sillage_core::{Error, Result, TrackPoint, TrackSink};

use super::{TrackWriter, WrittenSummary};

/// Batches that may wait for the writing thread.
pub const QUEUED_BATCHES: usize = 4;

/// A [`TrackWriter`] whose writing happens on a background thread.
pub struct BackgroundWriter {
    batches: Option<Sender<Vec<TrackPoint>>>,
    /// Emptied batch buffers coming back, reused so a run allocates no batch per frame.
    spare: Receiver<Vec<TrackPoint>>,
    worker: Option<JoinHandle<Result<WrittenSummary>>>,
}

impl std::fmt::Debug for BackgroundWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BackgroundWriter").finish_non_exhaustive()
    }
}

/// Moves `writer` onto a thread of its own; the returned writer queues the batches to it.
pub fn write_in_background(writer: Box<dyn TrackWriter + Send>) -> Result<BackgroundWriter> {
    let (batches, queue) = crossbeam_channel::bounded::<Vec<TrackPoint>>(QUEUED_BATCHES);
    let (give_back, spare) = crossbeam_channel::bounded(QUEUED_BATCHES + 1);
    let worker = std::thread::Builder::new()
        .name("sillage-writer".into())
        .spawn(move || {
            let mut writer = writer;
            let mut failure = None;
            for mut batch in queue {
                if failure.is_none()
                    && let Err(e) = writer.accept(&batch)
                {
                    failure = Some(e);
                }
                batch.clear();
                let _ = give_back.try_send(batch);
            }
            // The rows written so far stay valid: the file is completed either way.
            let written = writer.finish();
            match failure {
                Some(e) => Err(e),
                None => written,
            }
        })
        .map_err(|e| Error::input(format!("cannot start the track-writing thread: {e}")))?;
    Ok(BackgroundWriter {
        batches: Some(batches),
        spare,
        worker: Some(worker),
    })
}

impl BackgroundWriter {
    /// Stops the thread and returns its outcome.
    fn join(&mut self) -> Result<WrittenSummary> {
        self.batches = None;
        match self.worker.take().map(JoinHandle::join) {
            Some(Ok(outcome)) => outcome,
            Some(Err(_)) => Err(Error::input(
                "the track-writing thread stopped unexpectedly; the output may be incomplete",
            )),
            None => Err(Error::input("the track writer was already finished")),
        }
    }
}

impl TrackSink for BackgroundWriter {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        if points.is_empty() {
            return Ok(());
        }
        let mut batch = self.spare.try_recv().unwrap_or_default();
        batch.extend_from_slice(points);
        let sent = self
            .batches
            .as_ref()
            .is_some_and(|batches| batches.send(batch).is_ok());
        if sent {
            Ok(())
        } else {
            // The thread has ended: its error says why.
            self.join().and_then(|_| {
                Err(Error::input(
                    "the track-writing thread ended before the run; the output may be incomplete",
                ))
            })
        }
    }
}

impl TrackWriter for BackgroundWriter {
    fn finish(mut self: Box<Self>) -> Result<WrittenSummary> {
        self.join()
    }
}

impl Drop for BackgroundWriter {
    fn drop(&mut self) {
        if self.worker.is_some() {
            // Finished or not, the thread completes its file before the writer goes away.
            let _ = self.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tracks::{TrackFileHeader, TrackFormat, create_track_writer};
    use sillage_core::Point2;

    fn batches() -> Vec<Vec<TrackPoint>> {
        (0..50u64)
            .map(|frame| {
                (1..=300u64)
                    .map(|id| {
                        let x = (frame * 7 + id * 13) as f64 / 3.0;
                        TrackPoint::at(frame, id, Point2::new(x, x / 7.0))
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn the_file_is_the_one_written_on_the_calling_thread() {
        let dir = tempfile::tempdir().unwrap();
        let header = TrackFileHeader::default();
        for format in [TrackFormat::Tractrac, TrackFormat::Csv] {
            let direct = dir.path().join("direct.txt");
            let background = dir.path().join("background.txt");
            let mut writer = create_track_writer(&direct, format, &header).unwrap();
            let mut threaded =
                write_in_background(create_track_writer(&background, format, &header).unwrap())
                    .unwrap();
            for batch in batches() {
                writer.accept(&batch).unwrap();
                threaded.accept(&batch).unwrap();
            }
            let a = writer.finish().unwrap();
            let b = Box::new(threaded).finish().unwrap();
            assert_eq!(a.rows, b.rows);
            assert_eq!(
                std::fs::read(direct).unwrap(),
                std::fs::read(background).unwrap()
            );
        }
    }

    #[test]
    fn a_write_error_comes_back_and_the_rows_before_it_stay() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("t.csv");
        let header = TrackFileHeader::default();
        let mut threaded =
            write_in_background(create_track_writer(&out, TrackFormat::Csv, &header).unwrap())
                .unwrap();
        threaded.accept(&batches()[0]).unwrap();
        let bad = [TrackPoint::at(1, 1, Point2::new(f64::NAN, 0.0))];
        // The error is found on the writing thread: it comes back at a later call or at the
        // end, never lost.
        let later = threaded
            .accept(&bad)
            .and_then(|()| Box::new(threaded).finish());
        assert!(later.is_err());
        let text = std::fs::read_to_string(&out).unwrap();
        assert_eq!(text.lines().count(), 1 + 300, "{}", &text[..200]);
    }
}

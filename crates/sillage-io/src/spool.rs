//! The row spool of a checkpointed run: every batch of track points the tracker emits,
//! appended to `.NAME.rows.partial` beside the output in a compact binary record, so that a
//! run killed at any moment can be resumed from the spool's length at its last checkpoint
//! (the bytes after it are cut off). At the end the batches are replayed, in order and as
//! they came, into the real writer: the output is byte for byte the one an uninterrupted
//! run writes, whatever its format (Parquet and HDF5 files cannot be appended to).
//!
//! A batch is `u32` point count then the points; a point is its frame, track id and position
//! (`u64`, `u64`, 2 × `f64`), a `u16` of flags saying which optional fields follow, the
//! motion state (`u8`) and class (`u32`), then the fields present. Little-endian throughout.

use std::fs::{File, OpenOptions};
use std::io::{BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use sillage_core::{BoundingBox, Error, MotionState, Point2, Result, TrackPoint, TrackSink, Vec2};

use crate::partial::hidden_beside;

/// Bytes of a point's fixed part: frame, track id, position, flags, state and class.
const FIXED_LEN: usize = 39;
const VEL: u16 = 1;
const ACC: u16 = 1 << 1;
const VEL_PRED: u16 = 1 << 2;
const LOG_ERR: u16 = 1 << 3;
const SPREAD: u16 = 1 << 4;
const DETECTION: u16 = 1 << 5;
const BBOX: u16 = 1 << 6;

/// `.NAME.rows.partial` beside the output `path`: where its rows are spooled.
pub fn spool_path(path: &Path) -> Result<PathBuf> {
    hidden_beside(path, ".rows.partial")
}

/// Appends batches of track points to a spool file.
#[derive(Debug)]
pub struct SpoolWriter {
    path: PathBuf,
    file: BufWriter<File>,
    bytes: u64,
    record: Vec<u8>,
}

impl SpoolWriter {
    /// A new, empty spool at `path` (an older one is replaced).
    pub fn create(path: &Path) -> Result<Self> {
        let file = File::create(path).map_err(|e| Error::io(path, e))?;
        Ok(Self::over(path, file, 0))
    }

    /// The spool at `path` cut back to its first `bytes` bytes (the length a checkpoint
    /// recorded), to append to. Errors when the file is shorter: it is not the spool the
    /// checkpoint was made with.
    pub fn resume(path: &Path, bytes: u64) -> Result<Self> {
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|e| Error::io(path, e))?;
        let length = file.metadata().map_err(|e| Error::io(path, e))?.len();
        if length < bytes {
            return Err(Error::format(
                path,
                None,
                format!(
                    "the row spool holds {length} bytes but the checkpoint recorded {bytes}; it \
                     was changed since. Run again without --resume"
                ),
            ));
        }
        file.set_len(bytes).map_err(|e| Error::io(path, e))?;
        let mut file = file;
        file.seek(SeekFrom::End(0))
            .map_err(|e| Error::io(path, e))?;
        Ok(Self::over(path, file, bytes))
    }

    fn over(path: &Path, file: File, bytes: u64) -> Self {
        Self {
            path: path.to_path_buf(),
            file: BufWriter::with_capacity(1 << 20, file),
            bytes,
            record: Vec::new(),
        }
    }

    /// Writes everything accepted so far to the disk (flushed and synced) and returns the
    /// spool's length: the offset a checkpoint records.
    pub fn commit(&mut self) -> Result<u64> {
        self.file.flush().map_err(|e| Error::io(&self.path, e))?;
        self.file
            .get_ref()
            .sync_data()
            .map_err(|e| Error::io(&self.path, e))?;
        Ok(self.bytes)
    }

    /// The spool's path.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl TrackSink for SpoolWriter {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        if points.is_empty() {
            return Ok(());
        }
        self.record.clear();
        let count = u32::try_from(points.len())
            .map_err(|_| Error::input("a batch of more than 2^32 track points"))?;
        self.record.extend_from_slice(&count.to_le_bytes());
        for point in points {
            encode(point, &mut self.record);
        }
        self.file
            .write_all(&self.record)
            .map_err(|e| Error::io(&self.path, e))?;
        self.bytes += self.record.len() as u64;
        Ok(())
    }
}

fn put_f64(out: &mut Vec<u8>, value: f64) {
    out.extend_from_slice(&value.to_le_bytes());
}

fn put_vec(out: &mut Vec<u8>, v: Vec2) {
    put_f64(out, v.x);
    put_f64(out, v.y);
}

fn encode(p: &TrackPoint, out: &mut Vec<u8>) {
    out.extend_from_slice(&p.frame.to_le_bytes());
    out.extend_from_slice(&p.track_id.to_le_bytes());
    put_f64(out, p.pos_px.x);
    put_f64(out, p.pos_px.y);
    let flag = |present: bool, bit: u16| if present { bit } else { 0 };
    let flags = flag(p.vel_px_per_frame.is_some(), VEL)
        | flag(p.acc_px_per_frame2.is_some(), ACC)
        | flag(p.vel_pred_px_per_frame.is_some(), VEL_PRED)
        | flag(p.log10_pred_err.is_some(), LOG_ERR)
        | flag(p.spread_px.is_some(), SPREAD)
        | flag(p.detection.is_some(), DETECTION)
        | flag(p.bbox.is_some(), BBOX);
    out.extend_from_slice(&flags.to_le_bytes());
    out.push(p.motion_state.bead_tracking_code());
    out.extend_from_slice(&p.class.to_le_bytes());
    [
        p.vel_px_per_frame,
        p.acc_px_per_frame2,
        p.vel_pred_px_per_frame,
    ]
    .into_iter()
    .flatten()
    .for_each(|v| put_vec(out, v));
    if let Some(e) = p.log10_pred_err {
        put_f64(out, e);
    }
    if let Some(s) = p.spread_px {
        put_f64(out, s);
    }
    if let Some(d) = p.detection {
        out.extend_from_slice(&d.to_le_bytes());
    }
    if let Some(b) = p.bbox {
        for value in [b.left_px, b.top_px, b.width_px, b.height_px] {
            put_f64(out, value);
        }
    }
}

/// Reads a spool's records back.
struct Decoder<'a> {
    bytes: &'a [u8],
}

impl Decoder<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let (head, rest) = self.bytes.split_first_chunk::<N>()?;
        self.bytes = rest;
        Some(*head)
    }

    fn u64(&mut self) -> Option<u64> {
        self.take().map(u64::from_le_bytes)
    }

    fn u32(&mut self) -> Option<u32> {
        self.take().map(u32::from_le_bytes)
    }

    fn f64(&mut self) -> Option<f64> {
        self.take().map(f64::from_le_bytes)
    }

    fn vec(&mut self) -> Option<Vec2> {
        Some(Vec2::new(self.f64()?, self.f64()?))
    }

    fn point(&mut self) -> Option<TrackPoint> {
        let frame = self.u64()?;
        let track_id = self.u64()?;
        let pos = Point2::new(self.f64()?, self.f64()?);
        let flags = u16::from_le_bytes(self.take()?);
        let [state] = self.take()?;
        let motion_state = MotionState::from_bead_tracking_code(f64::from(state))?;
        let class = self.u32()?;
        let mut optional_vec = |bit| (flags & bit != 0).then(|| self.vec()).flatten();
        let vel = optional_vec(VEL);
        let acc = optional_vec(ACC);
        let vel_pred = optional_vec(VEL_PRED);
        let present = |bit: u16| flags & bit != 0;
        Some(TrackPoint {
            vel_px_per_frame: vel,
            acc_px_per_frame2: acc,
            vel_pred_px_per_frame: vel_pred,
            log10_pred_err: if present(LOG_ERR) {
                Some(self.f64()?)
            } else {
                None
            },
            spread_px: if present(SPREAD) {
                Some(self.f64()?)
            } else {
                None
            },
            detection: if present(DETECTION) {
                Some(self.u32()?)
            } else {
                None
            },
            bbox: if present(BBOX) {
                Some(BoundingBox {
                    left_px: self.f64()?,
                    top_px: self.f64()?,
                    width_px: self.f64()?,
                    height_px: self.f64()?,
                })
            } else {
                None
            },
            motion_state,
            class,
            ..TrackPoint::at(frame, track_id, pos)
        })
    }
}

/// Appends `points` to `out` in the spool's record form (a count, then the records): the
/// compact form a time window's tracks travel in from a worker (about 100 bytes a PTV point).
pub fn encode_points(points: &[TrackPoint], out: &mut Vec<u8>) {
    out.extend_from_slice(&(points.len() as u64).to_le_bytes());
    out.reserve(points.len() * (FIXED_LEN + 64));
    for point in points {
        encode(point, out);
    }
}

/// The points [`encode_points`] wrote at the start of `bytes`, and the bytes after them;
/// `None` when `bytes` do not hold such records.
pub fn decode_points(bytes: &[u8]) -> Option<(Vec<TrackPoint>, &[u8])> {
    let mut decoder = Decoder { bytes };
    let count = usize::try_from(decoder.u64()?).ok()?;
    // At least the fixed part per point must follow: no huge allocation for bad input.
    if count > decoder.bytes.len() / FIXED_LEN {
        return None;
    }
    let mut points = Vec::with_capacity(count);
    for _ in 0..count {
        points.push(decoder.point()?);
    }
    Some((points, decoder.bytes))
}

/// Replays the first `bytes` bytes of the spool at `path` into `sink`, batch by batch as
/// they were accepted; returns the number of points.
pub fn replay_spool(path: &Path, bytes: u64, sink: &mut dyn TrackSink) -> Result<u64> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let mut reader = BufReader::with_capacity(1 << 20, file.take(bytes));
    let corrupt = || {
        Error::format(
            path,
            None,
            "the row spool is damaged; run again without --resume",
        )
    };
    let (mut points, mut batch, mut record) = (0u64, Vec::new(), Vec::new());
    loop {
        let mut count = [0u8; 4];
        match reader.read_exact(&mut count) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => break,
            Err(e) => return Err(Error::io(path, e)),
        }
        let count = u32::from_le_bytes(count) as usize;
        batch.clear();
        for _ in 0..count {
            // The fixed part, then the optional fields its flags announce.
            record.resize(FIXED_LEN, 0);
            reader.read_exact(&mut record).map_err(|_| corrupt())?;
            let flags = u16::from_le_bytes([record[32], record[33]]);
            let extra = optional_len(flags);
            record.resize(FIXED_LEN + extra, 0);
            reader
                .read_exact(&mut record[FIXED_LEN..])
                .map_err(|_| corrupt())?;
            let point = Decoder { bytes: &record }.point().ok_or_else(corrupt)?;
            batch.push(point);
        }
        sink.accept(&batch)?;
        points += count as u64;
    }
    Ok(points)
}

/// Bytes of the optional fields a point's `flags` announce.
fn optional_len(flags: u16) -> usize {
    [
        (VEL, 16),
        (ACC, 16),
        (VEL_PRED, 16),
        (LOG_ERR, 8),
        (SPREAD, 8),
        (DETECTION, 4),
        (BBOX, 32),
    ]
    .into_iter()
    .filter(|&(bit, _)| flags & bit != 0)
    .map(|(_, len)| len)
    .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points() -> Vec<TrackPoint> {
        vec![
            TrackPoint::at(0, 1, Point2::new(1.5, -2.25)),
            TrackPoint {
                vel_px_per_frame: Some(Vec2::new(0.1, f64::NAN)),
                acc_px_per_frame2: Some(Vec2::new(-0.0, 1e-300)),
                vel_pred_px_per_frame: Some(Vec2::new(3.0, 4.0)),
                log10_pred_err: Some(-2.5),
                motion_state: MotionState::Rolling,
                class: 7,
                spread_px: Some(0.75),
                detection: Some(42),
                bbox: Some(BoundingBox {
                    left_px: 1.0,
                    top_px: 2.0,
                    width_px: 3.0,
                    height_px: 4.0,
                }),
                ..TrackPoint::at(u64::MAX, 2, Point2::new(f64::INFINITY, 0.0))
            },
        ]
    }

    fn same(a: &TrackPoint, b: &TrackPoint) -> bool {
        // Bit for bit, NaN included.
        format!("{a:?}") == format!("{b:?}")
    }

    #[test]
    fn batches_come_back_as_they_went_in_and_a_resume_cuts_the_tail() {
        let dir = tempfile::tempdir().unwrap();
        let path = spool_path(&dir.path().join("t.csv")).unwrap();
        assert_eq!(path.file_name().unwrap(), ".t.csv.rows.partial");
        let mut spool = SpoolWriter::create(&path).unwrap();
        spool.accept(&points()).unwrap();
        let first = spool.commit().unwrap();
        spool.accept(&points()[..1]).unwrap();
        spool.commit().unwrap();
        drop(spool);
        let mut back: Vec<TrackPoint> = Vec::new();
        assert_eq!(replay_spool(&path, u64::MAX, &mut back).unwrap(), 3);
        for (a, b) in back.iter().zip(points().iter().chain(&points()[..1])) {
            assert!(same(a, b), "{a:?} vs {b:?}");
        }
        // Resumed at the first checkpoint: the second batch is gone, new ones follow.
        let mut spool = SpoolWriter::resume(&path, first).unwrap();
        spool.accept(&points()[1..]).unwrap();
        let end = spool.commit().unwrap();
        let mut back: Vec<TrackPoint> = Vec::new();
        assert_eq!(replay_spool(&path, end, &mut back).unwrap(), 3);
        assert!(same(&back[2], &points()[1]));
    }

    #[test]
    fn a_short_or_damaged_spool_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s");
        let mut spool = SpoolWriter::create(&path).unwrap();
        spool.accept(&points()).unwrap();
        let end = spool.commit().unwrap();
        drop(spool);
        let err = SpoolWriter::resume(&path, end + 1).unwrap_err().to_string();
        assert!(err.contains("without --resume"), "{err}");
        let mut sink: Vec<TrackPoint> = Vec::new();
        let err = replay_spool(&path, end - 3, &mut sink)
            .unwrap_err()
            .to_string();
        assert!(err.contains("damaged"), "{err}");
    }
}

//! Linking a table of detections (one row per detection, trackpy's layout) with the PTV
//! tracker, and carrying the trajectory ids back to the rows.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use numpy::ndarray::ArrayView1;
use sillage::core::{Detection, Error, FrameIndex, Point2, Result, TrackPoint, TrackSink};
use sillage::{Pipeline, PipelineConfig};

use crate::hooks::Between;

/// Per row: its trajectory id and velocity.
pub struct LinkedRows {
    /// Trajectory id; rows in no trajectory get ids of their own after the largest one.
    pub particle: Vec<i64>,
    /// Velocity along x, px/frame (NaN where the row is in no trajectory).
    pub vx: Vec<f64>,
    /// Velocity along y, px/frame (NaN where the row is in no trajectory).
    pub vy: Vec<f64>,
}

/// Links the rows (`frame[i]`, `x[i]`, `y[i]`) frame by frame, in increasing frame order; a
/// missing frame number is tracked as an empty frame, so no trajectory jumps over it.
pub fn link_rows(
    config: &PipelineConfig,
    frame: ArrayView1<'_, i64>,
    x: ArrayView1<'_, f64>,
    y: ArrayView1<'_, f64>,
    between: &Between,
) -> Result<LinkedRows> {
    let rows = frame.len();
    if x.len() != rows || y.len() != rows {
        return Err(Error::input(format!(
            "the frame, x and y columns differ in length ({rows}, {}, {})",
            x.len(),
            y.len()
        )));
    }
    if let Some(row) = frame.iter().position(|&f| f < 0) {
        return Err(Error::input(format!(
            "row {row} has frame {}; frame numbers must be ≥ 0",
            frame[row]
        )));
    }
    let mut order: Vec<usize> = (0..rows).collect();
    // DataFrames from `batch` are already in frame order: no sort then.
    if !frame.iter().is_sorted() {
        order.sort_unstable_by_key(|&row| (frame[row], row));
    }

    // Where each emitted point comes from: (frame, x bits, y bits) → row, the tracker
    // emitting the detections' own coordinates. Rows at the same place in the same frame are
    // chained through `same_place`.
    let key = |row: usize| (frame[row], x[row].to_bits(), y[row].to_bits());
    let mut row_at: HashMap<(i64, u64, u64), usize, BuildHasherDefault<PlaceHasher>> =
        HashMap::with_capacity_and_hasher(rows, BuildHasherDefault::default());
    let mut same_place = vec![usize::MAX; rows];
    for &row in order.iter().rev() {
        if let Some(next) = row_at.insert(key(row), row) {
            same_place[row] = next;
        }
    }

    let inputs = frame_inputs(&order, frame, x, y);
    let mut writer = RowWriter {
        row_at,
        same_place,
        linked: LinkedRows {
            particle: vec![-1; rows],
            vx: vec![f64::NAN; rows],
            vy: vec![f64::NAN; rows],
        },
    };
    let mut pipeline = Pipeline::from_config(config)?;
    pipeline.run_detections(between.frames(inputs), &mut writer, &mut |_| {
        between.advance()
    })?;
    let mut linked = writer.linked;
    let first_free = linked.particle.iter().max().map_or(0, |&m| m + 1);
    let unlinked = linked.particle.iter_mut().filter(|p| **p < 0);
    for (id, particle) in (first_free..).zip(unlinked) {
        *particle = id;
    }
    Ok(linked)
}

/// A track sink that writes each point's id and velocity into the row it came from as the
/// tracker emits it (a run of 20 frames of 20,000 points would otherwise hold ~350,000 track
/// points of ~150 bytes before mapping them).
struct RowWriter {
    /// (frame, x bits, y bits) → the next row at that place not yet given a point.
    row_at: HashMap<(i64, u64, u64), usize, BuildHasherDefault<PlaceHasher>>,
    /// Per row: the next row of the same frame at the same place (`usize::MAX`: none).
    same_place: Vec<usize>,
    linked: LinkedRows,
}

impl TrackSink for RowWriter {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        for point in points {
            let place = (
                point.frame as i64,
                point.pos_px.x.to_bits(),
                point.pos_px.y.to_bits(),
            );
            let row = self
                .row_at
                .get_mut(&place)
                .filter(|row| **row != usize::MAX);
            let Some(row) = row else {
                return Err(Error::input(format!(
                    "internal: the tracker emitted a point at ({}, {}) in frame {} that is no row",
                    point.pos_px.x, point.pos_px.y, point.frame
                )));
            };
            let at = *row;
            *row = self.same_place[at];
            self.linked.particle[at] = point.track_id as i64;
            if let Some(v) = point.vel_px_per_frame {
                self.linked.vx[at] = v.x;
                self.linked.vy[at] = v.y;
            }
        }
        Ok(())
    }
}

/// The detections of every frame from the first to the last row's, in order (rows sorted by
/// frame in `order`), with one empty frame standing for each gap in the frame numbers.
fn frame_inputs<'a>(
    order: &'a [usize],
    frame: ArrayView1<'a, i64>,
    x: ArrayView1<'a, f64>,
    y: ArrayView1<'a, f64>,
) -> impl Iterator<Item = Result<(FrameIndex, Vec<Detection>)>> + 'a {
    let mut start = 0;
    let mut previous: Option<i64> = None;
    std::iter::from_fn(move || {
        let &first = order.get(start)?;
        let number = frame[first];
        if let Some(p) = previous
            && number > p + 1
        {
            previous = Some(p + 1);
            return Some(Ok(((p + 1) as FrameIndex, Vec::new())));
        }
        let end = start + order[start..].partition_point(|&row| frame[row] == number);
        let detections = order[start..end]
            .iter()
            .map(|&row| Detection::new(Point2::new(x[row], y[row]), 1.0))
            .collect();
        start = end;
        previous = Some(number);
        Some(Ok((number as FrameIndex, detections)))
    })
}

/// A fast hasher for the (frame, x bits, y bits) keys of `link_rows` (FxHash's multiply and
/// rotate): the keys are not chosen by an adversary, and SipHash's cost showed in profiles
/// of 20,000-point frames.
#[derive(Default)]
struct PlaceHasher(u64);

impl Hasher for PlaceHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            self.write_u64(u64::from(byte));
        }
    }

    fn write_u64(&mut self, value: u64) {
        self.0 = (self.0.rotate_left(5) ^ value).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }

    fn write_i64(&mut self, value: i64) {
        self.write_u64(value as u64);
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

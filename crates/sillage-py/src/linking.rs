//! Linking a table of detections (one row per detection, trackpy's layout) with the PTV
//! tracker, and carrying the trajectory ids back to the rows.

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
    let starts = frame_starts(&order, frame);
    let inputs = frame_inputs(&starts, &order, x, y);
    let mut writer = RowWriter {
        frame_starts: &starts,
        order: &order,
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
/// points of ~150 bytes before mapping them). The row is found from the point's frame and
/// detection index: frame `f`'s detections are the rows `order[start..]` from its start.
struct RowWriter<'a> {
    /// (frame number, first position in `order`) of every frame with rows, in frame order.
    frame_starts: &'a [(i64, usize)],
    /// The rows sorted by frame, as the detections were handed to the tracker.
    order: &'a [usize],
    linked: LinkedRows,
}

impl TrackSink for RowWriter<'_> {
    fn accept(&mut self, points: &[TrackPoint]) -> Result<()> {
        // The points of one call are mostly of one frame: its rows are looked up once.
        let mut frame_rows: Option<(u64, &[usize])> = None;
        for point in points {
            let rows = match frame_rows {
                Some((frame, rows)) if frame == point.frame => rows,
                _ => {
                    let rows = rows_of(self.frame_starts, self.order, point.frame as i64);
                    frame_rows = Some((point.frame, rows));
                    rows
                }
            };
            let Some(&row) = point.detection.and_then(|d| rows.get(d as usize)) else {
                return Err(Error::input(format!(
                    "internal: the tracker emitted a point of frame {} (detection {:?}) that is \
                     no row",
                    point.frame, point.detection
                )));
            };
            self.linked.particle[row] = point.track_id as i64;
            if let Some(v) = point.vel_px_per_frame {
                self.linked.vx[row] = v.x;
                self.linked.vy[row] = v.y;
            }
        }
        Ok(())
    }
}

/// The rows of frame `frame` in `order`, in the order of its detections (none when it has no
/// row), from the `frame_starts` of [`frame_starts`].
fn rows_of<'o>(frame_starts: &[(i64, usize)], order: &'o [usize], frame: i64) -> &'o [usize] {
    frame_starts
        .binary_search_by_key(&frame, |&(f, _)| f)
        .map_or(&[], |at| rows_at(frame_starts, order, at))
}

/// The rows of the `at`-th frame of `frame_starts`.
fn rows_at<'o>(frame_starts: &[(i64, usize)], order: &'o [usize], at: usize) -> &'o [usize] {
    let end = frame_starts.get(at + 1).map_or(order.len(), |&(_, s)| s);
    &order[frame_starts[at].1..end]
}

/// (frame number, first position in `order`) of every frame that has rows, in frame order.
fn frame_starts(order: &[usize], frame: ArrayView1<'_, i64>) -> Vec<(i64, usize)> {
    let mut starts: Vec<(i64, usize)> = Vec::new();
    for (position, &row) in order.iter().enumerate() {
        if starts.last().is_none_or(|&(f, _)| f != frame[row]) {
            starts.push((frame[row], position));
        }
    }
    starts
}

/// The detections of every frame from the first to the last row's, in order (the frames of
/// `frame_starts`), with one empty frame standing for each gap in the frame numbers.
fn frame_inputs<'a>(
    frame_starts: &'a [(i64, usize)],
    order: &'a [usize],
    x: ArrayView1<'a, f64>,
    y: ArrayView1<'a, f64>,
) -> impl Iterator<Item = Result<(FrameIndex, Vec<Detection>)>> + 'a {
    let (first, last) = match (frame_starts.first(), frame_starts.last()) {
        (Some(&(first, _)), Some(&(last, _))) => (first, last),
        _ => (0, -1),
    };
    let mut next = 0;
    (first..=last).map(move |number| {
        let rows = if frame_starts[next].0 == number {
            next += 1;
            rows_at(frame_starts, order, next - 1)
        } else {
            &[]
        };
        let detections = rows
            .iter()
            .map(|&row| Detection::new(Point2::new(x[row], y[row]), 1.0))
            .collect();
        Ok((number as FrameIndex, detections))
    })
}

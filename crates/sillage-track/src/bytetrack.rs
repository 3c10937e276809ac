//! ByteTrack (Zhang et al., *ByteTrack: Multi-Object Tracking by Associating Every Detection
//! Box*, ECCV 2022) as the `supervision` package (0.30.9, `sv.ByteTrack`) implements it: one
//! Kalman filter per box over centre, aspect ratio and height `(x, y, a, h)` and their rates
//! (noises proportional to the height), a first association of the confident detections
//! (score ≥ the activation threshold) to tracked and lost tracks on IoU fused with the score,
//! a second association of the weak ones (0.1 < score < threshold) to the tracks left, the
//! unconfirmed tracks (one detection so far) matched last; lost tracks are kept
//! `lost_track_buffer` frames. The boxes written are the detections matched (IoU ≥ 0.5) to
//! the activated tracks, with the tracks' ids, as `update_with_detections` returns them.

use sillage_assoc::LapSolver;
use sillage_core::{BoundingBox, Error, Result};

/// ByteTrack's parameters, with `supervision`'s defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ByteTrackParams {
    /// Detections scoring at least this enter the first association; default 0.25. A new
    /// track starts from a detection scoring at least this + 0.1.
    pub track_activation_threshold: f64,
    /// Frames a lost track is kept (at 30 frames/s); default 30.
    pub lost_track_buffer: u32,
    /// Largest fused cost `1 − IoU·score` of a first-association match; default 0.8.
    pub minimum_matching_threshold: f64,
    /// Frame rate, frames/s: the buffer scales with it; default 30.
    pub frame_rate: f64,
    /// Matches before a track gets its id and is written; default 1.
    pub minimum_consecutive_frames: u32,
}

impl Default for ByteTrackParams {
    fn default() -> Self {
        Self {
            track_activation_threshold: 0.25,
            lost_track_buffer: 30,
            minimum_matching_threshold: 0.8,
            frame_rate: 30.0,
            minimum_consecutive_frames: 1,
        }
    }
}

impl ByteTrackParams {
    /// Checks the values; errors name the key.
    pub fn validate(&self) -> Result<()> {
        for (key, value) in [
            (
                "track_activation_threshold",
                self.track_activation_threshold,
            ),
            (
                "minimum_matching_threshold",
                self.minimum_matching_threshold,
            ),
        ] {
            if !value.is_finite() {
                return Err(Error::parameter(key, value, "must be a finite number"));
            }
        }
        if !(self.frame_rate.is_finite() && self.frame_rate > 0.0) {
            return Err(Error::parameter(
                "frame_rate",
                self.frame_rate,
                "must be a finite number > 0",
            ));
        }
        Ok(())
    }
}

/// A scored detection box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScoredBox {
    /// The box.
    pub bbox: BoundingBox,
    /// The detector's score.
    pub score: f64,
}

/// A detection written with a track id.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackedDetection {
    /// Track id, from 1.
    pub id: u64,
    /// The detection's box.
    pub bbox: BoundingBox,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Tracked,
    Lost,
}

type Mean = [f64; 8];
type Cov = [[f64; 8]; 8];

const STD_POSITION: f64 = 1.0 / 20.0;
const STD_VELOCITY: f64 = 1.0 / 160.0;

/// One track: the Kalman state over `(x, y, a, h, ẋ, ẏ, ȧ, ḣ)` and its life cycle.
#[derive(Debug, Clone)]
struct Track {
    internal_id: u64,
    external_id: Option<u64>,
    state: State,
    activated: bool,
    start_frame: u64,
    frame: u64,
    mean: Mean,
    cov: Cov,
    tracklet_len: u32,
    /// Place in the tracked list at the start of the frame (the reference keeps that order).
    order: usize,
}

/// `(x, y, a, h)` of a box.
fn xyah(b: &BoundingBox) -> [f64; 4] {
    [
        b.left_px + b.width_px / 2.0,
        b.top_px + b.height_px / 2.0,
        b.width_px / b.height_px,
        b.height_px,
    ]
}

impl Track {
    fn bbox(&self) -> BoundingBox {
        let [x, y, a, h] = [self.mean[0], self.mean[1], self.mean[2], self.mean[3]];
        let w = a * h;
        BoundingBox {
            left_px: x - w / 2.0,
            top_px: y - h / 2.0,
            width_px: w,
            height_px: h,
        }
    }

    /// `F P Fᵀ + Q(h)`, `x ← F x`; the height rate of a track not tracked is zeroed first.
    fn predict(&mut self) {
        if self.state != State::Tracked {
            self.mean[7] = 0.0;
        }
        let h = self.mean[3];
        let q = [
            STD_POSITION * h,
            STD_POSITION * h,
            1e-2,
            STD_POSITION * h,
            STD_VELOCITY * h,
            STD_VELOCITY * h,
            1e-5,
            STD_VELOCITY * h,
        ];
        for i in 0..4 {
            self.mean[i] += self.mean[i + 4];
        }
        for i in 0..4 {
            for j in 0..8 {
                self.cov[i][j] += self.cov[i + 4][j];
            }
        }
        for row in &mut self.cov {
            for j in 0..4 {
                row[j] += row[j + 4];
            }
        }
        for (i, s) in q.iter().enumerate() {
            self.cov[i][i] += s * s;
        }
    }

    /// The Kalman correction with the box `b`.
    fn correct(&mut self, b: &BoundingBox) {
        let z = xyah(b);
        let h = self.mean[3];
        let r = [STD_POSITION * h, STD_POSITION * h, 1e-1, STD_POSITION * h];
        let s: [[f64; 4]; 4] = std::array::from_fn(|i| {
            std::array::from_fn(|j| self.cov[i][j] + if i == j { r[i] * r[i] } else { 0.0 })
        });
        let Some(s_inv) = crate::sort::invert4(&s) else {
            return;
        };
        let k: [[f64; 4]; 8] = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..4).map(|m| self.cov[i][m] * s_inv[m][j]).sum())
        });
        let y: [f64; 4] = std::array::from_fn(|i| z[i] - self.mean[i]);
        for (x, gain) in self.mean.iter_mut().zip(&k) {
            *x += gain.iter().zip(&y).map(|(g, y)| g * y).sum::<f64>();
        }
        // P ← P − K S Kᵀ.
        let ks: [[f64; 4]; 8] = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..4).map(|m| k[i][m] * s[m][j]).sum())
        });
        for (i, row) in self.cov.iter_mut().enumerate() {
            for (j, value) in row.iter_mut().enumerate() {
                *value -= (0..4).map(|m| ks[i][m] * k[j][m]).sum::<f64>();
            }
        }
    }
}

/// The ByteTrack tracker: call [`ByteTracker::step`] once per frame, in order.
#[derive(Debug, Clone)]
pub struct ByteTracker {
    params: ByteTrackParams,
    det_threshold: f64,
    max_time_lost: u64,
    frame: u64,
    tracked: Vec<Track>,
    lost: Vec<Track>,
    next_internal: u64,
    next_external: u64,
    solver: LapSolver,
}

/// Pairs `(row, column)` of the assignment of least cost over `costs` (rows × cols) in which
/// every cost above `threshold` counts as `threshold + 1e-4`, kept where the true cost is at
/// most `threshold` (`supervision`'s `linear_assignment`).
pub(crate) fn assign(
    solver: &mut LapSolver,
    rows: usize,
    cols: usize,
    costs: &[f64],
    threshold: f64,
) -> Vec<(usize, usize)> {
    if rows == 0 || cols == 0 {
        return Vec::new();
    }
    let clamped: Vec<f64> = costs
        .iter()
        .map(|&c| if c > threshold { threshold + 1e-4 } else { c })
        .collect();
    solver
        .solve(rows, cols, &clamped)
        .iter()
        .enumerate()
        .filter_map(|(r, c)| {
            c.filter(|&c| costs[r * cols + c] <= threshold)
                .map(|c| (r, c))
        })
        .collect()
}

/// `1 − IoU` between every track of `tracks` (rows) and box of `boxes` (columns), in
/// single precision as the reference computes it; with `scores`, fused: `1 − IoU·score`.
fn iou_costs(tracks: &[&Track], boxes: &[ScoredBox], fuse: bool) -> Vec<f64> {
    let mut costs = Vec::with_capacity(tracks.len() * boxes.len());
    for t in tracks {
        let tb = t.bbox();
        for b in boxes {
            let sim = tb.iou(&b.bbox) as f32;
            let cost = if fuse {
                1.0 - sim * b.score as f32
            } else {
                1.0 - sim
            };
            costs.push(f64::from(cost));
        }
    }
    costs
}

impl ByteTracker {
    /// A tracker with validated `params`.
    pub fn new(params: ByteTrackParams) -> Result<Self> {
        params.validate()?;
        let det = params.track_activation_threshold + 0.1;
        Ok(Self {
            params,
            det_threshold: if det > 1.0 {
                params.track_activation_threshold
            } else {
                det
            },
            max_time_lost: (params.frame_rate / 30.0 * f64::from(params.lost_track_buffer)) as u64,
            frame: 0,
            tracked: Vec::new(),
            lost: Vec::new(),
            next_internal: 0,
            next_external: 1,
            solver: LapSolver::new(),
        })
    }

    /// A new track from detection `b`.
    fn activate(&mut self, b: &BoundingBox) -> Track {
        let z = xyah(b);
        let h = z[3];
        let std = [
            2.0 * STD_POSITION * h,
            2.0 * STD_POSITION * h,
            1e-2,
            2.0 * STD_POSITION * h,
            10.0 * STD_VELOCITY * h,
            10.0 * STD_VELOCITY * h,
            1e-5,
            10.0 * STD_VELOCITY * h,
        ];
        let mut cov = [[0.0; 8]; 8];
        for (i, s) in std.iter().enumerate() {
            cov[i][i] = s * s;
        }
        let internal_id = self.next_internal;
        self.next_internal += 1;
        let activated = self.frame == 1 && 1 >= self.params.minimum_consecutive_frames;
        let external_id = activated.then(|| self.new_external());
        Track {
            internal_id,
            external_id,
            state: State::Tracked,
            activated,
            start_frame: self.frame,
            frame: self.frame,
            mean: [z[0], z[1], z[2], z[3], 0.0, 0.0, 0.0, 0.0],
            cov,
            tracklet_len: 1,
            order: usize::MAX,
        }
    }

    fn new_external(&mut self) -> u64 {
        let id = self.next_external;
        self.next_external += 1;
        id
    }

    /// A matched track takes detection `b` (`update`; `re_activate` for a lost one).
    fn take(&mut self, track: &mut Track, b: &BoundingBox) {
        track.correct(b);
        track.frame = self.frame;
        if track.state == State::Tracked {
            track.tracklet_len += 1;
            if track.tracklet_len >= self.params.minimum_consecutive_frames {
                track.activated = true;
                if track.external_id.is_none() {
                    track.external_id = Some(self.new_external());
                }
            }
        } else {
            track.tracklet_len = 0;
        }
        track.state = State::Tracked;
    }

    /// One frame: the scored detections in (boxes with a size ≤ 0 or a non-finite value are
    /// skipped, as the reference does); the detections matched to activated tracks, with
    /// their ids, out (in the order of `detections`).
    pub fn step(&mut self, detections: &[ScoredBox]) -> Vec<TrackedDetection> {
        self.frame += 1;
        let usable = |d: &&ScoredBox| {
            d.bbox.width_px > 0.0
                && d.bbox.height_px > 0.0
                && [
                    d.bbox.left_px,
                    d.bbox.top_px,
                    d.bbox.width_px,
                    d.bbox.height_px,
                    d.score,
                ]
                .iter()
                .all(|v| v.is_finite())
        };
        let valid: Vec<ScoredBox> = detections.iter().filter(usable).copied().collect();
        let tau = self.params.track_activation_threshold;
        let high: Vec<ScoredBox> = valid.iter().filter(|d| d.score >= tau).copied().collect();
        let low: Vec<ScoredBox> = valid
            .iter()
            .filter(|d| d.score > 0.1 && d.score < tau)
            .copied()
            .collect();
        // Tracks: confirmed (activated) ones and lost ones form the pool; unconfirmed apart.
        let mut tracked = std::mem::take(&mut self.tracked);
        for (order, t) in tracked.iter_mut().enumerate() {
            t.order = order;
        }
        let (confirmed, mut unconfirmed): (Vec<Track>, Vec<Track>) =
            tracked.into_iter().partition(|t| t.activated);
        let mut pool = confirmed;
        let lost = std::mem::take(&mut self.lost);
        for t in lost {
            if !pool.iter().any(|p| p.internal_id == t.internal_id) {
                pool.push(t);
            }
        }
        for t in &mut pool {
            t.predict();
        }
        // First association: confident detections, IoU fused with the score.
        let refs: Vec<&Track> = pool.iter().collect();
        let costs = iou_costs(&refs, &high, true);
        let first = assign(
            &mut self.solver,
            pool.len(),
            high.len(),
            &costs,
            self.params.minimum_matching_threshold,
        );
        let mut pool_matched = vec![false; pool.len()];
        let mut high_matched = vec![false; high.len()];
        let mut activated: Vec<Track> = Vec::new();
        let mut refound: Vec<Track> = Vec::new();
        let mut pool_slots: Vec<Option<Track>> = pool.into_iter().map(Some).collect();
        for &(t, d) in &first {
            pool_matched[t] = true;
            high_matched[d] = true;
        }
        for &(t, d) in &first {
            if let Some(mut track) = pool_slots[t].take() {
                let was_tracked = track.state == State::Tracked;
                self.take(&mut track, &high[d].bbox);
                if was_tracked {
                    activated.push(track);
                } else {
                    refound.push(track);
                }
            }
        }
        // Second association: the weak detections and the tracked tracks left.
        let remaining: Vec<usize> = (0..pool_slots.len())
            .filter(|&t| !pool_matched[t])
            .filter(|&t| {
                pool_slots[t]
                    .as_ref()
                    .is_some_and(|tr| tr.state == State::Tracked)
            })
            .collect();
        let refs: Vec<&Track> = remaining
            .iter()
            .filter_map(|&t| pool_slots[t].as_ref())
            .collect();
        let costs = iou_costs(&refs, &low, false);
        let second = assign(&mut self.solver, remaining.len(), low.len(), &costs, 0.5);
        let mut second_matched = vec![false; remaining.len()];
        for &(r, d) in &second {
            second_matched[r] = true;
            if let Some(mut track) = pool_slots[remaining[r]].take() {
                self.take(&mut track, &low[d].bbox);
                activated.push(track);
            }
        }
        let mut newly_lost: Vec<Track> = Vec::new();
        for (r, &t) in remaining.iter().enumerate() {
            if !second_matched[r]
                && let Some(mut track) = pool_slots[t].take()
            {
                track.state = State::Lost;
                newly_lost.push(track);
            }
        }
        // Lost tracks of the pool that matched nothing stay lost.
        let still_lost: Vec<Track> = pool_slots.into_iter().flatten().collect();
        // Unconfirmed tracks against the confident detections left.
        let left: Vec<ScoredBox> = (0..high.len())
            .filter(|&d| !high_matched[d])
            .map(|d| high[d])
            .collect();
        let refs: Vec<&Track> = unconfirmed.iter().collect();
        let costs = iou_costs(&refs, &left, true);
        let third = assign(&mut self.solver, unconfirmed.len(), left.len(), &costs, 0.7);
        let mut left_matched = vec![false; left.len()];
        let mut detection_of = vec![None; unconfirmed.len()];
        for &(t, d) in &third {
            left_matched[d] = true;
            detection_of[t] = Some(d);
        }
        // Unmatched unconfirmed tracks are removed.
        for (mut track, d) in unconfirmed.drain(..).zip(detection_of) {
            if let Some(d) = d {
                self.take(&mut track, &left[d].bbox);
                activated.push(track);
            }
        }
        // The tracks of the frame's start still tracked, in their order, then the new ones
        // from the confident detections nobody took, then the lost ones found again.
        activated.sort_by_key(|t| t.order);
        for (d, det) in left.iter().enumerate() {
            if !left_matched[d] && det.score >= self.det_threshold {
                let track = self.activate(&det.bbox);
                activated.push(track);
            }
        }
        let mut tracked = activated;
        tracked.extend(refound);
        // Lost tracks beyond the buffer are removed; the others stay lost, then the new lost.
        let max_time_lost = self.max_time_lost;
        let frame = self.frame;
        let mut lost: Vec<Track> = still_lost
            .into_iter()
            .filter(|t| frame - t.frame <= max_time_lost)
            .collect();
        lost.extend(newly_lost);
        // Duplicates: a tracked and a lost track over the same box; the younger goes.
        let mut drop_tracked = vec![false; tracked.len()];
        let mut drop_lost = vec![false; lost.len()];
        for (a, ta) in tracked.iter().enumerate() {
            let ba = ta.bbox();
            for (b, tb) in lost.iter().enumerate() {
                let distance = 1.0 - ba.iou(&tb.bbox()) as f32;
                if distance < 0.05 {
                    let age_a = ta.frame - ta.start_frame;
                    let age_b = tb.frame - tb.start_frame;
                    if age_a > age_b {
                        drop_lost[b] = true;
                    } else {
                        drop_tracked[a] = true;
                    }
                }
            }
        }
        let mut keep = drop_tracked.iter().map(|d| !d);
        tracked.retain(|_| keep.next().unwrap_or(true));
        let mut keep = drop_lost.iter().map(|d| !d);
        lost.retain(|_| keep.next().unwrap_or(true));
        self.tracked = tracked;
        self.lost = lost;
        self.written(detections)
    }

    /// The input detections matched (IoU ≥ 0.5, one to one) to the activated tracks, with the
    /// tracks' ids (`update_with_detections`).
    fn written(&mut self, detections: &[ScoredBox]) -> Vec<TrackedDetection> {
        let out: Vec<&Track> = self.tracked.iter().filter(|t| t.activated).collect();
        if out.is_empty() || detections.is_empty() {
            return Vec::new();
        }
        let mut costs = Vec::with_capacity(detections.len() * out.len());
        for d in detections {
            for t in &out {
                costs.push(f64::from(1.0 - d.bbox.iou(&t.bbox()) as f32));
            }
        }
        let ids: Vec<Option<u64>> = out.iter().map(|t| t.external_id).collect();
        let pairs = assign(&mut self.solver, detections.len(), ids.len(), &costs, 0.5);
        let mut written: Vec<(usize, TrackedDetection)> = pairs
            .into_iter()
            .filter_map(|(d, t)| {
                ids[t].map(|id| {
                    (
                        d,
                        TrackedDetection {
                            id,
                            bbox: detections[d].bbox,
                        },
                    )
                })
            })
            .collect();
        written.sort_by_key(|(d, _)| *d);
        written.into_iter().map(|(_, w)| w).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scored(left: f64, score: f64) -> ScoredBox {
        ScoredBox {
            bbox: BoundingBox {
                left_px: left,
                top_px: 20.0,
                width_px: 20.0,
                height_px: 50.0,
            },
            score,
        }
    }

    #[test]
    fn a_weak_detection_keeps_a_track_through_a_partial_occlusion() {
        let mut byte = ByteTracker::new(ByteTrackParams::default()).unwrap();
        let mut ids = Vec::new();
        for frame in 0..12 {
            let x = 4.0 * frame as f64;
            // Frames 5-7: the detector is unsure (score 0.15, below the activation 0.25).
            let score = if (5..8).contains(&frame) { 0.15 } else { 0.9 };
            let out = byte.step(&[scored(x, score)]);
            ids.extend(out.iter().map(|t| t.id));
            // The written box is the detection's.
            assert!(out.iter().all(|t| t.bbox.left_px == x));
        }
        // One identity all along: the weak boxes were taken by the second association.
        assert_eq!(ids.len(), 12);
        assert!(ids.iter().all(|&id| id == 1), "{ids:?}");
    }

    #[test]
    fn a_lost_track_is_found_again_within_the_buffer() {
        let mut byte = ByteTracker::new(ByteTrackParams::default()).unwrap();
        for _ in 0..5 {
            byte.step(&[scored(100.0, 0.9)]);
        }
        for _ in 0..10 {
            assert!(byte.step(&[]).is_empty());
        }
        let out = byte.step(&[scored(100.0, 0.9)]);
        assert_eq!(out.iter().map(|t| t.id).collect::<Vec<_>>(), [1]);
        // A new object far away gets a new id once matched a second time.
        byte.step(&[scored(100.0, 0.9), scored(400.0, 0.9)]);
        let out = byte.step(&[scored(100.0, 0.9), scored(400.0, 0.9)]);
        assert_eq!(out.iter().map(|t| t.id).collect::<Vec<_>>(), [1, 2]);
    }

    #[test]
    fn bad_boxes_are_skipped_and_bad_parameters_refused() {
        let mut byte = ByteTracker::new(ByteTrackParams::default()).unwrap();
        let mut bad = scored(0.0, 0.9);
        bad.bbox.width_px = -3.0;
        assert!(byte.step(&[bad, scored(0.0, f64::NAN)]).is_empty());
        let params = ByteTrackParams {
            frame_rate: 0.0,
            ..ByteTrackParams::default()
        };
        let e = ByteTracker::new(params).unwrap_err().to_string();
        assert!(e.contains("`frame_rate`"), "{e}");
    }
}

//! SORT (Bewley et al., *Simple Online and Realtime Tracking*, ICIP 2016): the baseline of
//! box trackers. One constant-velocity Kalman filter per object over the box centre, area and
//! aspect ratio `(u, v, s, r, u̇, v̇, ṡ)`, predicted each frame and associated to the detections
//! by the Hungarian algorithm on IoU; a pair below the IoU threshold is no match. An unmatched
//! detection starts a filter; a filter unmatched for more than `max_age` frames ends; a track is
//! written once it has `min_hits` consecutive matches (or during the first `min_hits` frames).
//!
//! The constants are those of the authors' public code (`sort.py`, 2016-2020): measurement
//! noise `diag(1, 1, 10, 10)`, initial covariance `diag(10, 10, 10, 10, 10⁴, 10⁴, 10⁴)`,
//! process noise `diag(1, 1, 1, 1, 0.01, 0.01, 10⁻⁴)`, the Joseph-form update, and the
//! boxes written are the filter's estimates.

use sillage_assoc::LapSolver;
use sillage_core::{BoundingBox, Error, Result};

/// SORT's three parameters, with the authors' defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SortParams {
    /// Frames a filter may go unmatched before it ends; default 1.
    pub max_age: u32,
    /// Consecutive matches before a track is written; default 3.
    pub min_hits: u32,
    /// Smallest IoU of a match; default 0.3.
    pub iou_threshold: f64,
}

impl Default for SortParams {
    fn default() -> Self {
        Self {
            max_age: 1,
            min_hits: 3,
            iou_threshold: 0.3,
        }
    }
}

impl SortParams {
    /// Checks the IoU threshold; errors name the key.
    pub fn validate(&self) -> Result<()> {
        if !(self.iou_threshold.is_finite() && (0.0..=1.0).contains(&self.iou_threshold)) {
            return Err(Error::parameter(
                "iou_threshold",
                self.iou_threshold,
                "must lie in [0, 1] (SORT uses 0.3)",
            ));
        }
        Ok(())
    }
}

/// A box tracked in one frame: its track id (from 1) and the filter's box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackedBox {
    /// Track id, from 1 (MOTChallenge's ids are positive).
    pub id: u64,
    /// The filter's estimate after this frame's update.
    pub bbox: BoundingBox,
}

type State = [f64; 7];
type Covariance = [[f64; 7]; 7];

/// One object's Kalman filter and counters.
#[derive(Debug, Clone)]
struct BoxFilter {
    id: u64,
    x: State,
    p: Covariance,
    time_since_update: u32,
    hit_streak: u32,
}

/// `(u, v, s, r)`: centre, area and aspect ratio of `b`.
fn measurement(b: &BoundingBox) -> [f64; 4] {
    [
        b.left_px + b.width_px / 2.0,
        b.top_px + b.height_px / 2.0,
        b.width_px * b.height_px,
        b.width_px / b.height_px,
    ]
}

/// The box of state `x` (NaN sizes when the area or ratio went negative).
fn state_box(x: &State) -> BoundingBox {
    let w = (x[2] * x[3]).sqrt();
    let h = x[2] / w;
    BoundingBox {
        left_px: x[0] - w / 2.0,
        top_px: x[1] - h / 2.0,
        width_px: w,
        height_px: h,
    }
}

const MEASUREMENT_NOISE: [f64; 4] = [1.0, 1.0, 10.0, 10.0];
const PROCESS_NOISE: State = [1.0, 1.0, 1.0, 1.0, 0.01, 0.01, 1e-4];
const INITIAL_VARIANCE: State = [10.0, 10.0, 10.0, 10.0, 1e4, 1e4, 1e4];

impl BoxFilter {
    fn new(id: u64, b: &BoundingBox) -> Self {
        let z = measurement(b);
        let mut p = [[0.0; 7]; 7];
        for (i, row) in p.iter_mut().enumerate() {
            row[i] = INITIAL_VARIANCE[i];
        }
        Self {
            id,
            x: [z[0], z[1], z[2], z[3], 0.0, 0.0, 0.0],
            p,
            time_since_update: 0,
            hit_streak: 0,
        }
    }

    /// `x ← F x`, `P ← F P Fᵀ + Q` (positions and area advance by their rates).
    fn predict(&mut self) -> BoundingBox {
        if self.x[6] + self.x[2] <= 0.0 {
            self.x[6] = 0.0;
        }
        for i in 0..3 {
            self.x[i] += self.x[i + 4];
        }
        // F P: rows 0..3 gain rows 4..7; then (F P) Fᵀ: columns 0..3 gain columns 4..7.
        for i in 0..3 {
            for j in 0..7 {
                self.p[i][j] += self.p[i + 4][j];
            }
        }
        for row in &mut self.p {
            for j in 0..3 {
                row[j] += row[j + 4];
            }
        }
        for (i, q) in PROCESS_NOISE.iter().enumerate() {
            self.p[i][i] += q;
        }
        if self.time_since_update > 0 {
            self.hit_streak = 0;
        }
        self.time_since_update += 1;
        state_box(&self.x)
    }

    /// The Kalman update with the box `b` (measurement `H x = x[0..4]`), Joseph form.
    fn update(&mut self, b: &BoundingBox) {
        self.time_since_update = 0;
        self.hit_streak += 1;
        let z = measurement(b);
        // S = H P Hᵀ + R: the top-left 4×4 block of P plus R.
        let s: [[f64; 4]; 4] = std::array::from_fn(|i| {
            std::array::from_fn(|j| self.p[i][j] + if i == j { MEASUREMENT_NOISE[i] } else { 0.0 })
        });
        let Some(s_inv) = invert4(&s) else {
            return;
        };
        // K = P Hᵀ S⁻¹: the first four columns of P times S⁻¹.
        let k: [[f64; 4]; 7] = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..4).map(|m| self.p[i][m] * s_inv[m][j]).sum())
        });
        let y: [f64; 4] = std::array::from_fn(|i| z[i] - self.x[i]);
        for (x, gain) in self.x.iter_mut().zip(&k) {
            *x += gain.iter().zip(&y).map(|(g, y)| g * y).sum::<f64>();
        }
        // P ← (I − K H) P (I − K H)ᵀ + K R Kᵀ.
        let a: Covariance = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let kh = if j < 4 { k[i][j] } else { 0.0 };
                f64::from(u8::from(i == j)) - kh
            })
        });
        let ap: Covariance = mul7(&a, &self.p);
        let p: Covariance = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let apat: f64 = (0..7).map(|m| ap[i][m] * a[j][m]).sum();
                let krk: f64 = (0..4)
                    .map(|m| k[i][m] * MEASUREMENT_NOISE[m] * k[j][m])
                    .sum();
                apat + krk
            })
        });
        self.p = p;
    }
}

fn mul7(a: &Covariance, b: &Covariance) -> Covariance {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..7).map(|m| a[i][m] * b[m][j]).sum()))
}

/// The inverse of a 4×4 matrix by Gauss–Jordan elimination with partial pivoting; `None` when
/// singular.
pub(crate) fn invert4(m: &[[f64; 4]; 4]) -> Option<[[f64; 4]; 4]> {
    let mut a = *m;
    let mut inv = [[0.0; 4]; 4];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for col in 0..4 {
        let pivot = (col..4).max_by(|&r, &s| a[r][col].abs().total_cmp(&a[s][col].abs()))?;
        if a[pivot][col].abs() < 1e-300 || !a[pivot][col].is_finite() {
            return None;
        }
        a.swap(col, pivot);
        inv.swap(col, pivot);
        let d = a[col][col];
        for j in 0..4 {
            a[col][j] /= d;
            inv[col][j] /= d;
        }
        for r in 0..4 {
            if r != col {
                let f = a[r][col];
                for j in 0..4 {
                    a[r][j] -= f * a[col][j];
                    inv[r][j] -= f * inv[col][j];
                }
            }
        }
    }
    Some(inv)
}

/// The SORT tracker: call [`SortTracker::step`] once per frame, in order, frames without
/// detections included.
#[derive(Debug, Clone)]
pub struct SortTracker {
    params: SortParams,
    filters: Vec<BoxFilter>,
    frames: u64,
    next_id: u64,
    solver: LapSolver,
    costs: Vec<f64>,
}

impl SortTracker {
    /// A tracker with validated `params`.
    pub fn new(params: SortParams) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            params,
            filters: Vec::new(),
            frames: 0,
            next_id: 0,
            solver: LapSolver::new(),
            costs: Vec::new(),
        })
    }

    /// One frame: the detections' boxes (finite, positive sizes) in; the boxes of the tracks
    /// written at this frame out, by increasing id.
    pub fn step(&mut self, detections: &[BoundingBox]) -> Result<Vec<TrackedBox>> {
        let usable = |b: &&BoundingBox| {
            b.width_px > 0.0
                && b.height_px > 0.0
                && [b.left_px, b.top_px, b.width_px, b.height_px]
                    .iter()
                    .all(|v| v.is_finite())
        };
        if let Some(bad) = detections.iter().find(|b| !usable(b)) {
            return Err(Error::input(format!(
                "frame {}: a detection box {bad:?} has a size ≤ 0 or a non-finite value; remove \
                 it or fix the detector",
                self.frames
            )));
        }
        self.frames += 1;
        let predicted: Vec<BoundingBox> = self.filters.iter_mut().map(BoxFilter::predict).collect();
        let valid = |b: &BoundingBox| {
            b.left_px.is_finite() && b.width_px.is_finite() && b.height_px.is_finite()
        };
        let mut keep = predicted.iter().map(valid);
        self.filters.retain(|_| keep.next().unwrap_or(false));
        let predicted: Vec<BoundingBox> = predicted.into_iter().filter(valid).collect();
        let matches = self.associate(detections, &predicted);
        let mut matched_detection = vec![false; detections.len()];
        for &(d, t) in &matches {
            self.filters[t].update(&detections[d]);
            matched_detection[d] = true;
        }
        for (d, b) in detections.iter().enumerate() {
            if !matched_detection[d] {
                self.filters.push(BoxFilter::new(self.next_id, b));
                self.next_id += 1;
            }
        }
        let p = self.params;
        let early = self.frames <= u64::from(p.min_hits);
        let mut out: Vec<TrackedBox> = self
            .filters
            .iter()
            .filter(|f| f.time_since_update < 1 && (f.hit_streak >= p.min_hits || early))
            .map(|f| TrackedBox {
                id: f.id + 1,
                bbox: state_box(&f.x),
            })
            .collect();
        self.filters.retain(|f| f.time_since_update <= p.max_age);
        out.sort_by_key(|t| t.id);
        Ok(out)
    }

    /// Pairs `(detection, filter)` with IoU at least the threshold: the unique pairs above it
    /// when no detection or filter has two, else the Hungarian assignment of largest IoU.
    fn associate(
        &mut self,
        detections: &[BoundingBox],
        predicted: &[BoundingBox],
    ) -> Vec<(usize, usize)> {
        let (n, m) = (detections.len(), predicted.len());
        if n == 0 || m == 0 {
            return Vec::new();
        }
        let threshold = self.params.iou_threshold;
        let mut costs = std::mem::take(&mut self.costs);
        costs.clear();
        costs.extend(
            detections
                .iter()
                .flat_map(|d| predicted.iter().map(move |t| -d.iou(t))),
        );
        let iou_of = |d: usize, t: usize| -costs[d * m + t];
        let unique = (0..n).all(|d| (0..m).filter(|&t| iou_of(d, t) > threshold).count() <= 1)
            && (0..m).all(|t| (0..n).filter(|&d| iou_of(d, t) > threshold).count() <= 1);
        let pairs: Vec<(usize, usize)> = if unique {
            (0..n)
                .flat_map(|d| {
                    (0..m)
                        .filter(move |&t| iou_of(d, t) > threshold)
                        .map(move |t| (d, t))
                })
                .collect()
        } else {
            self.solver
                .solve(n, m, &costs)
                .iter()
                .enumerate()
                .filter_map(|(d, t)| t.map(|t| (d, t)))
                .collect()
        };
        let matches = pairs
            .into_iter()
            .filter(|&(d, t)| iou_of(d, t) >= threshold)
            .collect();
        self.costs = costs;
        matches
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bbox(left: f64, top: f64, w: f64, h: f64) -> BoundingBox {
        BoundingBox {
            left_px: left,
            top_px: top,
            width_px: w,
            height_px: h,
        }
    }

    #[test]
    fn two_walkers_keep_their_ids_and_tracks_wait_for_three_hits() {
        let mut sort = SortTracker::new(SortParams::default()).unwrap();
        let mut ids = Vec::new();
        for frame in 0..10 {
            let x = 5.0 * frame as f64;
            let out = sort
                .step(&[bbox(x, 10.0, 20.0, 50.0), bbox(300.0 - x, 10.0, 20.0, 50.0)])
                .unwrap();
            assert_eq!(out.len(), 2, "frame {frame}");
            ids.push([out[0].id, out[1].id]);
            // The estimate follows the detection.
            assert!((out[0].bbox.left_px - x).abs() < 3.0, "{out:?}");
        }
        assert!(ids.iter().all(|pair| *pair == [1, 2]), "{ids:?}");
    }

    #[test]
    fn a_filter_unmatched_beyond_max_age_ends_and_a_new_id_starts() {
        let mut sort = SortTracker::new(SortParams::default()).unwrap();
        for _ in 0..5 {
            sort.step(&[bbox(0.0, 0.0, 10.0, 10.0)]).unwrap();
        }
        sort.step(&[]).unwrap();
        sort.step(&[]).unwrap();
        // The first filter is gone: the box starts track 2, written once three updates
        // follow its creation (as the authors' code).
        for _ in 0..3 {
            let out = sort.step(&[bbox(0.0, 0.0, 10.0, 10.0)]).unwrap();
            assert!(out.is_empty(), "{out:?}");
        }
        let out = sort.step(&[bbox(0.0, 0.0, 10.0, 10.0)]).unwrap();
        assert_eq!(out.iter().map(|t| t.id).collect::<Vec<_>>(), [2]);
    }

    #[test]
    fn the_hungarian_assignment_takes_the_largest_total_iou() {
        // Two filters, two detections each overlapping both: the crossing pairing is worse.
        let mut sort = SortTracker::new(SortParams::default()).unwrap();
        let a = bbox(0.0, 0.0, 10.0, 10.0);
        let b = bbox(6.0, 0.0, 10.0, 10.0);
        for _ in 0..4 {
            sort.step(&[a, b]).unwrap();
        }
        let out = sort
            .step(&[bbox(1.0, 0.0, 10.0, 10.0), bbox(7.0, 0.0, 10.0, 10.0)])
            .unwrap();
        assert_eq!(out.len(), 2);
        assert!(out[0].bbox.left_px < out[1].bbox.left_px, "{out:?}");
    }

    #[test]
    fn bad_boxes_and_thresholds_are_refused() {
        let mut sort = SortTracker::new(SortParams::default()).unwrap();
        let e = sort
            .step(&[bbox(0.0, 0.0, -1.0, 5.0)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("size ≤ 0"), "{e}");
        let e = sort
            .step(&[bbox(f64::NAN, 0.0, 1.0, 5.0)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("non-finite"), "{e}");
        let params = SortParams {
            iou_threshold: 1.5,
            ..SortParams::default()
        };
        let e = SortTracker::new(params).unwrap_err().to_string();
        assert!(e.contains("`iou_threshold`"), "{e}");
    }

    #[test]
    fn invert4_inverts() {
        let m = [
            [4.0, 1.0, 0.0, 0.5],
            [1.0, 3.0, 0.2, 0.0],
            [0.0, 0.2, 2.0, 0.1],
            [0.5, 0.0, 0.1, 5.0],
        ];
        let inv = invert4(&m).unwrap();
        for (i, row) in m.iter().enumerate() {
            for j in 0..4 {
                let v: f64 = row.iter().zip(&inv).map(|(a, b)| a * b[j]).sum();
                assert!((v - f64::from(u8::from(i == j))).abs() < 1e-12);
            }
        }
        assert!(invert4(&[[0.0; 4]; 4]).is_none());
    }
}

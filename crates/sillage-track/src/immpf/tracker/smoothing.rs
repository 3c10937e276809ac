//! Fixed-lag Gaussian smoothing of one tracker's reported boxes over frames (detection-driven
//! mode, `detection.smooth_frames`): each reported box becomes the value at its frame of a
//! line fitted to the tracker's reported boxes within `reach` frames of it, weighted by a
//! Gaussian of the frame distance (σ = `smooth_frames`; `reach` =
//! [`crate::immpf::DetectionLikelihoodParams::smoothing_lag_frames`]). This is the
//! Gaussian-smoothed interpolation StrongSORT's authors run on their output files (Du et al.
//! 2023, "GSI", there with a Gaussian process), done as the tracker runs: the tracker says
//! when a box is final (`write_smoothed` in `on_detections`). Detections place boxes with a
//! noise of their own from frame to frame; averaging neighbours cancels part of it while a
//! person walks at a steady pace.

use std::collections::VecDeque;

use sillage_core::{BoundingBox, FrameIndex};

use super::PedestrianEstimate;

/// The reported boxes of one tracker that are not written yet, with the last written ones
/// kept as their past neighbours; in frame order.
#[derive(Debug, Clone, Default)]
pub(super) struct BoxSmoother {
    rows: VecDeque<PedestrianEstimate>,
    /// Rows at the front already written.
    written: usize,
}

impl BoxSmoother {
    /// Adds a reported estimate, later in frame than every one before it.
    pub(super) fn push(&mut self, estimate: PedestrianEstimate) {
        debug_assert!(self.rows.back().is_none_or(|r| r.frame < estimate.frame));
        self.rows.push_back(estimate);
    }

    /// Frame of the last reported estimate.
    pub(super) fn last_frame(&self) -> Option<FrameIndex> {
        self.rows.back().map(|r| r.frame)
    }

    /// Writes to `out`, smoothed (σ `sigma_frames`, neighbours within `reach` frames), the
    /// estimates not yet written whose frame is at most `through`, and forgets those no longer
    /// within `reach` of one still to write.
    pub(super) fn write_through(
        &mut self,
        through: FrameIndex,
        (sigma_frames, reach): (f64, u64),
        out: &mut Vec<PedestrianEstimate>,
    ) {
        while let Some(row) = self.rows.get(self.written) {
            if row.frame > through {
                break;
            }
            out.push(self.smoothed(self.written, reach, sigma_frames));
            self.written += 1;
        }
        let oldest_needed = self
            .rows
            .get(self.written)
            .map_or(FrameIndex::MAX, |r| r.frame.saturating_sub(reach));
        while self.written > 0 && self.rows[0].frame < oldest_needed {
            self.rows.pop_front();
            self.written -= 1;
        }
    }

    /// Writes every estimate not yet written (the tracker ended, or the input did).
    pub(super) fn write_all(&mut self, kernel: (f64, u64), out: &mut Vec<PedestrianEstimate>) {
        self.write_through(FrameIndex::MAX, kernel, out);
    }

    /// Row `i` with its box edges and size fitted by Gaussian-weighted local linear regression
    /// on the boxes within `reach` frames (the line's value at row `i`'s frame): where the
    /// neighbours sit on both sides, the weighted mean; at a track's end or a gap's edge, the
    /// trend carried on rather than a mean pulled inwards (a box growing as a person comes
    /// closer stays on its growth).
    fn smoothed(&self, i: usize, reach: u64, sigma_frames: f64) -> PedestrianEstimate {
        let centre = &self.rows[i];
        // Σw, Σw·d, Σw·d² and, per box value, Σw·v and Σw·d·v, d the frame offset.
        let (mut s0, mut s1, mut s2) = (0.0, 0.0, 0.0);
        let (mut t0, mut t1) = ([0.0; 4], [0.0; 4]);
        for row in &self.rows {
            let distance = row.frame.abs_diff(centre.frame);
            if distance > reach {
                continue;
            }
            let d = row.frame as f64 - centre.frame as f64;
            let z = d / sigma_frames;
            let w = (-0.5 * z * z).exp();
            let b = &row.bbox;
            for (k, v) in [b.left_px, b.top_px, b.width_px, b.height_px]
                .into_iter()
                .enumerate()
            {
                t0[k] += w * v;
                t1[k] += w * d * v;
            }
            s0 += w;
            s1 += w * d;
            s2 += w * d * d;
        }
        let det = s0 * s2 - s1 * s1;
        // One row alone (or all on one frame): no line to fit, the row as it is.
        let at_centre = |k: usize| {
            if det > 1e-9 * s0 * s0 {
                (s2 * t0[k] - s1 * t1[k]) / det
            } else {
                t0[k] / s0
            }
        };
        PedestrianEstimate {
            bbox: BoundingBox {
                left_px: at_centre(0),
                top_px: at_centre(1),
                width_px: at_centre(2),
                height_px: at_centre(3),
            },
            ..centre.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_core::Vec2;

    fn row(frame: FrameIndex, left_px: f64) -> PedestrianEstimate {
        PedestrianEstimate {
            frame,
            track_id: 1,
            bbox: BoundingBox {
                left_px,
                top_px: 10.0,
                width_px: 20.0,
                height_px: 40.0,
            },
            vel_px_per_frame: Vec2::ZERO,
            model_weights: vec![1.0],
        }
    }

    #[test]
    fn a_steady_walk_is_kept_and_a_jitter_is_averaged() {
        let mut smoother = BoxSmoother::default();
        let mut out = Vec::new();
        // A walk at 2 px/frame with one box thrown 6 px off at frame 5.
        for f in 0..10u64 {
            let jitter = if f == 5 { 6.0 } else { 0.0 };
            smoother.push(row(f, 2.0 * f as f64 + jitter));
            smoother.write_through(f.saturating_sub(2), (1.0, 2), &mut out);
        }
        assert_eq!(out.len(), 8, "frames 0-7 are final at frame 9 (reach 2)");
        smoother.write_all((1.0, 2), &mut out);
        let frames: Vec<u64> = out.iter().map(|e| e.frame).collect();
        assert_eq!(frames, (0..10).collect::<Vec<_>>());
        // Away from the jitter a straight walk is unchanged, at its ends too (the local line
        // carries the trend where a mean would pull the box inwards).
        let off = |f: usize| out[f].bbox.left_px - 2.0 * f as f64;
        for f in [0, 1, 2, 8, 9] {
            assert!(off(f).abs() < 1e-9, "frame {f}: {}", off(f));
        }
        // The jitter is spread: frame 5 moves well under its 6 px, its neighbours a little.
        assert!(off(5) > 1.0 && off(5) < 3.0, "{}", off(5));
        assert!(off(4) > 0.5 && off(4) < off(5));
        assert!((out[5].bbox.width_px - 20.0).abs() < 1e-9);
        // Only the rows within reach of the next one to write are kept.
        assert!(smoother.rows.is_empty() || smoother.written == smoother.rows.len());
    }

    #[test]
    fn boxes_across_a_gap_wider_than_the_reach_are_not_mixed() {
        let mut smoother = BoxSmoother::default();
        let mut out = Vec::new();
        smoother.push(row(0, 0.0));
        smoother.push(row(10, 100.0));
        smoother.write_all((1.0, 2), &mut out);
        assert_eq!(out[0].bbox.left_px, 0.0);
        assert_eq!(out[1].bbox.left_px, 100.0);
    }
}

//! The detection-driven mode of the pedestrian tracker: the detections are both the births and
//! the measurements, alone or with colour frames. Each person keeps its IMM particle filter
//! (the competing motion models of the paper predict where its box goes). The detections are
//! assigned to the predicted boxes by the Hungarian algorithm on IoU (with frames, optionally
//! plus the colour distance to the person's reference histograms of §4.3) in two stages: the
//! confident detections to every tracker, then the weak ones to the trackers that a detection
//! held in the previous frame (ByteTrack's idea: a partly occluded person scores low). A
//! tracker's life follows SORT and ByteTrack: confirmed after `min_hits` matches in a row (its
//! earlier frames then reported too, with `report_first_hits`), only confident detections
//! start trackers, a tentative tracker ends at its first miss, a confirmed one is kept
//! `lost_frames` frames without a detection and may take one back, and a tracker is reported
//! on the frames a detection holds it.

use rayon::prelude::*;
use sillage_core::{BoundingBox, FrameIndex};

use super::{Candidate, PedestrianEstimate, PedestrianTracker, Track, estimate_foot, estimate_of};
use crate::bytetrack::assign;
use crate::immpf::{Appearance, DetectionLikelihoodParams, FrameCues, HistogramScratch};

/// σ of the velocities the proposal draws around the detections' velocity, as a multiple of
/// `σ / elapsed` (σ the foot likelihood's, `elapsed` the frames between the two detections):
/// the difference of two independent foot points would have √2; the smoothing over a streak
/// makes it smaller. Tried on all nine detection sequences, not held out (0.2, 0.5 and √2,
/// with the velocity drawn at the first match of a streak only: 0.2 and 0.5 within 0.5 point
/// of mean (MOTA + IDF1) / 2, √2 about 1 point below; smoothed at every match with weight
/// 0.2: 0.2 half a point above 0.5).
const VELOCITY_PROPOSAL_SD: f64 = 0.2;

impl PedestrianTracker {
    /// One frame of the detection-driven mode ([`PedestrianTracker::step`] without cues, or
    /// with cues and detections as measurements).
    pub(super) fn step_on_detections(
        &mut self,
        frame: FrameIndex,
        candidates: &[Candidate],
        cues: Option<&FrameCues>,
        out: &mut Vec<PedestrianEstimate>,
    ) {
        let models = &self.models;
        let size_rate = self.params.detection.size_rate;
        self.tracks.par_iter_mut().for_each(|track| {
            track.filter.predict(models);
            if size_rate {
                // As SORT's Kalman filter carries its area rate through misses; a size stays
                // at least a pixel (SORT zeroes a rate that would make the area negative).
                track.size_px.0 = (track.size_px.0 + track.size_rate.0).max(1.0);
                track.size_px.1 = (track.size_px.1 + track.size_rate.1).max(1.0);
            }
        });
        let looks: Vec<Option<Appearance>> = match cues {
            Some(cues) if self.params.detection.colour_weight > 0.0 => candidates
                .par_iter()
                .map(|c| Appearance::capture(&self.params.appearance, cues, &c.bbox))
                .collect(),
            _ => vec![None; candidates.len()],
        };
        let unmatched = self.match_in_two_stages(candidates, &looks);
        self.correct_on_detections(frame, cues);
        self.end_lost_trackers(out);
        for d in unmatched {
            let candidate = candidates[d];
            self.next_id += 1;
            let look = looks[d].clone();
            let mut track = self.spawn(self.next_id - 1, &candidate.bbox, look, 0);
            track.matched = Some(candidate.bbox);
            track.hit_streak = 1;
            track.last_detection = Some((frame, candidate.bbox));
            self.tracks.push(track);
        }
        self.report_on_detections(frame, out);
    }

    /// Assigns `candidates` (their colour histograms `looks`, with frames) to the trackers
    /// (`Track::matched`): first those of score ≥ `high_score` to every tracker (IoU ≥
    /// `match_iou`), then the others to the trackers still free that a detection held in the
    /// previous frame (IoU ≥ `low_match_iou`). Returns the indices of the confident
    /// candidates left, the births.
    fn match_in_two_stages(
        &mut self,
        candidates: &[Candidate],
        looks: &[Option<Appearance>],
    ) -> Vec<usize> {
        let params = &self.params.detection;
        let predicted: Vec<BoundingBox> = self
            .tracks
            .iter()
            .map(|t| self.sizing.box_at(estimate_foot(&t.filter), t.size_px))
            .collect();
        self.tracks.iter_mut().for_each(|t| t.matched = None);
        let (strong, weak): (Vec<usize>, Vec<usize>) =
            (0..candidates.len()).partition(|&d| candidates[d].score >= params.high_score);
        let (match_iou, low_match_iou) = (params.match_iou, params.low_match_iou);
        let everyone: Vec<usize> = (0..self.tracks.len()).collect();
        let pool = Pool { candidates, looks };
        let (free, left) = self.assign_stage(&predicted, &everyone, &pool, &strong, match_iou);
        let held_last: Vec<usize> = free
            .into_iter()
            .filter(|&t| self.tracks[t].unsupported_frames == 0)
            .collect();
        self.assign_stage(&predicted, &held_last, &pool, &weak, low_match_iou);
        left
    }

    /// The Hungarian assignment of the candidates `dets` to the trackers `tracks` on
    /// `1 − IoU + w·d²` with their predicted boxes (`w` = `colour_weight`, d² the colour
    /// distance of the detection to the tracker's reference, 0 without frames), pairs of
    /// IoU ≥ `min_iou` kept and recorded in `Track::matched`. Returns the trackers and the
    /// candidates left.
    fn assign_stage(
        &mut self,
        predicted: &[BoundingBox],
        tracks: &[usize],
        pool: &Pool<'_>,
        dets: &[usize],
        min_iou: f64,
    ) -> (Vec<usize>, Vec<usize>) {
        let weight = self.params.detection.colour_weight;
        // The most the colour term can add: w (d² ≤ 1) where detections have a look (with
        // frames), nothing without.
        let colour_bound = if pool.looks.iter().any(Option::is_some) {
            weight
        } else {
            0.0
        };
        let costs: Vec<f64> = tracks
            .iter()
            .flat_map(|&t| dets.iter().map(move |&d| (t, d)))
            .map(|(t, d)| {
                let iou = predicted[t].iou(&pool.candidates[d].bbox);
                if iou < min_iou {
                    return f64::INFINITY;
                }
                let colour = match (&self.tracks[t].appearance, &pool.looks[d]) {
                    (Some(reference), Some(look)) if weight > 0.0 => {
                        weight * reference.colour_distance(look)
                    }
                    _ => 0.0,
                };
                1.0 - iou + colour
            })
            .collect();
        let pairs = assign(
            &mut self.solver,
            tracks.len(),
            dets.len(),
            &costs,
            1.0 - min_iou + colour_bound,
        );
        let mut track_taken = vec![false; tracks.len()];
        let mut det_taken = vec![false; dets.len()];
        for (r, c) in pairs {
            track_taken[r] = true;
            det_taken[c] = true;
            self.tracks[tracks[r]].matched = Some(pool.candidates[dets[c]].bbox);
        }
        let tracks_left = (0..tracks.len()).filter(|&r| !track_taken[r]);
        let dets_left = (0..dets.len()).filter(|&c| !det_taken[c]);
        (
            tracks_left.map(|r| tracks[r]).collect(),
            dets_left.map(|c| dets[c]).collect(),
        )
    }

    /// Weighs and resamples the particles of every tracker a detection holds: a Gaussian of
    /// the foot-point distance (σ = `foot_sigma_fraction` × the detection's height) after a
    /// share `proposal_share` of them was drawn around that foot point
    /// ([`propose_on_detection`]); the others coast on their prediction. Counts matches in a
    /// row and frames without one, lets the box size follow the detections and, with frames
    /// (`cues`), the colour reference follow the matched detection ([`Appearance::adapt`]).
    fn correct_on_detections(&mut self, frame: FrameIndex, cues: Option<&FrameCues>) {
        let (params, sizing) = (&self.params.detection, &self.sizing);
        let appearance_params = &self.params.appearance;
        let tracks = self.tracks.par_iter_mut();
        tracks.for_each_init(HistogramScratch::default, |scratch, track| {
            match track.matched {
                Some(detection) => {
                    if let (Some(reference), Some(cues)) = (&mut track.appearance, cues) {
                        reference.adapt(appearance_params, cues, &detection, scratch);
                    }
                    let foot = detection.foot();
                    follow_size_rate(track, &detection, frame, params.velocity_smoothing);
                    let sigma = (params.foot_sigma_fraction * detection.height_px).max(1.0);
                    propose_on_detection(track, &detection, sigma, frame, params);
                    let scale = 0.5 / (sigma * sigma);
                    track
                        .filter
                        .weight(|p| -scale * (p.pos_px - foot).norm_squared());
                    track.filter.resample();
                    let alpha = params.size_smoothing;
                    track.size_px = (
                        (1.0 - alpha) * track.size_px.0 + alpha * detection.width_px,
                        (1.0 - alpha) * track.size_px.1 + alpha * detection.height_px,
                    );
                    track.hit_streak += 1;
                    track.unsupported_frames = 0;
                }
                None => {
                    // No likelihood: the weights stay as they are, and no resampling, which
                    // would only thin out the particles' velocities while the tracker coasts.
                    track.hit_streak = 0;
                    track.unsupported_frames += 1;
                }
            }
            track.bbox = sizing.box_at(estimate_foot(&track.filter), track.size_px);
        });
    }

    /// Ends the tentative trackers that missed their detection, the confirmed ones that
    /// went `lost_frames` frames without one, and those whose foot left the image; the
    /// estimates they still held back for smoothing go to `out`.
    fn end_lost_trackers(&mut self, out: &mut Vec<PedestrianEstimate>) {
        let (lost, frame_size) = (self.params.detection.lost_frames, self.frame_size_px);
        let kernel = self.smoothing_kernel();
        self.tracks.retain_mut(|t| {
            let limit = if t.confirmed { lost } else { 0 };
            let alive = t.foot_inside(frame_size) && t.unsupported_frames <= limit;
            if !alive {
                t.smoother.write_all(kernel, out);
            }
            alive
        });
    }

    /// σ and reach, in frames, of the smoothing of the reported boxes.
    pub(super) fn smoothing_kernel(&self) -> (f64, u64) {
        let params = &self.params.detection;
        (params.smooth_frames, params.smoothing_lag_frames())
    }

    /// Appends the estimate of every reported tracker that a detection holds at `frame`
    /// (every confirmed one with `report_coasting`). A tracker is reported once `min_hits`
    /// detections in a row held it — again after a miss with `reconfirm_after_loss` — and
    /// its estimates until then are held: reported at that moment with
    /// `report_first_hits`, dropped without (SORT).
    fn report_on_detections(&mut self, frame: FrameIndex, out: &mut Vec<PedestrianEstimate>) {
        let params = &self.params.detection;
        let models = self.models.len();
        for track in &mut self.tracks {
            track.age += 1;
            let observed = track.matched.is_some();
            if params.reconfirm_after_loss && observed && track.hit_streak == 1 {
                track.reported = false;
            }
            if !track.reported && track.hit_streak >= params.min_hits {
                track.confirmed = true;
                track.reported = true;
                if !params.report_first_hits {
                    track.held.clear();
                }
                for estimate in std::mem::take(&mut track.held) {
                    self.gap_rows += report(track, estimate, params, out);
                }
            }
            if !(observed || params.report_coasting && track.confirmed) {
                continue;
            }
            let estimate = estimate_of(track, frame, models);
            if track.reported {
                self.gap_rows += report(track, estimate, params, out);
            } else {
                track.held.push(estimate);
            }
        }
        if params.smooth_frames > 0.0 {
            self.write_smoothed(frame, out);
        }
    }

    /// Writes the smoothed estimates that later reports will not change: those `reach` frames
    /// or more before a tracker's last reported one (later ones come after it), and those
    /// older than `reach + fill_gaps + min_hits` frames, which bounds how far back a filled
    /// gap before a re-confirmation's streak reaches. (A re-confirmation after broken streaks
    /// may report older held frames; a box near them is then smoothed without them.)
    fn write_smoothed(&mut self, frame: FrameIndex, out: &mut Vec<PedestrianEstimate>) {
        let kernel = self.smoothing_kernel();
        let params = &self.params.detection;
        let late = kernel.1 + u64::from(params.fill_gaps) + u64::from(params.min_hits);
        for track in &mut self.tracks {
            let Some(last) = track.smoother.last_frame() else {
                continue;
            };
            let through = last.checked_sub(kernel.1).max(frame.checked_sub(late));
            if let Some(through) = through {
                track.smoother.write_through(through, kernel, out);
            }
        }
    }
}

/// Reports `estimate` of `track`, after the frames since the tracker's last reported
/// estimate when there are at least one and at most `fill_gaps` of them ([`interpolated`]):
/// appended to `out`, or to the tracker's smoother with `detection.smooth_frames`. Returns
/// the number of those filled frames.
fn report(
    track: &mut Track,
    estimate: PedestrianEstimate,
    params: &DetectionLikelihoodParams,
    out: &mut Vec<PedestrianEstimate>,
) -> u64 {
    let smooth = params.smooth_frames > 0.0;
    let mut emit = |row: PedestrianEstimate| {
        if smooth {
            track.smoother.push(row);
        } else {
            out.push(row);
        }
    };
    let mut filled = 0;
    if let Some(before) = &track.last_reported {
        let gap = estimate.frame.saturating_sub(before.frame + 1);
        if gap > 0 && gap <= u64::from(params.fill_gaps) {
            (before.frame + 1..estimate.frame)
                .for_each(|f| emit(interpolated(before, &estimate, f)));
            filled = gap;
        }
    }
    emit(estimate.clone());
    track.last_reported = Some(estimate);
    filled
}

/// The estimate at `frame`, between those of the same tracker at `before.frame` and
/// `after.frame`: box edges, sizes and model weights interpolated linearly, the velocity that
/// of the foot point from one to the other.
fn interpolated(
    before: &PedestrianEstimate,
    after: &PedestrianEstimate,
    frame: FrameIndex,
) -> PedestrianEstimate {
    let span = (after.frame - before.frame) as f64;
    let s = (frame - before.frame) as f64 / span;
    let lerp = |a: f64, b: f64| a + s * (b - a);
    let (a, b) = (&before.bbox, &after.bbox);
    PedestrianEstimate {
        frame,
        track_id: after.track_id,
        bbox: BoundingBox {
            left_px: lerp(a.left_px, b.left_px),
            top_px: lerp(a.top_px, b.top_px),
            width_px: lerp(a.width_px, b.width_px),
            height_px: lerp(a.height_px, b.height_px),
        },
        vel_px_per_frame: (b.foot() - a.foot()) / span,
        model_weights: before
            .model_weights
            .iter()
            .zip(&after.model_weights)
            .map(|(&p, &q)| lerp(p, q))
            .collect(),
    }
}

/// Draws `proposal_share` of a matched tracker's particles around its detection's foot point
/// `foot` (σ `sigma`) and, with `velocity_proposal`, their velocities around the detections'
/// velocity: the difference of its last two detections' foot points per frame, smoothed
/// exponentially (`velocity_smoothing`) over a streak of matches and taken as it is at the
/// streak's first (a tracker's second detection, or its first after a miss) — as the second
/// update of SORT's Kalman filter takes the velocity at once and its small process noise
/// then smooths it.
fn propose_on_detection(
    track: &mut Track,
    detection: &BoundingBox,
    sigma: f64,
    frame: FrameIndex,
    params: &DetectionLikelihoodParams,
) {
    let share = params.proposal_share;
    let foot = detection.foot();
    let measured = track
        .last_detection
        .filter(|_| params.velocity_proposal)
        .map(|(then, before)| {
            let elapsed = (frame - then) as f64;
            ((foot - before.foot()) / elapsed, elapsed)
        });
    match measured {
        Some((velocity, elapsed)) => {
            let smoothed = match track.detection_velocity {
                Some(old) if track.hit_streak > 1 => {
                    old + (velocity - old) * params.velocity_smoothing
                }
                _ => velocity,
            };
            track.detection_velocity = Some(smoothed);
            let vel_sd = VELOCITY_PROPOSAL_SD * sigma / elapsed;
            track
                .filter
                .propose_moving_near(share, foot, sigma, smoothed, vel_sd);
        }
        None => track.filter.propose_near(share, foot, sigma),
    }
    track.last_detection = Some((frame, *detection));
}

/// Updates a matched tracker's size rate (`Track::size_rate`, px/frame) with `detection`: the
/// change of width and height since its last detection per frame, smoothed exponentially
/// (newest weight `smoothing`) from zero at its birth. Call before [`propose_on_detection`],
/// which records `detection` as the last one.
fn follow_size_rate(track: &mut Track, detection: &BoundingBox, frame: FrameIndex, smoothing: f64) {
    let Some((then, seen)) = track.last_detection else {
        return;
    };
    let elapsed = (frame - then) as f64;
    let measured = (
        (detection.width_px - seen.width_px) / elapsed,
        (detection.height_px - seen.height_px) / elapsed,
    );
    let (w, h) = track.size_rate;
    track.size_rate = (
        w + smoothing * (measured.0 - w),
        h + smoothing * (measured.1 - h),
    );
}

/// The candidates of one frame with their colour histograms (`None` without frames).
struct Pool<'a> {
    candidates: &'a [Candidate],
    looks: &'a [Option<Appearance>],
}

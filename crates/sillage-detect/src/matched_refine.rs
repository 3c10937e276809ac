//! The particles' own scale as a second look: isolated particles re-fitted there, and faint
//! ones only it can see added.
//!
//! The automatic blob scale is smaller than the particle images (it must resolve neighbours),
//! which costs twice: the 3-point fit sees a peak flattened by noise at a scale the particle
//! does not fill, and faint particles stay under the threshold. So the DoG at δ = σ (the
//! matched scale) is computed too: a particle with no other detection within
//! [`ISOLATION_SIGMAS`] σ is re-fitted on it (~1.2× the Cramér–Rao bound), and its peaks
//! above its own threshold with no detection within [`MERGE_SIGMAS`] σ are added (faint
//! particles). Crowded
//! particles keep the resolving scale's position, since the matched filter pulls neighbours
//! together; so does an "isolated" one whose matched peak is flatter in some direction than a
//! single particle's ([`FLAT_PEAK_SIGMAS`]): a second particle overlaps it that the
//! resolving scale did not separate, and the matched peak lies between the two. Detections
//! within [`MERGE_SIGMAS`] σ of each other that climb to one round matched peak, with no other
//! detection near, are twins (noise splits a large particle's peak at the small resolving
//! scale): they become one detection, re-fitted.

use rayon::prelude::*;

use crate::cell_grid::CellGrid;
use crate::deblend::Deblender;
use sillage_core::{Detection, GrayImage, Point2, Result};
use sillage_image::{
    DogFilter, Peak, PeakFinder, Polarity, SubpixelFit, median_mad_of, refine_peak,
};

/// A detection is isolated when no other lies within this many particle σ.
pub const ISOLATION_SIGMAS: f64 = 4.0;
/// A matched-scale peak with no detection within this many σ is a particle the resolving
/// scale missed. Measured on isolated spots of σ = 2 px at SNR 5: 4σ finds 97.8 % of them
/// (noise detections within 4σ hide faint spots), 2σ 100 %; the same on the tune half of
/// the accuracy family.
pub const MERGE_SIGMAS: f64 = 2.0;
/// A re-fit is taken only where the matched peak's sharpness (its least log-curvature over
/// the two axes and the two diagonals) is at most this many standard deviations below the
/// frame's median over the isolated detections (the deviation from their median absolute
/// deviation): a flatter peak holds a second particle, and its fit lands between the two.
///
/// Tuned on the tune halves of both `sillage bench ptv-accuracy` families (36 cases): with no
/// test 21 cases within 2 points of tuned, 4 with ≤ 2 % false, mean 72.5 / 9.9 %; 2σ 25, 9,
/// 73.2 / 9.1; 3σ 24, 9, 73.1 / 9.3; 4σ 23, 9, 73.0 / 9.4. 2σ takes isolated particles of σ 3
/// px at SNR 5 to 1.63× the Cramér–Rao bound (`tests/localisation.rs`; 1.41× with no test,
/// 1.44× at 3σ), so 3σ. On the report halves (never used to choose): 20 → 26 of 36 cases
/// within 2 points of tuned, 6 → 11 with ≤ 2 % false, mean 69.3 / 11.4 → 69.9 / 10.7 %, no
/// case losing true recoveries.
pub const FLAT_PEAK_SIGMAS: f64 = 3.0;
/// The flat-peak test never refuses a peak whose sharpness is at least this share of the
/// frame's median (nor above what the sub-pixel phase alone explains, [`phase_spread`]). In
/// clean frames the robust spread of the sharpness is tiny (0.3 % of the median on a lattice of
/// σ 2 px spots at SNR 40), and a round peak then read 4 % below the median was refused; the
/// pairs the test is for read 25 % and more below (unit tests). On both accuracy families'
/// tune halves, where noise sets the floor, 0.85 and 0.9 change nothing.
const ROUND_PEAK_SHARE: f64 = 0.9;
/// Farthest a 3-point sub-pixel fit moves a peak from its pixel (half a pixel per axis,
/// `√0.5` px), with a margin for rounding.
const FIT_SHIFT_BOUND_PX: f64 = 0.75;
/// Fewest detections or peaks a rayon task handles.
const PAR_MIN_LEN: usize = 512;
/// Steps of the climb from a detection to the matched image's local maximum.
const MAX_CLIMB_STEPS: usize = 3;

/// Where a detection's climb on the matched image ended.
#[derive(Debug, Clone, Copy)]
struct Climb {
    /// The local maximum reached, pixel.
    peak: (u32, u32),
    /// Its sub-pixel fit.
    pos_px: Point2,
    /// Its [`sharpness`].
    sharpness: f64,
}

/// The matched-scale filter and its buffers.
#[derive(Debug, Clone)]
pub(crate) struct MatchedRefiner {
    dog: DogFilter,
    matched: GrayImage,
    /// The particle images' std σ, px.
    sigma_px: f64,
    /// The share of the median sharpness above which the flat-peak test never refuses: the
    /// least of [`ROUND_PEAK_SHARE`] and what the sub-pixel phase alone gives
    /// ([`phase_spread`]).
    round_share: f64,
    isolation_px: f64,
    finder: PeakFinder,
    peaks: Vec<Peak>,
    /// The detections bucketed in cells as wide as the isolation radius.
    grid: CellGrid,
    /// Whether each detection's neighbours within the isolation radius all lie within the
    /// merge radius (possible twins from one particle), so that it is climbed.
    candidate: Vec<bool>,
    /// Each candidate detection's climb on the matched image (reused).
    climbs: Vec<Option<Climb>>,
    /// Whether each climbed detection is isolated: every other within the isolation radius
    /// reached its peak (reused).
    isolated: Vec<bool>,
    /// Climbed detections grouped by the matched peak they reach (reused).
    order: Vec<u32>,
    /// The groups to re-fit, as ranges of `order` (reused).
    groups: Vec<std::ops::Range<usize>>,
    /// Detections found to be a second detection of a particle, removed after the look.
    twins: Vec<bool>,
    /// The sharpness values, for their median and spread (reused).
    sharpness: Vec<f32>,
    /// The completion's candidates, in peak order (reused).
    added: Vec<Option<Detection>>,
    /// Splits the detections that are two particles (`detector.deblend`).
    deblender: Option<Deblender>,
}

impl MatchedRefiner {
    /// A refiner for particle images of std `sigma_px`, which also splits unresolved pairs
    /// with `deblend` and then re-fits the crowded detections with `refit_crowded`.
    pub(crate) fn new(sigma_px: f64, deblend: bool, refit_crowded: bool) -> Result<Self> {
        let mut dog = DogFilter::new(sigma_px)?;
        let round_share = phase_spread(&mut dog, sigma_px).min(ROUND_PEAK_SHARE);
        Ok(Self {
            dog,
            matched: GrayImage::default(),
            sigma_px,
            round_share,
            isolation_px: ISOLATION_SIGMAS * sigma_px,
            finder: PeakFinder::default(),
            peaks: Vec::new(),
            grid: CellGrid::default(),
            candidate: Vec::new(),
            climbs: Vec::new(),
            isolated: Vec::new(),
            order: Vec::new(),
            groups: Vec::new(),
            twins: Vec::new(),
            sharpness: Vec::new(),
            added: Vec::new(),
            deblender: deblend.then(|| Deblender::new(sigma_px, refit_crowded)),
        })
    }

    /// Re-fits the isolated ones of `detections` (positions in `input`'s pixels plus
    /// `offset`) on the matched DoG of `input`, then adds its peaks above `threshold` (a rule
    /// applied to that image) that no detection is near. A re-fit more than σ from the
    /// first position is not taken.
    pub(crate) fn refine(
        &mut self,
        input: &GrayImage,
        polarity: Polarity,
        fit: SubpixelFit,
        offset: (f64, f64),
        threshold: impl FnOnce(&GrayImage) -> Option<f32>,
        detections: &mut Vec<Detection>,
    ) {
        self.dog.apply(input, polarity, &mut self.matched);
        self.added.clear();
        self.mark_candidates(input.dimensions(), offset, detections);
        self.refit_isolated(fit, offset, detections);
        if let Some(threshold) = threshold(&self.matched) {
            self.complete(threshold, fit, offset, detections);
        }
        let mut twins = self.twins.iter();
        detections.retain(|_| !twins.next().copied().unwrap_or(false));
        detections.extend(self.added.iter().flatten());
        if let Some(deblender) = &mut self.deblender {
            let sign = f64::from(polarity.sign());
            deblender.split(input, sign, &self.matched, offset, detections);
        }
    }

    /// Finds the matched image's peaks above `threshold` that no detection is near (faint
    /// particles the resolving scale missed), into `self.added`.
    fn complete(
        &mut self,
        threshold: f32,
        fit: SubpixelFit,
        offset: (f64, f64),
        detections: &[Detection],
    ) {
        self.finder
            .find(&self.matched, 1, threshold, &mut self.peaks);
        let merge_px = MERGE_SIGMAS * self.sigma_px;
        let merge2 = merge_px.powi(2);
        // Half a pixel on each axis is 0.7071 px; the margin also covers rounding.
        let merge_sure2 = (merge_px - FIT_SHIFT_BOUND_PX).max(0.0).powi(2);
        // The grid holds the detections as they were before any is added.
        let mut added = std::mem::take(&mut self.added);
        let this = &*self;
        let found: &[Detection] = detections;
        this.peaks
            .par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map(|peak| {
                // The fit moves a peak by at most half a pixel per axis: a detection well
                // within the merge radius of the pixel is within it of the fit too, and
                // most matched peaks are the particles already found.
                let pixel = Point2::new(peak.x as f64 + offset.0, peak.y as f64 + offset.1);
                if this.nearest_within(pixel, found, merge_sure2) {
                    return None;
                }
                let local = refine_peak(&this.matched, peak.x, peak.y, fit)?;
                let p = Point2::new(local.x + offset.0, local.y + offset.1);
                (!this.nearest_within(p, found, merge2))
                    .then(|| Detection::new(p, this.matched.get(peak.x, peak.y)))
            })
            .collect_into_vec(&mut added);
        self.added = added;
    }

    /// Moves each isolated particle's detection to its re-fit on the matched image, unless the
    /// fit is more than σ away or its peak is flatter than a single particle's. A particle is
    /// isolated when every detection within the isolation radius climbs to the same matched
    /// peak: noise can split a large particle's peak at the resolving scale, and the twins
    /// then become one detection (the first), the others marked in `self.twins`.
    fn refit_isolated(
        &mut self,
        fit: SubpixelFit,
        offset: (f64, f64),
        detections: &mut [Detection],
    ) {
        let max_shift = self.sigma_px;
        let r2 = self.isolation_px.powi(2);
        let mut climbs = std::mem::take(&mut self.climbs);
        let mut isolated = std::mem::take(&mut self.isolated);
        let mut order = std::mem::take(&mut self.order);
        let mut groups = std::mem::take(&mut self.groups);
        let this = &*self;
        detections
            .par_iter()
            .zip(this.candidate.par_iter())
            .with_min_len(PAR_MIN_LEN)
            .map(|(detection, &candidate)| {
                if !candidate {
                    return None;
                }
                let local =
                    Point2::new(detection.pos_px.x - offset.0, detection.pos_px.y - offset.1);
                this.climb(local, fit).map(|climb| Climb {
                    pos_px: Point2::new(climb.pos_px.x + offset.0, climb.pos_px.y + offset.1),
                    ..climb
                })
            })
            .collect_into_vec(&mut climbs);
        // A climbed detection is isolated when every other within the radius reached its peak.
        (0..detections.len())
            .into_par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map(|i| {
                let Some(own) = climbs[i] else {
                    return false;
                };
                let p = detections[i].pos_px;
                !this.any_neighbour(p, |j| {
                    j != i && {
                        let q = detections[j].pos_px;
                        (q.x - p.x).powi(2) + (q.y - p.y).powi(2) < r2
                            && climbs[j].map(|c| c.peak) != Some(own.peak)
                    }
                })
            })
            .collect_into_vec(&mut isolated);
        // Groups of detections that reached one peak, each in detection order; a group is
        // re-fitted when all its members are isolated and one lies within σ of the fit.
        let peak_of = |i: u32| climbs[i as usize].map(|c| c.peak);
        order.clear();
        order.extend((0..detections.len() as u32).filter(|&i| climbs[i as usize].is_some()));
        order.sort_unstable_by_key(|&i| (peak_of(i), i));
        groups.clear();
        let mut start = 0;
        for group in order.chunk_by(|&a, &b| peak_of(a) == peak_of(b)) {
            let range = start..start + group.len();
            start = range.end;
            let near_fit = climbs[group[0] as usize].is_some_and(|climb| {
                group
                    .iter()
                    .any(|&i| detections[i as usize].pos_px.distance(climb.pos_px) < max_shift)
            });
            if near_fit && group.iter().all(|&i| isolated[i as usize]) {
                groups.push(range);
            }
        }
        let climb_of = |group: &std::ops::Range<usize>| climbs[order[group.start] as usize];
        self.sharpness.clear();
        self.sharpness.extend(
            groups
                .iter()
                .filter_map(climb_of)
                .map(|climb| climb.sharpness as f32)
                .filter(|sharpness| sharpness.is_finite()),
        );
        self.twins.clear();
        self.twins.resize(detections.len(), false);
        if let Some(stats) = median_mad_of(&mut self.sharpness) {
            let floor = (stats.median - FLAT_PEAK_SIGMAS * stats.sigma)
                .min(stats.median * self.round_share);
            for group in &groups {
                if let Some(climb) = climb_of(group)
                    && climb.sharpness >= floor
                    && let Some((leader, twins)) = order[group.clone()].split_first()
                {
                    detections[*leader as usize].pos_px = climb.pos_px;
                    for &twin in twins {
                        self.twins[twin as usize] = true;
                    }
                }
            }
        }
        self.isolated = isolated;
        self.groups = groups;
        self.climbs = climbs;
        self.order = order;
    }

    /// Sets `self.candidate`: whether each detection's neighbours within the isolation radius
    /// (a grid of cells as wide as the radius, counting-sorted) all lie within the merge radius
    /// — none, or possible twins.
    fn mark_candidates(
        &mut self,
        (width, height): (usize, usize),
        offset: (f64, f64),
        detections: &[Detection],
    ) {
        let r = self.isolation_px;
        self.grid.rebuild((width, height), detections, offset, r);
        let r2 = r * r;
        let twin2 = (MERGE_SIGMAS * self.sigma_px).powi(2);
        let mut candidate = std::mem::take(&mut self.candidate);
        let this = &*self;
        detections
            .par_iter()
            .enumerate()
            .with_min_len(PAR_MIN_LEN)
            .map(|(i, d)| {
                !this.any_neighbour(d.pos_px, |j| {
                    j != i && {
                        let q = detections[j].pos_px;
                        let d2 = (q.x - d.pos_px.x).powi(2) + (q.y - d.pos_px.y).powi(2);
                        d2 < r2 && d2 >= twin2
                    }
                })
            })
            .collect_into_vec(&mut candidate);
        self.candidate = candidate;
    }

    /// Whether `test` holds for one of the detections in the grid cells around `p`'s (the
    /// grid built by [`MatchedRefiner::mark_candidates`]); stops at the first.
    fn any_neighbour(&self, p: Point2, test: impl FnMut(usize) -> bool) -> bool {
        self.grid.near(p).any(test)
    }

    /// Whether one of `detections` (those the grid was built on) lies within `√r2` of `p`.
    fn nearest_within(&self, p: Point2, detections: &[Detection], r2: f64) -> bool {
        self.any_neighbour(p, |j| {
            let q = detections[j].pos_px;
            (q.x - p.x).powi(2) + (q.y - p.y).powi(2) < r2
        })
    }

    /// The climb from `p` to the matched image's local maximum, with the 3-point fit there
    /// and that peak's [`sharpness`] (positions in the matched image's pixels).
    fn climb(&self, p: Point2, fit: SubpixelFit) -> Option<Climb> {
        let (width, height) = self.matched.dimensions();
        if width < 3 || height < 3 {
            return None;
        }
        let clamp = |v: f64, len: usize| (v.round().max(1.0) as usize).min(len - 2);
        let (mut x, mut y) = (clamp(p.x, width), clamp(p.y, height));
        for _ in 0..MAX_CLIMB_STEPS {
            let mut best = (x, y, self.matched.get(x, y));
            for ny in y - 1..=y + 1 {
                for nx in x - 1..=x + 1 {
                    let v = self.matched.get(nx, ny);
                    if v > best.2 && (1..width - 1).contains(&nx) && (1..height - 1).contains(&ny) {
                        best = (nx, ny, v);
                    }
                }
            }
            if (best.0, best.1) == (x, y) {
                break;
            }
            (x, y) = (best.0, best.1);
        }
        Some(Climb {
            peak: (x as u32, y as u32),
            pos_px: refine_peak(&self.matched, x, y, fit)?,
            sharpness: sharpness(&self.matched, x, y)?,
        })
    }
}

/// The least over the largest [`sharpness`] of one noiseless particle image of std `sigma_px`
/// on `dog`, over sub-pixel phases across a pixel (directions too sharp to measure left out).
/// Below 1 because the DoG's response is not exactly Gaussian: in clean frames a round peak
/// can read this much flatter than another by its phase alone (0.80 at σ 1 px, 0.97 at σ 2).
fn phase_spread(dog: &mut DogFilter, sigma_px: f64) -> f64 {
    let side = (16.0 * sigma_px).ceil() as usize + 8;
    let centre = (side / 2) as f64;
    let (mut least, mut most) = (f64::INFINITY, 0.0f64);
    let mut image = GrayImage::new(side, side);
    let mut filtered = GrayImage::default();
    for (px, py) in [
        (0.0, 0.0),
        (0.25, 0.0),
        (0.5, 0.0),
        (0.25, 0.25),
        (0.5, 0.25),
        (0.5, 0.5),
    ] {
        for y in 0..side {
            for x in 0..side {
                let r2 = (x as f64 - centre - px).powi(2) + (y as f64 - centre - py).powi(2);
                image.set(x, y, (-r2 / (2.0 * sigma_px * sigma_px)).exp() as f32);
            }
        }
        dog.apply(&image, Polarity::Bright, &mut filtered);
        let c = side / 2;
        if let Some(value) = sharpness(&filtered, c, c).filter(|v| v.is_finite()) {
            least = least.min(value);
            most = most.max(value);
        }
    }
    if most > 0.0 && least > 0.0 {
        least / most
    } else {
        1.0
    }
}

/// The least second difference of `ln(value)` through pixel `(x, y)` (one pixel inside the
/// image) along the two axes and, halved for their √2 step, the two diagonals: how sharp the
/// peak is in its flattest direction. A single Gaussian particle gives the same in every
/// direction; two that overlap give a flat ridge along the line joining them. A direction
/// whose neighbours are not both positive does not count (a narrow peak falls below zero
/// within a pixel there: it is not the flat one); +∞ when none counts, `None` when the centre
/// is not positive. (One logarithm: `2 ln c − ln a − ln b = ln(c² / ab)`, and the least of the
/// logarithms is the logarithm of the least ratio.)
fn sharpness(image: &GrayImage, x: usize, y: usize) -> Option<f64> {
    let at = |dx: isize, dy: isize| {
        f64::from(image.get((x as isize + dx) as usize, (y as isize + dy) as usize))
    };
    let centre = at(0, 0);
    if centre <= 0.0 {
        return None;
    }
    let centre_sq = centre * centre;
    let ratio = |dx: isize, dy: isize| {
        let (a, b) = (at(-dx, -dy), at(dx, dy));
        if a > 0.0 && b > 0.0 {
            centre_sq / (a * b)
        } else {
            f64::INFINITY
        }
    };
    let axes = ratio(1, 0).min(ratio(0, 1));
    let diagonals = ratio(1, 1).min(ratio(1, -1));
    Some(axes.min(diagonals.sqrt()).ln())
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_synth::{Noise, NoiseKind, render_spots};

    const SIGMA_PX: f64 = 2.0;

    fn image(spots: &[(Point2, f64, f64)]) -> GrayImage {
        let noise = Noise {
            kind: NoiseKind::Gaussian,
            magnitude: 0.01,
        };
        render_spots(256, 256, spots, noise, 7).unwrap()
    }

    #[test]
    fn the_phase_spread_shrinks_as_particles_grow() {
        let spread = |sigma: f64| phase_spread(&mut DogFilter::new(sigma).unwrap(), sigma);
        let values = [1.0, 1.5, 2.0, 3.0].map(spread);
        assert!(values.windows(2).all(|w| w[0] < w[1]), "{values:?}");
        assert!(values[0] > 0.7 && values[3] < 1.0, "{values:?}");
    }

    #[test]
    fn a_pair_is_flatter_than_a_single_particle() {
        let single = image(&[(Point2::new(100.3, 80.6), 0.5, SIGMA_PX)]);
        let pair = image(&[
            (Point2::new(100.0, 80.0), 0.5, SIGMA_PX),
            (Point2::new(103.0, 81.0), 0.4, SIGMA_PX),
        ]);
        let matched = |img: &GrayImage| {
            let mut out = GrayImage::default();
            DogFilter::new(SIGMA_PX)
                .unwrap()
                .apply(img, Polarity::Bright, &mut out);
            out
        };
        let peak = |img: &GrayImage| {
            let (mut best, mut at) = (f32::MIN, (0, 0));
            for y in 60..100 {
                for x in 90..115 {
                    if img.get(x, y) > best {
                        (best, at) = (img.get(x, y), (x, y));
                    }
                }
            }
            at
        };
        let (single, pair) = (matched(&single), matched(&pair));
        let ((sx, sy), (px, py)) = (peak(&single), peak(&pair));
        let round = sharpness(&single, sx, sy).unwrap();
        let ridge = sharpness(&pair, px, py).unwrap();
        assert!(ridge < 0.75 * round, "pair {ridge} vs single {round}");
    }

    /// The re-fits of `detections` on `frame`, at σ = `SIGMA_PX`, adding no faint particles.
    fn refine_without_completion(frame: &GrayImage, detections: &mut Vec<Detection>) {
        let mut refiner = MatchedRefiner::new(SIGMA_PX, false, false).unwrap();
        refiner.refine(
            frame,
            Polarity::Bright,
            SubpixelFit::Gaussian,
            (0.0, 0.0),
            |_| None,
            detections,
        );
    }

    #[test]
    fn an_unresolved_pair_keeps_its_first_position() {
        // Isolated particles on a 32-px grid, their detections 0.4 px off; one site holds a
        // pair 3 px apart that the resolving scale saw as one detection, on the brighter one.
        let mut spots = Vec::new();
        let mut detections = Vec::new();
        for gy in 1..8 {
            for gx in 1..8 {
                let p = Point2::new(32.0 * gx as f64 + 0.1 * gy as f64, 32.0 * gy as f64);
                spots.push((p, 0.5, SIGMA_PX));
                detections.push(Detection::new(Point2::new(p.x + 0.4, p.y - 0.3), 1.0));
            }
        }
        let pair = 3 * 7 + 3;
        let first = spots[pair].0;
        spots.push((Point2::new(first.x + 3.0, first.y), 0.45, SIGMA_PX));
        detections[pair] = Detection::new(first, 1.0);
        let frame = image(&spots);
        refine_without_completion(&frame, &mut detections);
        let moved_home = (0..spots.len() - 1)
            .filter(|&k| k != pair)
            .filter(|&k| detections[k].pos_px.distance(spots[k].0) < 0.1)
            .count();
        assert!(moved_home >= 45, "{moved_home} of 48 singles re-fitted");
        assert_eq!(detections[pair].pos_px, first, "the pair's detection moved");
    }

    /// 48 isolated particles on a 32-px grid; particle `twin_site` carries two detections
    /// 1.5 px either side of it (a peak split by noise), particle `pair_site` a second particle
    /// 3.5 px away (within the twin radius: only the flat-peak test keeps them two), each with
    /// its own detection.
    fn twin_and_pair_scene() -> (Vec<Point2>, Vec<Detection>, GrayImage, usize, usize) {
        let (twin_site, pair_site) = (2 * 7 + 2, 5 * 7 + 4);
        let mut spots = Vec::new();
        let mut detections = Vec::new();
        for gy in 1..8 {
            for gx in 1..8 {
                let p = Point2::new(32.0 * gx as f64 + 0.1 * gy as f64, 32.0 * gy as f64 + 0.2);
                spots.push((p, 0.5, SIGMA_PX));
                detections.push(Detection::new(Point2::new(p.x + 0.3, p.y - 0.2), 1.0));
            }
        }
        let twin = spots[twin_site].0;
        detections[twin_site] = Detection::new(Point2::new(twin.x - 1.5, twin.y + 0.2), 1.0);
        detections.push(Detection::new(Point2::new(twin.x + 1.5, twin.y - 0.1), 1.0));
        let partner = Point2::new(spots[pair_site].0.x + 3.5, spots[pair_site].0.y);
        spots.push((partner, 0.5, SIGMA_PX));
        detections.push(Detection::new(partner, 1.0));
        let truth = spots.iter().map(|s| s.0).collect();
        (truth, detections, image(&spots), twin_site, pair_site)
    }

    #[test]
    fn twins_of_one_particle_become_one_refitted_detection_and_a_pair_stays_two() {
        let (truth, mut detections, frame, twin_site, pair_site) = twin_and_pair_scene();
        let before = detections.len();
        let pair_first = detections[pair_site].pos_px;
        refine_without_completion(&frame, &mut detections);
        assert_eq!(detections.len(), before - 1, "exactly one twin removed");
        let near = |p: Point2, r: f64| {
            detections
                .iter()
                .filter(|d| d.pos_px.distance(p) < r)
                .count()
        };
        assert_eq!(
            near(truth[twin_site], 3.0),
            1,
            "one detection left on the split particle"
        );
        assert!(
            detections[twin_site].pos_px.distance(truth[twin_site]) < 0.1,
            "the twin re-fitted: {:?} vs {:?}",
            detections[twin_site].pos_px,
            truth[twin_site]
        );
        assert_eq!(
            near(truth[pair_site], 5.0),
            2,
            "the pair keeps both detections"
        );
        assert_eq!(
            detections[pair_site].pos_px, pair_first,
            "the pair is not re-fitted"
        );
    }
}

//! Unresolved pairs split by a two-particle fit (`detector.deblend`), and crowded particles
//! re-fitted alone (`detector.refit_crowded`).
//!
//! Two particles closer than about twice their images' σ make one peak at every scale, and
//! the detection lies between them, 1–2 px from both: on the accuracy family's moderate tune
//! half these blends are nearly all of the estimated points 1–2 px from any true particle,
//! the largest share of the false recoveries once particles reach σ 1.5–2 px.
//!
//! A blend shows as a matched-scale peak flatter along one direction than across it (the
//! ratio of its Hessian's eigenvalues below [`FLATNESS_GATE`]). Around such a detection a
//! window of the frame is fitted by least squares with a constant background, Gaussians of
//! the measured σ at the detection and at the other detections nearby, their amplitudes free
//! (a screen). Where that leaves more than [`SPLIT_CHI2`] noise variances of residual above
//! its degrees of freedom, the neighbours are subtracted with the screen's amplitudes and the
//! window is fitted again (Levenberg–Marquardt) with one and with two Gaussians of a free
//! common width and free centres: the pair replaces the detection when it lowers the residual by more than [`SPLIT_CHI2`]
//! noise variances, both amplitudes are positive and the two lie at least
//! [`MIN_SEPARATION_SIGMAS`] σ apart, inside the window and off the neighbours. The noise
//! variance is the median residual variance of the screens of a sample of round peaks (mostly
//! single particles).
//!
//! Then, with `detector.refit_crowded`, every detection with another within
//! [`CROWDED_SIGMAS`] σ is re-fitted alone, its neighbours' images subtracted: the resolving
//! scale's position of a particle is pulled towards a close neighbour.

mod model;
mod window;

use crate::cell_grid::CellGrid;
use model::{Amplitudes, Profiles, fit, linear_fit};
use rayon::prelude::*;
use sillage_core::{Detection, GrayImage, Point2};
use window::Window;

/// Largest ratio of the matched peak's two curvatures (flattest over sharpest) at which a
/// detection is examined: a single round particle reads about 1, two overlapping ones less.
///
/// Tuned with [`SPLIT_CHI2`] on the tune halves of both `sillage bench ptv-accuracy`
/// families (36 cases; without deblending 33 within 2 points of tuned, mean true / false
/// 73.7 / 9.25 %), on a first form of this module (every flat peak fitted, the noise from the
/// pair fits): 0.5 → 33 cases, 74.6 / 9.3 %; 0.7 → 36, 76.6 / 9.0; 0.85 → 36, 77.4 / 8.7; 0.9
/// → 35, 77.4 / 8.9; 1 (no gate) → 35, 77.4 / 9.1. The form kept gives 36, 77.6 / 8.4 there;
/// on the report halves (unseen) 35 → 36 of 36 cases within 2 points of tuned and 70.5 /
/// 12.0 → 74.1 / 11.4 % (docs/ptv.md, "Overlapping particles split").
pub const FLATNESS_GATE: f64 = 0.85;
/// Least drop of the squared residual, in noise variances, for which two particles replace
/// one (and least excess of the screen's residual for the fits to run). Tuned with
/// [`FLATNESS_GATE`] (gate 0.85, same first form): 10 → 32 cases, 76.9 / 9.3 %; 20 → 36, 77.5 /
/// 8.9; 30 → 36, 77.4 / 8.8; 40 → 36, 77.4 / 8.7; 60 → 36, 77.3 / 8.6.
pub const SPLIT_CHI2: f64 = 40.0;
/// Least distance between the two particles of a split, in σ: closer, the pair fits noise or
/// a particle wider than the others (not tuned).
pub const MIN_SEPARATION_SIGMAS: f64 = 0.5;
/// How far from the detection, in σ, the two particles of a pair fit start at most and at
/// least: at ±h along the window's major axis, h² the excess of its second moment along that
/// axis over across it (h for two equal particles at ±h), held within these bounds.
///
/// Before 2026-12-01 every pair fit started at ±σ/2, the lower bound now (not tuned); the
/// upper bound was not tuned either (0.25σ for the lower one gives the same means within
/// 0.02 point). Measured on the tune halves of both `sillage bench ptv-accuracy` families
/// (mean true / false recoveries %): main 65.68 / 13.01 → 66.23 / 13.30, moderate 89.78 /
/// 2.14 → 90.30 / 2.26; on the report halves (unseen): moderate 90.20 / 1.92 → **90.75 /
/// 1.97** (21 of 24 cases gain true recoveries, up to 1.1 points), main 51.48 / 22.45 → 51.66 /
/// 25.83 (the false rise is one case whose images cover the frame, `cellular_array-1`,
/// 2.5 / 60.5 → 0.1 / 98.1 %, warned as too dense either way); 40 frames of 25,000 particles
/// on 2048² (issue 35's benchmark flow, σ̂ 2.07 px): 87.3 / 2.0 → 88.3 / 2.1 %.
pub const PAIR_START_SIGMAS: (f64, f64) = (0.5, 1.5);
/// The fits stop at an iteration that lowers the squared residual by less than this many
/// noise variances (far below the [`SPLIT_CHI2`] the decision needs). Against a relative
/// drop of 10⁻⁴ (0.02 noise variances in a window of σ 2 px), the tune halves score the
/// same (77.6 / 8.35 %) for ~10 % less detection time on 25,000 particles of σ 2 px; with it,
/// the report halves (unseen) give 36 of 36 cases within 2 points of tuned, 74.1 / 11.4 %.
const FIT_TOLERANCE: f64 = 0.1;
/// A detection with another within this many σ is re-fitted with its neighbours' images
/// subtracted (the resolving scale's 3-point fit is pulled towards a neighbour this close).
///
/// Chosen on the tune halves of both `sillage bench ptv-accuracy` families (mean true / false
/// recoveries %, main then moderate): without the re-fit 65.30 / 13.38 and 89.63 / 2.28; 3σ
/// 65.68 / 13.01 and 89.78 / 2.14; 4σ 65.75 / 13.10 and 89.70 / 2.20; 5σ 65.73 / 13.22 and
/// 89.68 / 2.23; 3σ costs the least of the three. A second pass from the moved positions
/// added at most 0.15 point for twice the cost (3σ: 65.74 / 12.86 and 89.80 / 2.12). On the
/// report halves (unseen): main 51.06 / 25.58 → 51.27 / 25.69 (`fourier_turbulence-1` 73.1 /
/// 19.9 → 75.7 / 17.0; the false rise is two cases warned as too dense), moderate 90.05 /
/// 2.03 → 90.20 / 1.92 (22 of 24 cases gain), its mean position error of true recoveries
/// 0.145 → 0.131 px (docs/ptv.md, "Crowded particles re-fitted").
pub const CROWDED_SIGMAS: f64 = 3.0;
/// Largest move of a crowded detection's re-fit, in σ (tuned with [`CROWDED_SIGMAS`] = 3 on
/// the same tune halves: 0.5 → 65.68 / 13.01 and 89.78 / 2.14 %, 1 → 65.62 / 13.18 and 89.73 /
/// 2.19 %). A larger move is a fit that slid onto a neighbour or into noise.
pub const MAX_REFIT_SHIFT_SIGMAS: f64 = 0.5;
/// Half-width of the fitted window, in σ (not tuned: 2σ gave 76.6 / 8.4 % on the tune
/// halves).
const WINDOW_SIGMAS: f64 = 2.5;
/// Detections near an examined one, fitted as Gaussians of free amplitude, at most; a more
/// crowded detection is left as it is.
const MAX_NEIGHBOURS: usize = 4;
/// Round peaks screened to measure the noise (about; every n/this-th detection).
const NOISE_SAMPLE: usize = 512;
/// Fewest round peaks in a frame for its noise variance to be measured.
const MIN_SCREENS: usize = 8;
/// Fewest detections a rayon task examines.
const PAR_MIN_LEN: usize = 64;

/// The splitter of unresolved pairs for particle images of std `sigma_px`.
#[derive(Debug, Clone)]
pub(crate) struct Deblender {
    sigma_px: f64,
    /// Re-fit the crowded detections after the splits.
    refit: bool,
    half_width: usize,
    /// Whether each detection of the frame is a flat peak (reused between frames).
    flat: Vec<bool>,
    /// The sampled round peaks' residual variances (reused between frames).
    variances: Vec<f64>,
    /// The detections bucketed in cells as wide as the reach of a neighbour.
    grid: CellGrid,
}

/// Buffers of one rayon task: the examined detection then its neighbours, the window's
/// values (as read, with the neighbours subtracted, and sorted for their median), the fits'
/// profiles.
#[derive(Debug, Default)]
struct Scratch {
    centres: Vec<Point2>,
    values: Vec<f64>,
    cleaned: Vec<f64>,
    sorted: Vec<f64>,
    profiles: Profiles,
}

/// What the screen of one detection found ([`Deblender::screen`]): its window, the squared
/// residual of the linear fit there, its amplitudes (background, then one per centre) and
/// its degrees of freedom.
struct Screen<'v> {
    window: Window<'v>,
    residual: f64,
    amplitudes: Amplitudes,
    dof: usize,
}

impl Deblender {
    /// A splitter for particle images of std `sigma_px`, which re-fits the crowded detections
    /// too with `refit_crowded`.
    pub(crate) fn new(sigma_px: f64, refit_crowded: bool) -> Self {
        Self {
            sigma_px,
            refit: refit_crowded,
            half_width: (WINDOW_SIGMAS * sigma_px).ceil().max(2.0) as usize,
            flat: Vec::new(),
            variances: Vec::new(),
            grid: CellGrid::default(),
        }
    }

    /// Splits the detections (positions in `input`'s pixels plus `offset`) that are two
    /// particles: `sign` makes the input's particles positive, `matched` is its matched-scale
    /// DoG. The first particle of a pair takes the detection's place, the second is appended.
    /// Then, when asked, the crowded detections are re-fitted ([`Deblender::refit_crowded`]).
    pub(crate) fn split(
        &mut self,
        input: &GrayImage,
        sign: f64,
        matched: &GrayImage,
        offset: (f64, f64),
        detections: &mut Vec<Detection>,
    ) {
        self.grid
            .rebuild(input.dimensions(), detections, offset, self.reach());
        let mut flat = std::mem::take(&mut self.flat);
        (0..detections.len())
            .into_par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map(|i| is_flat(matched, local_position(detections, offset, i)))
            .collect_into_vec(&mut flat);
        let noise = self.noise(input, sign, offset, detections, &flat);
        if let Some(noise) = noise {
            self.split_flat_peaks(input, sign, offset, detections, &flat, noise);
        }
        self.flat = flat;
    }

    /// Screens each `flat` peak of `detections` and splits those that are two particles
    /// (see [`Deblender::split`]), then re-fits the crowded ones when asked; `noise` is the
    /// frame's noise variance.
    fn split_flat_peaks(
        &mut self,
        input: &GrayImage,
        sign: f64,
        offset: (f64, f64),
        detections: &mut Vec<Detection>,
        flat: &[bool],
        noise: f64,
    ) {
        let this = &*self;
        let found: &[Detection] = detections;
        // Each flat peak is screened: where one particle of the measured σ, its neighbours
        // fitted beside it, leaves more than `SPLIT_CHI2` noise variances above its degrees of
        // freedom, the neighbours are subtracted with the screen's amplitudes and the pair is
        // fitted.
        let pairs: Vec<(usize, [Point2; 2])> = (0..found.len())
            .into_par_iter()
            .with_min_len(PAR_MIN_LEN)
            .filter(|&i| flat[i])
            .map_init(Scratch::default, |scratch, i| {
                let Scratch {
                    centres,
                    values,
                    cleaned,
                    sorted,
                    profiles,
                } = scratch;
                let screen =
                    this.screen(input, sign, found, offset, i, centres, values, profiles)?;
                if screen.residual - screen.dof as f64 * noise <= SPLIT_CHI2 * noise {
                    return None;
                }
                let clean = screen.window.with_neighbours_subtracted(
                    centres,
                    &screen.amplitudes,
                    cleaned,
                    profiles,
                );
                let pair =
                    this.fit_pair(&clean, &centres[1..], centres[0], noise, sorted, profiles)?;
                Some((i, pair))
            })
            .flatten()
            .collect();
        for (i, [a, b]) in pairs {
            let strength = detections[i].strength;
            let at = |p: Point2| Point2::new(p.x + offset.0, p.y + offset.1);
            detections[i].pos_px = at(a);
            detections.push(Detection::new(at(b), strength));
        }
        if self.refit {
            self.refit_crowded(input, sign, offset, detections, noise);
        }
    }

    /// The frame's noise variance: the median residual variance of the screens of a sample
    /// of its round peaks (every `n / NOISE_SAMPLE`-th detection that is not `flat`), mostly
    /// single particles; `None` when fewer than [`MIN_SCREENS`] could be screened or it is
    /// not positive.
    fn noise(
        &mut self,
        input: &GrayImage,
        sign: f64,
        offset: (f64, f64),
        found: &[Detection],
        flat: &[bool],
    ) -> Option<f64> {
        let stride = (found.len() / NOISE_SAMPLE).max(1);
        let mut variances = std::mem::take(&mut self.variances);
        let this = &*self;
        variances.clear();
        variances.par_extend(
            (0..found.len())
                .into_par_iter()
                .step_by(stride)
                .filter(|&i| !flat[i])
                .map_init(Scratch::default, |scratch, i| {
                    let Scratch {
                        centres,
                        values,
                        profiles,
                        ..
                    } = scratch;
                    let screen =
                        this.screen(input, sign, found, offset, i, centres, values, profiles)?;
                    Some(screen.residual / screen.dof as f64).filter(|v| v.is_finite())
                })
                .flatten(),
        );
        let noise = (variances.len() >= MIN_SCREENS)
            .then(|| {
                let mid = variances.len() / 2;
                *variances.select_nth_unstable_by(mid, f64::total_cmp).1
            })
            .filter(|&noise| noise > 0.0);
        self.variances = variances;
        noise
    }

    /// The screen of detection `i` of `found`: its window of `input` and the linear fit
    /// there of a background and particles of the measured σ at it and at its neighbours
    /// (gathered into `centres`, the detection first). `None` when it has more than
    /// [`MAX_NEIGHBOURS`], its window leaves the frame or the fit is singular.
    #[allow(clippy::too_many_arguments)]
    fn screen<'v>(
        &self,
        input: &GrayImage,
        sign: f64,
        found: &[Detection],
        offset: (f64, f64),
        i: usize,
        centres: &mut Vec<Point2>,
        values: &'v mut Vec<f64>,
        profiles: &mut Profiles,
    ) -> Option<Screen<'v>> {
        if !self.gather(found, offset, i, centres) {
            return None;
        }
        let window = Window::around(input, sign, centres[0], self.half_width, values)?;
        let (residual, amplitudes) = linear_fit(&window, centres, self.sigma_px, profiles)?;
        let dof = window.len().saturating_sub(1 + centres.len()).max(1);
        Some(Screen {
            window,
            residual,
            amplitudes,
            dof,
        })
    }

    /// How far a neighbour may lie to enter a fit: the window's half-width and two σ.
    fn reach(&self) -> f64 {
        self.half_width as f64 + 2.0 * self.sigma_px
    }

    /// Detection `i` (in the input's pixels) then its neighbours within [`Self::reach`] into
    /// `centres`; false when there are more than [`MAX_NEIGHBOURS`]. The grid holds `found`.
    fn gather(
        &self,
        found: &[Detection],
        offset: (f64, f64),
        i: usize,
        centres: &mut Vec<Point2>,
    ) -> bool {
        let p = local_position(found, offset, i);
        // Squared distances: no square root per candidate.
        let reach2 = self.reach().powi(2);
        centres.clear();
        centres.push(p);
        let near = self.grid.near(found[i].pos_px).filter(|&j| j != i);
        centres.extend(
            near.map(|j| local_position(found, offset, j))
                .filter(|&q| (q - p).norm_squared() < reach2),
        );
        centres.len() <= 1 + MAX_NEIGHBOURS
    }

    /// Moves each crowded detection (another within [`CROWDED_SIGMAS`] σ) to the centre of a
    /// one-particle fit (Levenberg–Marquardt, width free) of its window with the neighbours'
    /// images subtracted, their amplitudes from the linear fit of all of them at the
    /// detected positions. A fit that moves the detection by [`MAX_REFIT_SHIFT_SIGMAS`] σ or
    /// more, or whose amplitude is not positive, is not taken. Every detection is re-fitted
    /// from the positions before any moved, so the result does not depend on the order.
    fn refit_crowded(
        &mut self,
        input: &GrayImage,
        sign: f64,
        offset: (f64, f64),
        detections: &mut [Detection],
        noise: f64,
    ) {
        self.grid
            .rebuild(input.dimensions(), detections, offset, self.reach());
        let this = &*self;
        let found: &[Detection] = detections;
        let sigma = this.sigma_px;
        let crowded2 = (CROWDED_SIGMAS * sigma).powi(2);
        let moved: Vec<(usize, Point2)> = (0..found.len())
            .into_par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map_init(Scratch::default, |scratch, i| {
                let Scratch {
                    centres,
                    values,
                    cleaned,
                    profiles,
                    ..
                } = scratch;
                if !this.gather(found, offset, i, centres) {
                    return None;
                }
                let p = centres[0];
                if centres[1..]
                    .iter()
                    .all(|&q| (q - p).norm_squared() >= crowded2)
                {
                    return None;
                }
                let window = Window::around(input, sign, p, this.half_width, values)?;
                let clean = window.without_neighbours(centres, sigma, cleaned, profiles)?;
                let one = fit(&clean, &[p], sigma, FIT_TOLERANCE * noise, profiles)?;
                let q = one.centres[0];
                (one.amplitudes[0] > 0.0 && q.distance(p) < MAX_REFIT_SHIFT_SIGMAS * sigma)
                    .then_some((i, q))
            })
            .flatten()
            .collect();
        for (i, q) in moved {
            detections[i].pos_px = Point2::new(q.x + offset.0, q.y + offset.1);
        }
    }

    /// The pair that replaces the detection at `p`, if two particles fit `window` (its
    /// neighbours `others` subtracted) better than one by [`SPLIT_CHI2`] noise variances
    /// (`noise`) and are a pair (see the module).
    fn fit_pair(
        &self,
        window: &Window<'_>,
        others: &[Point2],
        p: Point2,
        noise: f64,
        sorted: &mut Vec<f64>,
        profiles: &mut Profiles,
    ) -> Option<[Point2; 2]> {
        let sigma = self.sigma_px;
        let tolerance = FIT_TOLERANCE * noise;
        // The two start on each side of the detection along the axis where the window's
        // signal spreads most, as far from it as that spread says.
        let spread = window.spread(p, sorted);
        let (nearest, furthest) = PAIR_START_SIGMAS;
        let half = spread
            .excess_px2
            .max(0.0)
            .sqrt()
            .clamp(nearest * sigma, furthest * sigma);
        let start = [p + spread.axis * half, p + spread.axis * (-half)];
        let two = fit(window, &start, sigma, tolerance, profiles)?;
        let core = self.half_width as f64 - 1.0;
        let min_separation = MIN_SEPARATION_SIGMAS * sigma;
        let inside = |q: Point2| (q.x - p.x).abs() <= core && (q.y - p.y).abs() <= core;
        let clear = |q: Point2| others.iter().all(|o| o.distance(q) >= min_separation);
        let a_pair = two.amplitudes.iter().all(|&a| a > 0.0)
            && two.centres[0].distance(two.centres[1]) >= min_separation
            && two.centres.iter().all(|&q| inside(q) && clear(q));
        // The one-particle fit only where the pair could replace the detection (a third of
        // the pairs fitted are not one).
        if !a_pair {
            return None;
        }
        let one = fit(window, &[p], sigma, tolerance, profiles)?;
        ((one.residual - two.residual) / noise > SPLIT_CHI2).then_some(two.centres)
    }
}

/// Detection `i`'s position in the input's pixels (the frame's minus `offset`).
fn local_position(found: &[Detection], offset: (f64, f64), i: usize) -> Point2 {
    let p = found[i].pos_px;
    Point2::new(p.x - offset.0, p.y - offset.1)
}

/// Whether the matched image's peak at the pixel nearest `p` is flatter along one direction
/// than across it ([`FLATNESS_GATE`]).
fn is_flat(matched: &GrayImage, p: Point2) -> bool {
    let (width, height) = matched.dimensions();
    let (x, y) = (p.x.round(), p.y.round());
    if x < 1.0 || y < 1.0 || x >= (width - 1) as f64 || y >= (height - 1) as f64 {
        return false;
    }
    let (x, y) = (x as usize, y as usize);
    let m = |dx: isize, dy: isize| {
        f64::from(matched.get((x as isize + dx) as usize, (y as isize + dy) as usize))
    };
    // The negated Hessian: positive definite at a peak.
    let hxx = 2.0 * m(0, 0) - m(-1, 0) - m(1, 0);
    let hyy = 2.0 * m(0, 0) - m(0, -1) - m(0, 1);
    let hxy = -(m(1, 1) - m(1, -1) - m(-1, 1) + m(-1, -1)) / 4.0;
    let mean = 0.5 * (hxx + hyy);
    let spread = (0.25 * (hxx - hyy).powi(2) + hxy * hxy).sqrt();
    let (sharpest, flattest) = (mean + spread, mean - spread);
    sharpest > 0.0 && flattest < FLATNESS_GATE * sharpest
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_core::Vec2;
    use sillage_image::{DogFilter, Polarity};
    use sillage_synth::{Noise, NoiseKind, render_spots};

    const SIGMA_PX: f64 = 2.0;

    /// Site `k` of a 6 × 6 grid 40 px apart on a 256² frame, at a sub-pixel offset.
    fn site(k: usize) -> Point2 {
        Point2::new(
            28.0 + 40.0 * (k % 6) as f64 + 0.3 * (k % 3) as f64,
            28.0 + 40.0 * (k / 6) as f64 + 0.2 * (k % 4) as f64,
        )
    }

    /// `spots` rendered on a 256² frame with Gaussian noise of σ 0.02, seeded.
    fn rendered(spots: &[(Point2, f64, f64)], seed: u64) -> GrayImage {
        let noise = Noise {
            kind: NoiseKind::Gaussian,
            magnitude: 0.02,
        };
        render_spots(256, 256, spots, noise, seed).unwrap()
    }

    /// A 256² frame of 36 sites 40 px apart: at even sites a pair of σ 2 px particles 3.2 px
    /// apart (amplitudes 0.5 and 0.4, orientations turning), at odd sites one particle of σ
    /// 2 px or, every other one, 2.5 px (wider than the splitter expects); noise σ 0.02. Also
    /// the detections the resolving scale gives: one per site, a pair's at its intensity
    /// centroid.
    fn scene() -> (GrayImage, Vec<[Point2; 2]>, Vec<Point2>, Vec<Detection>) {
        let (mut spots, mut pairs, mut singles, mut detections) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for k in 0..36 {
            let centre = site(k);
            if k % 2 == 0 {
                let angle = 0.7 * k as f64;
                let half = Vec2::new(angle.cos(), angle.sin()) * 1.6;
                let (a, b) = (centre + half, centre + half * -1.0);
                spots.push((a, 0.5, SIGMA_PX));
                spots.push((b, 0.4, SIGMA_PX));
                pairs.push([a, b]);
                let centroid = centre + half * (0.1 / 0.9);
                detections.push(Detection::new(centroid, 1.0));
            } else {
                let sigma = if k % 4 == 1 {
                    SIGMA_PX
                } else {
                    1.25 * SIGMA_PX
                };
                spots.push((centre, 0.5, sigma));
                singles.push(centre);
                detections.push(Detection::new(centre, 1.0));
            }
        }
        let image = rendered(&spots, 3);
        (image, pairs, singles, detections)
    }

    fn matched(image: &GrayImage) -> GrayImage {
        let mut out = GrayImage::default();
        DogFilter::new(SIGMA_PX)
            .unwrap()
            .apply(image, Polarity::Bright, &mut out);
        out
    }

    #[test]
    fn pairs_are_split_onto_their_particles_and_single_particles_are_kept() {
        let (image, pairs, singles, mut detections) = scene();
        Deblender::new(SIGMA_PX, false).split(
            &image,
            1.0,
            &matched(&image),
            (0.0, 0.0),
            &mut detections,
        );
        let near = |p: Point2, r: f64| {
            detections
                .iter()
                .filter(|d| d.pos_px.distance(p) < r)
                .count()
        };
        for &single in &singles {
            assert_eq!(near(single, 4.0), 1, "single particle at {single:?} split");
        }
        let split = pairs
            .iter()
            .filter(|[a, b]| near(*a, 0.3) == 1 && near(*b, 0.3) == 1)
            .count();
        assert!(
            split >= 17,
            "{split} of {} pairs split onto their particles",
            pairs.len()
        );
        assert_eq!(detections.len(), singles.len() + 2 * split);
    }

    #[test]
    fn a_frame_with_too_few_flat_peaks_is_left_as_it_is() {
        let (image, _, _, detections) = scene();
        let mut few: Vec<Detection> = detections.into_iter().take(6).collect();
        let before = few.clone();
        Deblender::new(SIGMA_PX, false).split(&image, 1.0, &matched(&image), (0.0, 0.0), &mut few);
        assert_eq!(few, before);
    }

    /// 36 sites 40 px apart on a 256² frame: at even sites two σ 2 px particles 5 px apart
    /// (resolved, amplitudes 0.5 and 0.35), their detections 0.6 px too close to each other
    /// (the pull of a neighbour on a small-scale fit); at odd sites one particle, detected
    /// where it is.
    fn crowded_scene() -> (GrayImage, Vec<Point2>, Vec<Detection>) {
        let (mut spots, mut truth, mut detections) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..36 {
            let centre = site(k);
            if k % 2 == 0 {
                let angle = 0.7 * k as f64;
                let unit = Vec2::new(angle.cos(), angle.sin());
                let (a, b) = (centre + unit * 2.5, centre + unit * -2.5);
                spots.push((a, 0.5, SIGMA_PX));
                spots.push((b, 0.35, SIGMA_PX));
                truth.extend([a, b]);
                detections.push(Detection::new(a + unit * -0.6, 1.0));
                detections.push(Detection::new(b + unit * 0.6, 1.0));
            } else {
                spots.push((centre, 0.5, SIGMA_PX));
                truth.push(centre);
                detections.push(Detection::new(centre, 1.0));
            }
        }
        let image = rendered(&spots, 5);
        (image, truth, detections)
    }

    #[test]
    fn crowded_detections_are_moved_onto_their_particles_only_when_asked() {
        let (image, truth, detections) = crowded_scene();
        // Mean distance from a particle to the nearest detection.
        let mean_miss = |found: &[Detection]| {
            let miss = |t: &Point2| {
                found
                    .iter()
                    .map(|d| d.pos_px.distance(*t))
                    .fold(f64::INFINITY, f64::min)
            };
            truth.iter().map(miss).sum::<f64>() / truth.len() as f64
        };
        let mut kept = detections.clone();
        Deblender::new(SIGMA_PX, false).split(&image, 1.0, &matched(&image), (0.0, 0.0), &mut kept);
        let mut refitted = detections;
        Deblender::new(SIGMA_PX, true).split(
            &image,
            1.0,
            &matched(&image),
            (0.0, 0.0),
            &mut refitted,
        );
        // The re-fits move detections; they never add or remove one.
        assert_eq!(refitted.len(), kept.len());
        // Two thirds of the particles are crowded, each detected 0.6 px off.
        let (before, after) = (mean_miss(&kept), mean_miss(&refitted));
        assert!(before > 0.35, "kept: mean miss {before}");
        assert!(after < 0.1, "re-fitted: mean miss {after}");
    }
}

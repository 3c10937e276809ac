//! Unresolved pairs split by a two-particle fit (`detector.deblend`).
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

use rayon::prelude::*;
use sillage_core::{Detection, GrayImage, Point2, Vec2};

/// Largest ratio of the matched peak's two curvatures (flattest over sharpest) at which a
/// detection is examined: a single round particle reads about 1, two overlapping ones less.
///
/// Tuned with [`SPLIT_CHI2`] on the tune halves of both `sillage bench ptv-accuracy`
/// families (36 cases; without deblending 33 within 2 points of tuned, mean true / false
/// 73.7 / 9.25 %), on a first form of this module (every flat peak fitted, the noise from the
/// pair fits): 0.5 → 33 cases, 74.6 / 9.3 %; 0.7 → 36, 76.6 / 9.0; 0.85 → 36, 77.4 / 8.7; 0.9
/// → 35, 77.4 / 8.9; 1 (no gate) → 35, 77.4 / 9.1. The form kept gives 36, 77.6 / 8.4 there;
/// on the report halves (unseen) 35 → 36 of 36 cases within 2 points of tuned and 70.5 /
/// 12.0 → 74.1 / 11.5 % (docs/ptv.md, "Overlapping particles split").
pub const FLATNESS_GATE: f64 = 0.85;
/// Least drop of the squared residual, in noise variances, for which two particles replace
/// one (and least excess of the screen's residual for the fits to run). Tuned with
/// [`FLATNESS_GATE`] (gate 0.85, same first form): 10 → 32 cases, 76.9 / 9.3 %; 20 → 36, 77.5 /
/// 8.9; 30 → 36, 77.4 / 8.8; 40 → 36, 77.4 / 8.7; 60 → 36, 77.3 / 8.6.
pub const SPLIT_CHI2: f64 = 40.0;
/// Least distance between the two particles of a split, in σ: closer, the pair fits noise or
/// a particle wider than the others (not tuned).
pub const MIN_SEPARATION_SIGMAS: f64 = 0.5;
/// Half-width of the fitted window, in σ (not tuned: 2σ gave 76.6 / 8.4 % on the tune
/// halves).
const WINDOW_SIGMAS: f64 = 2.5;
/// Detections near an examined one, fitted as Gaussians of free amplitude, at most; a more
/// crowded detection is left as it is.
const MAX_NEIGHBOURS: usize = 4;
/// Parameters of a fit at most: background, width, two free particles, the neighbours.
const MAX_PARAMETERS: usize = 2 + 3 * 2 + MAX_NEIGHBOURS;
/// Levenberg–Marquardt iterations at most.
const MAX_ITERATIONS: usize = 12;
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
    half_width: usize,
    screens: Vec<Option<Screen>>,
}

/// What the screen of one detection found: the squared residual of one particle of the
/// measured σ at the detection, and its degrees of freedom.
#[derive(Debug, Clone, Copy)]
struct Screen {
    residual: f64,
    dof: usize,
}

/// Buffers of one rayon task: the neighbours, the window's values (as read, and with the
/// neighbours subtracted), the Gaussian factors.
#[derive(Debug, Default)]
struct Scratch {
    others: Vec<Point2>,
    values: Vec<f64>,
    cleaned: Vec<f64>,
    factors: Factors,
}

/// Per component of a model, its Gaussian factors along the window's columns and rows; and
/// the window's values sorted, for its median ([`Window::major_axis`]).
#[derive(Debug, Default)]
struct Factors {
    gx: Vec<f64>,
    gy: Vec<f64>,
    sorted: Vec<f64>,
}

impl Deblender {
    /// A splitter for particle images of std `sigma_px`.
    pub(crate) fn new(sigma_px: f64) -> Self {
        Self {
            sigma_px,
            half_width: (WINDOW_SIGMAS * sigma_px).ceil().max(2.0) as usize,
            screens: Vec::new(),
        }
    }

    /// Splits the detections (positions in `input`'s pixels plus `offset`) that are two
    /// particles: `sign` makes the input's particles positive, `matched` is its matched-scale
    /// DoG. The first particle of a pair takes the detection's place, the second is appended.
    pub(crate) fn split(
        &mut self,
        input: &GrayImage,
        sign: f64,
        matched: &GrayImage,
        offset: (f64, f64),
        detections: &mut Vec<Detection>,
    ) {
        let reach = self.half_width as f64 + 2.0 * self.sigma_px;
        let neighbours = Neighbours::new(detections, offset, reach);
        let mut screens = std::mem::take(&mut self.screens);
        let this = &*self;
        let found: &[Detection] = detections;
        let local = |i: usize| {
            let p = found[i].pos_px;
            Point2::new(p.x - offset.0, p.y - offset.1)
        };
        // The neighbours of detection `i`, false when there are too many.
        let gather = |others: &mut Vec<Point2>, i: usize| {
            others.clear();
            others.extend(neighbours.near(found, offset, local(i), i, reach));
            others.len() <= MAX_NEIGHBOURS
        };
        // Flat peaks are screened; so is a sample of the round ones (every `stride`-th
        // detection), whose residuals, mostly single particles', measure the noise.
        let stride = (found.len() / NOISE_SAMPLE).max(1);
        let mut variances: Vec<f64> = Vec::new();
        let screened: Vec<(Option<Screen>, Option<f64>)> = (0..found.len())
            .into_par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map_init(Scratch::default, |scratch, i| {
                let flat = is_flat(matched, local(i));
                if !flat && i % stride != 0 {
                    return (None, None);
                }
                let Scratch {
                    others,
                    values,
                    factors,
                    ..
                } = scratch;
                if !gather(others, i) {
                    return (None, None);
                }
                let Some(window) = Window::around(input, sign, local(i), this.half_width, values)
                else {
                    return (None, None);
                };
                let model = Model::new(&window, others, 1, this.sigma_px);
                let Some((residual, _)) = model.linear_fit(&[local(i)], factors) else {
                    return (None, None);
                };
                let dof = window.len().saturating_sub(2 + others.len()).max(1);
                let screen = flat.then_some(Screen { residual, dof });
                (screen, (!flat).then_some(residual / dof as f64))
            })
            .collect();
        screens.clear();
        for (screen, variance) in screened {
            screens.push(screen);
            variances.extend(variance.filter(|v| v.is_finite()));
        }
        if variances.len() >= MIN_SCREENS {
            let mid = variances.len() / 2;
            let noise = *variances.select_nth_unstable_by(mid, f64::total_cmp).1;
            if noise > 0.0 {
                let pairs: Vec<(usize, [Point2; 2])> = screens
                    .par_iter()
                    .enumerate()
                    .with_min_len(PAR_MIN_LEN)
                    .filter(|(_, screen)| {
                        screen
                            .is_some_and(|s| s.residual - s.dof as f64 * noise > SPLIT_CHI2 * noise)
                    })
                    .map_init(Scratch::default, |scratch, (i, _)| {
                        let Scratch {
                            others,
                            values,
                            cleaned,
                            factors,
                        } = scratch;
                        gather(others, i);
                        let p = local(i);
                        let window = Window::around(input, sign, p, this.half_width, values)?;
                        let clean = window.without_neighbours(
                            p,
                            others,
                            this.sigma_px,
                            cleaned,
                            factors,
                        )?;
                        let pair = this.fit_pair(&clean, others, p, noise, factors)?;
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
            }
        }
        self.screens = screens;
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
        factors: &mut Factors,
    ) -> Option<[Point2; 2]> {
        let sigma = self.sigma_px;
        let one = Model::new(window, &[], 1, sigma).fit(&[p], factors);
        // The two start σ/2 on each side of the detection along the axis where the window's
        // signal spreads most.
        let axis = window.major_axis(p, &mut factors.sorted);
        let start = [p + axis * (0.5 * sigma), p + axis * (-0.5 * sigma)];
        let two = Model::new(window, &[], 2, sigma).fit(&start, factors);
        let core = self.half_width as f64 - 1.0;
        let min_separation = MIN_SEPARATION_SIGMAS * sigma;
        let inside = |q: Point2| (q.x - p.x).abs() <= core && (q.y - p.y).abs() <= core;
        let clear = |q: Point2| others.iter().all(|o| o.distance(q) >= min_separation);
        match (one, two) {
            (Some(one), Some(two))
                if (one.residual - two.residual) / noise > SPLIT_CHI2
                    && two.amplitudes.iter().all(|&a| a > 0.0)
                    && two.centres[0].distance(two.centres[1]) >= min_separation
                    && two.centres.iter().all(|&q| inside(q) && clear(q)) =>
            {
                Some(two.centres)
            }
            _ => None,
        }
    }
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

/// The pixels of a square window of the frame, particles positive.
struct Window<'v> {
    x0: usize,
    y0: usize,
    side: usize,
    values: &'v [f64],
}

impl<'v> Window<'v> {
    /// The window of half-width `half` around the pixel nearest `p`, if it lies inside the
    /// image, its values times `sign` (stored in `values`).
    fn around(
        image: &GrayImage,
        sign: f64,
        p: Point2,
        half: usize,
        values: &'v mut Vec<f64>,
    ) -> Option<Self> {
        let (width, height) = image.dimensions();
        let (cx, cy) = (p.x.round(), p.y.round());
        if cx < half as f64 || cy < half as f64 {
            return None;
        }
        let (cx, cy) = (cx as usize, cy as usize);
        if cx + half >= width || cy + half >= height {
            return None;
        }
        let side = 2 * half + 1;
        let (x0, y0) = (cx - half, cy - half);
        values.clear();
        for y in y0..y0 + side {
            values.extend(
                image.row(y)[x0..x0 + side]
                    .iter()
                    .map(|&v| sign * f64::from(v)),
            );
        }
        Some(Self {
            x0,
            y0,
            side,
            values,
        })
    }

    fn len(&self) -> usize {
        self.values.len()
    }

    /// This window with the particles at `others` subtracted: Gaussians of std `sigma` with
    /// the amplitudes of the linear fit of a background and particles at `p` and `others`
    /// (stored in `cleaned`); `None` when that fit is singular.
    fn without_neighbours<'c>(
        &self,
        p: Point2,
        others: &[Point2],
        sigma: f64,
        cleaned: &'c mut Vec<f64>,
        factors: &mut Factors,
    ) -> Option<Window<'c>> {
        let (_, solution) = Model::new(self, others, 1, sigma).linear_fit(&[p], factors)?;
        let side = self.side;
        cleaned.clear();
        cleaned.extend_from_slice(self.values);
        // Component 0 is the particle at `p`; the neighbours follow, amplitudes after the
        // background and the particle's.
        for c in 1..=others.len() {
            let amplitude = solution[1 + c];
            let (gx, gy) = (
                &factors.gx[c * side..][..side],
                &factors.gy[c * side..][..side],
            );
            for (row, &fy) in cleaned.chunks_exact_mut(side).zip(gy) {
                for (v, &fx) in row.iter_mut().zip(gx) {
                    *v -= amplitude * fy * fx;
                }
            }
        }
        Some(Window {
            x0: self.x0,
            y0: self.y0,
            side,
            values: cleaned,
        })
    }

    /// The unit direction along which the window's signal above its median spreads most
    /// about `p` (the major axis of its second moments); `sorted` is a reused buffer.
    fn major_axis(&self, p: Point2, sorted: &mut Vec<f64>) -> Vec2 {
        sorted.clear();
        sorted.extend_from_slice(self.values);
        let mid = sorted.len() / 2;
        let floor = *sorted.select_nth_unstable_by(mid, f64::total_cmp).1;
        let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
        for (k, &v) in self.values.iter().enumerate() {
            let w = (v - floor).max(0.0);
            let dx = (self.x0 + k % self.side) as f64 - p.x;
            let dy = (self.y0 + k / self.side) as f64 - p.y;
            sxx += w * dx * dx;
            syy += w * dy * dy;
            sxy += w * dx * dy;
        }
        let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        Vec2::new(angle.cos(), angle.sin())
    }
}

/// A fit's result: the free particles' centres and amplitudes, and the squared residual.
struct Fitted {
    centres: [Point2; 2],
    amplitudes: [f64; 2],
    residual: f64,
}

/// Background + Σ amplitude · Gaussian(width) over a window: `free` particles (centres and
/// amplitudes fitted), then the `fixed` centres (amplitudes fitted). Parameters: background,
/// width, (amplitude, x, y) per free particle, the fixed ones' amplitudes.
struct Model<'a> {
    window: &'a Window<'a>,
    fixed: &'a [Point2],
    free: usize,
    sigma: f64,
}

type Params = [f64; MAX_PARAMETERS];
type Normal = [f64; MAX_PARAMETERS * MAX_PARAMETERS];

impl<'a> Model<'a> {
    fn new(window: &'a Window<'a>, fixed: &'a [Point2], free: usize, sigma: f64) -> Self {
        Self {
            window,
            fixed,
            free,
            sigma,
        }
    }

    fn parameters(&self) -> usize {
        2 + 3 * self.free + self.fixed.len()
    }

    fn components(&self) -> usize {
        self.free + self.fixed.len()
    }

    fn centre(&self, theta: &Params, c: usize) -> Point2 {
        if c < self.free {
            Point2::new(theta[3 + 3 * c], theta[4 + 3 * c])
        } else {
            self.fixed[c - self.free]
        }
    }

    /// Per component, its Gaussian factors of width `s` along the window's columns and rows
    /// (into the scratch's `gx`, `gy`).
    fn factors(&self, theta: &Params, s: f64, factors: &mut Factors) {
        let (w, inv2) = (self.window, 1.0 / (2.0 * s * s));
        factors.gx.clear();
        factors.gy.clear();
        for c in 0..self.components() {
            let centre = self.centre(theta, c);
            let factor = |k: usize, origin: usize, at: f64| {
                (-((origin + k) as f64 - at).powi(2) * inv2).exp()
            };
            factors
                .gx
                .extend((0..w.side).map(|k| factor(k, w.x0, centre.x)));
            factors
                .gy
                .extend((0..w.side).map(|k| factor(k, w.y0, centre.y)));
        }
    }

    /// The linear least-squares fit with the free particles at `centres` and the measured σ
    /// (background and amplitudes only): its squared residual and its solution (background,
    /// then one amplitude per component); `None` when singular. Leaves the components'
    /// factors in `factors`.
    fn linear_fit(&self, centres: &[Point2], factors: &mut Factors) -> Option<(f64, Params)> {
        let mut theta = [0.0; MAX_PARAMETERS];
        for (c, centre) in centres.iter().enumerate() {
            theta[3 + 3 * c] = centre.x;
            theta[4 + 3 * c] = centre.y;
        }
        self.factors(&theta, self.sigma, factors);
        // Basis: 1, then one Gaussian per component.
        let n = 1 + self.components();
        let (w, side) = (self.window, self.window.side);
        let mut normal: Normal = [0.0; MAX_PARAMETERS * MAX_PARAMETERS];
        let mut projection = [0.0; MAX_PARAMETERS];
        let mut basis = [0.0; MAX_PARAMETERS];
        let mut total = 0.0;
        for row in 0..side {
            for col in 0..side {
                basis[0] = 1.0;
                for c in 0..n - 1 {
                    basis[1 + c] = factors.gx[c * side + col] * factors.gy[c * side + row];
                }
                let z = w.values[row * side + col];
                total += z * z;
                for a in 0..n {
                    projection[a] += basis[a] * z;
                    for b in a..n {
                        normal[a * n + b] += basis[a] * basis[b];
                    }
                }
            }
        }
        mirror(&mut normal, n);
        let mut solution = projection;
        if !solve_symmetric(&mut normal[..n * n], &mut solution[..n], n) {
            return None;
        }
        let explained: f64 = (0..n).map(|a| projection[a] * solution[a]).sum();
        Some(((total - explained).max(0.0), solution))
    }

    /// Levenberg–Marquardt from the free particles at `start` with the measured σ; `None`
    /// when the residual is not finite.
    fn fit(&self, start: &[Point2], factors: &mut Factors) -> Option<Fitted> {
        let n = self.parameters();
        let mut theta: Params = [0.0; MAX_PARAMETERS];
        let values = self.window.values;
        let floor = values.iter().copied().fold(f64::INFINITY, f64::min);
        let peak = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        theta[0] = floor;
        theta[1] = self.sigma;
        for (c, centre) in start.iter().enumerate() {
            theta[2 + 3 * c] = (peak - floor) / start.len() as f64;
            theta[3 + 3 * c] = centre.x;
            theta[4 + 3 * c] = centre.y;
        }
        let mut lambda = 1e-3;
        let (mut normal, mut gradient): (Normal, Params) = (
            [0.0; MAX_PARAMETERS * MAX_PARAMETERS],
            [0.0; MAX_PARAMETERS],
        );
        let mut residual = self.accumulate(&theta, factors, Some((&mut normal, &mut gradient)));
        for _ in 0..MAX_ITERATIONS {
            let mut system = normal;
            for d in 0..n {
                system[d * n + d] += lambda * normal[d * n + d].max(1e-12);
            }
            let mut step = gradient;
            if !solve_symmetric(&mut system[..n * n], &mut step[..n], n) {
                lambda *= 10.0;
                continue;
            }
            let mut trial = theta;
            for d in 0..n {
                trial[d] += step[d];
            }
            let width_ok = trial[1] > 0.25 * self.sigma && trial[1] < 4.0 * self.sigma;
            let tried = if width_ok {
                self.accumulate(&trial, factors, None)
            } else {
                f64::INFINITY
            };
            if tried < residual {
                let gain = (residual - tried) / residual.max(f64::MIN_POSITIVE);
                theta = trial;
                residual = self.accumulate(&theta, factors, Some((&mut normal, &mut gradient)));
                lambda = (lambda * 0.1).max(1e-9);
                if gain < 1e-4 {
                    break;
                }
            } else {
                lambda *= 10.0;
                if lambda > 1e6 {
                    break;
                }
            }
        }
        let last = start.len() - 1;
        residual.is_finite().then(|| Fitted {
            centres: [self.centre(&theta, 0), self.centre(&theta, last)],
            amplitudes: [theta[2], theta[2 + 3 * last]],
            residual,
        })
    }

    /// The squared residual at `theta`; with `system`, also JᵀJ and Jᵀr (the fits have free
    /// particles only: one or two).
    fn accumulate(
        &self,
        theta: &Params,
        factors: &mut Factors,
        system: Option<(&mut Normal, &mut Params)>,
    ) -> f64 {
        debug_assert!(
            self.fixed.is_empty(),
            "fitted models have free particles only"
        );
        self.factors(theta, theta[1], factors);
        match (self.free, system) {
            (1, Some(system)) => self.accumulate_system::<5>(theta, factors, system),
            (_, Some(system)) => self.accumulate_system::<8>(theta, factors, system),
            (_, None) => self.residual(theta, factors),
        }
    }

    /// The squared residual at `theta`, the factors already computed.
    fn residual(&self, theta: &Params, factors: &Factors) -> f64 {
        let (w, side) = (self.window, self.window.side);
        let mut total = 0.0;
        for (row, values) in w.values.chunks_exact(side).enumerate() {
            for (col, &z) in values.iter().enumerate() {
                let mut value = theta[0];
                for c in 0..self.free {
                    value +=
                        theta[2 + 3 * c] * factors.gx[c * side + col] * factors.gy[c * side + row];
                }
                total += (z - value).powi(2);
            }
        }
        total
    }

    /// The squared residual at `theta` with JᵀJ and Jᵀr for `N` parameters, the factors
    /// already computed.
    fn accumulate_system<const N: usize>(
        &self,
        theta: &Params,
        factors: &Factors,
        (normal, gradient): (&mut Normal, &mut Params),
    ) -> f64 {
        let (w, side) = (self.window, self.window.side);
        let s = theta[1];
        let inv_s2 = 1.0 / (s * s);
        let inv_s3 = inv_s2 / s;
        let free = (N - 2) / 3;
        let mut upper = [[0.0; N]; N];
        let mut projection = [0.0; N];
        let mut total = 0.0;
        for (row, values) in w.values.chunks_exact(side).enumerate() {
            let y = (w.y0 + row) as f64;
            for (col, &z) in values.iter().enumerate() {
                let x = (w.x0 + col) as f64;
                let mut jac = [0.0; N];
                jac[0] = 1.0;
                let mut value = theta[0];
                for c in 0..free {
                    let g = factors.gx[c * side + col] * factors.gy[c * side + row];
                    let ag = theta[2 + 3 * c] * g;
                    let (dx, dy) = (x - theta[3 + 3 * c], y - theta[4 + 3 * c]);
                    value += ag;
                    jac[1] += ag * (dx * dx + dy * dy) * inv_s3;
                    jac[2 + 3 * c] = g;
                    jac[3 + 3 * c] = ag * dx * inv_s2;
                    jac[4 + 3 * c] = ag * dy * inv_s2;
                }
                let r = z - value;
                total += r * r;
                for a in 0..N {
                    projection[a] += jac[a] * r;
                    for b in a..N {
                        upper[a][b] += jac[a] * jac[b];
                    }
                }
            }
        }
        for a in 0..N {
            gradient[a] = projection[a];
            for b in a..N {
                normal[a * N + b] = upper[a][b];
                normal[b * N + a] = upper[a][b];
            }
        }
        total
    }
}

/// Copies the upper triangle of an n × n row-major matrix to its lower one.
fn mirror(matrix: &mut [f64], n: usize) {
    for a in 0..n {
        for b in 0..a {
            matrix[a * n + b] = matrix[b * n + a];
        }
    }
}

/// Solves `a·x = b` for a symmetric positive definite `a` (n × n, row-major) by Cholesky, in
/// place (`b` becomes `x`); false when `a` is not positive definite.
fn solve_symmetric(a: &mut [f64], b: &mut [f64], n: usize) -> bool {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut v = a[i * n + j];
            for k in 0..j {
                v -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = v / d;
        }
    }
    for i in 0..n {
        let mut v = b[i];
        for k in 0..i {
            v -= a[i * n + k] * b[k];
        }
        b[i] = v / a[i * n + i];
    }
    for i in (0..n).rev() {
        let mut v = b[i];
        for k in i + 1..n {
            v -= a[k * n + i] * b[k];
        }
        b[i] = v / a[i * n + i];
    }
    true
}

/// The detections bucketed on a grid, for the neighbours of an examined one.
struct Neighbours {
    cell: f64,
    cols: usize,
    rows: usize,
    start: Vec<u32>,
    members: Vec<u32>,
}

impl Neighbours {
    fn new(detections: &[Detection], offset: (f64, f64), cell: f64) -> Self {
        let extent = detections.iter().fold((0.0f64, 0.0f64), |(w, h), d| {
            (w.max(d.pos_px.x - offset.0), h.max(d.pos_px.y - offset.1))
        });
        let cols = (extent.0.max(0.0) / cell) as usize + 1;
        let rows = (extent.1.max(0.0) / cell) as usize + 1;
        let cell_of = |d: &Detection| {
            let cx = ((d.pos_px.x - offset.0).max(0.0) / cell) as usize;
            let cy = ((d.pos_px.y - offset.1).max(0.0) / cell) as usize;
            cy.min(rows - 1) * cols + cx.min(cols - 1)
        };
        let mut start = vec![0u32; cols * rows + 1];
        for d in detections {
            start[cell_of(d) + 1] += 1;
        }
        for c in 1..start.len() {
            start[c] += start[c - 1];
        }
        let mut fill = start.clone();
        let mut members = vec![0u32; detections.len()];
        for (i, d) in detections.iter().enumerate() {
            let c = cell_of(d);
            members[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        Self {
            cell,
            cols,
            rows,
            start,
            members,
        }
    }

    /// The positions (image pixels) of the detections other than `own` within `reach` of `p`.
    fn near<'a>(
        &'a self,
        detections: &'a [Detection],
        offset: (f64, f64),
        p: Point2,
        own: usize,
        reach: f64,
    ) -> impl Iterator<Item = Point2> + 'a {
        let cx = (p.x.max(0.0) / self.cell) as usize;
        let cy = (p.y.max(0.0) / self.cell) as usize;
        let (cx, cy) = (cx.min(self.cols - 1), cy.min(self.rows - 1));
        let rows = cy.saturating_sub(1)..=(cy + 1).min(self.rows - 1);
        let (x0, x1) = (cx.saturating_sub(1), (cx + 1).min(self.cols - 1));
        rows.flat_map(move |y| {
            let (first, last) = (y * self.cols + x0, y * self.cols + x1);
            self.members[self.start[first] as usize..self.start[last + 1] as usize].iter()
        })
        .filter(move |&&j| j as usize != own)
        .map(move |&j| {
            let q = detections[j as usize].pos_px;
            Point2::new(q.x - offset.0, q.y - offset.1)
        })
        .filter(move |q| q.distance(p) < reach)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_image::{DogFilter, Polarity};
    use sillage_synth::{Noise, NoiseKind, render_spots};

    const SIGMA_PX: f64 = 2.0;

    /// A 256² frame of 36 sites 40 px apart: at even sites a pair of σ 2 px particles 3.2 px
    /// apart (amplitudes 0.5 and 0.4, orientations turning), at odd sites one particle of σ
    /// 2 px or, every other one, 2.5 px (wider than the splitter expects); noise σ 0.02. Also
    /// the detections the resolving scale gives: one per site, a pair's at its intensity
    /// centroid.
    fn scene() -> (GrayImage, Vec<[Point2; 2]>, Vec<Point2>, Vec<Detection>) {
        let (mut spots, mut pairs, mut singles, mut detections) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for k in 0..36 {
            let centre = Point2::new(
                28.0 + 40.0 * (k % 6) as f64 + 0.3 * (k % 3) as f64,
                28.0 + 40.0 * (k / 6) as f64 + 0.2 * (k % 4) as f64,
            );
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
        let noise = Noise {
            kind: NoiseKind::Gaussian,
            magnitude: 0.02,
        };
        let image = render_spots(256, 256, &spots, noise, 3).unwrap();
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
        Deblender::new(SIGMA_PX).split(&image, 1.0, &matched(&image), (0.0, 0.0), &mut detections);
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
        Deblender::new(SIGMA_PX).split(&image, 1.0, &matched(&image), (0.0, 0.0), &mut few);
        assert_eq!(few, before);
    }
}

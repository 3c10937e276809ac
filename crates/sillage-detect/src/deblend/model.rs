//! Sums of Gaussians fitted by least squares over a window of the frame.
//!
//! The Gaussians are separable, so every sum over the window's pixels that a fit needs (its
//! residual, its normal equations) is a product of a sum along the columns and a sum along
//! the rows, or a sum along the rows of the window's values projected on a column profile.
//! A Levenberg–Marquardt step of two particles then costs seven passes of one multiply–add
//! over the window instead of one pass of ~60 (one per entry of JᵀJ and Jᵀr).

use super::MAX_NEIGHBOURS;
use super::window::Window;
use sillage_core::Point2;

/// Components of a linear fit at most: the examined detection and its neighbours.
const MAX_COMPONENTS: usize = 1 + MAX_NEIGHBOURS;
/// Free particles of a Levenberg–Marquardt fit at most.
const MAX_FREE: usize = 2;
/// Profiles along one axis at most: the constant, then per component its Gaussian times the
/// offset from its centre to the power 0, 1 and 2.
const MAX_PROFILES: usize = 1 + 3 * MAX_COMPONENTS;
/// Separable terms of a fitted model and its Jacobian at most: the constant, then per free
/// particle five ([`Term::of`]).
const MAX_TERMS: usize = 1 + 5 * MAX_FREE;
/// Parameters of a fitted model at most: background, width, (amplitude, x, y) per particle.
const MAX_PARAMETERS: usize = 2 + 3 * MAX_FREE;
/// Levenberg–Marquardt iterations at most.
const MAX_ITERATIONS: usize = 12;

/// The background and the amplitudes of a linear fit, in the order of its components.
pub(super) type Amplitudes = [f64; 1 + MAX_COMPONENTS];
type Params = [f64; MAX_PARAMETERS];
type Normal = [f64; MAX_PARAMETERS * MAX_PARAMETERS];
/// The inner products of the profiles along one axis.
type Gram = [[f64; MAX_PROFILES]; MAX_PROFILES];

/// The index of component `c`'s profile: its Gaussian times the offset from its centre to
/// the power `power` (0–2). Profile 0 is the constant 1.
fn profile(c: usize, power: usize) -> usize {
    1 + 3 * c + power
}

/// A separable function over the window: a column profile times a row profile.
#[derive(Debug, Clone, Copy)]
struct Term {
    col: usize,
    row: usize,
}

impl Term {
    const CONSTANT: Term = Term { col: 0, row: 0 };

    /// Free particle `c`'s term `k`: 0 its Gaussian g, then g·dx, g·dy, g·dx², g·dy² (the
    /// derivatives of g in its centre and width are combinations of these).
    fn of(c: usize, k: usize) -> Term {
        let (col, row) = [(0, 0), (1, 0), (0, 1), (2, 0), (0, 2)][k];
        Term {
            col: profile(c, col),
            row: profile(c, row),
        }
    }
}

/// The components' profiles over one window, the window's values projected on them and
/// their inner products (buffers reused between fits).
#[derive(Debug, Default)]
pub(super) struct Profiles {
    side: usize,
    /// Column profiles, `side` values each (the layout of [`profile`]).
    cols: Vec<f64>,
    /// Row profiles, likewise.
    rows: Vec<f64>,
    /// Per row profile, per column: the column's values times the profile, summed.
    projected: Vec<f64>,
    /// Inner products of the column profiles.
    col_gram: Gram,
    /// Inner products of the row profiles.
    row_gram: Gram,
}

impl Profiles {
    /// Sets the profiles of Gaussians of std `s` at `centres` over `window`.
    fn set(&mut self, window: &Window<'_>, centres: impl Iterator<Item = Point2>, s: f64) {
        let side = window.side;
        self.side = side;
        self.cols.clear();
        self.rows.clear();
        self.cols.resize(side, 1.0);
        self.rows.resize(side, 1.0);
        let inv2 = 1.0 / (2.0 * s * s);
        let step = (-2.0 * inv2).exp();
        for centre in centres {
            push_axis(&mut self.cols, side, window.x0, centre.x, inv2, step);
            push_axis(&mut self.rows, side, window.y0, centre.y, inv2, step);
        }
    }

    /// Projects the window's values on the row profiles `which` and takes the inner
    /// products among them and among the column profiles of the same indices.
    fn prepare(&mut self, window: &Window<'_>, which: &[usize]) {
        self.prepare_more(window, &[], which);
    }

    /// [`Profiles::prepare`] for the profiles `new` when those of `done` are prepared
    /// already (same profiles): projects `new` and takes the inner products of `new` with
    /// `done` and among themselves.
    fn prepare_more(&mut self, window: &Window<'_>, done: &[usize], new: &[usize]) {
        let side = self.side;
        self.projected.resize(self.rows.len(), 0.0);
        project_widest(window.values, side, &self.rows, new, &mut self.projected);
        let axes = [
            (&self.cols, &mut self.col_gram),
            (&self.rows, &mut self.row_gram),
        ];
        for (profiles, gram) in axes {
            inner_products_widest(profiles, side, done, new, gram);
        }
    }

    fn col(&self, p: usize) -> &[f64] {
        &self.cols[p * self.side..][..self.side]
    }

    fn row(&self, p: usize) -> &[f64] {
        &self.rows[p * self.side..][..self.side]
    }

    /// Σ over the window of its values times `t` (its row profile prepared).
    fn data(&self, t: Term) -> f64 {
        dot(
            &self.projected[t.row * self.side..][..self.side],
            self.col(t.col),
        )
    }

    /// Σ over the window of `a` times `b` (their profiles prepared).
    fn gram(&self, a: Term, b: Term) -> f64 {
        self.col_gram[a.col][b.col] * self.row_gram[a.row][b.row]
    }

    /// Component `c`'s Gaussian along the columns and along the rows.
    pub(super) fn gaussian(&self, c: usize) -> (&[f64], &[f64]) {
        (self.col(profile(c, 0)), self.row(profile(c, 0)))
    }
}

/// Per row profile `q` of `which` and per column `i` of the window (`values`, `side`²):
/// `projected[q][i] = Σ_j rows[q][j] · values[j][i]`, summed in the order of `j` from zero.
/// Row by row, so that each update runs along contiguous values.
fn project(values: &[f64], side: usize, rows: &[f64], which: &[usize], projected: &mut [f64]) {
    for &q in which {
        projected[q * side..][..side].fill(0.0);
    }
    for (j, values) in values.chunks_exact(side).enumerate() {
        for &q in which {
            let weight = rows[q * side + j];
            for (sum, &z) in projected[q * side..][..side].iter_mut().zip(values) {
                *sum += weight * z;
            }
        }
    }
}

/// [`project`], on AVX-512 where the CPU has it (the same bits: each sum in the same order,
/// multiply and add not fused).
fn project_widest(
    values: &[f64],
    side: usize,
    rows: &[f64],
    which: &[usize],
    projected: &mut [f64],
) {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx512f") {
        // SAFETY: the CPU supports AVX-512F, checked just above.
        unsafe { project_avx512(values, side, rows, which, projected) };
        return;
    }
    project(values, side, rows, which, projected);
}

/// [`project`] eight columns at a time, the sums of up to six profiles held in registers
/// across the rows.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn project_avx512(
    values: &[f64],
    side: usize,
    rows: &[f64],
    which: &[usize],
    projected: &mut [f64],
) {
    for which in which.chunks(6) {
        match which.len() {
            1 => project_avx512_n::<1>(values, side, rows, which, projected),
            2 => project_avx512_n::<2>(values, side, rows, which, projected),
            3 => project_avx512_n::<3>(values, side, rows, which, projected),
            4 => project_avx512_n::<4>(values, side, rows, which, projected),
            5 => project_avx512_n::<5>(values, side, rows, which, projected),
            _ => project_avx512_n::<6>(values, side, rows, which, projected),
        }
    }
}

/// [`project_avx512`] for `N` profiles.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn project_avx512_n<const N: usize>(
    values: &[f64],
    side: usize,
    rows: &[f64],
    which: &[usize],
    projected: &mut [f64],
) {
    use std::arch::x86_64::{
        _mm512_add_pd, _mm512_mask_storeu_pd, _mm512_maskz_loadu_pd, _mm512_mul_pd, _mm512_set1_pd,
        _mm512_setzero_pd,
    };
    let values = &values[..side * side];
    let weights: [&[f64]; N] = std::array::from_fn(|a| &rows[which[a] * side..][..side]);
    let mut first = 0;
    while first < side {
        let mask = (0xffu32 >> 8usize.saturating_sub(side - first)) as u8;
        // SAFETY: AVX-512F is enabled in the only caller. Lane `l` of a load or store at
        // `first` is at most `first + l < side` within a row of `side` values (of `values`,
        // or of a profile's `side` entries of `projected`, both sliced to length); the other
        // lanes are masked, neither read nor written. `j < side`, each weight slice's length.
        unsafe {
            let mut sums = [_mm512_setzero_pd(); N];
            for j in 0..side {
                let z = _mm512_maskz_loadu_pd(mask, values.as_ptr().add(j * side + first));
                for (sum, weights) in sums.iter_mut().zip(&weights) {
                    let weight = _mm512_set1_pd(*weights.get_unchecked(j));
                    *sum = _mm512_add_pd(*sum, _mm512_mul_pd(weight, z));
                }
            }
            for (sum, &q) in sums.iter().zip(which) {
                let out = &mut projected[q * side..][..side];
                _mm512_mask_storeu_pd(out.as_mut_ptr().add(first), mask, *sum);
            }
        }
        first += 8;
    }
}

/// Appends a component's three profiles along one axis: g, g·d, g·d² at the `side` pixels
/// from `origin`, d the offset from `at`. The Gaussian by its recurrence, g(d + 1) = g(d) ·
/// r(d) with r(d + 1) = r(d) · `step` (`inv2` = 1/2s², `step` = e^(−1/s²), the same for every
/// component): two exponentials, not `side`.
fn push_axis(profiles: &mut Vec<f64>, side: usize, origin: usize, at: f64, inv2: f64, step: f64) {
    let start = profiles.len();
    profiles.resize(start + 3 * side, 0.0);
    let (g, rest) = profiles[start..].split_at_mut(side);
    let (gd, gd2) = rest.split_at_mut(side);
    let d0 = origin as f64 - at;
    let mut value = (-d0 * d0 * inv2).exp();
    let mut ratio = (-(2.0 * d0 + 1.0) * inv2).exp();
    for k in 0..side {
        let d = d0 + k as f64;
        (g[k], gd[k], gd2[k]) = (value, value * d, value * d * d);
        value *= ratio;
        ratio *= step;
    }
}

/// The inner products of the profiles `new` (`side` values each in `profiles`, the layout
/// of [`profile`]) with those of `done` and among themselves, stored both ways in `gram`.
#[inline(always)]
fn inner_products(profiles: &[f64], side: usize, done: &[usize], new: &[usize], gram: &mut Gram) {
    let of = |p: usize| &profiles[p * side..][..side];
    for (a, &p) in new.iter().enumerate() {
        for &q in done.iter().chain(&new[a..]) {
            let value = dot(of(p), of(q));
            (gram[p][q], gram[q][p]) = (value, value);
        }
    }
}

sillage_core::multiversion! {
    /// [`inner_products`] on the widest SIMD the CPU offers.
    fn inner_products_widest(profiles: &[f64], side: usize, done: &[usize], new: &[usize], gram: &mut Gram) => inner_products
}

/// The inner product of two profiles, in four independent sums (so that the additions
/// pipeline and vectorise; the order is fixed, so results are reproducible).
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut lanes = [0.0; 4];
    let (a4, b4) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = a4
        .remainder()
        .iter()
        .zip(b4.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in a4.zip(b4) {
        for k in 0..4 {
            lanes[k] += x[k] * y[k];
        }
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
}

/// The linear least-squares fit over `window` of a background and Gaussians of std `sigma`
/// at `centres`, amplitudes free: its squared residual and its solution (background, then
/// one amplitude per centre); `None` when singular. Leaves the components' profiles in
/// `profiles`.
pub(super) fn linear_fit(
    window: &Window<'_>,
    centres: &[Point2],
    sigma: f64,
    profiles: &mut Profiles,
) -> Option<(f64, Amplitudes)> {
    debug_assert!(centres.len() <= MAX_COMPONENTS);
    profiles.set(window, centres.iter().copied(), sigma);
    let n = 1 + centres.len();
    let basis = |a: usize| match a {
        0 => Term::CONSTANT,
        a => Term::of(a - 1, 0),
    };
    let mut which = [0; 1 + MAX_COMPONENTS];
    for (a, w) in which[..n].iter_mut().enumerate() {
        *w = basis(a).col;
    }
    profiles.prepare(window, &which[..n]);
    let mut normal = [0.0; (1 + MAX_COMPONENTS) * (1 + MAX_COMPONENTS)];
    let mut projection: Amplitudes = [0.0; 1 + MAX_COMPONENTS];
    for a in 0..n {
        projection[a] = profiles.data(basis(a));
        for b in 0..n {
            normal[a * n + b] = profiles.gram(basis(a), basis(b));
        }
    }
    let mut solution = projection;
    if !solve_symmetric(&mut normal[..n * n], &mut solution[..n], n) {
        return None;
    }
    let explained: f64 = (0..n).map(|a| projection[a] * solution[a]).sum();
    Some(((window.sum_sq - explained).max(0.0), solution))
}

/// A Levenberg–Marquardt fit's result: the particles' centres and amplitudes (the first
/// and the last particle's) and the squared residual.
pub(super) struct Fitted {
    pub(super) centres: [Point2; 2],
    pub(super) amplitudes: [f64; 2],
    pub(super) residual: f64,
}

/// Background + Σ amplitude · Gaussian(width) over a window, `free` particles of free
/// centres and amplitudes. Parameters θ: background, width, (amplitude, x, y) per particle.
struct Model<'a> {
    window: &'a Window<'a>,
    free: usize,
    sigma: f64,
    /// The least drop of the squared residual for an iteration not to be the last.
    tolerance: f64,
}

/// The JᵀJ and Jᵀr of a model at θ.
struct System {
    normal: Normal,
    gradient: Params,
}

/// Levenberg–Marquardt over `window` from particles at `start` (one or two) of the std
/// `sigma`, width then free, until an iteration lowers the squared residual by less than
/// `tolerance`; `None` when the residual is not finite.
pub(super) fn fit(
    window: &Window<'_>,
    start: &[Point2],
    sigma: f64,
    tolerance: f64,
    profiles: &mut Profiles,
) -> Option<Fitted> {
    debug_assert!((1..=MAX_FREE).contains(&start.len()));
    let model = Model {
        window,
        free: start.len(),
        sigma,
        tolerance,
    };
    model.fit(start, profiles)
}

impl Model<'_> {
    fn parameters(&self) -> usize {
        2 + 3 * self.free
    }

    fn centre(theta: &Params, c: usize) -> Point2 {
        Point2::new(theta[3 + 3 * c], theta[4 + 3 * c])
    }

    fn fit(&self, start: &[Point2], profiles: &mut Profiles) -> Option<Fitted> {
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
        let mut residual = self.evaluate(&theta, profiles);
        let mut system = self.system(&theta, profiles);
        for _ in 0..MAX_ITERATIONS {
            let mut damped = system.normal;
            for d in 0..n {
                damped[d * n + d] += lambda * system.normal[d * n + d].max(1e-12);
            }
            let mut step = system.gradient;
            if !solve_symmetric(&mut damped[..n * n], &mut step[..n], n) {
                lambda *= 10.0;
                continue;
            }
            let mut trial = theta;
            for d in 0..n {
                trial[d] += step[d];
            }
            let width_ok = trial[1] > 0.25 * self.sigma && trial[1] < 4.0 * self.sigma;
            let tried = if width_ok {
                self.evaluate(&trial, profiles)
            } else {
                f64::INFINITY
            };
            if tried < residual {
                let gain = residual - tried;
                (theta, residual) = (trial, tried);
                if gain < self.tolerance {
                    break;
                }
                // `evaluate` left the profiles at the trial, now θ.
                system = self.system(&theta, profiles);
                lambda = (lambda * 0.1).max(1e-9);
            } else {
                lambda *= 10.0;
                if lambda > 1e6 {
                    break;
                }
            }
        }
        let last = self.free - 1;
        residual.is_finite().then(|| Fitted {
            centres: [Self::centre(&theta, 0), Self::centre(&theta, last)],
            amplitudes: [theta[2], theta[2 + 3 * last]],
            residual,
        })
    }

    /// Sets the profiles of the particles at θ.
    fn set_profiles(&self, theta: &Params, profiles: &mut Profiles) {
        let centres = (0..self.free).map(|c| Self::centre(theta, c));
        profiles.set(self.window, centres, theta[1]);
    }

    /// The model's coefficients on its terms: the background on the constant, each
    /// amplitude on its particle's Gaussian.
    /// (term index, term, coefficient), the first `1 + free` entries used.
    fn coefficients(&self, theta: &Params) -> [(usize, Term, f64); 1 + MAX_FREE] {
        let mut out = [(0, Term::CONSTANT, theta[0]); 1 + MAX_FREE];
        for c in 0..self.free {
            out[1 + c] = (1 + 5 * c, Term::of(c, 0), theta[2 + 3 * c]);
        }
        out
    }

    /// The squared residual at θ (the profiles set and prepared there).
    fn evaluate(&self, theta: &Params, profiles: &mut Profiles) -> f64 {
        self.set_profiles(theta, profiles);
        let mut which = [0; 1 + MAX_FREE];
        for c in 0..self.free {
            which[1 + c] = profile(c, 0);
        }
        profiles.prepare(self.window, &which[..1 + self.free]);
        self.residual(theta, profiles)
    }

    /// The squared residual at θ from the Gaussians' profiles as [`Model::evaluate`] leaves
    /// them: Σz² − 2 Σ αₘ⟨z, tₘ⟩ + Σₘ αₘ Σₖ αₖ⟨tₖ, tₘ⟩ over the model's terms tₘ and
    /// coefficients αₘ, in that order (one formula for every caller, so that the residual of
    /// an accepted trial is the one its system would give, bit for bit).
    fn residual(&self, theta: &Params, profiles: &Profiles) -> f64 {
        let coefficients = self.coefficients(theta);
        let coefficients = &coefficients[..1 + self.free];
        let mut total = self.window.sum_sq;
        let mut model_gram = [0.0; 1 + MAX_FREE];
        for &(_, a, alpha) in coefficients {
            total -= 2.0 * alpha * profiles.data(a);
            for (sum, &(_, b, _)) in model_gram.iter_mut().zip(coefficients) {
                *sum += alpha * profiles.gram(a, b);
            }
        }
        for (&(_, _, alpha), &sum) in coefficients.iter().zip(&model_gram) {
            total += alpha * sum;
        }
        total.max(0.0)
    }

    /// JᵀJ and Jᵀr at θ, from `profiles` as [`Model::evaluate`] at the same θ leaves them
    /// (the Gaussians' profiles prepared; the others are added).
    fn system(&self, theta: &Params, profiles: &mut Profiles) -> System {
        let mut done = [0; 1 + MAX_FREE];
        let mut new = [0; 2 * MAX_FREE];
        for c in 0..self.free {
            done[1 + c] = profile(c, 0);
            (new[2 * c], new[2 * c + 1]) = (profile(c, 1), profile(c, 2));
        }
        profiles.prepare_more(self.window, &done[..1 + self.free], &new[..2 * self.free]);
        // The terms: the constant, then five per particle.
        let term_count = 1 + 5 * self.free;
        let terms: [Term; MAX_TERMS] = std::array::from_fn(|m| match m {
            0 => Term::CONSTANT,
            m => Term::of((m - 1) / 5, (m - 1) % 5),
        });
        let terms = &terms[..term_count];
        let mut gram = [[0.0; MAX_TERMS]; MAX_TERMS];
        let mut data = [0.0; MAX_TERMS];
        // The inner products are symmetric (the profiles' are stored both ways).
        for (m, &a) in terms.iter().enumerate() {
            data[m] = profiles.data(a);
            for (k, &b) in terms.iter().enumerate().skip(m) {
                let g = profiles.gram(a, b);
                (gram[m][k], gram[k][m]) = (g, g);
            }
        }
        // The model on the terms (constant and Gaussians), its fit to the data and the
        // residual's projection on every term.
        let coefficients = self.coefficients(theta);
        let mut model_gram = [0.0; MAX_TERMS];
        for &(m, _, alpha) in &coefficients[..1 + self.free] {
            for k in 0..term_count {
                model_gram[k] += alpha * gram[m][k];
            }
        }
        // ∂model/∂θ as combinations of the terms: background → constant; width → Σ a/s³
        // (g·dx² + g·dy²); amplitude → g; x → a/s² g·dx; y → a/s² g·dy.
        let s = theta[1];
        let mut jacobian = [[(0usize, 0.0f64); 2 * MAX_FREE]; MAX_PARAMETERS];
        let mut entries = [0usize; MAX_PARAMETERS];
        let mut push = |k: usize, m: usize, weight: f64| {
            jacobian[k][entries[k]] = (m, weight);
            entries[k] += 1;
        };
        push(0, 0, 1.0);
        for c in 0..self.free {
            let (a, base) = (theta[2 + 3 * c], 1 + 5 * c);
            push(1, base + 3, a / (s * s * s));
            push(1, base + 4, a / (s * s * s));
            push(2 + 3 * c, base, 1.0);
            push(3 + 3 * c, base + 1, a / (s * s));
            push(4 + 3 * c, base + 2, a / (s * s));
        }
        let n = self.parameters();
        let mut system = System {
            normal: [0.0; MAX_PARAMETERS * MAX_PARAMETERS],
            gradient: [0.0; MAX_PARAMETERS],
        };
        let gram = &gram;
        for k in 0..n {
            let row = &jacobian[k][..entries[k]];
            system.gradient[k] = row
                .iter()
                .map(|&(m, w)| w * (data[m] - model_gram[m]))
                .sum();
            for l in k..n {
                let column = &jacobian[l][..entries[l]];
                let value: f64 = row
                    .iter()
                    .flat_map(|&(m, w)| column.iter().map(move |&(q, v)| w * v * gram[m][q]))
                    .sum();
                system.normal[k * n + l] = value;
                system.normal[l * n + k] = value;
            }
        }
        system
    }
}

/// Solves `a·x = b` for a symmetric positive definite `a` (n × n, row-major) by Cholesky, in
/// place (`b` becomes `x`); false when `a` is not positive definite.
fn solve_symmetric(a: &mut [f64], b: &mut [f64], n: usize) -> bool {
    // The sizes of the Levenberg–Marquardt fits, compiled for their constant size.
    match n {
        5 => cholesky(a, b, 5),
        8 => cholesky(a, b, 8),
        n => cholesky(a, b, n),
    }
}

/// [`solve_symmetric`]'s body.
#[inline(always)]
fn cholesky(a: &mut [f64], b: &mut [f64], n: usize) -> bool {
    let (a, b) = (&mut a[..n * n], &mut b[..n]);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A 13² window of two Gaussians on a background, with a deterministic ripple.
    fn values(x0: usize, y0: usize) -> Vec<f64> {
        let mut values = Vec::new();
        for y in y0..y0 + 13 {
            for x in x0..x0 + 13 {
                let g = |cx: f64, cy: f64, s: f64| {
                    (-((x as f64 - cx).powi(2) + (y as f64 - cy).powi(2)) / (2.0 * s * s)).exp()
                };
                let ripple = 0.03 * ((7 * x + 3 * y) as f64).sin();
                values.push(0.1 + 0.8 * g(26.3, 40.8, 2.1) + 0.5 * g(28.9, 42.1, 2.1) + ripple);
            }
        }
        values
    }

    /// The window of `values(21, 35)`.
    fn window(values: &[f64]) -> Window<'_> {
        Window {
            x0: 21,
            y0: 35,
            side: 13,
            values,
            sum_sq: values.iter().map(|v| v * v).sum(),
        }
    }

    /// The model at θ and its derivatives in θ at every pixel, summed directly.
    fn direct(window: &Window<'_>, model: &Model<'_>, theta: &Params) -> (f64, Normal, Params) {
        let n = model.parameters();
        let at = |theta: &Params, x: f64, y: f64| {
            let s = theta[1];
            (0..model.free).fold(theta[0], |v, c| {
                let centre = Model::centre(theta, c);
                let d2 = (x - centre.x).powi(2) + (y - centre.y).powi(2);
                v + theta[2 + 3 * c] * (-d2 / (2.0 * s * s)).exp()
            })
        };
        let (mut residual, mut normal, mut gradient) = (0.0, [0.0; 64], [0.0; 8]);
        for (k, &z) in window.values.iter().enumerate() {
            let x = (window.x0 + k % window.side) as f64;
            let y = (window.y0 + k / window.side) as f64;
            let r = z - at(theta, x, y);
            residual += r * r;
            let mut jacobian = [0.0; 8];
            for (d, j) in jacobian.iter_mut().enumerate().take(n) {
                let (mut up, mut down) = (*theta, *theta);
                up[d] += 1e-6;
                down[d] -= 1e-6;
                *j = (at(&up, x, y) - at(&down, x, y)) / 2e-6;
            }
            for a in 0..n {
                gradient[a] += jacobian[a] * r;
                for b in 0..n {
                    normal[a * n + b] += jacobian[a] * jacobian[b];
                }
            }
        }
        (residual, normal, gradient)
    }

    #[test]
    fn separable_sums_equal_the_sums_over_the_pixels() {
        let values = values(21, 35);
        let window = window(&values);
        let mut profiles = Profiles::default();
        for free in 1..=2 {
            let model = Model {
                window: &window,
                free,
                sigma: 2.0,
                tolerance: 0.0,
            };
            let theta: Params = [0.12, 2.3, 0.7, 26.0, 41.0, 0.4, 29.4, 41.7];
            let (residual, normal, gradient) = direct(&window, &model, &theta);
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * (1.0 + a.abs().max(b.abs()));
            let separable = model.evaluate(&theta, &mut profiles);
            assert!(close(separable, residual), "{separable} vs {residual}");
            let system = model.system(&theta, &mut profiles);
            let n = model.parameters();
            for a in 0..n {
                assert!(
                    close(system.gradient[a], gradient[a]),
                    "Jᵀr[{a}], {free} free"
                );
                for b in 0..n {
                    let (got, want) = (system.normal[a * n + b], normal[a * n + b]);
                    assert!(
                        close(got, want),
                        "JᵀJ[{a}][{b}] {got} vs {want}, {free} free"
                    );
                }
            }
        }
    }

    #[test]
    fn the_vector_projection_gives_the_bits_of_the_plain_loop() {
        for side in [5, 8, 9, 13, 16, 17, 21] {
            let values: Vec<f64> = (0..side * side)
                .map(|k| (0.37 * k as f64).sin() * 1e3 + 0.1)
                .collect();
            let rows: Vec<f64> = (0..MAX_PROFILES * side)
                .map(|k| (0.11 * k as f64).cos())
                .collect();
            for count in 1..=MAX_PROFILES {
                let mut which: Vec<usize> =
                    (0..count).map(|k| (5 * k + side) % MAX_PROFILES).collect();
                which.sort_unstable();
                which.dedup();
                let (mut plain, mut widest) = (vec![7.0; rows.len()], vec![7.0; rows.len()]);
                project(&values, side, &rows, &which, &mut plain);
                project_widest(&values, side, &rows, &which, &mut widest);
                for &q in &which {
                    let (a, b) = (&plain[q * side..][..side], &widest[q * side..][..side]);
                    assert!(
                        a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()),
                        "side {side}, profile {q}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_linear_fit_recovers_the_amplitudes_of_known_centres() {
        let values = values(21, 35);
        let window = window(&values);
        let centres = [Point2::new(26.3, 40.8), Point2::new(28.9, 42.1)];
        let (residual, solution) =
            linear_fit(&window, &centres, 2.1, &mut Profiles::default()).unwrap();
        // The ripple (amplitude 0.03) is all that is left.
        assert!((solution[1] - 0.8).abs() < 0.02 && (solution[2] - 0.5).abs() < 0.02);
        assert!(residual < 169.0 * 0.03 * 0.03, "{residual}");
    }
}

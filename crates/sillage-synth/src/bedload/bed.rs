//! The static bed: hexagonal layers of black beads in contact at the bottom of the frame,
//! some transparent beads lodged in its top layers, and the surface on which the creeping
//! layers ([`super::creep`]) and the mobile beads rest, roll and land.

use std::collections::HashMap;

use rand::RngExt;
use sillage_core::{
    BLACK_BEAD_CLASS, ObjectClass, Point2, RngStream, TRANSPARENT_BEAD_CLASS, Vec2,
};

use super::BedloadSceneParams;

/// Sampling step of the surface tables, px.
const SURFACE_STEP_PX: f64 = 0.25;

/// One lattice site of the static bed: its layer (0 at the bottom), its position before
/// disorder, and whether its bead is in the frame (sites beyond the left and right edges
/// only shape the surface).
#[derive(Debug, Clone, Copy)]
struct Site {
    layer: usize,
    pos: Point2,
    in_frame: bool,
}

/// How far the bed extends beyond the left and right edges, px: far enough that the
/// surface near the edges is that of an unbroken bed.
fn margin_px(params: &BedloadSceneParams) -> f64 {
    let r_max = params.black_radius_px.max(params.transparent_radius_px);
    4.0 * params.black_radius_px + 2.0 * r_max
}

/// Number of static layers: the bed's layers below the creeping ones.
fn static_layers(params: &BedloadSceneParams) -> usize {
    params.bed_layers.saturating_sub(params.creeping_layers)
}

/// The lattice sites of the static layers, bottom layer first, left to right: layer `j`
/// has its centres at `y = height − 1 − r − j·√3·r` (the bottom layer on the frame's last
/// row), spaced `2r`, odd layers shifted by `r`, so that every bead touches its six
/// neighbours.
fn sites(params: &BedloadSceneParams) -> impl Iterator<Item = Site> + '_ {
    let r = params.black_radius_px;
    let last_x = params.width as f64 - 1.0;
    let margin = margin_px(params);
    (0..static_layers(params)).flat_map(move |layer| {
        let y = params.height as f64 - 1.0 - r - layer as f64 * 3f64.sqrt() * r;
        let offset = if layer % 2 == 0 { r } else { 0.0 };
        let first = ((-margin - offset) / (2.0 * r)).ceil() as i64;
        let last = ((last_x + margin - offset) / (2.0 * r)).floor() as i64;
        (first..=last).map(move |i| {
            let x = offset + 2.0 * r * i as f64;
            Site {
                layer,
                pos: Point2::new(x, y),
                in_frame: (0.0..=last_x).contains(&x),
            }
        })
    })
}

/// Whether a site's bead may be a lodged transparent one: in the top static layer or two
/// layers below it (a black layer between them, so that every lodged bead lies on two
/// black ones), the beads it lies on inside the frame.
fn lodging(params: &BedloadSceneParams, site: &Site) -> bool {
    let (r, last_x) = (params.black_radius_px, params.width as f64 - 1.0);
    let inside = site.pos.x - r >= 0.0 && site.pos.x + r <= last_x;
    let top = static_layers(params);
    inside && (site.layer + 1 == top || site.layer + 3 == top)
}

/// The centre of a bead of radius `radius` lying on the beads `a` and `b` (centres and
/// radii), touching both: the upper intersection of the circles of the sums of the radii.
fn lying_on(a: (Point2, f64), b: (Point2, f64), radius: f64) -> Point2 {
    let (ra, rb) = (a.1 + radius, b.1 + radius);
    let ab = b.0 - a.0;
    let d = ab.norm();
    let along = (ra * ra - rb * rb + d * d) / (2.0 * d);
    let h = (ra * ra - along * along).max(0.0).sqrt();
    let mid = a.0 + ab * (along / d);
    let normal = Vec2::new(-ab.y, ab.x) * (h / d);
    let (p, q) = (mid + normal, mid - normal);
    if p.y < q.y { p } else { q }
}

/// Number of sites that can hold a lodged transparent bead.
pub(crate) fn lodging_site_count(params: &BedloadSceneParams) -> usize {
    sites(params).filter(|site| lodging(params, site)).count()
}

/// Number of transparent beads lodged in the static bed: `transparent_in_bed` of them,
/// rounded.
pub(crate) fn lodged_count(params: &BedloadSceneParams) -> usize {
    (params.transparent_in_bed * params.n_transparent as f64).round() as usize
}

/// Number of beads of the static bed inside the frame, black and lodged transparent ones.
pub(crate) fn static_bead_count(params: &BedloadSceneParams) -> usize {
    sites(params).filter(|site| site.in_frame).count()
}

/// Number of beads in each creeping layer: as many as fit side by side, in contact or
/// nearly, along the frame's width (its last column excluded: the layer wraps around it).
pub(crate) fn creeping_layer_count(params: &BedloadSceneParams) -> usize {
    let period = params.width as f64 - 1.0;
    ((period / (2.0 * params.black_radius_px)).floor() as usize).max(1)
}

/// Number of black beads of the bed, static and creeping: the rest of `n_black` are mobile.
pub(crate) fn bed_black_count(params: &BedloadSceneParams) -> usize {
    (static_bead_count(params) + params.creeping_layers * creeping_layer_count(params))
        .saturating_sub(lodged_count(params))
}

/// A lower bound of the surface's y for either class (its highest point): the top layer's
/// crests, or the flume floor without a bed. A creeping layer lies at most the black–black
/// contact distance above the one below, which may exceed the lattice's `√3·r`.
pub(crate) fn lowest_surface_y(params: &BedloadSceneParams) -> f64 {
    let r = params.black_radius_px;
    let r_max = r.max(params.transparent_radius_px);
    let contact = params.contact_distance_px(BLACK_BEAD_CLASS, BLACK_BEAD_CLASS);
    let rise = (contact - 3f64.sqrt() * r).max(0.0) * params.creeping_layers as f64;
    match params.bed_layers {
        0 => params.height as f64 - 1.0 - r_max,
        n => {
            let top = params.height as f64 - 1.0 - r - (n - 1) as f64 * 3f64.sqrt() * r;
            top - rise - r - r_max - params.bed_disorder_px
        }
    }
}

/// A point uniform in the disk of `radius` about the origin (rejection from the square:
/// cheaper than a sine and a cosine).
pub(crate) fn disk_offset(rng: &mut RngStream, radius: f64) -> Vec2 {
    if radius == 0.0 {
        return Vec2::ZERO;
    }
    loop {
        let (u, v) = (
            2.0 * rng.random::<f64>() - 1.0,
            2.0 * rng.random::<f64>() - 1.0,
        );
        if u * u + v * v <= 1.0 {
            return Vec2::new(radius * u, radius * v);
        }
    }
}

/// The bed surface for each bead class: the y of the centre of a bead of that class
/// resting on the bed at a given x, i.e. the upper envelope of the circles of the contact
/// distance ([`BedloadSceneParams::contact_distance_px`]) about the bed beads (the flume
/// floor where there is no bed).
/// Tabulated exactly every 0.25 px, linear in between (within 0.1 px of the envelope).
#[derive(Debug, Clone)]
pub(crate) struct BedSurface {
    x0: f64,
    tables: [Vec<f64>; 2],
}

impl BedSurface {
    fn new(params: &BedloadSceneParams, beads: &[(Point2, ObjectClass)]) -> Self {
        let margin = margin_px(params);
        let len = ((params.width as f64 - 1.0 + 2.0 * margin) / SURFACE_STEP_PX).ceil() as usize;
        let tables = [BLACK_BEAD_CLASS, TRANSPARENT_BEAD_CLASS]
            .map(|class| vec![params.height as f64 - 1.0 - params.radius_px(class); len + 1]);
        let mut surface = Self {
            x0: -margin,
            tables,
        };
        for &(bead, class) in beads {
            surface.lay(bead, class, params);
        }
        surface
    }

    /// Raises the surface over a bead of `class` at `bead`: a bead lying on the surface
    /// then touches it or lies higher.
    pub(crate) fn lay(&mut self, bead: Point2, class: ObjectClass, params: &BedloadSceneParams) {
        let x0 = self.x0;
        for (table, other) in self
            .tables
            .iter_mut()
            .zip([BLACK_BEAD_CLASS, TRANSPARENT_BEAD_CLASS])
        {
            let reach = params.contact_distance_px(class, other);
            let first = (((bead.x - reach - x0) / SURFACE_STEP_PX).ceil().max(0.0)) as usize;
            let last = (((bead.x + reach - x0) / SURFACE_STEP_PX).floor()).max(0.0) as usize;
            for (i, y) in table.iter_mut().enumerate().take(last + 1).skip(first) {
                let dx = x0 + i as f64 * SURFACE_STEP_PX - bead.x;
                let top = bead.y - (reach * reach - dx * dx).max(0.0).sqrt();
                *y = y.min(top);
            }
        }
    }

    /// The y of the centre of a bead of `class` resting on the bed at `x` (x beyond the
    /// tabulated span takes the value at its end).
    pub(crate) fn y(&self, x: f64, class: ObjectClass) -> f64 {
        let table = &self.tables[usize::from(class != BLACK_BEAD_CLASS)];
        let t = ((x - self.x0) / SURFACE_STEP_PX).clamp(0.0, (table.len() - 1) as f64);
        let i = (t.floor() as usize).min(table.len() - 2);
        let frac = t - i as f64;
        table[i] + (table[i + 1] - table[i]) * frac
    }
}

/// The static bed: the rest points and classes of its beads inside the frame (bottom layer
/// first, left to right, each off its lattice site by up to `bed_disorder_px`) and its
/// surface.
#[derive(Debug, Clone)]
pub(crate) struct Bed {
    /// Rest points and classes of the bed beads inside the frame.
    pub anchors: Vec<(Point2, ObjectClass)>,
    /// The surface of the static bed.
    pub surface: BedSurface,
}

impl Bed {
    /// The bed of `params`, its disorder and its lodged transparent beads drawn from `rng`.
    /// A lodged transparent bead lies at the bottom of its site, on the two beads below it
    /// at the sum of the radii (on the floor in the bottom layer).
    pub(crate) fn new(params: &BedloadSceneParams, rng: &mut RngStream) -> Self {
        let last = Point2::new(params.width as f64 - 1.0, params.height as f64 - 1.0);
        let (r, rt) = (params.black_radius_px, params.transparent_radius_px);
        let mut all: Vec<(Point2, ObjectClass)> = Vec::new();
        let mut candidates = Vec::new();
        let sites: Vec<Site> = sites(params).collect();
        for site in &sites {
            if lodging(params, site) {
                candidates.push(all.len());
            }
            let pos = site.pos + disk_offset(rng, params.bed_disorder_px);
            all.push((pos, BLACK_BEAD_CLASS));
        }
        let key = |layer: usize, x: f64| (layer, (x / r).round() as i64);
        let index: HashMap<(usize, i64), usize> = sites
            .iter()
            .enumerate()
            .map(|(i, site)| (key(site.layer, site.pos.x), i))
            .collect();
        let neighbour = |i: usize, up: bool, dx: f64| {
            let site = &sites[i];
            let layer = if up {
                site.layer + 1
            } else {
                site.layer.checked_sub(1)?
            };
            index.get(&key(layer, site.pos.x + dx)).copied()
        };
        // A partial Fisher–Yates shuffle picks the lodged sites.
        let lodged = lodged_count(params).min(candidates.len());
        for k in 0..lodged {
            let pick = k + rng.random_range(0..candidates.len() - k);
            candidates.swap(k, pick);
            all[candidates[k]].1 = TRANSPARENT_BEAD_CLASS;
        }
        let mut lodged_sites = candidates[..lodged].to_vec();
        // Each lodged bead lies on the two beads below its site, bottom layer first.
        lodged_sites.sort_unstable();
        let bead = |(pos, class): (Point2, ObjectClass)| (pos, params.radius_px(class));
        for i in lodged_sites {
            let below = [-r, r].map(|dx| neighbour(i, false, dx));
            all[i].0 = match below {
                [Some(a), Some(b)] => lying_on(bead(all[a]), bead(all[b]), rt),
                _ => Point2::new(all[i].0.x, sites[i].pos.y + r - rt),
            };
        }
        let anchors = sites
            .iter()
            .zip(&all)
            .filter(|(site, _)| site.in_frame)
            .map(|(_, &(pos, class))| {
                let pos = Point2::new(pos.x.clamp(0.0, last.x), pos.y.clamp(0.0, last.y));
                (pos, class)
            })
            .collect();
        let surface = BedSurface::new(params, &all);
        Self { anchors, surface }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sillage_core::rng_stream;

    #[test]
    fn the_surface_touches_the_bed_without_overlapping_it() {
        let params = BedloadSceneParams::default();
        let mut rng = rng_stream(1, 0);
        let all: Vec<(Point2, ObjectClass)> = sites(&params)
            .map(|site| {
                let pos = site.pos + disk_offset(&mut rng, params.bed_disorder_px);
                (pos, BLACK_BEAD_CLASS)
            })
            .collect();
        let surface = BedSurface::new(&params, &all);
        for class in [BLACK_BEAD_CLASS, TRANSPARENT_BEAD_CLASS] {
            let reach = params.contact_distance_px(BLACK_BEAD_CLASS, class);
            for step in 0..=(1279 * 7) {
                let x = step as f64 / 7.0;
                let centre = Point2::new(x, surface.y(x, class));
                let gap = all
                    .iter()
                    .map(|(bead, _)| bead.distance(centre) - reach)
                    .fold(f64::INFINITY, f64::min);
                // In contact (the nearest bed bead at the contact distance) within the
                // linear interpolation's error; never sunk into the bed by more than it.
                assert!(gap.abs() < 0.1, "x = {x}: gap {gap}");
            }
        }
    }

    #[test]
    fn no_bed_means_the_floor() {
        let params = BedloadSceneParams {
            bed_layers: 0,
            ..Default::default()
        };
        let bed = Bed::new(&params, &mut rng_stream(0, 0));
        assert!(bed.anchors.is_empty());
        assert_eq!(bed.surface.y(100.0, TRANSPARENT_BEAD_CLASS), 309.0);
        assert_eq!(bed.surface.y(-1e9, BLACK_BEAD_CLASS), 304.0);
    }
}

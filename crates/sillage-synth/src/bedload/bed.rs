//! The static bed: hexagonal layers of black beads in contact at the bottom of the frame,
//! and the surface on which the mobile beads rest, roll and land.

use rand::RngExt;
use sillage_core::{
    BLACK_BEAD_CLASS, ObjectClass, Point2, RngStream, TRANSPARENT_BEAD_CLASS, Vec2,
};

use super::BedloadSceneParams;

/// Sampling step of the surface tables, px.
const SURFACE_STEP_PX: f64 = 0.25;

/// One lattice site of the bed: its position before disorder, and whether its bead is in
/// the frame (sites beyond the left and right edges only shape the surface).
#[derive(Debug, Clone, Copy)]
struct Site {
    pos: Point2,
    in_frame: bool,
}

/// How far the bed extends beyond the left and right edges, px: far enough that the
/// surface near the edges is that of an unbroken bed.
fn margin_px(params: &BedloadSceneParams) -> f64 {
    let r_max = params.black_radius_px.max(params.transparent_radius_px);
    4.0 * params.black_radius_px + 2.0 * r_max
}

/// The lattice sites, bottom layer first, left to right: layer `j` has its centres at
/// `y = height − 1 − r − j·√3·r` (the bottom layer on the frame's last row), spaced `2r`,
/// odd layers shifted by `r`, so that every bead touches its six neighbours.
fn sites(params: &BedloadSceneParams) -> impl Iterator<Item = Site> + '_ {
    let r = params.black_radius_px;
    let last_x = params.width as f64 - 1.0;
    let margin = margin_px(params);
    (0..params.bed_layers).flat_map(move |layer| {
        let y = params.height as f64 - 1.0 - r - layer as f64 * 3f64.sqrt() * r;
        let offset = if layer % 2 == 0 { r } else { 0.0 };
        let first = ((-margin - offset) / (2.0 * r)).ceil() as i64;
        let last = ((last_x + margin - offset) / (2.0 * r)).floor() as i64;
        (first..=last).map(move |i| {
            let x = offset + 2.0 * r * i as f64;
            Site {
                pos: Point2::new(x, y),
                in_frame: (0.0..=last_x).contains(&x),
            }
        })
    })
}

/// Number of bed beads inside the frame: all resting black beads of `bed_layers` layers.
pub(crate) fn bed_bead_count(params: &BedloadSceneParams) -> usize {
    sites(params).filter(|site| site.in_frame).count()
}

/// A lower bound of the surface's y for either class (its highest point): the top layer's
/// crests, or the flume floor without a bed.
pub(crate) fn lowest_surface_y(params: &BedloadSceneParams) -> f64 {
    let r = params.black_radius_px;
    let r_max = r.max(params.transparent_radius_px);
    match params.bed_layers {
        0 => params.height as f64 - 1.0 - r_max,
        n => {
            let top = params.height as f64 - 1.0 - r - (n - 1) as f64 * 3f64.sqrt() * r;
            top - r - r_max - params.bed_disorder_px
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
    fn new(params: &BedloadSceneParams, beads: &[Point2]) -> Self {
        let margin = margin_px(params);
        let len = ((params.width as f64 - 1.0 + 2.0 * margin) / SURFACE_STEP_PX).ceil() as usize;
        let tables = [BLACK_BEAD_CLASS, TRANSPARENT_BEAD_CLASS]
            .map(|class| vec![params.height as f64 - 1.0 - params.radius_px(class); len + 1]);
        let mut surface = Self {
            x0: -margin,
            tables,
        };
        for &bead in beads {
            surface.lay(bead, BLACK_BEAD_CLASS, params);
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

/// The static bed: the rest points of the in-frame bed beads (bottom layer first, left to
/// right, each off its lattice site by up to `bed_disorder_px`) and the surface.
#[derive(Debug, Clone)]
pub(crate) struct Bed {
    /// Rest points of the bed beads inside the frame.
    pub anchors: Vec<Point2>,
    /// The surface the mobile beads move on.
    pub surface: BedSurface,
}

impl Bed {
    /// The bed of `params`, its disorder drawn from `rng`.
    pub(crate) fn new(params: &BedloadSceneParams, rng: &mut RngStream) -> Self {
        let last = Point2::new(params.width as f64 - 1.0, params.height as f64 - 1.0);
        let mut all = Vec::new();
        let mut anchors = Vec::new();
        for site in sites(params) {
            let pos = site.pos + disk_offset(rng, params.bed_disorder_px);
            all.push(pos);
            if site.in_frame {
                anchors.push(Point2::new(
                    pos.x.clamp(0.0, last.x),
                    pos.y.clamp(0.0, last.y),
                ));
            }
        }
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
        let all: Vec<Point2> = sites(&params)
            .map(|site| site.pos + disk_offset(&mut rng, params.bed_disorder_px))
            .collect();
        let surface = BedSurface::new(&params, &all);
        for class in [BLACK_BEAD_CLASS, TRANSPARENT_BEAD_CLASS] {
            let reach = params.contact_distance_px(BLACK_BEAD_CLASS, class);
            for step in 0..=(1279 * 7) {
                let x = step as f64 / 7.0;
                let centre = Point2::new(x, surface.y(x, class));
                let gap = all
                    .iter()
                    .map(|bead| bead.distance(centre) - reach)
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

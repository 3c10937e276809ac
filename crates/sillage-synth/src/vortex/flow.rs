//! The particle positions of the vortex flow, advanced frame by frame without any image
//! (TracTrac paper §4.1.1, Eqs. 13-16).

use std::f64::consts::PI;

use rand::RngExt;
use rand_distr::StandardNormal;
use sillage_core::{Error, FrameIndex, Point2, Result, RngStream, TrackId, Vec2, rng_stream};

use super::{FlowField, VortexParams};

/// The deterministic map of Eqs. 13-16 (ξ = 0) for frame index `n` and time step `delta`:
/// `c` is a position relative to the image centre, the result is its position one frame on.
///
/// Eqs. 13-14 rotate `c` about the centre (r kept, θ advanced by the two Gaussian vortices);
/// Eqs. 15-16 then shear the rotated point `(x, y)`, both right-hand sides using that same
/// rotated point. Axes are the image axes (`y` down), which mirrors the paper's plots.
pub fn vortex_map(c: Vec2, n: FrameIndex, delta: f64) -> Vec2 {
    let n = n as f64;
    let r = c.norm();
    let theta = c.y.atan2(c.x)
        + 4.0 * delta * (n * PI / 50.0).cos() * (-0.5 * (r / 80.0).powi(2)).exp()
        - 10.0 * delta * (n * PI / 25.0).cos() * (-0.5 * (r / 50.0).powi(2)).exp();
    let (x, y) = (r * theta.cos(), r * theta.sin());
    Vec2::new(x + 2.0 * delta * (PI * n / 100.0).sin() * y, y + delta * x)
}

/// The particles of the vortex flow: positions and identities, advanced one frame at a time.
///
/// Each particle lives in a slot; a slot keeps its identity from frame to frame unless the
/// particle leaves the image (periodic boundaries: it re-enters on the other side as a NEW
/// identity, so that every identity moves continuously) or is re-seeded by intermittency
/// (a new identity at a uniformly random position). Each identity draws from its own stream
/// `rng_stream(seed, track_id)`.
#[derive(Debug, Clone)]
pub struct VortexFlow {
    params: VortexParams,
    field: FlowField,
    frame: FrameIndex,
    ids: Vec<TrackId>,
    positions: Vec<Point2>,
    rngs: Vec<RngStream>,
    next_id: TrackId,
}

impl VortexFlow {
    /// Frame 0 of the flow: `params.n_particles` identities `0..N` at uniformly random
    /// positions over the image.
    pub fn new(params: &VortexParams) -> Result<Self> {
        params.validate()?;
        let mut flow = Self::empty(params.clone());
        for _ in 0..params.n_particles {
            let (id, mut rng) = flow.new_identity();
            let position = flow.random_position(&mut rng);
            flow.push(id, position, rng);
        }
        Ok(flow)
    }

    /// Frame 0 of the flow with particles at the given positions (identities `0..len`), for
    /// tests that need to place particles; `params.n_particles` is ignored.
    pub fn with_positions(params: &VortexParams, positions: &[Point2]) -> Result<Self> {
        params.validate()?;
        let mut flow = Self::empty(params.clone());
        for (index, &position) in positions.iter().enumerate() {
            if !flow.inside(position) {
                return Err(Error::input(format!(
                    "particle {index} at ({}, {}) is not inside the {}×{} image",
                    position.x, position.y, params.width, params.height
                )));
            }
            let (id, rng) = flow.new_identity();
            flow.push(id, position, rng);
        }
        Ok(flow)
    }

    fn empty(params: VortexParams) -> Self {
        let field = FlowField::new(
            params.flow,
            params.width,
            params.height,
            params.delta,
            params.max_displacement_px,
            params.seed,
        );
        Self {
            params,
            field,
            frame: 0,
            ids: Vec::new(),
            positions: Vec::new(),
            rngs: Vec::new(),
            next_id: 0,
        }
    }

    /// The index of the frame the positions belong to.
    pub fn frame(&self) -> FrameIndex {
        self.frame
    }

    /// Identity of the particle in each slot.
    pub fn track_ids(&self) -> &[TrackId] {
        &self.ids
    }

    /// Position of the particle in each slot, px.
    pub fn positions(&self) -> &[Point2] {
        &self.positions
    }

    /// The parameters the flow runs with.
    pub fn params(&self) -> &VortexParams {
        &self.params
    }

    /// Moves every particle to the next frame: the flow's map (Eqs. 13-16 for the paper's
    /// vortex) with ξ = `brownian` × the local
    /// deterministic displacement magnitude × N(0, 1) per axis, then the periodic boundary,
    /// then intermittency.
    pub fn advance(&mut self) {
        let centre = self.centre();
        for slot in 0..self.ids.len() {
            let c = self.positions[slot] - centre;
            let deterministic = self.field.map(c, self.frame);
            let rng = &mut self.rngs[slot];
            let xi = if self.params.brownian > 0.0 {
                let scale = self.params.brownian * (deterministic - c).norm();
                Vec2::new(rng.sample(StandardNormal), rng.sample(StandardNormal)) * scale
            } else {
                Vec2::ZERO
            };
            let reseeded =
                self.params.intermittency > 0.0 && rng.random::<f64>() < self.params.intermittency;
            let moved = Point2::new(centre.x, centre.y) + deterministic + xi;
            if reseeded || !self.inside(moved) {
                let (id, mut rng) = self.new_identity();
                self.positions[slot] = if reseeded {
                    self.random_position(&mut rng)
                } else {
                    self.wrap(moved)
                };
                self.ids[slot] = id;
                self.rngs[slot] = rng;
            } else {
                self.positions[slot] = moved;
            }
        }
        self.frame += 1;
    }

    /// The image centre in pixel coordinates, origin of Eqs. 13-16.
    fn centre(&self) -> Point2 {
        Point2::new(
            (self.params.width as f64 - 1.0) / 2.0,
            (self.params.height as f64 - 1.0) / 2.0,
        )
    }

    /// True when `p` lies in the image's area `[−0.5, W − 0.5) × [−0.5, H − 0.5)`.
    fn inside(&self, p: Point2) -> bool {
        let (w, h) = (self.params.width as f64, self.params.height as f64);
        (-0.5..w - 0.5).contains(&p.x) && (-0.5..h - 0.5).contains(&p.y)
    }

    /// `p` brought back into the image area by periodic boundaries.
    fn wrap(&self, p: Point2) -> Point2 {
        Point2::new(
            wrap_coordinate(p.x, self.params.width as f64),
            wrap_coordinate(p.y, self.params.height as f64),
        )
    }

    fn random_position(&self, rng: &mut RngStream) -> Point2 {
        let (w, h) = (self.params.width as f64, self.params.height as f64);
        Point2::new(
            rng.random_range(-0.5..w - 0.5),
            rng.random_range(-0.5..h - 0.5),
        )
    }

    fn new_identity(&mut self) -> (TrackId, RngStream) {
        let id = self.next_id;
        self.next_id += 1;
        (id, rng_stream(self.params.seed, id))
    }

    fn push(&mut self, id: TrackId, position: Point2, rng: RngStream) {
        self.ids.push(id);
        self.positions.push(position);
        self.rngs.push(rng);
    }
}

/// `value` brought into `[−0.5, len − 0.5)` modulo `len`.
fn wrap_coordinate(value: f64, len: f64) -> f64 {
    let wrapped = (value + 0.5).rem_euclid(len);
    // rem_euclid may round up to `len` itself.
    if wrapped >= len { -0.5 } else { wrapped - 0.5 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn far_from_the_vortices_frame_zero_is_a_pure_shear_along_y() {
        // n = 0: sin(0) = 0, so Eq. 15 leaves x; the vortex terms are < 1e-4 px at r = 400.
        let moved = vortex_map(Vec2::new(400.0, 0.0), 0, 0.01);
        assert!((moved.x - 400.0).abs() < 1e-4, "{moved:?}");
        assert!((moved.y - 4.0).abs() < 1e-4, "{moved:?}");
    }

    #[test]
    fn matches_eqs_13_to_16_at_n_50() {
        // r = 50 on the x axis, n = 50: cos(π) = -1, cos(2π) = 1, sin(π/2) = 1, so
        // θ = -0.04 e^{-0.5 (50/80)²} - 0.1 e^{-0.5} = -0.0935576...; x' = 50 cos θ,
        // y' = 50 sin θ; x'' = x' + 0.02 y', y'' = y' + 0.01 x' (values from a calculator).
        let moved = vortex_map(Vec2::new(50.0, 0.0), 50, 0.01);
        assert!((moved.x - 49.687_920_893_591_226).abs() < 1e-9, "{moved:?}");
        assert!((moved.y - -4.173_174_049_593_876).abs() < 1e-9, "{moved:?}");
    }

    #[test]
    fn wrap_stays_in_the_image_area() {
        assert_eq!(wrap_coordinate(10.0, 8.0), 2.0);
        assert_eq!(wrap_coordinate(-0.75, 8.0), 7.25);
        assert_eq!(wrap_coordinate(7.5, 8.0), -0.5);
    }
}

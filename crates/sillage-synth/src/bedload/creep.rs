//! The creeping layers: the top `creeping_layers` layers of the deposit slip downstream
//! over the static bed, each over the one below it, in stop-and-go spells, as the real
//! sequence's top 2–3 bead layers do (its rolling beads, a third of the black ones, creep
//! at about 1 px/frame; MMPF+ §4.2). Each layer is a row of black beads spaced evenly
//! along the frame, lying on the surface below it (the static bed for the lowest, the
//! layer below for the others), so that it rises and sinks over the beads it passes. A
//! layer wraps around the frame: a bead leaving downstream comes back upstream as a new
//! identity, so the counts stay constant.
//!
//! A layer starts and stops slipping with the probabilities `creep_switching` (by default
//! stopping as a rolling bead does in Eq. (11), slipping 63 % of the time), at a speed drawn at each start from `creep_speed_px_per_frame` and scaled by its rank
//! (`k/n` for the layer `k` of `n` from the bottom); it is carried by the layers below, so
//! the upper layers move more often and faster, as in the real sequence.

use sillage_core::{BLACK_BEAD_CLASS, MotionState, Point2, RngStream, TrackId};

use super::BedloadSceneParams;
use super::bed::{BedSurface, creeping_layer_count};
use super::motion::uniform;
use rand::RngExt;

/// One creeping layer.
#[derive(Debug, Clone)]
struct Layer {
    /// The x of its first bead, modulo the period, px.
    phase: f64,
    /// Whether it slips over the layer below.
    slipping: bool,
    /// Its speed over the layer below while slipping, px/frame.
    speed: f64,
    /// Its displacement along x in the last frame, px (downstream, never negative).
    shift: f64,
    /// Identity and centre of each bead.
    beads: Vec<(TrackId, Point2)>,
}

/// The creeping layers and the surface of the deposit (the static bed and the layers), on
/// which the mobile beads lie.
#[derive(Debug, Clone)]
pub(crate) struct Creep {
    period: f64,
    spacing: f64,
    layers: Vec<Layer>,
    surface: BedSurface,
}

impl Creep {
    /// The layers of `params` on the static bed `bed`, their phases and states drawn from
    /// `rng` (slipping with the chain's stationary probability, at the speed of a spell),
    /// identities from `next_id`.
    pub(crate) fn new(
        params: &BedloadSceneParams,
        bed: &BedSurface,
        rng: &mut RngStream,
        next_id: &mut TrackId,
    ) -> Self {
        let period = params.width as f64 - 1.0;
        let n = creeping_layer_count(params);
        let (start, stop) = switching(params);
        let moving = if start + stop > 0.0 {
            start / (start + stop)
        } else {
            0.0
        };
        let layers = (0..params.creeping_layers)
            .map(|k| Layer {
                phase: period * rng.random::<f64>(),
                slipping: rng.random::<f64>() < moving,
                speed: spell_speed(params, k, rng),
                shift: 0.0,
                beads: (0..n)
                    .map(|_| {
                        *next_id += 1;
                        (*next_id - 1, Point2::new(0.0, 0.0))
                    })
                    .collect(),
            })
            .collect();
        let mut creep = Self {
            period,
            spacing: period / n as f64,
            layers,
            surface: bed.clone(),
        };
        creep.place(params, bed, None);
        creep
    }

    /// Number of beads in all the layers.
    pub(crate) fn len(&self) -> usize {
        self.layers.iter().map(|layer| layer.beads.len()).sum()
    }

    /// The surface of the deposit: the static bed and the creeping layers as they are now.
    pub(crate) fn surface(&self) -> &BedSurface {
        &self.surface
    }

    /// The top layer's displacement along x in the last frame, signed (0 without layers):
    /// what it carries the beads lying on it by.
    pub(crate) fn top_shift(&self, params: &BedloadSceneParams) -> f64 {
        self.layers.last().map_or(0.0, |layer| layer.shift) * f64::from(params.flow_direction)
    }

    /// Every bead of the layers, bottom layer first: identity, centre, and its state in
    /// the last frame (rolling where its layer moved, resting else).
    pub(crate) fn beads(&self) -> impl Iterator<Item = (TrackId, Point2, MotionState)> + '_ {
        self.layers.iter().flat_map(|layer| {
            let state = if layer.shift > 0.0 {
                MotionState::Rolling
            } else {
                MotionState::Resting
            };
            layer.beads.iter().map(move |&(id, pos)| (id, pos, state))
        })
    }

    /// One frame: each layer switches between slipping and stopped, moves by its slip and
    /// that of the layers below, and lies on the surface below; a bead that wrapped around
    /// the frame takes a new identity from `next_id`.
    pub(crate) fn advance(
        &mut self,
        params: &BedloadSceneParams,
        bed: &BedSurface,
        rng: &mut RngStream,
        next_id: &mut TrackId,
    ) {
        let (start, stop) = switching(params);
        let mut carried = 0.0;
        for (k, layer) in self.layers.iter_mut().enumerate() {
            let u = rng.random::<f64>();
            if layer.slipping {
                layer.slipping = u >= stop;
            } else if u < start {
                layer.slipping = true;
                layer.speed = spell_speed(params, k, rng);
            }
            carried += if layer.slipping { layer.speed } else { 0.0 };
            layer.shift = carried;
            let step = f64::from(params.flow_direction) * carried;
            layer.phase = (layer.phase + step).rem_euclid(self.period);
        }
        self.place(params, bed, Some(next_id));
    }

    /// Lays the layers, bottom first, on the surface below each, and makes the deposit's
    /// surface. With `next_id`, a bead whose x went upstream (it wrapped around the frame)
    /// takes a new identity.
    fn place(
        &mut self,
        params: &BedloadSceneParams,
        bed: &BedSurface,
        mut next_id: Option<&mut TrackId>,
    ) {
        let direction = f64::from(params.flow_direction);
        self.surface.clone_from(bed);
        for layer in &mut self.layers {
            for (j, bead) in layer.beads.iter_mut().enumerate() {
                let x = (layer.phase + j as f64 * self.spacing).rem_euclid(self.period);
                if let Some(next_id) = next_id.as_deref_mut()
                    && direction * (x - bead.1.x) < 0.0
                {
                    bead.0 = *next_id;
                    *next_id += 1;
                }
                bead.1 = Point2::new(x, self.surface.y(x, BLACK_BEAD_CLASS).max(0.0));
            }
            // The layer, with its images a period away at both ends, under the next.
            for &(_, pos) in &layer.beads {
                for image in [-self.period, 0.0, self.period] {
                    let at = Point2::new(pos.x + image, pos.y);
                    self.surface.lay(at, BLACK_BEAD_CLASS, params);
                }
            }
        }
    }
}

/// The slip speed of a moving spell of layer `k` (0 at the bottom), px/frame.
fn spell_speed(params: &BedloadSceneParams, k: usize, rng: &mut RngStream) -> f64 {
    let scale = (k + 1) as f64 / params.creeping_layers as f64;
    scale * uniform(rng, params.creep_speed_px_per_frame)
}

/// The probabilities that a stopped layer starts slipping and that a slipping one stops,
/// per frame (`creep_switching`).
fn switching(params: &BedloadSceneParams) -> (f64, f64) {
    let [start, stop] = params.creep_switching;
    (start, stop)
}

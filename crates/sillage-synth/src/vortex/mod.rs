//! The synthetic vortex flow of the TracTrac paper (§4.1, Eqs. 13-16): positions, truth,
//! rendered frames, and the flow's displacement statistics.

mod fields;
mod flow;
mod params;
mod sequence;
mod truth;

pub use fields::{FlowField, FlowKind};
pub use flow::{VortexFlow, vortex_map};
pub use params::VortexParams;
pub use sequence::{SyntheticFrame, VortexSequence};
pub use truth::{TruthFrame, VortexTruth};

use serde::Serialize;
use sillage_core::Result;

/// The inverse particle-spacing ratio `p⁻¹ = v̄ · sqrt(N / S)` of Fig. 4: mean displacement
/// (px/frame) over the mean distance between neighbours, for `n_objects` in `area_px2`.
/// PTV is hard above 1; TracTrac keeps < 6 % false recoveries at p⁻¹ ≈ 4.5 (§4.1.2).
pub fn p_inverse(mean_displacement_px: f64, n_objects: usize, area_px2: f64) -> f64 {
    mean_displacement_px * (n_objects as f64 / area_px2).sqrt()
}

/// Statistics of the true displacement magnitudes |v| (px/frame) over a sequence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DisplacementStats {
    /// Smallest |v|.
    pub min_px: f64,
    /// Mean |v|: the v̄ of Fig. 4.
    pub mean_px: f64,
    /// Largest |v|.
    pub max_px: f64,
    /// Number of truth points with a velocity the statistics cover (0: all fields are 0).
    pub count: usize,
    /// `p⁻¹` of the sequence: `mean_px · sqrt(N / (width · height))`.
    pub p_inverse: f64,
}

/// The displacement statistics of the sequence `params` describe (positions only, no
/// rendering), from the truth velocities of all its frames; use it to tune δ or N to a
/// target `p⁻¹`.
pub fn displacement_stats(params: &VortexParams) -> Result<DisplacementStats> {
    let (mut min_px, mut max_px, mut sum, mut count) = (f64::INFINITY, 0.0f64, 0.0, 0usize);
    for frame in VortexTruth::new(params)? {
        for speed in frame
            .truth
            .iter()
            .filter_map(|p| p.vel_px_per_frame.map(|v| v.norm()))
        {
            min_px = min_px.min(speed);
            max_px = max_px.max(speed);
            sum += speed;
            count += 1;
        }
    }
    if count == 0 {
        min_px = 0.0;
    }
    let mean_px = if count == 0 { 0.0 } else { sum / count as f64 };
    let area = (params.width * params.height) as f64;
    Ok(DisplacementStats {
        min_px,
        mean_px,
        max_px,
        count,
        p_inverse: p_inverse(mean_px, params.n_particles, area),
    })
}

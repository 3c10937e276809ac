//! `sillage bench ptv-accuracy`: PTV accuracy over a family of synthetic flows the defaults
//! were not chosen on, against the best of a grid search per case.
//!
//! The family crosses six flows (the paper's vortex, a Lamb–Oseen pair, a stagnation point, a
//! shear layer, a cellular array, Fourier-mode turbulence) with particle images of σ 0.7–3 px,
//! seeding densities 0.001–0.05 particles per pixel, displacements 0.5–10 px per frame, two
//! noise levels and intermittent particles in some cases: four cases per flow, each level of
//! each factor once per flow (a Latin arrangement). Cases alternate between the **tune** half
//! (where defaults may be chosen) and the **report** half (where they are only measured).

use std::path::PathBuf;

use serde::Serialize;
use sillage_core::{Result, TrackPoint, TruthPoint};
use sillage_detect::blob::{PolarityChoice, Scale};
use sillage_detect::{Polarity, Threshold, measure_particle_images};
use sillage_eval::ptv::{PtvAccuracy, PtvAccuracyParams, ptv_accuracy};
use sillage_io::Frame;
use sillage_synth::vortex::{FlowKind, VortexParams, VortexSequence};
use sillage_track::ptv::VoteSearch;

use crate::config::{DetectorConfig, PipelineConfig, TrackerConfig};
use crate::pipeline::Pipeline;

/// Particle image σ levels, px.
pub const SIGMA_LEVELS_PX: [f64; 4] = [0.7, 1.2, 2.0, 3.0];
/// Seeding density levels, particles per pixel.
pub const DENSITY_LEVELS_PPP: [f64; 4] = [0.001, 0.005, 0.02, 0.05];
/// Largest-displacement levels, px per frame.
pub const DISPLACEMENT_LEVELS_PX: [f64; 4] = [0.5, 2.0, 5.0, 10.0];
/// Signal-to-noise levels (peak over uniform-noise magnitude).
pub const SNR_LEVELS: [f64; 2] = [4.0, 12.0];

/// Seed of every case of [`family`].
pub const FAMILY_SEED: u64 = 11;

/// Which half of the family a case belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Half {
    /// Cases defaults may be chosen on.
    Tune,
    /// Cases defaults are only reported on.
    Report,
}

/// One case of the family.
#[derive(Debug, Clone, Serialize)]
pub struct FamilyCase {
    /// A short name: flow and index.
    pub name: String,
    /// Which half it is in.
    pub half: Half,
    /// The flow.
    pub flow: FlowKind,
    /// Smallest particle image σ, px (each particle's σ is drawn up to 1.25 times this).
    pub sigma_px: f64,
    /// Particles per pixel.
    pub density_ppp: f64,
    /// Largest displacement, px per frame.
    pub max_displacement_px: f64,
    /// Peak over noise magnitude.
    pub snr: f64,
    /// Probability per particle and frame of re-appearing elsewhere.
    pub intermittency: f64,
    /// Seed of the particles' positions, sizes and noise.
    pub seed: u64,
}

/// The family: six flows × four cases, alternately in the tune and the report half.
pub fn family() -> Vec<FamilyCase> {
    let mut cases = Vec::new();
    for (f, &flow) in FlowKind::ALL.iter().enumerate() {
        for j in 0..4 {
            let index = cases.len();
            cases.push(FamilyCase {
                name: format!("{}-{j}", flow.name()),
                half: if index % 2 == 0 {
                    Half::Tune
                } else {
                    Half::Report
                },
                flow,
                sigma_px: SIGMA_LEVELS_PX[(j + f) % 4],
                density_ppp: DENSITY_LEVELS_PPP[(j + 2 * f + f / 2) % 4],
                max_displacement_px: DISPLACEMENT_LEVELS_PX[(3 * j + f) % 4],
                snr: SNR_LEVELS[(j + f / 2) % 2],
                intermittency: if (j + f) % 3 == 0 { 0.02 } else { 0.0 },
                seed: FAMILY_SEED,
            });
        }
    }
    cases
}

/// Largest displacements, as shares of the mean particle spacing, of [`moderate_family`].
pub const MODERATE_SPACING_SHARES: [f64; 4] = [0.3, 0.4, 0.5, 0.6];

/// A second family where the displacements are 0.3–0.6 of the particles' mean spacing, the
/// range where nearest neighbours from rest start to fail and the automatic first-link vote
/// decides how the run starts (few cases of [`family`] fall there): six flows × eight cases,
/// σ 1–2 px, 0.003–0.008 particles per pixel, both noise levels, each case with its own seed,
/// alternately in the tune and the report half.
pub fn moderate_family() -> Vec<FamilyCase> {
    let mut cases = Vec::new();
    for (f, &flow) in FlowKind::ALL.iter().enumerate() {
        for j in 0..8 {
            let density_ppp = [0.003, 0.005, 0.008][(j + 2 * f) % 3];
            let share = MODERATE_SPACING_SHARES[(j / 2 + f) % 4];
            cases.push(FamilyCase {
                name: format!("{}-m{j}", flow.name()),
                half: if j % 2 == 0 { Half::Tune } else { Half::Report },
                flow,
                sigma_px: [1.0, 1.5, 2.0, 1.2][(j + f) % 4],
                density_ppp,
                max_displacement_px: share / density_ppp.sqrt(),
                snr: SNR_LEVELS[(j / 2 + f) % 2],
                intermittency: if (j + f) % 4 == 0 { 0.02 } else { 0.0 },
                seed: 100 + (8 * f + j) as u64,
            });
        }
    }
    cases
}

impl FamilyCase {
    /// The synthetic sequence of this case on `size`² frames, `frames` long.
    pub fn params(&self, size: usize, frames: usize) -> VortexParams {
        VortexParams {
            width: size,
            height: size,
            n_particles: (self.density_ppp * (size * size) as f64).round() as usize,
            n_frames: frames,
            flow: self.flow,
            // The paper's vortex moves ~5 px per frame at δ = 0.01 on 1024² frames.
            delta: 0.002 * self.max_displacement_px,
            max_displacement_px: self.max_displacement_px,
            blob_sigma_px: self.sigma_px,
            blob_sigma_max_px: Some(1.25 * self.sigma_px),
            snr: self.snr,
            intermittency: self.intermittency,
            seed: self.seed,
            ..VortexParams::default()
        }
    }
}

/// The rendered frames and truth of one case, kept in memory to run many settings on.
pub struct CaseData {
    frames: Vec<Frame>,
    truth: Vec<TruthPoint>,
}

impl CaseData {
    /// Renders `case` on `size`² frames, `frames` long.
    pub fn render(case: &FamilyCase, size: usize, frames: usize) -> Result<Self> {
        let mut truth = Vec::new();
        let frames = VortexSequence::new(case.params(size, frames))?
            .map(|f| {
                truth.extend_from_slice(&f.truth);
                Frame {
                    index: f.index,
                    path: PathBuf::from(format!("{}:{}", case.name, f.index)),
                    image: f.image,
                    colour: None,
                }
            })
            .collect();
        Ok(Self { frames, truth })
    }

    /// The accuracy of `config` on this case.
    pub fn score(&self, config: &PipelineConfig) -> Result<PtvAccuracy> {
        let mut tracks: Vec<TrackPoint> = Vec::new();
        Pipeline::from_config(config)?.run(
            self.frames.iter().cloned().map(Ok),
            &mut tracks,
            &mut |_| {},
        )?;
        ptv_accuracy(&self.truth, &tracks, &PtvAccuracyParams::default())
    }

    /// The σ of the particle images measured on the first frame, px, with their polarity.
    pub fn measured_sigma(&self) -> Result<(f64, Polarity)> {
        let m = measure_particle_images(&self.frames[0].image)?;
        Ok((m.sigma_px, m.polarity))
    }

    /// The source density measured on the first frame (`ParticleImages::source_density`).
    pub fn measured_source_density(&self) -> Result<f64> {
        Ok(measure_particle_images(&self.frames[0].image)?.source_density)
    }
}

/// One setting of the grid search: the main keys.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GridSetting {
    /// `detector.scale_px`, px.
    pub scale_px: f64,
    /// `detector.threshold.noise.k`.
    pub noise_k: f64,
    /// `tracker.filter_std`.
    pub filter_std: f64,
    /// `tracker.vote_search_px` (none: off).
    pub vote_search_px: Option<f64>,
}

impl GridSetting {
    /// The configuration of this setting (bright particles, as the family renders them).
    pub fn config(&self) -> PipelineConfig {
        let mut config = PipelineConfig::default();
        if let DetectorConfig::Blob(blob) = &mut config.detector {
            blob.scale_px = Scale::Px(self.scale_px);
            blob.polarity = PolarityChoice::Bright;
            blob.threshold = Threshold::Noise { k: self.noise_k };
        }
        if let TrackerConfig::Ptv(ptv) = &mut config.tracker {
            ptv.filter_std = self.filter_std;
            ptv.vote_search_px = self.vote_search_px.map_or(VoteSearch::OFF, VoteSearch::Px);
        }
        config
    }
}

/// The grid searched for the per-case "tuned" result: scale 0.7–3.5 px × threshold k 3, 4, 6 ×
/// `filter_std` 1.5, 3 × voting off or over twice the case's largest displacement.
pub fn grid(case: &FamilyCase) -> Vec<GridSetting> {
    let mut settings = Vec::new();
    for scale_px in [0.7, 1.0, 1.5, 2.0, 2.5, 3.5] {
        for noise_k in [3.0, 4.0, 6.0] {
            for filter_std in [1.5, 3.0] {
                for vote in [false, true] {
                    settings.push(GridSetting {
                        scale_px,
                        noise_k,
                        filter_std,
                        vote_search_px: vote.then_some(2.0 * case.max_displacement_px + 2.0),
                    });
                }
            }
        }
    }
    settings
}

/// True and false recovery rates of a run, %.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Recoveries {
    /// True recoveries, % of the true points with a velocity.
    pub true_pct: f64,
    /// False recoveries, % of the estimated points.
    pub false_pct: f64,
    /// Mean position error of the true recoveries, px.
    pub position_error_px: Option<f64>,
    /// Mean displacement error of the true recoveries, px per frame.
    pub displacement_error_px: Option<f64>,
}

impl From<&PtvAccuracy> for Recoveries {
    fn from(a: &PtvAccuracy) -> Self {
        Self {
            true_pct: 100.0 * a.true_recovery_rate.unwrap_or(0.0),
            false_pct: 100.0 * a.false_recovery_rate.unwrap_or(0.0),
            position_error_px: a.mean_position_error_px,
            displacement_error_px: a.mean_displacement_error_px,
        }
    }
}

impl Recoveries {
    /// What the grid search maximises: true minus false recoveries.
    pub fn merit(&self) -> f64 {
        self.true_pct - self.false_pct
    }

    /// The bar: a true recovery within [`NEAR_TUNED_POINTS`] of `tuned`'s.
    pub fn near(&self, tuned: &Recoveries) -> bool {
        self.true_pct >= tuned.true_pct - NEAR_TUNED_POINTS
    }
}

/// How far below the per-case tuned true recovery the defaults may stay, points of %.
pub const NEAR_TUNED_POINTS: f64 = 2.0;

/// One row of the table.
#[derive(Debug, Clone, Serialize)]
pub struct FamilyRow {
    /// The case.
    pub case: FamilyCase,
    /// Particles in the frame.
    pub particles: usize,
    /// The particle σ measured on the first frame, px.
    pub measured_sigma_px: Option<f64>,
    /// The source density measured on the first frame.
    pub measured_source_density: Option<f64>,
    /// The defaults (scale and polarity measured).
    pub defaults: Recoveries,
    /// The defaults of before this family existed: `scale_px = 2`, bright.
    pub old_defaults: Recoveries,
    /// The best grid setting for this case (by true − false recoveries), when searched.
    pub tuned: Option<(GridSetting, Recoveries)>,
}

/// Runs `case` on `size`² frames, `frames` long: `defaults` (the library's, or with some keys
/// set), old defaults and, when `search`, the grid.
pub fn run_case(
    case: &FamilyCase,
    size: usize,
    frames: usize,
    search: bool,
    defaults: &PipelineConfig,
) -> Result<FamilyRow> {
    let data = CaseData::render(case, size, frames)?;
    let defaults = Recoveries::from(&data.score(defaults)?);
    let old = GridSetting {
        scale_px: 2.0,
        noise_k: sillage_detect::DEFAULT_NOISE_K,
        filter_std: 1.5,
        vote_search_px: None,
    };
    let old_defaults = Recoveries::from(&data.score(&old.config())?);
    let tuned = if search {
        let mut best: Option<(GridSetting, Recoveries)> = None;
        for setting in grid(case) {
            let r = Recoveries::from(&data.score(&setting.config())?);
            if best.is_none_or(|(_, b)| r.merit() > b.merit()) {
                best = Some((setting, r));
            }
        }
        best
    } else {
        None
    };
    Ok(FamilyRow {
        particles: case.params(size, frames).n_particles,
        measured_sigma_px: data.measured_sigma().ok().map(|(s, _)| s),
        measured_source_density: data.measured_source_density().ok(),
        case: case.clone(),
        defaults,
        old_defaults,
        tuned,
    })
}

/// A change to the defaults tried by [`sweep`]: it gets the configuration and the particle σ
/// measured on the case's first frame.
pub type Variant<'a> = &'a dyn Fn(&mut PipelineConfig, f64);

/// The defaults changed by each of `variants` on `case`: how defaults are chosen, on the
/// tune half only (`tests/ptv_family_tuning.rs`).
pub fn sweep(
    case: &FamilyCase,
    size: usize,
    frames: usize,
    variants: &[Variant<'_>],
) -> Result<Vec<Recoveries>> {
    let data = CaseData::render(case, size, frames)?;
    let (sigma, _) = data.measured_sigma()?;
    variants
        .iter()
        .map(|variant| {
            let mut config = PipelineConfig::default();
            variant(&mut config, sigma);
            Ok(Recoveries::from(&data.score(&config)?))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_family_alternates_halves_and_crosses_every_level_once_per_flow() {
        let cases = family();
        assert_eq!(cases.len(), 24);
        let tune = cases.iter().filter(|c| c.half == Half::Tune).count();
        assert_eq!(tune, 12);
        for flow in FlowKind::ALL {
            let of_flow: Vec<_> = cases.iter().filter(|c| c.flow == flow).collect();
            assert_eq!(of_flow.len(), 4, "{flow:?}");
            for (levels, value) in [
                (
                    &SIGMA_LEVELS_PX,
                    (|c: &FamilyCase| c.sigma_px) as fn(&FamilyCase) -> f64,
                ),
                (&DENSITY_LEVELS_PPP, |c: &FamilyCase| c.density_ppp),
                (&DISPLACEMENT_LEVELS_PX, |c: &FamilyCase| {
                    c.max_displacement_px
                }),
            ] {
                for level in levels {
                    assert_eq!(
                        of_flow.iter().filter(|c| value(c) == *level).count(),
                        1,
                        "{flow:?}: level {level}"
                    );
                }
            }
            // Both halves see every flow.
            assert!(of_flow.iter().any(|c| c.half == Half::Tune));
            assert!(of_flow.iter().any(|c| c.half == Half::Report));
        }
    }

    #[test]
    fn the_moderate_family_moves_particles_a_third_to_two_thirds_of_their_spacing() {
        let cases = moderate_family();
        assert_eq!(cases.len(), 48);
        assert_eq!(cases.iter().filter(|c| c.half == Half::Tune).count(), 24);
        let mut seeds: Vec<u64> = cases.iter().map(|c| c.seed).collect();
        seeds.sort_unstable();
        seeds.dedup();
        assert_eq!(seeds.len(), cases.len(), "each case has its own seed");
        for case in &cases {
            let share = case.max_displacement_px * case.density_ppp.sqrt();
            assert!((0.29..0.61).contains(&share), "{}: {share}", case.name);
        }
        for flow in FlowKind::ALL {
            for half in [Half::Tune, Half::Report] {
                let n = cases
                    .iter()
                    .filter(|c| c.flow == flow && c.half == half)
                    .count();
                assert_eq!(n, 4, "{flow:?} {half:?}");
            }
        }
    }

    #[test]
    fn a_small_case_is_scored_for_defaults_and_old_defaults() {
        let case = FamilyCase {
            name: "small".into(),
            half: Half::Report,
            flow: FlowKind::CellularArray,
            sigma_px: 1.2,
            density_ppp: 0.005,
            max_displacement_px: 2.0,
            snr: 12.0,
            intermittency: 0.0,
            seed: FAMILY_SEED,
        };
        let row = run_case(&case, 128, 6, false, &PipelineConfig::default()).unwrap();
        assert_eq!(row.particles, 82);
        assert!(row.tuned.is_none());
        let sigma = row.measured_sigma_px.unwrap();
        assert!((1.2..1.8).contains(&sigma), "{sigma}");
        assert!(row.defaults.true_pct > 50.0, "{:?}", row.defaults);
        assert!(row.old_defaults.true_pct > 0.0, "{:?}", row.old_defaults);
    }
}

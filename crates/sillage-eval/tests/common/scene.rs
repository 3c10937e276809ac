//! Seeded synthetic MOT scenes for property tests and benchmarks: boxes moving in fixed,
//! non-overlapping slots, replaced by new objects as they end, and a tracker's output with
//! misses, noise, identity switches and false positives.

use sillage_core::BoundingBox;
use sillage_eval::mot::{MotEstimate, MotTruth, Shape, TruthRole};

/// What to generate.
#[derive(Debug, Clone, Copy)]
pub struct SceneSpec {
    /// Number of frames.
    pub frames: u64,
    /// Objects present in every frame (one per slot).
    pub objects_per_frame: u64,
    /// Mean lifetime of an object, frames.
    pub lifetime: u64,
    /// Probability that the tracker misses an object in a frame.
    pub miss_rate: f64,
    /// False positives per frame.
    pub false_positives: u64,
    /// The tracker changes an object's id every this many frames of its life (0: never).
    pub switch_every: u64,
    /// Position noise of the tracker, px (uniform in ±noise).
    pub noise_px: f64,
    /// Seed.
    pub seed: u64,
}

/// SplitMix64 (Steele et al. 2014): a tiny seeded generator.
pub struct Rng(u64);

impl Rng {
    /// A generator started at `seed`.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn bbox(x: f64, y: f64) -> Shape {
    Shape::Box(BoundingBox {
        left_px: x,
        top_px: y,
        width_px: 20.0,
        height_px: 40.0,
    })
}

/// The truth and a tracker's estimates of a scene.
pub fn scene(spec: &SceneSpec) -> (Vec<MotTruth>, Vec<MotEstimate>) {
    let mut rng = Rng::new(spec.seed);
    let slots = spec.objects_per_frame;
    // Per slot: current object id, its first frame, its last frame.
    let mut next_id = 1u64;
    let mut current: Vec<(u64, u64, u64)> = (0..slots)
        .map(|_| {
            let life = 1 + rng.next_u64() % (2 * spec.lifetime.max(1));
            next_id += 1;
            (next_id - 1, 0, life)
        })
        .collect();
    let mut truth = Vec::with_capacity((spec.frames * slots) as usize);
    let mut estimates = Vec::with_capacity((spec.frames * (slots + spec.false_positives)) as usize);
    let mut next_fp_id = 1u64 << 40;
    for frame in 0..spec.frames {
        for (s, slot) in current.iter_mut().enumerate() {
            if frame >= slot.2 {
                let life = 1 + rng.next_u64() % (2 * spec.lifetime.max(1));
                *slot = (next_id, frame, frame + life);
                next_id += 1;
            }
            let (id, born, _) = *slot;
            let age = frame - born;
            let phase = id as f64 * 0.37 + age as f64 * 0.1;
            let x = 60.0 * (s % 32) as f64 + 5.0 * phase.sin();
            let y = 100.0 * (s / 32) as f64 + 5.0 * phase.cos();
            truth.push(MotTruth {
                frame,
                id,
                shape: bbox(x, y),
                role: TruthRole::Scored,
            });
            if rng.unit() < spec.miss_rate {
                continue;
            }
            let segment = age.checked_div(spec.switch_every).unwrap_or(0);
            let noise = spec.noise_px;
            estimates.push(MotEstimate {
                frame,
                id: id * 1000 + segment,
                shape: bbox(
                    x + noise * (2.0 * rng.unit() - 1.0),
                    y + noise * (2.0 * rng.unit() - 1.0),
                ),
            });
        }
        for _ in 0..spec.false_positives {
            // Below every slot row, where no truth is.
            let x = 2000.0 * rng.unit();
            let y = 100.0 * (slots / 32 + 1) as f64 + 500.0 * rng.unit();
            estimates.push(MotEstimate {
                frame,
                id: next_fp_id,
                shape: bbox(x, y),
            });
            next_fp_id += 1;
        }
    }
    (truth, estimates)
}

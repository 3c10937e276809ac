//! Parameters of the synthetic walkers sequence and its scenarios, and their checks.

use serde::{Deserialize, Serialize};
use sillage_core::{Error, Result};

use crate::noise::{Noise, NoiseKind};

/// Parameters of a walkers sequence. The defaults make 320×240 frames with 24×64 px walkers
/// (a person's 1:2.7 width:height), ten empty frames first, and 2/255 of Gaussian sensor noise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WalkersParams {
    /// Frame width, px (default 320).
    pub width: usize,
    /// Frame height, px (default 240).
    pub height: usize,
    /// Frames the sequence yields, warm-up included (default 150).
    pub n_frames: usize,
    /// Empty background frames before the first walker, so that a background model can learn
    /// the scene (default 10).
    pub warmup_frames: usize,
    /// Width of a walker at depth 1, px (default 24).
    pub walker_width_px: f64,
    /// Height of a walker at depth 1, px (default 64).
    pub walker_height_px: f64,
    /// Sensor noise added to every channel of every pixel, anew each frame, in grey levels of
    /// full scale 1 (default Gaussian, σ = 2/255).
    pub noise: Noise,
    /// What the walkers do.
    pub scenario: Scenario,
    /// Seed of the background, the looks, the random scenario and the noise (default 0).
    pub seed: u64,
}

impl Default for WalkersParams {
    fn default() -> Self {
        Self {
            width: 320,
            height: 240,
            n_frames: 150,
            warmup_frames: 10,
            walker_width_px: 24.0,
            walker_height_px: 64.0,
            noise: Noise::new(NoiseKind::Gaussian, 2.0 / 255.0),
            scenario: Scenario::default(),
            seed: 0,
        }
    }
}

/// The walkers' story: the acceptance cases of the SIFT-PF tracker (Souded et al. 2011) —
/// a full occlusion, a group that splits — and a random crowd for benchmarks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Scenario {
    /// Two walkers cross in opposite directions; the near one hides the far one completely.
    Crossing(CrossingParams),
    /// Two walkers enter touching (one motion blob), then one speeds away.
    GroupSplit(GroupSplitParams),
    /// Walkers entering from the left and right borders at random times.
    Random(RandomParams),
}

impl Default for Scenario {
    fn default() -> Self {
        Scenario::Crossing(CrossingParams::default())
    }
}

/// Two walkers crossing: the far one (id 1) walks right, the near one (id 2) walks left, on
/// the same band. The near one is made just large enough that the far one is fully hidden
/// (visibility 0) for `occlusion_frames` consecutive frames.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CrossingParams {
    /// Speed of each walker, px/frame (default 1).
    pub speed_px_per_frame: f64,
    /// Consecutive frames the far walker is fully hidden, at least (default 5).
    pub occlusion_frames: usize,
    /// Frames from the walkers' appearance to the middle of the occlusion (default 60).
    pub approach_frames: usize,
}

impl Default for CrossingParams {
    fn default() -> Self {
        Self {
            speed_px_per_frame: 1.0,
            occlusion_frames: 5,
            approach_frames: 60,
        }
    }
}

/// Two walkers entering from the left border together, the leader (id 2) touching the
/// follower (id 1): one motion blob. After `together_frames` the leader speeds away and
/// drifts down, and they become two blobs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GroupSplitParams {
    /// Speed of the group, px/frame (default 1.5).
    pub speed_px_per_frame: f64,
    /// Frames from the first appearance to the split (default 60: ~30 to enter, ~30 fully
    /// inside together).
    pub together_frames: usize,
    /// Extra horizontal speed of the leader after the split, px/frame (default 1.5).
    pub speedup_px_per_frame: f64,
    /// Downward speed of the leader after the split, px/frame (default 0.5).
    pub drift_px_per_frame: f64,
}

impl Default for GroupSplitParams {
    fn default() -> Self {
        Self {
            speed_px_per_frame: 1.5,
            together_frames: 60,
            speedup_px_per_frame: 1.5,
            drift_px_per_frame: 0.5,
        }
    }
}

/// `n` walkers entering from the left or right border at uniformly random frames of the
/// first 70 % of the sequence (after the warm-up), at uniformly random speeds, heading
/// across the frame within ±15° of the horizontal, their heading wandering a little.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RandomParams {
    /// Number of walkers (default 10).
    pub n: usize,
    /// Slowest speed, px/frame (default 0.5).
    pub min_speed_px_per_frame: f64,
    /// Fastest speed, px/frame (default 2.5).
    pub max_speed_px_per_frame: f64,
    /// Standard deviation of the heading's random walk, rad/frame (default 0.02).
    pub heading_noise_rad: f64,
}

impl Default for RandomParams {
    fn default() -> Self {
        Self {
            n: 10,
            min_speed_px_per_frame: 0.5,
            max_speed_px_per_frame: 2.5,
            heading_noise_rad: 0.02,
        }
    }
}

/// Largest frame side accepted, px.
const MAX_SIDE: usize = 8192;
/// Most walkers a random scenario may hold.
const MAX_WALKERS: usize = 10_000;
/// Fastest walker accepted, px/frame.
const MAX_SPEED: f64 = 50.0;

impl WalkersParams {
    /// Checks every value, and that the frame is large enough for the scenario; the error
    /// names the key and its allowed range.
    pub fn validate(&self) -> Result<()> {
        for (key, side) in [("width", self.width), ("height", self.height)] {
            if !(1..=MAX_SIDE).contains(&side) {
                return Err(Error::parameter(
                    key,
                    side,
                    format!("must be in 1..={MAX_SIDE}"),
                ));
            }
        }
        if self.n_frames <= self.warmup_frames {
            return Err(Error::parameter(
                "n_frames",
                self.n_frames,
                format!(
                    "must exceed warmup_frames ({}): the walkers come after the warm-up",
                    self.warmup_frames
                ),
            ));
        }
        check("walker_width_px", self.walker_width_px, 4.0, 512.0)?;
        check("walker_height_px", self.walker_height_px, 8.0, 1024.0)?;
        self.noise.validate()?;
        self.scenario
            .validate()
            .map_err(|e| e.in_section("scenario"))?;
        self.check_room()
    }

    /// The frame must hold the largest walker of the scenario with a margin.
    fn check_room(&self) -> Result<()> {
        let (width_px, height_px) = self.scenario.room_needed_px(self);
        let room = |key: &str, side: usize, needed: f64| {
            if side as f64 >= needed {
                Ok(())
            } else {
                Err(Error::parameter(
                    key,
                    side,
                    format!(
                        "too small for this scenario and walker size: at least {} px",
                        needed.ceil()
                    ),
                ))
            }
        };
        room("width", self.width, width_px)?;
        room("height", self.height, height_px)
    }
}

impl Scenario {
    /// Checks the scenario's own values.
    fn validate(&self) -> Result<()> {
        match self {
            Scenario::Crossing(p) => {
                check("speed_px_per_frame", p.speed_px_per_frame, 0.05, MAX_SPEED)?;
                positive("occlusion_frames", p.occlusion_frames)?;
                positive("approach_frames", p.approach_frames)
            }
            Scenario::GroupSplit(p) => {
                check("speed_px_per_frame", p.speed_px_per_frame, 0.05, MAX_SPEED)?;
                positive("together_frames", p.together_frames)?;
                check(
                    "speedup_px_per_frame",
                    p.speedup_px_per_frame,
                    0.0,
                    MAX_SPEED,
                )?;
                check("drift_px_per_frame", p.drift_px_per_frame, 0.0, MAX_SPEED)?;
                if p.speedup_px_per_frame == 0.0 && p.drift_px_per_frame == 0.0 {
                    return Err(Error::parameter(
                        "speedup_px_per_frame",
                        0,
                        "must be > 0 when drift_px_per_frame is 0, or the group never splits",
                    ));
                }
                Ok(())
            }
            Scenario::Random(p) => {
                if !(1..=MAX_WALKERS).contains(&p.n) {
                    return Err(Error::parameter(
                        "n",
                        p.n,
                        format!("must be in 1..={MAX_WALKERS}"),
                    ));
                }
                check(
                    "min_speed_px_per_frame",
                    p.min_speed_px_per_frame,
                    0.05,
                    MAX_SPEED,
                )?;
                check(
                    "max_speed_px_per_frame",
                    p.max_speed_px_per_frame,
                    p.min_speed_px_per_frame,
                    MAX_SPEED,
                )?;
                check("heading_noise_rad", p.heading_noise_rad, 0.0, 0.5)
            }
        }
    }

    /// The frame size, px, the scenario needs to stage its walkers fully inside.
    fn room_needed_px(&self, params: &WalkersParams) -> (f64, f64) {
        let (w, h) = (params.walker_width_px, params.walker_height_px);
        match self {
            Scenario::Crossing(p) => {
                let near_scale = super::motion::crossing_near_scale(p, w);
                let travel = 2.0 * p.speed_px_per_frame * p.approach_frames as f64;
                // Both start fully inside, 2 px from their border.
                (travel + near_scale * w + 4.0, near_scale * h + 4.0)
            }
            // The pair, side by side, must fit inside before the split.
            Scenario::GroupSplit(_) => (2.0 * w + 4.0, h + 8.0),
            Scenario::Random(_) => (2.0 * w, 1.5 * h),
        }
    }
}

/// `value` must be finite and in `[low, high]`.
fn check(key: &str, value: f64, low: f64, high: f64) -> Result<()> {
    if value.is_finite() && (low..=high).contains(&value) {
        Ok(())
    } else {
        Err(Error::parameter(
            key,
            value,
            format!("must be a finite number in [{low}, {high}]"),
        ))
    }
}

/// `value` must be at least 1.
fn positive(key: &str, value: usize) -> Result<()> {
    if value >= 1 {
        Ok(())
    } else {
        Err(Error::parameter(key, value, "must be ≥ 1"))
    }
}

//! The scenarios as paths: each walker's size, depth and box position in every frame from its
//! first, worked out once when the sequence is made (a few numbers per walker and frame).

use rand::RngExt;
use rand_distr::StandardNormal;
use sillage_core::{Point2, rng_stream};

use super::appearance::{SOLID_BODY_U, SOLID_BODY_V};
use super::params::{CrossingParams, GroupSplitParams, RandomParams, Scenario, WalkersParams};

/// Tag of the random scenario's per-walker streams `(seed, tag | walker)`.
const PATH_STREAM_TAG: u64 = 1 << 62;

/// Largest angle of a random walker's heading from the horizontal, rad (15°).
const MAX_HEADING_RAD: f64 = 0.26;

/// Depth range of the random walkers (depth 1: the nominal walker size; size ∝ 1 / depth).
const RANDOM_DEPTHS: (f64, f64) = (0.8, 1.25);

/// Share of the sequence after the warm-up in which random walkers enter.
const RANDOM_ENTRY_SHARE: f64 = 0.7;

/// Depth of the group-split follower: a little farther than the leader, so that the leader
/// covers it where they touch.
const FOLLOWER_DEPTH: f64 = 1.05;

/// Horizontal overlap of the group-split pair, px: they touch, one motion blob.
const GROUP_OVERLAP_PX: f64 = 2.0;

/// One walker's script: its id, depth, size, and the top-left corner of its box in each frame
/// from `first_frame` on.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct WalkerPath {
    /// Identity, from 1 (MOTChallenge ids are positive).
    pub id: u64,
    /// Distance from the camera in walker units: the nearer (smaller) covers the farther.
    pub depth: f64,
    /// Box width, px.
    pub width_px: f64,
    /// Box height, px.
    pub height_px: f64,
    /// Frame of the first position.
    pub first_frame: usize,
    /// Top-left corner of the box (its left and top edges, px), one per frame.
    pub top_left: Vec<Point2>,
}

impl WalkerPath {
    /// The box's top-left corner in `frame`, `None` before the first or after the last.
    pub fn top_left_at(&self, frame: usize) -> Option<Point2> {
        let offset = frame.checked_sub(self.first_frame)?;
        self.top_left.get(offset).copied()
    }
}

/// Scale of the crossing's near walker over the far one: large enough that the far walker's
/// whole silhouette fits inside the near one's solid body (torso and hips) while their centres
/// are within `speed · (occlusion_frames + 1)` of each other, and tall enough that the far
/// walker fits between the near one's shoulders and knees.
pub(crate) fn crossing_near_scale(p: &CrossingParams, width_px: f64) -> f64 {
    let solid_width = SOLID_BODY_U.1 - SOLID_BODY_U.0;
    let relative_travel = 2.0 * p.speed_px_per_frame * (p.occlusion_frames + 1) as f64;
    let by_width = (width_px + relative_travel) / (solid_width * width_px);
    // 2 % of margin, so the far walker's head and feet stay clear of the near one's edges.
    let by_height = 1.02 / (SOLID_BODY_V.1 - SOLID_BODY_V.0);
    by_width.max(by_height)
}

/// Every walker's path in the scenario of `params` (assumed valid).
pub(crate) fn walker_paths(params: &WalkersParams) -> Vec<WalkerPath> {
    match &params.scenario {
        Scenario::Crossing(p) => crossing(params, p),
        Scenario::GroupSplit(p) => group_split(params, p),
        Scenario::Random(p) => random(params, p),
    }
}

/// A straight walk from `start` at `velocity` px/frame over frames `first..n_frames`.
fn straight(start: Point2, velocity: (f64, f64), frames: usize) -> Vec<Point2> {
    (0..frames)
        .map(|t| {
            Point2::new(
                start.x + velocity.0 * t as f64,
                start.y + velocity.1 * t as f64,
            )
        })
        .collect()
}

/// Far walker (id 1) walking right, near walker (id 2) walking left; their centres meet in the
/// middle of the frame `approach_frames` after the warm-up.
fn crossing(params: &WalkersParams, p: &CrossingParams) -> Vec<WalkerPath> {
    let (w, h) = (params.walker_width_px, params.walker_height_px);
    let scale = crossing_near_scale(p, w);
    let (near_w, near_h) = (scale * w, scale * h);
    let centre_x = 0.5 * (params.width as f64 - 1.0);
    let near_top = (0.5 * (params.height as f64 - near_h)).floor();
    // The far walker's box sits in the middle of the near one's solid rows.
    let far_top = near_top + 0.5 * (SOLID_BODY_V.0 + SOLID_BODY_V.1) * near_h - 0.5 * h;
    let v = p.speed_px_per_frame;
    let approach = v * p.approach_frames as f64;
    let frames = params.n_frames - params.warmup_frames;
    let far = WalkerPath {
        id: 1,
        depth: scale,
        width_px: w,
        height_px: h,
        first_frame: params.warmup_frames,
        top_left: straight(
            Point2::new(centre_x - approach - 0.5 * w, far_top),
            (v, 0.0),
            frames,
        ),
    };
    let near = WalkerPath {
        id: 2,
        depth: 1.0,
        width_px: near_w,
        height_px: near_h,
        first_frame: params.warmup_frames,
        top_left: straight(
            Point2::new(centre_x + approach - 0.5 * near_w, near_top),
            (-v, 0.0),
            frames,
        ),
    };
    vec![far, near]
}

/// Follower (id 1) and leader (id 2) entering from the left border touching; from
/// `together_frames` after their appearance the leader speeds away and drifts down.
fn group_split(params: &WalkersParams, p: &GroupSplitParams) -> Vec<WalkerPath> {
    let (w, h) = (params.walker_width_px, params.walker_height_px);
    let (follower_w, follower_h) = (w / FOLLOWER_DEPTH, h / FOLLOWER_DEPTH);
    let frames = params.n_frames - params.warmup_frames;
    let v = p.speed_px_per_frame;
    let leader_top = (0.5 * (params.height as f64 - h)).floor();
    let leader_start = Point2::new(-w, leader_top);
    let leader: Vec<Point2> = (0..frames)
        .map(|t| {
            let after_split = t.saturating_sub(p.together_frames) as f64;
            Point2::new(
                leader_start.x + v * t as f64 + p.speedup_px_per_frame * after_split,
                leader_start.y + p.drift_px_per_frame * after_split,
            )
        })
        .collect();
    // Feet level with the leader's, its right edge overlapping the leader's left one.
    let follower_start = Point2::new(
        leader_start.x - follower_w + GROUP_OVERLAP_PX,
        leader_top + h - follower_h,
    );
    vec![
        WalkerPath {
            id: 1,
            depth: FOLLOWER_DEPTH,
            width_px: follower_w,
            height_px: follower_h,
            first_frame: params.warmup_frames,
            top_left: straight(follower_start, (v, 0.0), frames),
        },
        WalkerPath {
            id: 2,
            depth: 1.0,
            width_px: w,
            height_px: h,
            first_frame: params.warmup_frames,
            top_left: leader,
        },
    ]
}

/// `n` walkers from their own streams: entry frame, border, depth, height in the frame, speed
/// and heading, then a heading random walk; each path ends when the walker has left the frame.
fn random(params: &WalkersParams, p: &RandomParams) -> Vec<WalkerPath> {
    let (frame_w, frame_h) = (params.width as f64, params.height as f64);
    let entry_span =
        ((params.n_frames - params.warmup_frames) as f64 * RANDOM_ENTRY_SHARE) as usize;
    (0..p.n)
        .map(|index| {
            let mut rng = rng_stream(params.seed, PATH_STREAM_TAG | index as u64);
            let first_frame = params.warmup_frames + rng.random_range(0..=entry_span);
            let depth = rng.random_range(RANDOM_DEPTHS.0..=RANDOM_DEPTHS.1);
            let (w, h) = (
                params.walker_width_px / depth,
                params.walker_height_px / depth,
            );
            let from_left = rng.random::<bool>();
            let top = rng.random_range(0.0..=(frame_h - h).max(0.0));
            let speed = rng.random_range(p.min_speed_px_per_frame..=p.max_speed_px_per_frame);
            let base_heading = rng.random_range(-MAX_HEADING_RAD..=MAX_HEADING_RAD)
                + if from_left { 0.0 } else { std::f64::consts::PI };
            let mut heading = base_heading;
            let mut position = Point2::new(if from_left { -w } else { frame_w }, top);
            let mut top_left = Vec::new();
            for _ in first_frame..params.n_frames {
                top_left.push(position);
                heading += p.heading_noise_rad * rng.sample::<f64, _>(StandardNormal);
                heading = heading.clamp(
                    base_heading - MAX_HEADING_RAD,
                    base_heading + MAX_HEADING_RAD,
                );
                position = Point2::new(
                    position.x + speed * heading.cos(),
                    position.y + speed * heading.sin(),
                );
                let gone = position.x > frame_w
                    || position.x + w < -1.0
                    || position.y > frame_h
                    || position.y + h < -1.0;
                if gone {
                    break;
                }
            }
            WalkerPath {
                id: index as u64 + 1,
                depth,
                width_px: w,
                height_px: h,
                first_frame,
                top_left,
            }
        })
        .collect()
}

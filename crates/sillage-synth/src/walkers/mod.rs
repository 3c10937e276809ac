//! Synthetic people walking over a static background, with occlusions and ground truth: the
//! acceptance sequences of the SIFT-PF tracker (Souded et al. 2011), which follows people
//! found by motion detection by tracking SIFT features on them.
//!
//! - [`params`](WalkersParams): frame size, walker size, warm-up, noise, seed, and the
//!   [`Scenario`]: [`Crossing`](Scenario::Crossing) (a full occlusion of
//!   `occlusion_frames`), [`GroupSplit`](Scenario::GroupSplit) (one blob that becomes two),
//!   [`Random`](Scenario::Random) (a crowd entering from the borders).
//! - appearance: person-like silhouettes (head, torso, hips, legs in two stride poses) in
//!   seeded clothes: a dark dominant colour per walker with light stripes, checks and a logo
//!   patch (corners for SIFT, colours for histograms).
//! - motion: each scenario as per-walker paths (box, depth) worked out up front.
//! - render: the seeded background, walkers painted far to near with 4 × 4 area sampling,
//!   the visibility of each walker, sensor noise, 8-bit colour and Rec. 601 grey.
//! - [`WalkersSequence`]: the frames with their [`WalkerTruth`], one at a time.

mod appearance;
mod motion;
mod params;
mod render;
mod sequence;

pub use params::{CrossingParams, GroupSplitParams, RandomParams, Scenario, WalkersParams};
pub use sequence::{WalkerTruth, WalkersFrame, WalkersSequence};

//! The pedestrian tracker of Madrigal & Hayet, "Evaluation of multiple motion models for
//! multiple pedestrian visual tracking": one IMM particle filter per person, where constant
//! position, constant velocity, constant acceleration and a learned motion prior compete
//! through resampling ([`sillage_filter::ImmParticleFilter`]).
//!
//! - [`PedestrianTracker`]: births on motion blobs or detections no tracker explains, the
//!   colour and motion likelihood of §4.3 ([`Appearance`]), death when the mean particle
//!   likelihood stays low (§5.3); on detections (alone, or beside the frames, which may add
//!   colour to the assignment), detections assigned to the predicted boxes in two stages, a
//!   detection likelihood and SORT's and ByteTrack's life cycle;
//! - [`BoxSizing`]: box sizes from a ground-plane homography and an adult's size (§4);
//! - [`PedestrianParams`]: every parameter with the paper's defaults.

mod appearance;
mod foreground;
mod models;
mod params;
mod sizing;
mod tracker;

pub use appearance::{Appearance, AppearanceParams, FrameCues, HistogramScratch};
pub use models::PedestrianMotion;
pub use params::{
    DetectionLikelihoodParams, DetectionsWithFrames, ModelName, PedestrianParams, ProposalParams,
};
pub use sizing::BoxSizing;
pub use tracker::{Candidate, PedestrianEstimate, PedestrianFrame, PedestrianTracker};

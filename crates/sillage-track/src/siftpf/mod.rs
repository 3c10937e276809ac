//! The surveillance tracker of Souded, Giulieri & Bremond, "An object tracking in particle
//! filtering and data association framework, using SIFT features" (ICDP 2011): objects found
//! by motion detection, SIFT features selected on them and each followed by its own particle
//! filter, objects linked between frames through the features they share, with merges,
//! splits and occlusions.
//!
//! - [`SiftPfTracker`]: the frame loop of Fig. 1;
//! - feature selection (§2.1, [`FeatureSelector`]), in the paper's three configurations of
//!   §3.1.1 ([`FeatureSelection`]);
//! - the per-feature particle filter (§2.2, [`TrackedFeature`]);
//! - the link-score matrix of Eq. (6) and the four cases of §2.3 ([`LinkMatrix`]), with
//!   the detector's cuts of groups into people joined back where an object straddles one;
//! - occlusion management by SIFT matching, dominant colours and learned size and speed
//!   (§2.4, [`resume_score`]);
//! - validation of new objects (§2.5, [`is_object_of_interest`]);
//! - [`SiftPfParams`]: every parameter.

mod association;
mod coherence;
mod cuts;
mod feature;
mod object;
mod occlusion;
mod params;
mod selection;
mod tracker;
mod validation;

pub use association::{DetectedObject, LinkMatrix};
pub use coherence::{Coherence, WorldScale};
pub use feature::{FeatureFate, FeatureFrame, FeatureSeed, TrackedFeature};
pub use object::{HistoryEntry, ObjectState, TrackedObject};
pub use occlusion::{ResumeCandidate, matched_share, resume_pairs, resume_score};
pub use params::{
    AssociationParams, FeatureFilterParams, FeaturePlacementParams, FeatureSelection, SiftPfParams,
    ValidationParams,
};
pub use selection::{FeatureSelector, SelectionRequest, SubregionGrid, anchor_in, robustness};
pub use tracker::{SiftPfEstimate, SiftPfFrame, SiftPfTracker};
pub use validation::is_object_of_interest;

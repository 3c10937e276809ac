//! Resuming occluded objects (§2.4 of Souded et al.): a detection no tracked object links to
//! is compared with each object kept in occlusion by SIFT matching (the object's features
//! before the occlusion against the keypoints detected on the candidate), by the dominant
//! colour descriptor, and by the world coherency of its size and position with the object's
//! learned Gaussians; the best pairs are chosen by the Hungarian algorithm.

use sillage_assoc::solve_assignment;
use sillage_core::{FrameIndex, Point2};
use sillage_image::{DominantColours, SiftDescriptor};

use super::object::TrackedObject;
use super::params::AssociationParams;
use sillage_core::BoundingBox;

/// A descriptor farther than this from its nearest neighbour matches nothing, whatever the
/// ratio (unrelated unit-length descriptors lie 0.9-1.3 apart).
const MATCH_MAX_DISTANCE: f32 = 0.7;

/// What a free detection looks like to the occlusion management.
#[derive(Debug, Clone, PartialEq)]
pub struct ResumeCandidate {
    /// Its box.
    pub bbox: BoundingBox,
    /// Descriptors of the keypoints detected on it.
    pub descriptors: Vec<SiftDescriptor>,
    /// Its dominant colours (empty without a colour frame).
    pub colours: DominantColours,
    /// Where it stands (world or image units, as the objects learned).
    pub ground: Point2,
    /// Its size (world or image units).
    pub size: (f64, f64),
}

/// The share of `signature`'s descriptors whose nearest neighbour among `candidates` passes
/// Lowe's ratio test (`d₁ < ratio·d₂`) within `MATCH_MAX_DISTANCE`.
pub fn matched_share(
    signature: &[SiftDescriptor],
    candidates: &[SiftDescriptor],
    ratio: f64,
) -> f64 {
    if signature.is_empty() {
        return 0.0;
    }
    let matched = signature
        .iter()
        .filter(|s| {
            let (mut d1, mut d2) = (f32::INFINITY, f32::INFINITY);
            for c in candidates {
                let d = s.distance(c);
                if d < d1 {
                    d2 = d1;
                    d1 = d;
                } else if d < d2 {
                    d2 = d;
                }
            }
            d1 <= MATCH_MAX_DISTANCE && f64::from(d1) < ratio * f64::from(d2)
        })
        .count();
    matched as f64 / signature.len() as f64
}

/// The score in `[0, 1]` for `object` (occluded since `since`, last seen one-to-one at
/// `last_ground`) to resume on `candidate` at `frame`: the mean of the SIFT matched share
/// and the colour similarity (the matched share alone without colours); `None` when the
/// candidate's size or travel does not fit the learned Gaussians.
pub fn resume_score(
    object: &TrackedObject,
    candidate: &ResumeCandidate,
    frame: FrameIndex,
    params: &AssociationParams,
) -> Option<f64> {
    let (last_ground, last_frame) = object.last_ground?;
    let frames = u32::try_from(frame.saturating_sub(last_frame)).unwrap_or(u32::MAX);
    let travel = last_ground.distance(candidate.ground);
    if !object
        .coherence
        .admits(candidate.size, travel, frames, params.coherence_sigmas)
    {
        return None;
    }
    let sift = matched_share(
        &object.signature,
        &candidate.descriptors,
        params.match_ratio,
    );
    let score = if object.colours.colours().is_empty() || candidate.colours.colours().is_empty() {
        sift
    } else {
        0.5 * (sift + object.colours.similarity(&candidate.colours))
    };
    (score >= params.min_resume_score).then_some(score)
}

/// Pairs (object index, candidate index) that resume, by the Hungarian algorithm over the
/// admissible scores.
pub fn resume_pairs(
    objects: &[&TrackedObject],
    candidates: &[ResumeCandidate],
    frame: FrameIndex,
    params: &AssociationParams,
) -> Vec<(usize, usize)> {
    if objects.is_empty() || candidates.is_empty() {
        return Vec::new();
    }
    let costs: Vec<f64> = objects
        .iter()
        .flat_map(|o| {
            candidates
                .iter()
                .map(|c| resume_score(o, c, frame, params).map_or(f64::INFINITY, |s| 1.0 - s))
        })
        .collect();
    solve_assignment(objects.len(), candidates.len(), &costs)
        .into_iter()
        .enumerate()
        .filter_map(|(i, j)| j.map(|j| (i, j)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn descriptor(seed: usize) -> SiftDescriptor {
        let mut values = [0.0f32; 128];
        values[seed % 128] = 1.0;
        SiftDescriptor(values)
    }

    #[test]
    fn matched_share_needs_a_distinct_nearest_neighbour() {
        let signature = [descriptor(1), descriptor(2), descriptor(3), descriptor(4)];
        let candidates = [descriptor(1), descriptor(2), descriptor(9)];
        assert_eq!(matched_share(&signature, &candidates, 0.8), 0.5);
        assert_eq!(matched_share(&signature, &[], 0.8), 0.0);
        assert_eq!(matched_share(&[], &candidates, 0.8), 0.0);
    }
}

//! What the CLEAR MOT matching did to each trajectory over a sequence: the per-trajectory
//! counts that the papers' track-level scores (MMPF+ correct tracks, ETISEO M1–M3) are
//! built on, gathered once from [`clear_events`](crate::mot::clear_events).

use crate::mot::FrameEvents;
use crate::mot::ids::IdMap;

/// One true trajectory under the matching.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct TruthTally {
    /// Frames where it is present (scored).
    pub present: u64,
    /// Frames where it is matched.
    pub matched: u64,
    /// Frames where its match is an identity switch (a mismatch).
    pub switches: u64,
    /// Number of distinct estimates it was matched to.
    pub partners: u64,
    /// Frames matched to the estimate it was matched to longest.
    pub longest_partner_frames: u64,
}

/// The trajectories of a sequence under the matching.
#[derive(Debug, Clone, Default)]
pub(crate) struct TrajectoryTally {
    /// Every true trajectory, in order of first appearance.
    pub truths: Vec<TruthTally>,
    /// For every estimate matched at least once, the number of distinct true objects it was
    /// matched to, in increasing order.
    pub estimate_partners: Vec<u64>,
    /// Unmatched estimates, summed over frames.
    pub false_positives: u64,
}

impl TrajectoryTally {
    /// Tallies the per-frame events of one sequence.
    pub fn new(events: &[FrameEvents]) -> Self {
        let mut tally = Self::default();
        let mut truth_index: IdMap<u64, usize> = IdMap::default();
        let mut pair_frames: IdMap<(u64, u64), u64> = IdMap::default();
        let mut truth = |id: u64, truths: &mut Vec<TruthTally>| -> usize {
            *truth_index.entry(id).or_insert_with(|| {
                truths.push(TruthTally::default());
                truths.len() - 1
            })
        };
        for frame in events {
            for m in &frame.matches {
                let k = truth(m.truth_id, &mut tally.truths);
                let t = &mut tally.truths[k];
                t.present += 1;
                t.matched += 1;
                t.switches += u64::from(m.switched_from.is_some());
                *pair_frames.entry((m.truth_id, m.estimate_id)).or_insert(0) += 1;
            }
            for &id in &frame.misses {
                let k = truth(id, &mut tally.truths);
                tally.truths[k].present += 1;
            }
            tally.false_positives += frame.false_positives.len() as u64;
        }
        // Sums and maxima only: the hash order does not matter.
        let mut estimate_index: IdMap<u64, usize> = IdMap::default();
        for (&(truth_id, estimate_id), &frames) in &pair_frames {
            let k = truth(truth_id, &mut tally.truths);
            let t = &mut tally.truths[k];
            t.partners += 1;
            t.longest_partner_frames = t.longest_partner_frames.max(frames);
            let next = estimate_index.len();
            let e = *estimate_index.entry(estimate_id).or_insert(next);
            if e == tally.estimate_partners.len() {
                tally.estimate_partners.push(0);
            }
            tally.estimate_partners[e] += 1;
        }
        // An order that does not depend on the ids, for sums that do not either.
        tally.estimate_partners.sort_unstable();
        tally
    }
}

//! Global identities for the windows' tracks, handed out window by window from the seams
//! alone.

use std::collections::HashMap;

use sillage_core::{Error, Result, TrackId, TrackPoint};

/// One window's ids → global ids: a table when the window's ids are dense (PTV numbers its
/// tracks from 0), else a hash map.
#[derive(Debug, Clone)]
pub struct IdMap(Ids);

#[derive(Debug, Clone)]
enum Ids {
    Dense(Vec<TrackId>),
    Sparse(HashMap<TrackId, TrackId>),
}

/// Maps are equal when they map the same ids alike, however they are stored.
impl PartialEq for IdMap {
    fn eq(&self, other: &Self) -> bool {
        self.pairs() == other.pairs()
    }
}

/// A table slot no id was given.
const UNSET: TrackId = TrackId::MAX;

impl IdMap {
    /// An empty map for about `count` ids of which the largest is `max`: a table of `max + 1`
    /// slots when that is at most twice `count` (plus a little), else a hash map.
    fn for_ids(max: Option<TrackId>, count: usize) -> Self {
        match max {
            Some(max) if max < 2 * count as u64 + 1024 => {
                IdMap(Ids::Dense(vec![UNSET; max as usize + 1]))
            }
            _ => IdMap(Ids::Sparse(HashMap::with_capacity(count.min(1 << 16)))),
        }
    }

    fn insert(&mut self, local: TrackId, global: TrackId) {
        match &mut self.0 {
            Ids::Dense(table) => {
                if local as usize >= table.len() {
                    table.resize(local as usize + 1, UNSET);
                }
                table[local as usize] = global;
            }
            Ids::Sparse(map) => {
                map.insert(local, global);
            }
        }
    }

    /// The global id of the window's track `local`, `None` when it has none (a track the
    /// window's seams dropped).
    pub fn get(&self, local: TrackId) -> Option<TrackId> {
        match &self.0 {
            Ids::Dense(table) => table.get(local as usize).copied().filter(|&id| id != UNSET),
            Ids::Sparse(map) => map.get(&local).copied(),
        }
    }

    /// Every `(local, global)` pair, by local id.
    pub fn pairs(&self) -> Vec<(TrackId, TrackId)> {
        let mut pairs: Vec<(TrackId, TrackId)> = match &self.0 {
            Ids::Dense(table) => (0..)
                .zip(table.iter().copied())
                .filter(|&(_, global)| global != UNSET)
                .collect(),
            Ids::Sparse(map) => map.iter().map(|(&l, &g)| (l, g)).collect(),
        };
        pairs.sort_unstable();
        pairs
    }

    /// The map of these `(local, global)` pairs (as [`IdMap::pairs`] gives them).
    pub fn from_pairs(pairs: &[(TrackId, TrackId)]) -> Self {
        let mut map = Self::for_ids(pairs.iter().map(|&(l, _)| l).max(), pairs.len());
        for &(local, global) in pairs {
            map.insert(local, global);
        }
        map
    }

    /// `points` (the window's ids) under their global ids; an error naming a point whose
    /// track has none.
    pub fn renumber(&self, points: &mut [TrackPoint]) -> Result<()> {
        for p in points {
            p.track_id = self.get(p.track_id).ok_or_else(|| {
                Error::input(format!(
                    "track {} of frame {} has no identity in this window's map; pass the \
                     map made for this window",
                    p.track_id, p.frame
                ))
            })?;
        }
        Ok(())
    }
}

/// Hands out global identities, window by window in order: a window's tracks that go on past
/// its first cut get fresh ids in ascending order of their own, except those its seam with
/// the window before joined, which take their partner's.
#[derive(Debug, Clone, Default)]
pub(super) struct Numbering {
    next_id: TrackId,
}

impl Numbering {
    /// Global identities handed out so far: the trajectories of the stitched run.
    pub(super) fn tracks(&self) -> TrackId {
        self.next_id
    }

    /// The ids of a window whose tracks from its first cut on are `ids` (ascending,
    /// distinct), joined by `joined` pairs (`(its id, the earlier window's id)`) to the
    /// window before, whose map is `previous`.
    pub(super) fn window(
        &mut self,
        ids: &[TrackId],
        joined: &[(TrackId, TrackId)],
        previous: Option<&IdMap>,
    ) -> Result<IdMap> {
        let max = ids.iter().chain(joined.iter().map(|(l, _)| l)).max();
        let mut map = IdMap::for_ids(max.copied(), ids.len());
        let partner: HashMap<TrackId, TrackId> = joined.iter().copied().collect();
        for &id in ids.iter().filter(|id| !partner.contains_key(id)) {
            map.insert(id, self.next_id);
            self.next_id += 1;
        }
        for &(later, earlier) in joined {
            let global = previous.and_then(|p| p.get(earlier)).ok_or_else(|| {
                Error::input(format!(
                    "the seam joins track {later} to track {earlier} of the window before, \
                     which has no identity: windows must be numbered in order"
                ))
            })?;
            map.insert(later, global);
        }
        Ok(map)
    }
}

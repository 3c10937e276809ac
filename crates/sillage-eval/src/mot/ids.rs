//! Hash maps keyed by object ids and by (truth id, estimate id) pairs, so that the global
//! counts of Identity and HOTA cost memory and time in proportion to the pairs that occur,
//! not to (number of true ids) × (number of estimated ids).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A hash map with [`IdHasher`].
pub(crate) type IdMap<K, V> = HashMap<K, V, BuildHasherDefault<IdHasher>>;

/// The key of a (dense truth id, dense estimate id) pair.
pub(crate) fn pair_key(truth: u32, estimate: u32) -> u64 {
    (u64::from(truth) << 32) | u64::from(estimate)
}

/// The two dense ids of a [`pair_key`].
pub(crate) fn split_pair_key(key: u64) -> (u32, u32) {
    ((key >> 32) as u32, key as u32)
}

/// A fast hasher for integer keys: the SplitMix64 finaliser (Steele et al., OOPSLA 2014),
/// which mixes every input bit into the low bits that pick a bucket. Not DoS-resistant,
/// which is fine for ids read from one's own files.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct IdHasher(u64);

impl Hasher for IdHasher {
    fn finish(&self) -> u64 {
        let mut x = self.0;
        x ^= x >> 30;
        x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
        x ^= x >> 27;
        x = x.wrapping_mul(0x94d0_49bb_1331_11eb);
        x ^ (x >> 31)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = self.0.rotate_left(8) ^ u64::from(b);
        }
    }

    fn write_u64(&mut self, value: u64) {
        self.0 = self.0.rotate_left(32) ^ value;
    }
}

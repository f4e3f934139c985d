//! The sun/shadow history of one surface point as a compact record: one
//! bit per history sample, packed 64 to a word, stored inline (no heap
//! allocation) up to [`INLINE_SAMPLES`] samples — the default 48-h history
//! at 20-min shadow samples is 145 — and on the heap beyond.

use smallvec::SmallVec;

use crate::therm::cache::Flags;

/// Samples a history holds without a heap allocation.
pub const INLINE_SAMPLES: usize = 192;

/// Sunlit flags, sample `i` in bit `i % 64` of word `i / 64` (bits past
/// `len` are zero).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SunFlags {
    words: SmallVec<[u64; INLINE_SAMPLES / 64]>,
    len: u32,
}

impl SunFlags {
    /// `len` samples, all shaded.
    pub fn shaded(len: usize) -> Self {
        SunFlags {
            words: SmallVec::from_elem(0, len.div_ceil(64)),
            len: len as u32,
        }
    }

    /// `len` samples from their packed words (sample `i` in bit `i % 64`
    /// of `words[i / 64]`; `len.div_ceil(64)` words, bits past `len` zero).
    pub fn from_words(words: &[u64], len: usize) -> Self {
        debug_assert_eq!(words.len(), len.div_ceil(64));
        SunFlags {
            words: SmallVec::from_slice(words),
            len: len as u32,
        }
    }

    pub fn len(&self) -> usize {
        self.len as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Marks sample `i` sunlit.
    pub fn set_sunlit(&mut self, i: usize) {
        debug_assert!(i < self.len());
        self.words[i / 64] |= 1 << (i % 64);
    }

    /// Whether sample `i` is sunlit (false past the end).
    pub fn get(&self, i: usize) -> bool {
        i < self.len() && self.words[i / 64] >> (i % 64) & 1 == 1
    }

    /// The last sample (the image time); `None` for an empty history.
    pub fn last(&self) -> Option<bool> {
        self.len().checked_sub(1).map(|i| self.get(i))
    }

    /// Number of sunlit samples.
    pub fn count_sunlit(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// The flags in sample order.
    pub fn iter(&self) -> impl Iterator<Item = bool> + '_ {
        (0..self.len()).map(|i| self.get(i))
    }

    /// The flags as the thermal cache borrows them.
    pub fn flags(&self) -> Flags<'_> {
        Flags::Packed {
            words: &self.words,
            len: self.len(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Packed flags read back as the bools they were built from, and make
    /// the same cache flags as those bools (lengths across word edges and
    /// past the inline capacity).
    #[test]
    fn round_trip_and_cache_flags() {
        for len in [0usize, 1, 63, 64, 65, 145, 192, 193, 400] {
            let bools: Vec<bool> = (0..len).map(|i| (i * 7 + i / 3) % 5 < 2).collect();
            let mut f = SunFlags::shaded(len);
            for (i, &b) in bools.iter().enumerate() {
                if b {
                    f.set_sunlit(i);
                }
            }
            assert_eq!(f.iter().collect::<Vec<_>>(), bools);
            assert_eq!(SunFlags::from_words(&f.words, len), f);
            assert_eq!(f.count_sunlit(), bools.iter().filter(|b| **b).count());
            assert_eq!(f.last(), bools.last().copied());
            assert_eq!(f.flags(), Flags::Bools(&bools));
            assert_eq!(f.flags().any_shaded(), bools.iter().any(|b| !b));
            assert_eq!(f.flags().to_bools(), bools);
        }
        let mut all = SunFlags::shaded(130);
        (0..130).for_each(|i| all.set_sunlit(i));
        assert!(!all.flags().any_shaded());
    }
}

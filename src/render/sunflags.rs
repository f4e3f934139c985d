//! The sun/shadow history of one surface point as a compact record: the
//! flag of the first sample and the sample indices at which the flag
//! changes (its transitions), stored inline (no heap allocation) up to
//! [`INLINE_SWITCHES`] transitions. A history at a fine time resolution
//! (the transitions found by bisection, `render.shadow_resolution_min`)
//! costs no more memory than a coarse one with as many transitions.

use smallvec::SmallVec;

use crate::therm::cache::Flags;

/// Transitions a history holds without a heap allocation.
pub const INLINE_SWITCHES: usize = 6;

/// Sunlit flags of `len` samples: sample 0 is `first`; the flag flips at
/// each index of `switches` (ascending, each in 1..len).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SunFlags {
    switches: SmallVec<[u32; INLINE_SWITCHES]>,
    len: u32,
    first: bool,
}

impl SunFlags {
    /// `len` samples, all shaded.
    pub fn shaded(len: usize) -> Self {
        SunFlags {
            switches: SmallVec::new(),
            len: len as u32,
            first: false,
        }
    }

    /// `len` samples from their packed words (sample `i` in bit `i % 64`
    /// of `words[i / 64]`; `len.div_ceil(64)` words, bits past `len` zero).
    pub fn from_words(words: &[u64], len: usize) -> Self {
        debug_assert_eq!(words.len(), len.div_ceil(64));
        let bit = |i: usize| words[i / 64] >> (i % 64) & 1 == 1;
        let first = len > 0 && bit(0);
        let mut switches = SmallVec::new();
        let mut cur = first;
        for (w, &word) in words.iter().enumerate() {
            // Bits that differ from their predecessor: word ^ (word << 1
            // carrying the previous word's top bit / the current flag).
            // `cur`: the flag of the sample before this word's first
            // (sample 0 for the first word, so bit 0 never counts).
            let shifted = word << 1 | u64::from(cur);
            let n = (len - 64 * w).min(64);
            let valid = if n == 64 { u64::MAX } else { (1u64 << n) - 1 };
            let mut diff = (word ^ shifted) & valid;
            while diff != 0 {
                let b = diff.trailing_zeros() as usize;
                switches.push((64 * w + b) as u32);
                diff &= diff - 1;
            }
            if n > 0 {
                cur = word >> (n - 1) & 1 == 1;
            }
        }
        SunFlags {
            switches,
            len: len as u32,
            first,
        }
    }

    /// `len` samples: sample 0 is `first` and the flag flips at each of
    /// `switches` (ascending, in 1..len).
    pub fn from_switches(first: bool, switches: &[u32], len: usize) -> Self {
        debug_assert!(switches.windows(2).all(|w| w[0] < w[1]));
        debug_assert!(switches.iter().all(|&s| s >= 1 && (s as usize) < len));
        SunFlags {
            switches: SmallVec::from_slice(switches),
            len: len as u32,
            first: first && len > 0,
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.len as usize
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The sample indices at which the flag changes (ascending).
    pub fn switches(&self) -> &[u32] {
        &self.switches
    }

    /// Whether sample `i` is sunlit (false past the end).
    pub fn get(&self, i: usize) -> bool {
        if i >= self.len() {
            return false;
        }
        let flips = self.switches.partition_point(|&s| s as usize <= i);
        self.first ^ (flips % 2 == 1)
    }

    /// The last sample (the image time); `None` for an empty history.
    pub fn last(&self) -> Option<bool> {
        if self.is_empty() {
            None
        } else {
            Some(self.first ^ (self.switches.len() % 2 == 1))
        }
    }

    /// Number of sunlit samples.
    pub fn count_sunlit(&self) -> usize {
        let mut n = 0;
        let mut on = self.first;
        let mut from = 0usize;
        for &s in self.switches.iter().chain(std::iter::once(&self.len)) {
            if on {
                n += s as usize - from;
            }
            on = !on;
            from = s as usize;
        }
        n
    }

    /// The flags in sample order.
    pub fn iter(&self) -> impl Iterator<Item = bool> + '_ {
        (0..self.len()).map(|i| self.get(i))
    }

    /// The flags as the thermal cache borrows them.
    pub fn flags(&self) -> Flags<'_> {
        Flags::Switches {
            first: self.first,
            switches: &self.switches,
            len: self.len(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pack(bools: &[bool]) -> Vec<u64> {
        let mut w = vec![0u64; bools.len().div_ceil(64)];
        for (i, &b) in bools.iter().enumerate() {
            if b {
                w[i / 64] |= 1 << (i % 64);
            }
        }
        w
    }

    /// Packed flags read back as the bools they were built from, and make
    /// the same cache flags as those bools (lengths across word edges and
    /// past the inline capacity, few and many transitions).
    #[test]
    fn round_trip_and_cache_flags() {
        let patterns: [fn(usize) -> bool; 4] = [
            |i| (i * 7 + i / 3) % 5 < 2,
            |i| (i / 40) % 2 == 1,
            |_| true,
            |i| i % 64 == 63 || i % 64 == 0,
        ];
        for len in [0usize, 1, 63, 64, 65, 145, 192, 193, 400, 1153] {
            for p in patterns {
                let bools: Vec<bool> = (0..len).map(p).collect();
                let f = SunFlags::from_words(&pack(&bools), len);
                assert_eq!(f.iter().collect::<Vec<_>>(), bools, "len {len}");
                let sw: Vec<u32> = (1..len)
                    .filter(|&i| bools[i] != bools[i - 1])
                    .map(|i| i as u32)
                    .collect();
                assert_eq!(f.switches(), &sw[..]);
                assert_eq!(
                    SunFlags::from_switches(bools.first() == Some(&true), &sw, len),
                    f
                );
                assert_eq!(f.count_sunlit(), bools.iter().filter(|b| **b).count());
                assert_eq!(f.last(), bools.last().copied());
                assert_eq!(f.flags(), Flags::Bools(&bools));
                assert_eq!(f.flags().words().collect::<Vec<_>>(), pack(&bools));
                assert_eq!(f.flags().any_shaded(), bools.iter().any(|b| !b));
                assert_eq!(f.flags().to_bools(), bools);
            }
        }
        assert!(!SunFlags::shaded(0).flags().any_shaded());
        assert!(SunFlags::shaded(3).flags().any_shaded());
    }
}

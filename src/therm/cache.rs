//! Memoising cache of slab solutions (docs/models.md, "Memoising").
//!
//! A pixel's temperature depends only on (material, facet orientation,
//! sun/shadow history, weather); many pixels share such a key, so each key
//! is solved once. The orientation is quantised to
//! [`ThermCache::orientation_quantum_deg`] and the solve uses the
//! *quantised* orientation, so a result is a function of its key alone: the
//! output does not depend on which pixel (or thread) asked first, i.e. it is
//! deterministic whatever the thread count.
//!
//! Lookups: a [`ThermQuery`] borrows the pixel's history (nothing is cloned
//! or allocated); its 64-bit hash is computed once and picks the shard and
//! the map slot; equality is decided on the full key (hash collisions only
//! cost a comparison). A [`ThermMemo`] remembers the last key a worker
//! asked for and its temperature: neighbouring pixels mostly share keys, and
//! a memo hit skips the hash and the shard lock.
//!
//! Concurrency: 64 shards, each a `Mutex<HashMap<hash, [(key, slot)]>>`.
//! The shard lock is held only to find or insert the entry (and to read an
//! entry already solved); a solve runs outside it, inside
//! `OnceLock::get_or_init`, so every key is solved exactly once and
//! concurrent askers of the same key wait for that one solve.
//!
//! Meshes: the graded mesh depends only on the material's ρ, c, k, L and
//! the settings; it is built once per such material and shared by every
//! solve of it.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, DefaultHasher, Hash, Hasher};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

use super::balance::Orientation;
use super::forcing::Forcing;
use super::slab::{
    MarchState, Mesh, SPIN_UP_MEAN_WINDOW_S, SlabMaterial, SlabModel, SpinUpStart, SunHistory,
    ThermError, ThermSettings, ThermSolution,
};

const SHARDS: usize = 64;

/// The shard of a 64-bit hash: from bits the map's own slot choice does
/// not use (the solved entries and the checkpoint states alike).
fn shard_of(hash: u64) -> usize {
    ((hash >> 32) as usize) % SHARDS
}

/// The owned memoisation key (what an entry stores; a lookup borrows
/// its parts as a [`ThermQuery`]).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct ThermKey {
    /// The caller's id of the material.
    pub material_id: u32,
    /// Quantised slope and aspect, in units of the cache's quantum.
    pub slope_q: i32,
    /// Quantised aspect, in units of the cache's quantum.
    pub aspect_q: i32,
    /// Shadow history (all zeros / empty = always sunlit).
    pub shadow_start_s: i64,
    /// Interval of the history's samples, s.
    pub shadow_interval_s: i64,
    /// Number of history samples.
    pub shadow_len: u32,
    /// The sunlit flags, packed 64 to a word.
    pub shadow_bits: Box<[u64]>,
    /// Caller's identity of the forcing series (weather + site + time window).
    pub weather_id: u64,
    /// Facet height above the ground, quantised by [`ThermCache::quantise_height`].
    pub height_q: i32,
    /// Fraction of the hemisphere's sky hidden by the scene, in units of
    /// [`SKY_QUANTUM`] (0: unobstructed).
    pub blocked_q: i32,
}

/// A borrowed sun/shadow history: sample `i` at `start_s + i·interval_s`
/// (the same rules as [`SunHistory`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HistoryRef<'a> {
    /// Time of sample 0, s from the start of the run.
    pub start_s: i64,
    /// Interval between samples, s.
    pub interval_s: i64,
    /// The sunlit flag of each sample.
    pub sunlit: Flags<'a>,
}

/// Borrowed sunlit flags: one `bool` per sample, or packed 64 to a word
/// (bit `i % 64` of word `i / 64` = sample `i`; bits past `len` zero). Both
/// forms of the same flags make the same key.
#[derive(Clone, Copy, Debug)]
pub enum Flags<'a> {
    /// One `bool` per sample.
    Bools(&'a [bool]),
    /// Packed 64 to a word.
    Packed {
        /// The words (bit `i % 64` of word `i / 64` = sample `i`).
        words: &'a [u64],
        /// Number of samples.
        len: usize,
    },
    /// Sample 0 is `first`; the flag flips at each index of `switches`
    /// (ascending, in 1..len).
    Switches {
        /// The flag of sample 0.
        first: bool,
        /// Indices where the flag flips, ascending.
        switches: &'a [u32],
        /// Number of samples.
        len: usize,
    },
}

/// Bits `a..b` (0 ≤ a ≤ b ≤ 64) of a word set.
fn bit_range(a: usize, b: usize) -> u64 {
    if b <= a {
        0
    } else if b - a == 64 {
        u64::MAX
    } else {
        ((1u64 << (b - a)) - 1) << a
    }
}

/// The packed words of a [`Flags::Switches`], one word at a time.
fn switch_words<'a>(
    first: bool,
    switches: &'a [u32],
    len: usize,
) -> impl Iterator<Item = u64> + 'a {
    let mut j = 0usize;
    let mut cur = first;
    (0..len.div_ceil(64)).map(move |w| {
        let start = 64 * w;
        let end = (start + 64).min(len);
        let mut word = 0u64;
        let mut pos = start;
        while j < switches.len() && (switches[j] as usize) < end {
            let s = switches[j] as usize;
            if cur {
                word |= bit_range(pos - start, s - start);
            }
            cur = !cur;
            pos = s;
            j += 1;
        }
        if cur {
            word |= bit_range(pos - start, end - start);
        }
        word
    })
}

impl Flags<'_> {
    /// Number of samples.
    pub fn len(&self) -> usize {
        match self {
            Flags::Bools(b) => b.len(),
            Flags::Packed { len, .. } | Flags::Switches { len, .. } => *len,
        }
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The flags packed 64 to a word.
    pub fn words(&self) -> impl Iterator<Item = u64> + '_ {
        let (bools, words, sw) = match self {
            Flags::Bools(b) => (Some(*b), None, None),
            Flags::Packed { words, .. } => (None, Some(*words), None),
            Flags::Switches {
                first,
                switches,
                len,
            } => (None, None, Some(switch_words(*first, switches, *len))),
        };
        bools
            .into_iter()
            .flat_map(packed_words)
            .chain(words.into_iter().flatten().copied())
            .chain(sw.into_iter().flatten())
    }

    /// True when some sample is shaded.
    pub fn any_shaded(&self) -> bool {
        match self {
            Flags::Bools(b) => b.iter().any(|x| !x),
            Flags::Packed { words, len } => words.iter().enumerate().any(|(i, w)| {
                let n = (*len - 64 * i).min(64);
                let full = if n == 64 { u64::MAX } else { (1u64 << n) - 1 };
                w & full != full
            }),
            Flags::Switches {
                first,
                switches,
                len,
            } => *len > 0 && (!switches.is_empty() || !first),
        }
    }

    /// The flags, one `bool` per sample.
    pub fn to_bools(&self) -> Vec<bool> {
        match self {
            Flags::Bools(b) => b.to_vec(),
            Flags::Packed { words, len } => (0..*len)
                .map(|i| words[i / 64] >> (i % 64) & 1 == 1)
                .collect(),
            Flags::Switches {
                first,
                switches,
                len,
            } => {
                let mut v = vec![*first; *len];
                for (k, &s) in switches.iter().enumerate() {
                    let end = switches.get(k + 1).map_or(*len, |&e| e as usize);
                    v[s as usize..end].fill(*first ^ (k % 2 == 0));
                }
                v
            }
        }
    }
}

impl PartialEq for Flags<'_> {
    fn eq(&self, other: &Self) -> bool {
        self.len() == other.len() && self.words().eq(other.words())
    }
}

impl Eq for Flags<'_> {}

impl<'a> From<&'a SunHistory> for HistoryRef<'a> {
    fn from(h: &'a SunHistory) -> Self {
        HistoryRef {
            start_s: h.start_s,
            interval_s: h.interval_s,
            sunlit: Flags::Bools(&h.sunlit),
        }
    }
}

/// A cache key that borrows its history: what a lookup needs, built
/// without allocating by [`ThermCache::query`].
#[derive(Clone, Copy, Debug)]
pub struct ThermQuery<'a> {
    material_id: u32,
    slope_q: i32,
    aspect_q: i32,
    /// `None`: always sunlit (no history, or an all-sunlit one).
    history: Option<HistoryRef<'a>>,
    weather_id: u64,
    height_q: i32,
    blocked_q: i32,
}

/// What a caller knows of a facet side, in its own units, before the
/// cache quantises it into a [`ThermQuery`] ([`ThermCache::query`]).
/// [`FacetKey::new`] gives a sunlit facet at ground level under an open
/// sky; set the other fields with struct update syntax.
#[derive(Clone, Copy, Debug)]
pub struct FacetKey<'a> {
    /// The caller's id of the material (the cache trusts it: one id, one
    /// material).
    pub material_id: u32,
    /// Orientation of the facet (the cache quantises it).
    pub orientation: Orientation,
    /// Sun/shadow history; `None`: always sunlit.
    pub shadow: Option<HistoryRef<'a>>,
    /// The caller's id of the forcing series (weather + site + window).
    pub weather_id: u64,
    /// Height of the facet above the ground, m (the wind at the facet).
    pub height_m: f64,
    /// Fraction of the hemisphere's sky hidden by the scene, 0-1 (see
    /// `trace::sky_view`).
    pub blocked_sky: f64,
}

impl FacetKey<'_> {
    /// A sunlit facet at ground level under an open sky.
    pub fn new(material_id: u32, orientation: Orientation, weather_id: u64) -> Self {
        FacetKey {
            material_id,
            orientation,
            shadow: None,
            weather_id,
            height_m: 0.0,
            blocked_sky: 0.0,
        }
    }
}

/// The flags packed 64 to a word (bit i of word i/64 = sample i), one word
/// at a time.
fn packed_words(sunlit: &[bool]) -> impl Iterator<Item = u64> + '_ {
    sunlit.chunks(64).map(|c| {
        c.iter()
            .enumerate()
            .fold(0u64, |w, (i, &b)| w | (u64::from(b) << i))
    })
}

impl ThermQuery<'_> {
    /// The 64-bit hash of the key (SipHash-1-3 of its fields and packed
    /// history words; the same for equal keys, whatever built them).
    fn hash64(&self) -> u64 {
        let mut h = DefaultHasher::new();
        (self.material_id, self.slope_q, self.aspect_q).hash(&mut h);
        (self.weather_id, self.height_q, self.blocked_q).hash(&mut h);
        if let Some(s) = &self.history {
            (s.start_s, s.interval_s, s.sunlit.len()).hash(&mut h);
            for w in s.sunlit.words() {
                h.write_u64(w);
            }
        }
        h.finish()
    }

    /// True when `k` is this key.
    fn matches(&self, k: &ThermKey) -> bool {
        let scalars = k.material_id == self.material_id
            && k.slope_q == self.slope_q
            && k.aspect_q == self.aspect_q
            && k.weather_id == self.weather_id
            && k.height_q == self.height_q
            && k.blocked_q == self.blocked_q;
        scalars
            && match &self.history {
                None => k.shadow_len == 0,
                Some(s) => {
                    k.shadow_start_s == s.start_s
                        && k.shadow_interval_s == s.interval_s
                        && k.shadow_len as usize == s.sunlit.len()
                        && s.sunlit.words().eq(k.shadow_bits.iter().copied())
                }
            }
    }

    /// The owned key (allocates the history words).
    fn to_key(self) -> ThermKey {
        let (start, interval, len, bits) = match self.history {
            Some(s) => (
                s.start_s,
                s.interval_s,
                s.sunlit.len() as u32,
                s.sunlit.words().collect(),
            ),
            None => (0, 0, 0, Box::default()),
        };
        ThermKey {
            material_id: self.material_id,
            slope_q: self.slope_q,
            aspect_q: self.aspect_q,
            shadow_start_s: start,
            shadow_interval_s: interval,
            shadow_len: len,
            shadow_bits: bits,
            weather_id: self.weather_id,
            height_q: self.height_q,
            blocked_q: self.blocked_q,
        }
    }
}

/// The sky-view nodes of a point ([`ThermCache::sky_nodes`]): the lower
/// node's and the upper node's facet parts and the upper one's weight.
pub type SkyNodes = (FacetParts, FacetParts, f64);

/// The key parts of a facet side ([`ThermCache::facet_parts`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FacetParts {
    slope_q: i32,
    aspect_q: i32,
    blocked_q: i32,
}

impl FacetParts {
    /// The blocked sky fraction's key part, in [`SKY_QUANTUM`]s.
    pub fn blocked_q(&self) -> i32 {
        self.blocked_q
    }
}

/// A worker's memo of the last key it asked for and the surface
/// temperature found (see the module docs). Start one per worker (or per
/// chunk of pixels) with `ThermMemo::default()`; it keeps its own copy of
/// the last history (a buffer reused from key to key).
#[derive(Debug, Default)]
pub struct ThermMemo {
    valid: bool,
    scalars: (u32, i32, i32, u64, i32, i32),
    /// (start, interval) of the history; `None`: always sunlit.
    clock: Option<(i64, i64)>,
    /// The history's length and packed words.
    len: usize,
    words: Vec<u64>,
    temp_k: f64,
    /// Lookups answered by the memo.
    pub hits: u64,
}

impl ThermMemo {
    fn scalars(q: &ThermQuery) -> (u32, i32, i32, u64, i32, i32) {
        (
            q.material_id,
            q.slope_q,
            q.aspect_q,
            q.weather_id,
            q.height_q,
            q.blocked_q,
        )
    }

    /// The remembered temperature if `q` is the last key.
    fn get(&self, q: &ThermQuery) -> Option<f64> {
        let same = self.valid
            && self.scalars == Self::scalars(q)
            && match &q.history {
                None => self.clock.is_none(),
                Some(h) => {
                    self.clock == Some((h.start_s, h.interval_s))
                        && self.len == h.sunlit.len()
                        && h.sunlit.words().eq(self.words.iter().copied())
                }
            };
        same.then_some(self.temp_k)
    }

    fn set(&mut self, q: &ThermQuery, temp_k: f64) {
        self.valid = true;
        self.scalars = Self::scalars(q);
        self.clock = q.history.map(|h| (h.start_s, h.interval_s));
        self.words.clear();
        self.len = 0;
        if let Some(h) = &q.history {
            self.len = h.sunlit.len();
            self.words.extend(h.sunlit.words());
        }
        self.temp_k = temp_k;
    }
}

/// Keys are stored under their precomputed hash; this hasher passes it on.
#[derive(Default)]
struct PassHash(u64);

impl Hasher for PassHash {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        // Only `write_u64` is used (the map's key is the u64 hash).
        for &b in bytes {
            self.0 = self.0.rotate_left(8) ^ u64::from(b);
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = v;
    }
}

/// One shard: entries by hash; a bucket holds the keys that share a hash.
type Shard = HashMap<u64, Vec<(ThermKey, Slot)>, BuildHasherDefault<PassHash>>;

/// Memory the kept checkpoint states of one cache may take, bytes (64 MiB:
/// ~60,000 states of a 60-node slab; the airfield at 512² with irsig's
/// defaults keeps ~300,000 when unbounded, with `shadow_key_recent_h = 2`
/// ~43,000).
pub const CHECKPOINT_BUDGET_BYTES: u64 = 64 << 20;

/// The key of a checkpoint state: the key's scalar parts, the history's
/// clock, the forcing sample the march stands at, and the history's flags
/// up to the last sample a step before that sample reads (bits past it
/// zero).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct PrefixKey {
    scalars: (u32, i32, i32, u64, i32, i32),
    clock: (i64, i64, usize),
    at: usize,
    words: Box<[u64]>,
}

/// One shard of checkpoint states, by the hash of their [`PrefixKey`].
type PrefixShard = HashMap<u64, Vec<(PrefixKey, Arc<MarchState>)>, BuildHasherDefault<PassHash>>;

/// A checkpoint of a march: the forcing sample it stands at and the number
/// of history samples that decide the march up to there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Checkpoint {
    at: usize,
    flags: usize,
}

/// Quantum of the blocked sky fraction in the cache key (and the solve):
/// ±0.01 of the hemisphere, about ±1 W/m² of longwave — up to 0.29 K on a
/// thin shaded plate in the test `sky_nodes_interpolate_the_blocked_sky`;
/// a render solves at [`SKY_NODE_QUANTA`] nodes and interpolates instead.
pub const SKY_QUANTUM: f64 = 0.02;

/// Spacing of the sky-view nodes a render solves at, in [`SKY_QUANTUM`]s
/// (0.1 of the hemisphere): a point whose blocked fraction lies between two
/// nodes takes the linear interpolation of their surface temperatures
/// ([`ThermCache::sky_nodes`]). The surface temperature is a smooth
/// function of the blocked fraction (the longwave it trades, ≈ b·(σT_g⁴ −
/// L_sky), is linear in b; the balance's curvature in T is weak, largest
/// where convection changes regime), so against the slab model solved at
/// the point's own fraction the interpolation is off by RMS 0.016, max
/// 0.13 K (test `sky_nodes_interpolate_the_blocked_sky`; keying on the
/// quantum alone: 0.13, 0.29 K) — while the points along a sky-view
/// gradient (beside a building) share the solves of a few nodes instead of
/// one per quantum (BENCHMARKS.md, session 18: nodes 0.2 apart give max
/// 0.37 K).
pub const SKY_NODE_QUANTA: i32 = 5;

/// Hit/miss counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CacheStats {
    /// Lookups answered from an entry (or a worker's memo).
    pub hits: u64,
    /// Lookups that created an entry (each solved once).
    pub misses: u64,
    /// Entries held.
    pub entries: u64,
    /// Over all solves: accepted and rejected march steps, Newton
    /// iterations (surface-balance evaluations), and the core time spent
    /// solving, ns (a measurement, never part of an output).
    pub steps: u64,
    /// Rejected march steps.
    pub steps_rejected: u64,
    /// Newton iterations (surface-balance evaluations).
    pub newton_iterations: u64,
    /// Core time spent solving, ns.
    pub solve_ns: u64,
    /// March states kept at checkpoints, and solves that resumed from one
    /// instead of marching from the spin-up.
    pub checkpoints: u64,
    /// Solves that resumed from a checkpoint.
    pub resumed: u64,
}

type Slot = Arc<OnceLock<Result<Arc<ThermSolution>, ThermError>>>;

/// What the graded mesh depends on in a material: ρ, c, k, L and each
/// layer's L, k, ρ, c (bit patterns).
type MeshKey = Vec<u64>;

/// Concurrent memoising cache of [`ThermSolution`]s for one set of
/// [`ThermSettings`].
pub struct ThermCache {
    settings: ThermSettings,
    orientation_quantum_deg: f64,
    with_series: bool,
    shards: Vec<Mutex<Shard>>,
    /// March states at checkpoints, by the key part and history prefix
    /// that determine them (see [`ThermCache::checkpoints`]).
    prefixes: Vec<Mutex<PrefixShard>>,
    /// Checkpoint states kept, their bytes, and solves resumed from one.
    prefix_entries: AtomicU64,
    prefix_bytes: AtomicU64,
    resumed: AtomicU64,
    meshes: Mutex<Vec<(MeshKey, Arc<Mesh>)>>,
    hits: AtomicU64,
    misses: AtomicU64,
    steps: AtomicU64,
    steps_rejected: AtomicU64,
    newton: AtomicU64,
    solve_ns: AtomicU64,
}

impl ThermCache {
    /// Default orientation quantum, degrees (a 0.5° slope error changes
    /// cos(incidence) by < 0.9 %).
    pub const DEFAULT_QUANTUM_DEG: f64 = 0.5;

    /// `with_series`: keep the per-forcing-sample series in every entry
    /// (the render needs only the final temperature).
    pub fn new(
        settings: ThermSettings,
        orientation_quantum_deg: f64,
        with_series: bool,
    ) -> ThermCache {
        ThermCache {
            settings,
            orientation_quantum_deg: if orientation_quantum_deg > 0.0 {
                orientation_quantum_deg
            } else {
                Self::DEFAULT_QUANTUM_DEG
            },
            with_series,
            shards: (0..SHARDS).map(|_| Mutex::new(Shard::default())).collect(),
            prefixes: (0..SHARDS)
                .map(|_| Mutex::new(PrefixShard::default()))
                .collect(),
            prefix_entries: AtomicU64::new(0),
            prefix_bytes: AtomicU64::new(0),
            resumed: AtomicU64::new(0),
            meshes: Mutex::new(Vec::new()),
            hits: AtomicU64::new(0),
            misses: AtomicU64::new(0),
            steps: AtomicU64::new(0),
            steps_rejected: AtomicU64::new(0),
            newton: AtomicU64::new(0),
            solve_ns: AtomicU64::new(0),
        }
    }

    /// The thermal settings every solve of this cache uses.
    pub fn settings(&self) -> &ThermSettings {
        &self.settings
    }

    /// The orientation quantum, degrees.
    pub fn orientation_quantum_deg(&self) -> f64 {
        self.orientation_quantum_deg
    }

    /// Quantises an orientation: slope and aspect rounded to the quantum,
    /// aspect wrapped to [0°, 360°), and aspect set to 0 on a horizontal
    /// facet (where it does not matter). Returns the integer key parts and
    /// the orientation they stand for.
    pub fn quantise(&self, o: Orientation) -> (i32, i32, Orientation) {
        let q = self.orientation_quantum_deg;
        let slope_q = (o.slope_deg / q).round() as i32;
        let full = (360.0 / q).round() as i32;
        let mut aspect_q = ((o.aspect_deg / q).round() as i32).rem_euclid(full.max(1));
        if slope_q == 0 || slope_q as f64 * q >= 180.0 {
            aspect_q = 0;
        }
        (
            slope_q,
            aspect_q,
            Orientation {
                slope_deg: slope_q as f64 * q,
                aspect_deg: aspect_q as f64 * q,
            },
        )
    }

    /// The orientation that the integer key parts stand for.
    fn dequantise(&self, slope_q: i32, aspect_q: i32) -> Orientation {
        Orientation {
            slope_deg: slope_q as f64 * self.orientation_quantum_deg,
            aspect_deg: aspect_q as f64 * self.orientation_quantum_deg,
        }
    }

    /// Quantises a facet's height above the ground: steps of 5 % in
    /// `ln((z + 2 m)/2 m)` (the log-law wind changes by well under 1 % per
    /// step); returns the key part and the height it stands for, m.
    pub fn quantise_height(height_m: f64) -> (i32, f64) {
        let z = if height_m.is_finite() {
            height_m.clamp(0.0, 1e4)
        } else {
            0.0
        };
        let q = (((z + 2.0) / 2.0).ln() / 0.05).round() as i32;
        (q, Self::height_of(q))
    }

    /// The height that key part `q` stands for, m.
    fn height_of(q: i32) -> f64 {
        (2.0 * (0.05 * q as f64).exp() - 2.0).max(0.0)
    }

    /// The key part of a blocked sky fraction (see [`SKY_QUANTUM`]).
    fn quantise_blocked(blocked_sky: f64) -> i32 {
        (Self::blocked_fraction(blocked_sky) / SKY_QUANTUM).round() as i32
    }

    /// A blocked sky fraction as the key uses it: clamped to [0, 1], 0 when
    /// not finite.
    fn blocked_fraction(blocked_sky: f64) -> f64 {
        if blocked_sky.is_finite() {
            blocked_sky.clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// The borrowed key of facet `k` (its quantised orientation, height
    /// and blocked sky, and its history: an all-sunlit history is the same
    /// as none). Allocates nothing.
    pub fn query<'a>(&self, k: &FacetKey<'a>) -> ThermQuery<'a> {
        self.query_parts(
            k.material_id,
            self.facet_parts(k.orientation, k.blocked_sky),
            k.shadow,
            k.weather_id,
            Self::quantise_height(k.height_m).0,
        )
    }

    /// The key parts of a facet side: its quantised orientation and blocked
    /// sky (a pure function of them, so a caller may keep it for the next
    /// sample on the same facet).
    pub fn facet_parts(&self, o: Orientation, blocked_sky: f64) -> FacetParts {
        let (slope_q, aspect_q, _) = self.quantise(o);
        FacetParts {
            slope_q,
            aspect_q,
            blocked_q: Self::quantise_blocked(blocked_sky),
        }
    }

    /// The two sky-view nodes around a blocked sky fraction and the weight
    /// of the upper one: `(lo, hi, w)` with the fraction ≈ (1 − w)·lo + w·hi;
    /// `lo` and `hi` are facet parts whose blocked fraction is a multiple of
    /// [`SKY_NODE_QUANTA`] quanta. A fraction on a node (open ground:
    /// exactly 0) gives `w` = 0 and `hi` = `lo`. A pure function of the
    /// arguments (so the interpolated temperature is one of the key alone).
    pub fn sky_nodes(&self, o: Orientation, blocked_sky: f64) -> SkyNodes {
        let lo = self.facet_parts(o, 0.0);
        let x = Self::blocked_fraction(blocked_sky) / (SKY_QUANTUM * SKY_NODE_QUANTA as f64);
        let k = x.floor();
        let w = x - k;
        let at = |k: i32| FacetParts {
            blocked_q: k * SKY_NODE_QUANTA,
            ..lo
        };
        // (within 1e-9 of a node: that node alone; never a weight of 1)
        if w < 1e-9 {
            (at(k as i32), at(k as i32), 0.0)
        } else if w > 1.0 - 1e-9 {
            (at(k as i32 + 1), at(k as i32 + 1), 0.0)
        } else {
            (at(k as i32), at(k as i32 + 1), w)
        }
    }

    /// [`Self::query`] from a facet's key parts ([`Self::facet_parts`]) and
    /// a quantised height ([`Self::quantise_height`]): the same key.
    pub fn query_parts<'a>(
        &self,
        material_id: u32,
        facet: FacetParts,
        shadow: Option<HistoryRef<'a>>,
        weather_id: u64,
        height_q: i32,
    ) -> ThermQuery<'a> {
        ThermQuery {
            material_id,
            slope_q: facet.slope_q,
            aspect_q: facet.aspect_q,
            // An all-sunlit history is the same as no history.
            history: shadow.filter(|h| h.sunlit.any_shaded()),
            weather_id,
            height_q,
            blocked_q: facet.blocked_q,
        }
    }

    /// The solution of key `q`, solving it (once) on a miss. `material`
    /// must be the material that the key's `material_id` names and
    /// `forcing` the series that its `weather_id` names: the cache trusts
    /// the ids.
    pub fn solve_query(
        &self,
        q: &ThermQuery,
        material: &SlabMaterial,
        forcing: &[Forcing],
    ) -> Result<Arc<ThermSolution>, ThermError> {
        self.lookup(q, material, forcing, |r| r.clone())
    }

    /// The surface temperature at the image time of key `q`, K, through the
    /// worker's `memo` (see [`ThermCache::solve_query`] for what `material` and
    /// `forcing` must be). A memo hit counts as a cache hit.
    pub fn surface_temp_k_memo(
        &self,
        q: &ThermQuery,
        material: &SlabMaterial,
        forcing: &[Forcing],
        memo: &mut ThermMemo,
    ) -> Result<f64, ThermError> {
        if let Some(t) = memo.get(q) {
            memo.hits += 1;
            return Ok(t);
        }
        let t = self.lookup(q, material, forcing, |r| {
            r.as_ref().map(|s| s.surface_temp_k).map_err(Clone::clone)
        })?;
        memo.set(q, t);
        Ok(t)
    }

    /// Adds the memo's hits to the cache's counters (call once per memo,
    /// when its worker is done).
    pub fn absorb_memo(&self, memo: &ThermMemo) {
        self.hits.fetch_add(memo.hits, Ordering::Relaxed);
    }

    /// Finds or solves key `q` and reads the entry with `read` (under the
    /// shard lock when the entry is already solved, so that no reference
    /// count is touched on the common path).
    fn lookup<R>(
        &self,
        q: &ThermQuery,
        material: &SlabMaterial,
        forcing: &[Forcing],
        read: impl Fn(&Result<Arc<ThermSolution>, ThermError>) -> R,
    ) -> R {
        let hash = q.hash64();
        let shard = &self.shards[shard_of(hash)];
        let slot: Slot = {
            let mut map = shard.lock().unwrap_or_else(|e| e.into_inner());
            let bucket = map.entry(hash).or_default();
            match bucket.iter().find(|(k, _)| q.matches(k)) {
                Some((_, s)) => {
                    self.hits.fetch_add(1, Ordering::Relaxed);
                    if let Some(r) = s.get() {
                        return read(r);
                    }
                    s.clone()
                }
                None => {
                    self.misses.fetch_add(1, Ordering::Relaxed);
                    let s: Slot = Arc::new(OnceLock::new());
                    bucket.push((q.to_key(), s.clone()));
                    s
                }
            }
        };
        read(slot.get_or_init(|| {
            let t0 = std::time::Instant::now();
            let r = self.solve_key(q, material, forcing);
            let ns = t0.elapsed().as_nanos().min(u128::from(u64::MAX)) as u64;
            self.solve_ns.fetch_add(ns, Ordering::Relaxed);
            if let Ok(s) = &r {
                let add = |c: &AtomicU64, n: usize| c.fetch_add(n as u64, Ordering::Relaxed);
                add(&self.steps, s.steps_accepted);
                add(&self.steps_rejected, s.steps_rejected);
                add(&self.newton, s.newton_iterations);
            }
            r
        }))
    }

    /// The graded mesh of `material` under this cache's settings (built
    /// once per distinct ρ, c, k, L and layers).
    fn mesh(&self, material: &SlabMaterial) -> Arc<Mesh> {
        let layers = material.layers.iter().flat_map(|l| {
            [
                l.thickness_m,
                l.conductivity_w_mk,
                l.density_kg_m3,
                l.specific_heat_j_kgk,
            ]
        });
        let key: MeshKey = [
            material.density_kg_m3,
            material.specific_heat_j_kgk,
            material.conductivity_w_mk,
            material.thickness_m,
        ]
        .into_iter()
        .chain(layers)
        .map(f64::to_bits)
        .collect();
        let mut meshes = self.meshes.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, m)) = meshes.iter().find(|(k, _)| *k == key) {
            return m.clone();
        }
        let m = Arc::new(Mesh::graded(material, &self.settings));
        meshes.push((key, m.clone()));
        m
    }

    /// Solves the facet that key `q` stands for (quantised orientation,
    /// height and blocked sky).
    ///
    /// A march with a history (and no series kept) stops at the
    /// [`Self::checkpoints`] and keeps its state there, keyed by what
    /// decided it: the key's other parts and the history's flags up to
    /// there. A later key whose history begins the same resumes from the
    /// latest such state instead of marching from the spin-up. Resuming is
    /// bit for bit the march that did not stop ([`SlabModel::advance`]), so
    /// a result is still a function of its key alone, whichever key was
    /// solved first and on whichever thread: only the work depends on the
    /// order.
    fn solve_key(
        &self,
        q: &ThermQuery,
        material: &SlabMaterial,
        forcing: &[Forcing],
    ) -> Result<Arc<ThermSolution>, ThermError> {
        let history = q.history.map(|h| SunHistory {
            start_s: h.start_s,
            interval_s: h.interval_s,
            sunlit: h.sunlit.to_bools(),
        });
        material.validate()?;
        let oq = self.dequantise(q.slope_q, q.aspect_q);
        let model = SlabModel::with_mesh(material, oq, &self.settings, self.mesh(material))?
            .with_height(Self::height_of(q.height_q))
            .with_blocked_sky(q.blocked_q as f64 * SKY_QUANTUM);
        let (Some(h), Some(hr), false) = (history.as_ref(), q.history, self.with_series) else {
            return model
                .solve(forcing, history.as_ref(), self.with_series)
                .map(Arc::new);
        };
        let cps = self.checkpoints(forcing, h);
        if cps.is_empty() {
            return model.solve(forcing, Some(h), false).map(Arc::new);
        }
        let words: Vec<u64> = hr.sunlit.words().collect();
        let prefix = |cp: &Checkpoint| PrefixKey {
            scalars: ThermMemo::scalars(q),
            clock: (h.start_s, h.interval_s, h.sunlit.len()),
            at: cp.at,
            words: words
                .iter()
                .enumerate()
                .map(|(i, &w)| w & bit_range(0, cp.flags.saturating_sub(64 * i).min(64)))
                .collect(),
        };
        let found = cps
            .iter()
            .enumerate()
            .rev()
            .find_map(|(j, cp)| self.prefix_get(&prefix(cp)).map(|s| (j, s)));
        let (mut state, next, base) = match found {
            Some((j, s)) => {
                self.resumed.fetch_add(1, Ordering::Relaxed);
                let base = (s.accepted, s.rejected, s.newton);
                (MarchState::clone(&s), j + 1, base)
            }
            None => (model.initial_state(forcing, Some(h))?, 0, (0, 0, 0)),
        };
        for cp in &cps[next..] {
            model.advance(&mut state, forcing, Some(h), cp.at, None)?;
            self.prefix_put(prefix(cp), &state);
        }
        let mut sol = model.march_on(state, forcing, Some(h), false)?;
        // The counters say the work this solve did.
        sol.steps_accepted -= base.0;
        sol.steps_rejected -= base.1;
        sol.newton_iterations -= base.2;
        Ok(Arc::new(sol))
    }

    /// The forcing samples where a march with history `h` keeps its state
    /// (ascending): the samples 1, 2, 4, 8, … h before the last one
    /// (rounded down to a sample), and the first sample after the window
    /// the initial state reads ([`SPIN_UP_MEAN_WINDOW_S`] under the mean
    /// forcing); none before that window's end, and none when the forcing
    /// starts before the history (its periodic extension would read the
    /// history's end). Histories of one facet mostly differ in their recent
    /// transitions (and, keyed, `render::key_history`, coarsely in their
    /// old ones), so a key resumes within hours of the image time.
    fn checkpoints(&self, forcing: &[Forcing], h: &SunHistory) -> Vec<Checkpoint> {
        let n = forcing.len();
        if n < 3 || h.interval_s <= 0 || forcing[0].t_s < h.start_s as f64 {
            return Vec::new();
        }
        let t0 = forcing[0].t_s;
        let t_end = forcing[n - 1].t_s;
        let window_end = match self.settings.spin_up_start {
            SpinUpStart::MeanForcing => t0 + SPIN_UP_MEAN_WINDOW_S,
            SpinUpStart::FirstSample => t0,
        };
        let mut at: Vec<usize> = Vec::new();
        // First sample at or after the window's end.
        at.push(forcing.partition_point(|f| f.t_s < window_end));
        let mut age_s = 3600.0;
        while t_end - age_s >= window_end {
            // Last sample at or before t_end − age.
            at.push(
                forcing
                    .partition_point(|f| f.t_s <= t_end - age_s)
                    .saturating_sub(1),
            );
            age_s *= 2.0;
        }
        at.retain(|&i| i >= 1 && i < n - 1 && forcing[i].t_s >= window_end);
        at.sort_unstable();
        at.dedup();
        at.into_iter()
            .map(|i| {
                // A step ending at sample i reads flags up to index
                // ⌊(t_i − start)/Δ⌋ + 1 (the ramp's next sample).
                let x = ((forcing[i].t_s - h.start_s as f64) / h.interval_s as f64).floor();
                let flags = (x.max(0.0) as usize + 2).min(h.sunlit.len());
                Checkpoint { at: i, flags }
            })
            .collect()
    }

    fn prefix_hash(k: &PrefixKey) -> u64 {
        let mut h = DefaultHasher::new();
        k.hash(&mut h);
        h.finish()
    }

    /// The checkpoint state of `k`, if one was kept.
    fn prefix_get(&self, k: &PrefixKey) -> Option<Arc<MarchState>> {
        let hash = Self::prefix_hash(k);
        let shard = &self.prefixes[shard_of(hash)];
        let map = shard.lock().unwrap_or_else(|e| e.into_inner());
        map.get(&hash)?
            .iter()
            .find(|(key, _)| key == k)
            .map(|(_, s)| s.clone())
    }

    /// Keeps the checkpoint state of `k` (unless one is kept already: two
    /// marches to one prefix give the same bits), while the kept states
    /// stay within [`CHECKPOINT_BUDGET_BYTES`] (beyond it later keys march
    /// from what is kept: more work, the same results).
    fn prefix_put(&self, k: PrefixKey, state: &MarchState) {
        let bytes = (std::mem::size_of::<(PrefixKey, Arc<MarchState>, MarchState)>()
            + 8 * (k.words.len() + 2 * state.nodes())) as u64;
        if self.prefix_bytes.fetch_add(bytes, Ordering::Relaxed) + bytes > CHECKPOINT_BUDGET_BYTES {
            self.prefix_bytes.fetch_sub(bytes, Ordering::Relaxed);
            return;
        }
        let hash = Self::prefix_hash(&k);
        let shard = &self.prefixes[shard_of(hash)];
        let mut map = shard.lock().unwrap_or_else(|e| e.into_inner());
        let bucket = map.entry(hash).or_default();
        if bucket.iter().any(|(key, _)| *key == k) {
            self.prefix_bytes.fetch_sub(bytes, Ordering::Relaxed);
        } else {
            bucket.push((k, Arc::new(state.clone())));
            self.prefix_entries.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Counters of the cache's use so far.
    pub fn stats(&self) -> CacheStats {
        let entries = self
            .shards
            .iter()
            .map(|s| {
                let map = s.lock().unwrap_or_else(|e| e.into_inner());
                map.values().map(|b| b.len() as u64).sum::<u64>()
            })
            .sum();
        CacheStats {
            hits: self.hits.load(Ordering::Relaxed),
            misses: self.misses.load(Ordering::Relaxed),
            entries,
            steps: self.steps.load(Ordering::Relaxed),
            steps_rejected: self.steps_rejected.load(Ordering::Relaxed),
            newton_iterations: self.newton.load(Ordering::Relaxed),
            solve_ns: self.solve_ns.load(Ordering::Relaxed),
            checkpoints: self.prefix_entries.load(Ordering::Relaxed),
            resumed: self.resumed.load(Ordering::Relaxed),
        }
    }
}

#[cfg(test)]
mod tests;

//! Mutations of seed inputs and the campaign runner.

use std::sync::atomic::{AtomicU64, Ordering};

use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestCaseError, TestRunner};

/// Values that break parsers: limits of f32/f64/i32/chrono, non-finite
/// spellings, tiny and huge magnitudes, the edges of the bounds.
pub const INTERESTING: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1",
    "2",
    "1e308",
    "-1e308",
    "1e-308",
    "1e-320",
    "1e-10",
    "1e30",
    "-1e30",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e39",
    "3.5e38",
    "262143",
    "-262144",
    "2147483648",
    "4294967296",
    "18446744073709551616",
    "99999999999999999999",
    "65536",
    "65537",
    "1899",
    "2201",
    "2200",
    "1900",
    "0.2",
    "100",
    "1e6",
    "1e5",
    "-14",
    "14",
    "-12",
    "24",
    "60",
    "",
];

/// Tokens inserted at random places.
const TOKENS: &[&str] = &[
    ",",
    "\n",
    "=",
    "[",
    "]",
    "{",
    "}",
    "\"",
    "#",
    "-",
    "e",
    "9",
    " ",
    "\t",
    "\r\n",
    ".",
    ":",
    "/",
    "T",
    "Z",
    "+",
    "usemtl x\n",
    "f 1 2 3\n",
    "f -1 -2 -3\n",
    "v 1e39 0 0\n",
    "data f32le\n",
    "quantity ",
    "=1,2,3",
    "[[object]]\n",
    "\u{FEFF}",
    "\u{0}",
    "é",
];

/// One edit of the input; positions are taken modulo the input's length.
#[derive(Clone, Debug)]
pub enum Edit {
    /// Replace the k-th number in the text with an interesting value.
    Number(usize, usize),
    /// Replace a byte.
    Byte(usize, u8),
    /// Delete `len` bytes at a position.
    Delete(usize, usize),
    /// Insert a token at a position.
    Insert(usize, usize),
    /// Duplicate the k-th line (repeat it `n` times).
    DupLine(usize, usize),
    /// Delete the k-th line.
    DelLine(usize),
    /// Swap two lines.
    Swap(usize, usize),
    /// Cut the input at a position.
    Truncate(usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        4 => (any::<usize>(), 0..INTERESTING.len()).prop_map(|(k, v)| Edit::Number(k, v)),
        2 => (any::<usize>(), any::<u8>()).prop_map(|(p, b)| Edit::Byte(p, b)),
        1 => (any::<usize>(), 1usize..64).prop_map(|(p, n)| Edit::Delete(p, n)),
        2 => (any::<usize>(), 0..TOKENS.len()).prop_map(|(p, t)| Edit::Insert(p, t)),
        1 => (any::<usize>(), 1usize..40).prop_map(|(k, n)| Edit::DupLine(k, n)),
        1 => any::<usize>().prop_map(Edit::DelLine),
        1 => (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Edit::Swap(a, b)),
        1 => any::<usize>().prop_map(Edit::Truncate),
    ]
}

/// A seed index and 1-3 edits (more edits mostly break the syntax).
pub fn mutation(n_seeds: usize) -> impl Strategy<Value = (usize, Vec<Edit>)> {
    (0..n_seeds, prop::collection::vec(edit(), 1..4))
}

/// Byte ranges of the numbers in `b` (digits with sign, dot, exponent).
fn numbers(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() {
            let mut s = i;
            if s > 0 && b[s - 1] == b'-' {
                s -= 1;
            }
            let mut e = i;
            while e < b.len()
                && (b[e].is_ascii_digit()
                    || b[e] == b'.'
                    || ((b[e] == b'e' || b[e] == b'E') && e + 1 < b.len()))
            {
                e += 1;
            }
            out.push((s, e));
            i = e.max(i + 1);
        } else {
            i += 1;
        }
    }
    out
}

fn line_ranges(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut s = 0;
    for (i, &c) in b.iter().enumerate() {
        if c == b'\n' {
            out.push((s, i + 1));
            s = i + 1;
        }
    }
    if s < b.len() {
        out.push((s, b.len()));
    }
    out
}

/// Applies the edits to a copy of `seed`.
pub fn apply(seed: &[u8], edits: &[Edit]) -> Vec<u8> {
    let mut b = seed.to_vec();
    for e in edits {
        let n = b.len().max(1);
        match *e {
            Edit::Number(k, v) => {
                let nums = numbers(&b);
                if !nums.is_empty() {
                    let (s, t) = nums[k % nums.len()];
                    b.splice(s..t, INTERESTING[v].bytes());
                }
            }
            Edit::Byte(p, x) => {
                if !b.is_empty() {
                    b[p % n] = x;
                }
            }
            Edit::Delete(p, len) => {
                let s = p % n;
                let t = (s + len).min(b.len());
                if s < t {
                    b.drain(s..t);
                }
            }
            Edit::Insert(p, t) => {
                let s = p % (b.len() + 1);
                b.splice(s..s, TOKENS[t].bytes());
            }
            Edit::DupLine(k, times) => {
                let lines = line_ranges(&b);
                if !lines.is_empty() {
                    let (s, t) = lines[k % lines.len()];
                    let line = b[s..t].to_vec();
                    for _ in 0..times {
                        b.splice(t..t, line.iter().copied());
                    }
                }
            }
            Edit::DelLine(k) => {
                let lines = line_ranges(&b);
                if !lines.is_empty() {
                    let (s, t) = lines[k % lines.len()];
                    b.drain(s..t);
                }
            }
            Edit::Swap(x, y) => {
                let lines = line_ranges(&b);
                if lines.len() >= 2 {
                    let (i, j) = (x % lines.len(), y % lines.len());
                    let (i, j) = (i.min(j), i.max(j));
                    if i != j {
                        let (a, c) = (lines[i], lines[j]);
                        let mut out = b[..a.0].to_vec();
                        out.extend_from_slice(&b[c.0..c.1]);
                        out.extend_from_slice(&b[a.1..c.0]);
                        out.extend_from_slice(&b[a.0..a.1]);
                        out.extend_from_slice(&b[c.1..]);
                        b = out;
                    }
                }
            }
            Edit::Truncate(p) => b.truncate(p % n),
        }
    }
    b
}

/// Cases per target: `IRSIG_FUZZ_CASES` (default 10 000).
pub fn cases() -> u32 {
    std::env::var("IRSIG_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10_000)
}

/// Counts of one campaign.
#[derive(Default)]
pub struct Tally {
    pub accepted: AtomicU64,
    pub refused: AtomicU64,
}

impl Tally {
    pub fn ok(&self) {
        self.accepted.fetch_add(1, Ordering::Relaxed);
    }
    pub fn err(&self) {
        self.refused.fetch_add(1, Ordering::Relaxed);
    }
}

/// Runs `cases()` cases of `strategy` through `test` with a fixed seed
/// (`IRSIG_FUZZ_SEED`, default the target name's hash, so each target sees
/// its own stream) and prints the tally. Fails with the minimal input on the
/// first failing case (a panic counts as a failure).
pub fn campaign<S: Strategy>(
    target: &str,
    strategy: S,
    test: impl Fn(S::Value, &Tally) -> Result<(), TestCaseError>,
) {
    let seed = std::env::var("IRSIG_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| {
            target.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
                (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
            })
        });
    let config = Config {
        cases: cases(),
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        max_shrink_iters: 2_000,
        ..Config::default()
    };
    let tally = Tally::default();
    let t0 = std::time::Instant::now();
    let mut runner = TestRunner::new(config);
    let result = runner.run(&strategy, |v| test(v, &tally));
    let (a, r) = (
        tally.accepted.load(Ordering::Relaxed),
        tally.refused.load(Ordering::Relaxed),
    );
    println!(
        "fuzz {target}: {} cases, {a} accepted, {r} refused, {:.1} s (seed {seed})",
        cases(),
        t0.elapsed().as_secs_f64()
    );
    if let Err(e) = result {
        panic!("fuzz {target}: {e}");
    }
}

/// Fails the case unless `cond`.
#[macro_export]
macro_rules! require {
    ($cond:expr, $($fmt:tt)*) => {
        if !$cond {
            return Err(proptest::test_runner::TestCaseError::fail(format!($($fmt)*)));
        }
    };
}

//! How a frame is cut for the workers: blocks of sample pixels (one rayon
//! task each, 4x4 tiles inside) and bands of sample rows (what memory holds
//! at once).

/// Pixels per block side (in supersampled pixels) handed to one rayon task.
pub(super) const BLOCK: u32 = 16;

/// The supersampled pixels of block (`bx`, `by`) (its top-left sample
/// pixel) of a `w`×`h` sample image, in 4x4 tile order: the packets a frame
/// traces.
pub(super) fn block_pixels(bx: u32, by: u32, w: u32, h: u32) -> Vec<(u32, u32)> {
    let (bw, bh) = (BLOCK.min(w - bx), BLOCK.min(h - by));
    crate::sensor::camera::tile_order(bw, bh, 4)
        .into_iter()
        .map(|(x, y)| (bx + x, by + y))
        .collect()
}

/// Sample rows a band of a frame holds: a multiple of [`BLOCK`] and of
/// the supersampling `n`, about [`BAND_SAMPLES`] samples.
fn band_rows(sample_width: u32, n: u32) -> u32 {
    let gcd = |mut a: u32, mut b: u32| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a
    };
    let unit = BLOCK / gcd(BLOCK, n) * n;
    (band_target() / sample_width.max(1) / unit * unit).max(unit)
}

/// [`BAND_SAMPLES`], or the environment's `IRSIG_BAND_SAMPLES` (a test
/// knob: results do not depend on it, which tests check with small bands).
pub(super) fn band_target() -> u32 {
    static TARGET: std::sync::OnceLock<u32> = std::sync::OnceLock::new();
    *TARGET.get_or_init(|| {
        std::env::var("IRSIG_BAND_SAMPLES")
            .ok()
            .and_then(|v| v.parse().ok())
            .filter(|&v| v > 0)
            .unwrap_or(BAND_SAMPLES)
    })
}

/// Samples a band of a frame `sample_width` samples wide holds with
/// supersampling `n` (the most samples a render holds at once).
pub fn band_samples(sample_width: u32, n: u32) -> u64 {
    band_rows(sample_width, n) as u64 * sample_width as u64
}

/// Samples per band: a frame is traced, solved and turned into plane rows
/// one band of sample rows at a time, so memory holds one band of
/// samples (about 15-30 MB; adaptive sampling: two coarse bands and, per
/// worker, one refined pixel's samples) besides the planes. 2^17, not 2^18:
/// the default 2048² airfield render peaked at 646 MiB with 2^18 and
/// peaks at 578-581 MiB with 2^17 (the same bits; issue 29's 0.6 GiB
/// target), while a band still holds hundreds of blocks for the workers.
const BAND_SAMPLES: u32 = 1 << 17;

/// The bands of a frame's `sample_height` rows: (first, end) sample rows.
pub(super) fn bands(sample_width: u32, sample_height: u32, n: u32) -> Vec<(u32, u32)> {
    let rows = band_rows(sample_width, n);
    (0..sample_height)
        .step_by(rows as usize)
        .map(|y0| (y0, (y0 + rows).min(sample_height)))
        .collect()
}

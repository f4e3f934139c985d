//! OpenEXR's ZIP and ZIPS block compression, written here so that irsig
//! picks the zlib implementation and level: the exr crate compresses with
//! miniz_oxide at a level fixed inside the crate (4); zlib-rs (through
//! flate2) at level [`ZLIB_LEVEL`] compresses the same blocks 3.4x faster for a
//! file 11 % larger (BENCHMARKS.md, "EXR compression"). What is written is
//! ordinary ZIP/ZIPS data that any OpenEXR reader decodes (tests: the exr
//! crate and OpenEXR's reference library read every plane back bit for
//! bit).
//!
//! A block's bytes (little-endian samples, line by line, channel by
//! channel) are (1) split into their even- and odd-indexed bytes, (2)
//! replaced by their differences, then (3) deflated with a zlib wrapper;
//! a block whose compressed form is not smaller is stored raw (OpenEXR
//! `ImfZip.cpp`, `Zip::compress`; OpenEXR Technical Introduction, "Data
//! Compression").

use std::io::Write;

/// The zlib level of irsig's ZIP/ZIPS blocks, chosen by measurement
/// (BENCHMARKS.md, "EXR compression": the smallest write time × file size
/// on a 2048² render).
pub const ZLIB_LEVEL: u32 = 1;

/// Steps (1) and (2) of OpenEXR's ZIP predictor on a block's
/// little-endian bytes: the even-indexed bytes then the odd-indexed ones,
/// each byte after the first replaced by `(b[i] - b[i-1] + 128) mod 256`
/// (OpenEXR `ImfZip.cpp`: "Reorder the pixel data", "Predictor").
pub fn predict(block_le: &[u8]) -> Vec<u8> {
    let half = block_le.len().div_ceil(2);
    let mut out = vec![0u8; block_le.len()];
    let (even, odd) = out.split_at_mut(half);
    for (i, pair) in block_le.chunks(2).enumerate() {
        even[i] = pair[0];
        if let Some(&b) = pair.get(1) {
            odd[i] = b;
        }
    }
    let mut prev = out.first().copied().unwrap_or(0);
    for b in out.iter_mut().skip(1) {
        let cur = *b;
        *b = cur.wrapping_sub(prev).wrapping_add(128);
        prev = cur;
    }
    out
}

/// The inverse of [`predict`] (for tests): OpenEXR's `Zip::uncompress`
/// steps after inflating.
pub fn unpredict(predicted: &[u8]) -> Vec<u8> {
    let mut t = predicted.to_vec();
    for i in 1..t.len() {
        t[i] = t[i - 1].wrapping_add(t[i]).wrapping_sub(128);
    }
    let half = t.len().div_ceil(2);
    let (even, odd) = t.split_at(half);
    let mut out = Vec::with_capacity(t.len());
    for (i, &e) in even.iter().enumerate() {
        out.push(e);
        if let Some(&b) = odd.get(i) {
            out.push(b);
        }
    }
    out
}

/// A block's ZIP/ZIPS data: the zlib stream of [`predict`]`(block_le)` at
/// zlib `level` (0-9; irsig writes [`ZLIB_LEVEL`]), or the block itself
/// where that is not smaller.
pub fn compress(block_le: Vec<u8>, level: u32) -> Vec<u8> {
    let predicted = predict(&block_le);
    let mut z = flate2::write::ZlibEncoder::new(
        Vec::with_capacity(block_le.len() / 2),
        flate2::Compression::new(level),
    );
    // Writing into a Vec cannot fail.
    let packed = z
        .write_all(&predicted)
        .and_then(|()| z.finish())
        .unwrap_or_default();
    if !packed.is_empty() && packed.len() < block_le.len() {
        packed
    } else {
        block_le
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The predictor by hand on a 5-byte block: reorder [1, 2, 3, 4, 5] →
    /// [1, 3, 5, 2, 4], then differences + 128 mod 256.
    #[test]
    fn predictor_matches_openexr_by_hand() {
        let p = predict(&[1, 2, 3, 4, 5]);
        assert_eq!(p, vec![1, 130, 130, 125, 130]);
        assert_eq!(unpredict(&p), vec![1, 2, 3, 4, 5]);
        assert!(predict(&[]).is_empty());
        assert_eq!(predict(&[7]), vec![7]);
    }

    /// Round trip through zlib on data that compresses and data that does
    /// not (stored raw).
    #[test]
    fn compressed_blocks_inflate_to_the_prediction() {
        let smooth: Vec<u8> = (0..4096u32)
            .flat_map(|i| (300.0f32 + i as f32 * 1e-3).to_le_bytes())
            .collect();
        let c = compress(smooth.clone(), ZLIB_LEVEL);
        assert!(c.len() < smooth.len() / 2);
        let mut inflated = Vec::new();
        std::io::Read::read_to_end(&mut flate2::read::ZlibDecoder::new(&c[..]), &mut inflated)
            .unwrap();
        assert_eq!(unpredict(&inflated), smooth);
        // splitmix64 (Steele, Lea & Flood 2014): bytes with no pattern
        // the predictor or deflate could use.
        let noise: Vec<u8> = (1..=64u64)
            .map(|i| {
                let mut z = i.wrapping_mul(0x9E37_79B9_7F4A_7C15);
                z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
                (z ^ (z >> 31)) as u8
            })
            .collect();
        assert_eq!(compress(noise.clone(), ZLIB_LEVEL), noise);
    }
}

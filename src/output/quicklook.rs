//! PNG quicklook: 8-bit grey, linear stretch between the 2nd and 98th
//! percentiles of the finite values of one plane (stated in the file's
//! `tEXt` chunk), so that a few hot or cold pixels do not wash it out.

use std::path::Path;

use super::{OutputError, OutputSet};

/// The stretch applied: values at `lo` map to 0, at `hi` to 255.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stretch {
    pub lo: f32,
    pub hi: f32,
}

/// The 2 %-98 % percentile stretch of the finite values of `data`.
pub fn percentile_stretch(data: &[f32]) -> Stretch {
    let mut v: Vec<f32> = data.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return Stretch { lo: 0.0, hi: 1.0 };
    }
    v.sort_by(f32::total_cmp);
    let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    let (lo, hi) = (at(0.02), at(0.98));
    if hi > lo {
        Stretch { lo, hi }
    } else {
        Stretch { lo, hi: lo + 1.0 }
    }
}

/// 8-bit grey values of `data` under `s` (non-finite values → 0).
pub fn to_grey(data: &[f32], s: Stretch) -> Vec<u8> {
    data.iter()
        .map(|&x| {
            if x.is_finite() {
                ((x - s.lo) / (s.hi - s.lo) * 255.0)
                    .round()
                    .clamp(0.0, 255.0) as u8
            } else {
                0
            }
        })
        .collect()
}

/// Writes a grey PNG of `data` (`width × height`) with the percentile
/// stretch at `path`, a file of the output set `out`; returns the stretch
/// used.
pub fn write_png(
    out: &mut OutputSet,
    path: &Path,
    width: u32,
    height: u32,
    data: &[f32],
    what: &str,
) -> Result<Stretch, OutputError> {
    let s = percentile_stretch(data);
    write_grey_png(
        out,
        path,
        width,
        height,
        &to_grey(data, s),
        &format!(
            "{what}; linear stretch 2-98 percentile: {} .. {}",
            s.lo, s.hi
        ),
    )?;
    Ok(s)
}

/// Writes 8-bit grey pixels as PNG with a `Description` text chunk at
/// `path`, a file of the output set `out`.
pub fn write_grey_png(
    out: &mut OutputSet,
    path: &Path,
    width: u32,
    height: u32,
    grey: &[u8],
    description: &str,
) -> Result<(), OutputError> {
    out.stage(path, |w| {
        let mut enc = png::Encoder::new(w, width, height);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        enc.add_text_chunk("Description".into(), description.into())
            .map_err(|e| e.to_string())?;
        let mut wr = enc.write_header().map_err(|e| e.to_string())?;
        wr.write_image_data(grey).map_err(|e| e.to_string())
    })
}

//! PNG quicklook: 8-bit grey, linear stretch between the 2nd and 98th
//! percentiles of the finite values of one plane (stated in the file's
//! `tEXt` chunk), so that a few hot or cold pixels do not wash it out.

use std::path::Path;

use super::{OutputError, OutputSet};

/// The stretch applied: values at `lo` map to 0, at `hi` to 255.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stretch {
    /// Value drawn as 0.
    pub lo: f32,
    /// Value drawn as 255.
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

/// The colour map of a quicklook or a report image.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Colormap {
    /// Linear grey, black to white.
    #[default]
    Grey,
    /// matplotlib's `inferno` (perceptually uniform, monotonic in
    /// lightness, readable in greyscale and by colour-blind viewers).
    Inferno,
}

impl Colormap {
    /// Its name as the command line writes it (`grey`, `inferno`).
    pub fn name(self) -> &'static str {
        match self {
            Colormap::Grey => "grey",
            Colormap::Inferno => "inferno",
        }
    }

    /// The sRGB colour at `t` (0 … 1, clamped; NaN → black).
    pub fn colour(self, t: f64) -> [u8; 3] {
        if t.is_nan() {
            return [0, 0, 0];
        }
        let t = t.clamp(0.0, 1.0);
        match self {
            Colormap::Grey => {
                let g = (t * 255.0).round() as u8;
                [g, g, g]
            }
            Colormap::Inferno => {
                let table = &super::glyphs::INFERNO;
                let x = t * (table.len() - 1) as f64;
                let i = (x.floor() as usize).min(table.len() - 2);
                let f = x - i as f64;
                let mix = |k: usize| {
                    (table[i][k] as f64 * (1.0 - f) + table[i + 1][k] as f64 * f).round() as u8
                };
                [mix(0), mix(1), mix(2)]
            }
        }
    }
}

/// `s` widened about its centre to a span of at least `min_span` (the
/// plane's units; ≤ 0 or NaN: unchanged), so that a scene whose values
/// differ by less than `min_span` is not stretched to full contrast.
pub fn with_min_span(s: Stretch, min_span: f32) -> Stretch {
    let span = s.hi - s.lo;
    let wider = min_span > span;
    if !wider {
        return s;
    }
    let mid = 0.5 * (s.lo + s.hi);
    Stretch {
        lo: mid - 0.5 * min_span,
        hi: mid + 0.5 * min_span,
    }
}

/// `v` with 4 significant digits, in scientific notation outside
/// 0.01 … 100000.
pub fn label_number(v: f32) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if !(0.01..100_000.0).contains(&a) {
        format!("{v:.3e}")
    } else {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.decimals$}")
    }
}

/// Draws `text` in white on the RGB canvas `px` (`width` wide) with its
/// top-left corner at (`x`, `y`); characters outside ASCII 32-126 are
/// drawn as `?`, pixels outside the canvas are skipped.
fn draw_text(px: &mut [u8], width: usize, x: usize, y: usize, text: &str) {
    use super::glyphs::{GLYPH_H, GLYPH_W, GLYPHS};
    let height = px.len() / (3 * width);
    for (k, ch) in text.chars().enumerate() {
        let code = if (' '..='~').contains(&ch) { ch } else { '?' } as usize;
        let g = &GLYPHS[code - 32];
        for (gy, row) in g.iter().enumerate() {
            for gx in 0..GLYPH_W {
                let (cx, cy) = (x + k * GLYPH_W + gx, y + gy);
                if row >> (GLYPH_W - 1 - gx) & 1 == 1 && cx < width && cy < height {
                    px[3 * (cy * width + cx)..3 * (cy * width + cx) + 3].fill(255);
                }
            }
        }
        debug_assert!(GLYPH_H == g.len());
    }
}

/// How a quicklook is drawn.
#[derive(Clone, Debug)]
pub struct QuicklookStyle {
    /// The colour map.
    pub colormap: Colormap,
    /// The stretch's smallest span, in the plane's units (see
    /// [`with_min_span`]).
    pub min_span: f32,
    /// The colour bar's caption (the plane and its unit).
    pub caption: String,
}

/// The quicklook image: `data` (`width`×`height`) under the stretch `s`
/// and `style`'s colour map (non-finite values black), above a colour bar
/// (the map from `s.lo` at the left to `s.hi` at the right) labelled with
/// the two ends and `style.caption`. The canvas is widened (black) where
/// the labels need more room than the image. Returns (canvas width,
/// height, RGB pixels).
pub fn compose(
    width: u32,
    height: u32,
    data: &[f32],
    s: Stretch,
    style: &QuicklookStyle,
) -> (u32, u32, Vec<u8>) {
    use super::glyphs::{GLYPH_H, GLYPH_W};
    let (lo, hi) = (label_number(s.lo), label_number(s.hi));
    let caption: String = style.caption.chars().take(120).collect();
    let text_w = (lo.len() + hi.len() + 2).max(caption.chars().count()) * GLYPH_W + 4;
    let cw = (width as usize).max(text_w);
    let (gap, bar_h) = (4usize, 10usize);
    let ch = height as usize + gap + bar_h + 2 + 2 * GLYPH_H + 2;
    let mut px = vec![0u8; 3 * cw * ch];
    let w = width as usize;
    for (i, &v) in data.iter().enumerate() {
        let t = if v.is_finite() {
            ((v - s.lo) / (s.hi - s.lo)) as f64
        } else {
            f64::NAN
        };
        let (x, y) = (i % w, i / w);
        px[3 * (y * cw + x)..3 * (y * cw + x) + 3].copy_from_slice(&style.colormap.colour(t));
    }
    let bar_y = height as usize + gap;
    let bar_w = cw - 4;
    for x in 0..bar_w {
        let c = style.colormap.colour(x as f64 / (bar_w - 1).max(1) as f64);
        for y in bar_y..bar_y + bar_h {
            px[3 * (y * cw + x + 2)..3 * (y * cw + x + 2) + 3].copy_from_slice(&c);
        }
    }
    let ty = bar_y + bar_h + 2;
    draw_text(&mut px, cw, 2, ty, &lo);
    draw_text(&mut px, cw, cw - 2 - hi.len() * GLYPH_W, ty, &hi);
    draw_text(&mut px, cw, 2, ty + GLYPH_H, &caption);
    (cw as u32, ch as u32, px)
}

/// Writes the quicklook of `data` (`width`×`height`): the 2-98 %
/// percentile stretch widened to `style.min_span`, drawn by [`compose`]
/// as an RGB PNG with the stretch, colour map and caption in its
/// `Description` text chunk; returns the stretch used.
pub fn write_quicklook(
    out: &mut OutputSet,
    path: &Path,
    dims: (u32, u32),
    data: &[f32],
    style: &QuicklookStyle,
) -> Result<Stretch, OutputError> {
    write_quicklook_described(out, path, dims, data, None, style, "")
}

/// [`write_quicklook`] under the stretch `stretch` (`None`: the 2-98 %
/// percentile stretch of `data` widened to `style.min_span`), with `what`
/// (e.g. a contact sheet's layout) leading the `Description`.
pub fn write_quicklook_described(
    out: &mut OutputSet,
    path: &Path,
    (width, height): (u32, u32),
    data: &[f32],
    stretch: Option<Stretch>,
    style: &QuicklookStyle,
    what: &str,
) -> Result<Stretch, OutputError> {
    let s = stretch.unwrap_or_else(|| with_min_span(percentile_stretch(data), style.min_span));
    let (cw, ch, px) = compose(width, height, data, s, style);
    let description = format!(
        "{what}{}{}; image {width}x{height} at the top left, colour bar below; linear stretch 2-98 percentile widened to a span of at least {}: {} .. {}; colour map {:?}",
        if what.is_empty() { "" } else { "; " },
        style.caption,
        style.min_span,
        s.lo,
        s.hi,
        style.colormap
    );
    out.stage(path, |w| {
        let mut enc = png::Encoder::new(w, cw, ch);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.add_text_chunk("Description".into(), description)
            .map_err(|e| e.to_string())?;
        let mut wr = enc.write_header().map_err(|e| e.to_string())?;
        wr.write_image_data(&px).map_err(|e| e.to_string())
    })?;
    Ok(s)
}

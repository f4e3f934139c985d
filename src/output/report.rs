//! `irsig report <x.json>`: one self-contained HTML page of a render's
//! output set (no server, no network, no external file: the planes are
//! embedded as base64 float32 and drawn by inline JavaScript): each plane
//! as an image under a colour map with a colour bar (the stretch's ends
//! and the unit), a read-out of the value under the cursor, a histogram
//! (inline SVG) and statistics; the material table; the sun, sensor,
//! atmosphere and georeferencing summary of the JSON.
//!
//! The planes are read from the set's EXR (`x.exr`) or, without one, from
//! its GeoTIFF (`x.tif`); their units and order are the JSON's `planes`.
//! docs/render.md ("The report") describes the page.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use base64::Engine;
use serde::Serialize;

use super::quicklook::{Colormap, Stretch, percentile_stretch};

/// What `irsig report` draws.
#[derive(Clone, Debug, Default)]
pub struct ReportOptions {
    /// The planes shown (empty: all of the set's), in this order.
    pub planes: Vec<String>,
    /// The colour map of the planes' images.
    pub colormap: Colormap,
}

/// What a written report holds.
#[derive(Clone, Debug, Serialize)]
pub struct ReportInfo {
    /// The page written.
    pub html: PathBuf,
    /// The output set's JSON it was made from.
    pub source: PathBuf,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The planes shown.
    pub planes: Vec<String>,
    /// Size of the page, bytes.
    pub bytes: usize,
}

/// The most plane values a report embeds (4 bytes each, base64: a page
/// of about 350 MB); larger sets are refused with a hint to `--planes`.
pub const MAX_VALUES: usize = 64 << 20;

/// Number of histogram bins.
const BINS: usize = 48;

/// Planes whose values are classes: stretched over their full range.
fn is_class(name: &str) -> bool {
    matches!(name, "material" | "facet" | "case" | "sun_now")
}

/// One plane as the page's script reads it.
#[derive(Serialize)]
struct PlaneOut {
    name: String,
    unit: String,
    lo: f32,
    hi: f32,
    /// Little-endian float32 samples, row-major, base64.
    data: String,
}

/// Statistics of the finite values: (count, min, max, mean).
fn stats(d: &[f32]) -> (usize, f64, f64, f64) {
    let (mut n, mut lo, mut hi, mut sum) = (0usize, f64::INFINITY, f64::NEG_INFINITY, 0.0);
    for &v in d.iter().filter(|v| v.is_finite()) {
        let v = v as f64;
        n += 1;
        lo = lo.min(v);
        hi = hi.max(v);
        sum += v;
    }
    (n, lo, hi, if n > 0 { sum / n as f64 } else { f64::NAN })
}

/// Counts of the finite values of `d` in [`BINS`] equal bins over
/// `lo` … `hi` (the last bin closed).
fn histogram(d: &[f32], lo: f64, hi: f64) -> Vec<u64> {
    let mut h = vec![0u64; BINS];
    let span = hi - lo;
    for &v in d.iter().filter(|v| v.is_finite()) {
        let k = if span > 0.0 {
            (((v as f64 - lo) / span) * BINS as f64).floor() as usize
        } else {
            0
        };
        h[k.min(BINS - 1)] += 1;
    }
    h
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// JSON text safe inside a `<script>` element.
fn script_json<T: Serialize>(v: &T) -> anyhow::Result<String> {
    Ok(serde_json::to_string(v)?
        .replace("</", "<\\/")
        .replace("<!--", "<\\!--"))
}

/// A histogram as an inline SVG bar chart with its range under it.
fn histogram_svg(h: &[u64], lo: f64, hi: f64, unit: &str) -> String {
    let max = h.iter().copied().max().unwrap_or(0).max(1) as f64;
    let (w, ht) = (240.0, 80.0);
    let bw = w / h.len() as f64;
    let mut s = format!(
        "<svg class=\"hist\" width=\"{w}\" height=\"{}\" viewBox=\"0 0 {w} {}\" role=\"img\"><rect width=\"{w}\" height=\"{ht}\" fill=\"#f4f4f4\"/>",
        ht + 14.0,
        ht + 14.0
    );
    for (i, &c) in h.iter().enumerate() {
        let bh = c as f64 / max * (ht - 2.0);
        s += &format!(
            "<rect x=\"{:.2}\" y=\"{:.2}\" width=\"{:.2}\" height=\"{bh:.2}\" fill=\"#446\"><title>{c}</title></rect>",
            i as f64 * bw,
            ht - bh,
            (bw - 0.5).max(0.5)
        );
    }
    s += &format!(
        "<text x=\"0\" y=\"{}\" font-size=\"10\">{}</text><text x=\"{w}\" y=\"{}\" font-size=\"10\" text-anchor=\"end\">{} {}</text></svg>",
        ht + 12.0,
        esc(&fmt(lo)),
        ht + 12.0,
        esc(&fmt(hi)),
        esc(unit)
    );
    s
}

fn fmt(v: f64) -> String {
    if v.is_finite() {
        super::quicklook::label_number(v as f32)
    } else {
        "-".into()
    }
}

/// A table of `rows` (key, value), both escaped here.
fn table(rows: &[(String, String)]) -> String {
    let mut s = String::from("<table class=\"kv\">");
    for (k, v) in rows {
        s += &format!("<tr><th>{}</th><td>{}</td></tr>", esc(k), esc(v));
    }
    s + "</table>"
}

/// A JSON value as text for a table cell (strings bare, the rest compact
/// JSON).
fn text(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::String(s) => s.clone(),
        serde_json::Value::Null => "-".into(),
        v => v.to_string(),
    }
}

/// The planes of the set whose summary is `summary` (beside `dir`): from
/// the EXR, else the GeoTIFF; (source file, width, height, (name, data)).
type Read = (PathBuf, u32, u32, Vec<(String, Vec<f32>)>);

fn read_planes(json_path: &Path, summary: &serde_json::Value) -> anyhow::Result<Read> {
    let dir = json_path.parent().unwrap_or(Path::new("."));
    let files: Vec<String> = summary
        .get("files")
        .and_then(|f| f.as_array())
        .map(|a| {
            a.iter()
                .filter_map(|v| v.as_str().map(String::from))
                .collect()
        })
        .unwrap_or_default();
    let stem = json_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let exr = format!("{stem}.exr");
    let tif = format!("{stem}.tif");
    if files.contains(&exr) {
        let path = dir.join(&exr);
        let (w, h, chans) = super::exr::read_exr(&path).map_err(|e| anyhow::anyhow!(e))?;
        return Ok((path, w, h, chans));
    }
    if files.contains(&tif) {
        let path = dir.join(&tif);
        let names: Vec<String> = summary
            .get("planes")
            .and_then(|p| p.as_array())
            .map(|a| {
                a.iter()
                    .filter_map(|p| p.get(0).and_then(|n| n.as_str()).map(String::from))
                    .collect()
            })
            .unwrap_or_default();
        let (w, h, chans) = read_geotiff(&path, &names)?;
        return Ok((path, w, h, chans));
    }
    bail!(
        "{}: its output set has no {exr} or {tif} to read the planes from (files: {})",
        json_path.display(),
        files.join(", ")
    )
}

/// The float32 bands of a GeoTIFF written by [`super::geotiff`], named
/// `names` in order.
fn read_geotiff(path: &Path, names: &[String]) -> anyhow::Result<(u32, u32, super::exr::Channels)> {
    let f = std::fs::File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let bad = |e: tiff::TiffError| anyhow::anyhow!("{}: {e}", path.display());
    let mut dec = tiff::decoder::Decoder::new(std::io::BufReader::new(f)).map_err(bad)?;
    let (w, h) = dec.dimensions().map_err(bad)?;
    let data = match dec.read_image().map_err(bad)? {
        tiff::decoder::DecodingResult::F32(v) => v,
        _ => bail!("{}: not a float32 GeoTIFF", path.display()),
    };
    let npx = w as usize * h as usize;
    if npx == 0 || data.len() != npx * names.len() {
        bail!(
            "{}: {} samples for {} planes of {w}x{h} (the JSON's plane list)",
            path.display(),
            data.len(),
            names.len()
        );
    }
    let nb = names.len();
    Ok((
        w,
        h,
        names
            .iter()
            .enumerate()
            .map(|(b, n)| (n.clone(), (0..npx).map(|i| data[i * nb + b]).collect()))
            .collect(),
    ))
}

/// The report page of the output set whose JSON summary is `json_path`.
pub fn build_report(
    json_path: &Path,
    opts: &ReportOptions,
) -> anyhow::Result<(String, ReportInfo)> {
    let text_in = std::fs::read_to_string(json_path)
        .with_context(|| format!("cannot read {}", json_path.display()))?;
    let summary: serde_json::Value = serde_json::from_str(&text_in).with_context(|| {
        format!(
            "{}: not a render's JSON summary (invalid JSON)",
            json_path.display()
        )
    })?;
    if summary.get("planes").and_then(|p| p.as_array()).is_none() {
        bail!(
            "{}: not a render's JSON summary (no `planes` list; `irsig render` writes one beside its EXR/GeoTIFF)",
            json_path.display()
        );
    }
    let units: Vec<(String, String)> = summary["planes"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|p| {
            Some((
                p.get(0)?.as_str()?.to_string(),
                p.get(1)?.as_str()?.to_string(),
            ))
        })
        .collect();
    let (source, w, h, mut chans) = read_planes(json_path, &summary)?;
    let order: Vec<String> = if opts.planes.is_empty() {
        units.iter().map(|u| u.0.clone()).collect()
    } else {
        for p in &opts.planes {
            if !chans.iter().any(|c| &c.0 == p) {
                bail!(
                    "--planes {p}: not in {}; its planes are {}",
                    source.display(),
                    units
                        .iter()
                        .map(|u| u.0.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                );
            }
        }
        opts.planes.clone()
    };
    let npx = w as usize * h as usize;
    if npx * order.len() > MAX_VALUES {
        bail!(
            "{}: {} planes of {w}x{h} are {} values, more than a report embeds ({MAX_VALUES}); choose planes with --planes",
            source.display(),
            order.len(),
            npx * order.len()
        );
    }
    let materials: Vec<(i64, String)> = summary
        .get("materials")
        .and_then(|m| m.as_array())
        .into_iter()
        .flatten()
        .filter_map(|m| {
            Some((
                m.get("index")?.as_i64()?,
                m.get("name")?.as_str()?.to_string(),
            ))
        })
        .collect();

    let mut planes_out = Vec::new();
    let mut cards = String::new();
    for (k, name) in order.iter().enumerate() {
        let Some(pos) = chans.iter().position(|c| &c.0 == name) else {
            continue;
        };
        let data = std::mem::take(&mut chans[pos].1);
        let unit = units
            .iter()
            .find(|u| &u.0 == name)
            .map(|u| u.1.clone())
            .unwrap_or_default();
        let (n, min, max, mean) = stats(&data);
        let s = if is_class(name) && n > 0 {
            Stretch {
                lo: min as f32,
                hi: if max > min {
                    max as f32
                } else {
                    min as f32 + 1.0
                },
            }
        } else {
            percentile_stretch(&data)
        };
        let hist = histogram(&data, min, max);
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        cards += &format!(
            "<section class=\"plane\" id=\"plane-{k}\"><h3>{}</h3><div class=\"unit\">{}</div>\
<canvas class=\"img\" data-plane=\"{k}\" width=\"{w}\" height=\"{h}\"></canvas>\
<div class=\"bar\"><canvas class=\"cbar\" data-plane=\"{k}\" width=\"256\" height=\"12\"></canvas>\
<div class=\"ends\"><span>{}</span><span>{} {}</span></div></div>\
<div class=\"readout\" id=\"readout-{}\">move the cursor over the image</div>\
{}{}</section>\n",
            esc(name),
            esc(&unit),
            esc(&fmt(s.lo as f64)),
            esc(&fmt(s.hi as f64)),
            esc(&unit),
            esc(name),
            histogram_svg(&hist, min, max, &unit),
            table(&[
                ("finite pixels".into(), format!("{n} of {npx}")),
                ("min".into(), fmt(min)),
                ("mean".into(), fmt(mean)),
                ("max".into(), fmt(max)),
                (
                    "display stretch".into(),
                    if is_class(name) {
                        "min .. max".into()
                    } else {
                        "2-98 percentile".into()
                    }
                ),
            ])
        );
        planes_out.push(PlaneOut {
            name: name.clone(),
            unit,
            lo: s.lo,
            hi: s.hi,
            data: base64::engine::general_purpose::STANDARD.encode(&bytes),
        });
    }

    let g = |k: &str| summary.get(k).map(text).unwrap_or_else(|| "-".into());
    let mut scene_rows = vec![
        ("scene".to_string(), g("scene")),
        ("image time (UTC)".into(), g("image_time_utc")),
        ("band".into(), g("band")),
        ("band support (um)".into(), g("band_um")),
        ("estimators".into(), g("estimators")),
        ("overrides".into(), g("overrides")),
        ("size (px)".into(), format!("{w} x {h}")),
        ("planes read from".into(), source.display().to_string()),
        ("quicklook".into(), g("quicklook")),
    ];
    if let Some(v) = summary.get("irsig") {
        scene_rows.push(("irsig".into(), text(v)));
    }
    let sun_rows = vec![
        ("sun zenith (deg)".to_string(), g("sun_zenith_deg")),
        ("sun azimuth (deg, from north)".into(), g("sun_azimuth_deg")),
        ("sun elevation (deg)".into(), g("sun_elevation_deg")),
    ];
    let obj_rows = |k: &str| -> Vec<(String, String)> {
        match summary.get(k) {
            Some(serde_json::Value::Object(m)) => {
                m.iter().map(|(k, v)| (k.clone(), text(v))).collect()
            }
            Some(v) => vec![(k.to_string(), text(v))],
            None => vec![],
        }
    };
    let mut sensor_rows = vec![("pose".to_string(), g("pose"))];
    sensor_rows.extend(obj_rows("camera"));
    let mut mat_table = String::from(
        "<table class=\"materials\"><tr><th>material plane value</th><th>name</th><th>class</th><th>pixels</th></tr>",
    );
    let mat_plane = order
        .iter()
        .position(|n| n == "material")
        .and_then(|i| planes_out.get(i));
    let counts: Vec<usize> = {
        let mut c = vec![0usize; materials.len()];
        if let Some(p) = mat_plane {
            let bytes = base64::engine::general_purpose::STANDARD
                .decode(&p.data)
                .unwrap_or_default();
            for b in bytes.chunks_exact(4) {
                let v = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                if v >= 0.0 && (v as usize) < c.len() {
                    c[v as usize] += 1;
                }
            }
        }
        c
    };
    for (i, (idx, name)) in materials.iter().enumerate() {
        let class = summary["materials"][i]
            .get("class")
            .map(text)
            .unwrap_or_default();
        mat_table += &format!(
            "<tr><td>{idx}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            esc(name),
            esc(&class),
            if mat_plane.is_some() {
                counts.get(i).copied().unwrap_or(0).to_string()
            } else {
                "-".into()
            }
        );
    }
    mat_table += "</table>";

    let colormap: Vec<[u8; 3]> = (0..256)
        .map(|i| opts.colormap.colour(i as f64 / 255.0))
        .collect();
    let names: Vec<&str> = materials.iter().map(|m| m.1.as_str()).collect();
    let data_json = script_json(&serde_json::json!({
        "width": w,
        "height": h,
        "colormap": colormap,
        "materials": names,
        "planes": planes_out,
    }))?;
    let title = format!("irsig report: {}", g("scene"));
    let html = format!(
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data:">
<title>{title}</title>
<style>
body {{ font-family: sans-serif; margin: 1em; color: #222; }}
h1 {{ font-size: 1.3em; }} h2 {{ font-size: 1.1em; margin-top: 1.5em; }} h3 {{ margin: 0; font-size: 1em; }}
table {{ border-collapse: collapse; font-size: 0.85em; margin: 0.3em 0; }}
th, td {{ border: 1px solid #ccc; padding: 2px 6px; text-align: left; vertical-align: top; }}
td {{ font-family: monospace; word-break: break-all; max-width: 60em; }}
.planes {{ display: flex; flex-wrap: wrap; gap: 1em; }}
.plane {{ border: 1px solid #ccc; padding: 0.5em; }}
.unit {{ color: #666; font-size: 0.85em; }}
canvas.img {{ image-rendering: pixelated; display: block; cursor: crosshair; }}
canvas.cbar {{ width: 256px; height: 12px; display: block; }}
.ends {{ display: flex; justify-content: space-between; width: 256px; font-size: 0.8em; }}
.readout {{ font-family: monospace; font-size: 0.85em; min-height: 1.2em; }}
</style></head><body>
<h1>{title}</h1>
<h2>Image</h2>{scene}
<h2>Planes</h2>
<p>Hover over an image for the value under the cursor (column, row from the top left). Colour map {cmap:?}; the stretch of each plane is under its colour bar.</p>
<div class="planes">
{cards}</div>
<h2>Materials</h2>{mat_table}
<h2>Sun</h2>{sun}
<h2>Sensor</h2>{sensor}
<h2>Atmosphere</h2>{atmos}
<h2>Georeferencing</h2>{georef}
<script type="application/json" id="irsig-data">{data_json}</script>
<script>
(function () {{
  const D = JSON.parse(document.getElementById('irsig-data').textContent);
  const W = D.width, H = D.height;
  const scale = Math.max(1, Math.min(8, Math.floor(480 / Math.max(W, H))));
  function decode(b64) {{
    const s = atob(b64), n = s.length, u = new Uint8Array(n);
    for (let i = 0; i < n; i++) u[i] = s.charCodeAt(i);
    return new Float32Array(u.buffer);
  }}
  function colour(t) {{
    if (!isFinite(t)) return [0, 0, 0];
    const i = Math.max(0, Math.min(255, Math.round(t * 255)));
    return D.colormap[i];
  }}
  const values = D.planes.map(p => decode(p.data));
  function readout(k, col, row) {{
    const p = D.planes[k], v = values[k][row * W + col];
    let s = p.name + ' (' + col + ', ' + row + ') = ';
    s += isFinite(v) ? String(Number(v.toPrecision(7))) + ' ' + p.unit : 'no data';
    if (p.name === 'material' && v >= 0 && D.materials[v] !== undefined) s += ' (' + D.materials[v] + ')';
    document.getElementById('readout-' + p.name).textContent = s;
  }}
  document.querySelectorAll('canvas.img').forEach(c => {{
    const k = +c.dataset.plane, p = D.planes[k], v = values[k];
    c.style.width = (W * scale) + 'px'; c.style.height = (H * scale) + 'px';
    const ctx = c.getContext('2d'), img = ctx.createImageData(W, H);
    for (let i = 0; i < W * H; i++) {{
      const rgb = colour((v[i] - p.lo) / (p.hi - p.lo));
      img.data[4 * i] = rgb[0]; img.data[4 * i + 1] = rgb[1]; img.data[4 * i + 2] = rgb[2]; img.data[4 * i + 3] = 255;
    }}
    ctx.putImageData(img, 0, 0);
    c.addEventListener('mousemove', e => {{
      const r = c.getBoundingClientRect();
      const col = Math.min(W - 1, Math.max(0, Math.floor((e.clientX - r.left) * W / r.width)));
      const row = Math.min(H - 1, Math.max(0, Math.floor((e.clientY - r.top) * H / r.height)));
      readout(k, col, row);
    }});
  }});
  document.querySelectorAll('canvas.cbar').forEach(c => {{
    const ctx = c.getContext('2d');
    for (let x = 0; x < 256; x++) {{
      const rgb = D.colormap[x];
      ctx.fillStyle = 'rgb(' + rgb[0] + ',' + rgb[1] + ',' + rgb[2] + ')';
      ctx.fillRect(x, 0, 1, 12);
    }}
  }});
  // A scripted hover (for tests and links): #hover=PLANE:COL:ROW moves the
  // cursor over that pixel's centre of that plane's image.
  const m = /hover=([^:&]+):(\d+):(\d+)/.exec(decodeURIComponent(location.hash));
  if (m) {{
    const k = D.planes.findIndex(p => p.name === m[1]);
    const c = document.querySelector('canvas.img[data-plane="' + k + '"]');
    if (c) {{
      const r = c.getBoundingClientRect();
      const x = r.left + (+m[2] + 0.5) * r.width / W, y = r.top + (+m[3] + 0.5) * r.height / H;
      c.dispatchEvent(new MouseEvent('mousemove', {{ clientX: x, clientY: y, bubbles: true }}));
    }}
  }}
}})();
</script>
</body></html>
"#,
        title = esc(&title),
        scene = table(&scene_rows),
        sun = table(&sun_rows),
        sensor = table(&sensor_rows),
        atmos = table(&obj_rows("atmosphere")),
        georef = table(&obj_rows("georef")),
        cmap = opts.colormap,
    );
    let info = ReportInfo {
        html: PathBuf::new(),
        source,
        width: w,
        height: h,
        planes: planes_out.iter().map(|p| p.name.clone()).collect(),
        bytes: html.len(),
    };
    Ok((html, info))
}

/// Writes the report of the output set `json_path` at `html` (atomically).
pub fn write_report(
    json_path: &Path,
    html: &Path,
    opts: &ReportOptions,
) -> anyhow::Result<ReportInfo> {
    super::check_output_file(html)?;
    let (page, mut info) = build_report(json_path, opts)?;
    super::write_text(html, &page)?;
    info.html = html.to_path_buf();
    Ok(info)
}

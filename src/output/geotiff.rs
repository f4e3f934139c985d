//! GeoTIFF output: one file, one band per plane (pixel-interleaved, all
//! bands of one sample type, deflate-compressed), written with the `tiff`
//! crate (image-rs; pure Rust, so the binary needs no GDAL). The
//! georeferencing is the GeoTIFF 1.1 standard's (OGC 19-008r4) tags:
//!
//! * `GeoKeyDirectoryTag` (34735): projected model, pixel-is-area, the CRS
//!   (`ProjectedCSTypeGeoKey` = the EPSG code for UTM; for the local
//!   orthographic CRS a user-defined projection, `CT_Orthographic`, with
//!   its origin in `GeoDoubleParamsTag`);
//! * nadir views: `ModelPixelScaleTag` + `ModelTiepointTag` (north-up) or
//!   `ModelTransformationTag` (rotated) from the exact affine transform;
//! * oblique views: a grid of tie points (GDAL's GCPs) at pixels whose ray
//!   hits the scene, with the hit points' map coordinates.
//!
//! Band names and units, and dataset metadata, are in GDAL's
//! `GDAL_METADATA` tag (42112, XML: band `DESCRIPTION` and `UNITTYPE`
//! roles), the no-data value (NaN) in `GDAL_NODATA` (42113); GDAL, and so
//! rasterio, rioxarray and QGIS, read them. `gdal_translate -of COG` makes
//! a cloud-optimised GeoTIFF of it.

use std::io::Cursor;
use std::path::Path;

use tiff::encoder::colortype::{ColorType, Gray32Float, Gray64Float};
use tiff::encoder::{Compression, DeflateLevel, TiffEncoder, TiffValue};
use tiff::tags::{ExtraSamples, Tag};

use super::{OutputError, OutputSet};
use crate::scene::georef::{CrsInfo, Georef};

/// How the image maps to the CRS.
#[derive(Clone, Debug, PartialEq)]
pub enum Placement {
    /// None (no geographic placement).
    None,
    /// An affine transform in GDAL's order.
    Affine([f64; 6]),
    /// Tie points: (col, row, map x, map y) (pixel corners: the centre of
    /// pixel (i, j) is (i + 0.5, j + 0.5)).
    TiePoints(Vec<[f64; 4]>),
}

/// One band: name, unit, samples (row-major).
pub struct Band<'a, T> {
    /// Band name (the plane's).
    pub name: &'a str,
    /// Unit.
    pub unit: &'a str,
    /// Samples, row-major.
    pub data: &'a [T],
}

/// The placement of an image with georeferencing `g`: its affine transform
/// when there is one, else tie points at up to `n`×`n` pixel centres
/// whose map coordinates (`map_x`, `map_y`, row-major, NaN: no hit) are
/// known.
pub fn placement(g: &Georef, width: u32, map_x: &[f64], map_y: &[f64], n: u32) -> Placement {
    if let Some(gt) = g.geotransform {
        return Placement::Affine(gt);
    }
    let height = (map_x.len() / width.max(1) as usize) as u32;
    let pick = |len: u32| -> Vec<u32> {
        let k = n.min(len).max(1);
        let mut v: Vec<u32> = (0..k)
            .map(|i| ((i as f64 + 0.5) * len as f64 / k as f64) as u32)
            .collect();
        v.dedup();
        v
    };
    let mut tp = Vec::new();
    for &r in &pick(height) {
        for &c in &pick(width) {
            let i = (r * width + c) as usize;
            if map_x[i].is_finite() && map_y[i].is_finite() {
                tp.push([c as f64 + 0.5, r as f64 + 0.5, map_x[i], map_y[i]]);
            }
        }
    }
    if tp.is_empty() {
        Placement::None
    } else {
        Placement::TiePoints(tp)
    }
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The GeoKey directory and its double and ASCII parameters for `crs`.
fn geokeys(crs: &CrsInfo) -> (Vec<u16>, Vec<f64>, String) {
    // (key, location tag (0: value in place), count, value or index)
    let mut keys: Vec<[u16; 4]> = Vec::new();
    let mut doubles = Vec::new();
    let mut ascii = String::new();
    let mut text = |keys: &mut Vec<[u16; 4]>, key: u16, s: &str| {
        let s = format!("{}|", s.replace('|', "/"));
        keys.push([key, 34737, s.len() as u16, ascii.len() as u16]);
        ascii += &s;
    };
    keys.push([1024, 0, 1, 1]); // GTModelTypeGeoKey: projected
    keys.push([1025, 0, 1, 1]); // GTRasterTypeGeoKey: pixel is area
    text(&mut keys, 1026, &crs.name); // GTCitationGeoKey
    match (crs.epsg, crs.origin_deg) {
        (Some(epsg), _) => keys.push([3072, 0, 1, epsg as u16]), // ProjectedCSTypeGeoKey
        (None, Some((lat, lon))) => {
            keys.push([2048, 0, 1, 4326]); // GeographicTypeGeoKey: WGS 84
            keys.push([3072, 0, 1, 32767]); // ProjectedCSTypeGeoKey: user-defined
            text(&mut keys, 3073, &crs.name); // PCSCitationGeoKey
            keys.push([3074, 0, 1, 32767]); // ProjectionGeoKey: user-defined
            keys.push([3075, 0, 1, 21]); // ProjCoordTransGeoKey: CT_Orthographic
            keys.push([3076, 0, 1, 9001]); // ProjLinearUnitsGeoKey: metre
            for (key, v) in [(3080u16, lon), (3081, lat), (3082, 0.0), (3083, 0.0)] {
                // ProjNatOriginLong/Lat, ProjFalseEasting/Northing
                keys.push([key, 34736, 1, doubles.len() as u16]);
                doubles.push(v);
            }
        }
        (None, None) => {}
    }
    keys.sort_by_key(|k| k[0]);
    let mut dir = vec![1u16, 1, 0, keys.len() as u16];
    dir.extend(keys.iter().flatten());
    (dir, doubles, ascii)
}

/// Writes `bands` (all (`width`, `height`)) as a GeoTIFF at `path` (f32 or
/// f64 samples), placed by `placement` in `crs`, with `metadata` (name,
/// value) as dataset metadata items and `domains` (domain, items) as items
/// of GDAL's other metadata domains (e.g. `GEOLOCATION`); the file is
/// staged in the output set `out`.
#[allow(clippy::too_many_arguments)]
pub fn write_geotiff<T>(
    out: &mut OutputSet,
    path: &Path,
    (width, height): (u32, u32),
    bands: &[Band<T>],
    crs: Option<&CrsInfo>,
    placement: &Placement,
    metadata: &[(String, String)],
    domains: &[(&str, Vec<(String, String)>)],
) -> Result<(), OutputError>
where
    T: GeoTiffSample,
    [T]: TiffValue,
{
    let encode = |msg: String| OutputError::Encode {
        path: path.to_path_buf(),
        msg,
    };
    if bands.is_empty() {
        return Err(encode("no bands".into()));
    }
    let npx = width as usize * height as usize;
    if let Some(b) = bands.iter().find(|b| b.data.len() != npx) {
        return Err(encode(format!(
            "band {} has {} samples, expected {width}x{height}",
            b.name,
            b.data.len()
        )));
    }
    let nb = bands.len();
    let mut data = Vec::with_capacity(npx * nb);
    for i in 0..npx {
        data.extend(bands.iter().map(|b| b.data[i]));
    }
    let mut xml = String::from("<GDALMetadata>\n");
    for (k, v) in metadata {
        xml += &format!(
            "  <Item name=\"{}\">{}</Item>\n",
            xml_escape(k),
            xml_escape(v)
        );
    }
    for (domain, items) in domains {
        for (k, v) in items {
            xml += &format!(
                "  <Item name=\"{}\" domain=\"{}\">{}</Item>\n",
                xml_escape(k),
                xml_escape(domain),
                xml_escape(v)
            );
        }
    }
    for (i, b) in bands.iter().enumerate() {
        xml += &format!(
            "  <Item name=\"DESCRIPTION\" sample=\"{i}\" role=\"description\">{}</Item>\n",
            xml_escape(b.name)
        );
        xml += &format!(
            "  <Item name=\"UNITTYPE\" sample=\"{i}\" role=\"unittype\">{}</Item>\n",
            xml_escape(b.unit)
        );
    }
    xml += "</GDALMetadata>";
    let mut buf = Cursor::new(Vec::new());
    (|| -> tiff::TiffResult<()> {
        let mut enc = TiffEncoder::new(&mut buf)?
            .with_compression(Compression::Deflate(DeflateLevel::Balanced));
        let mut img = enc.new_image::<T::Color>(width, height)?;
        if nb > 1 {
            img.extra_samples(&vec![ExtraSamples::Unspecified; nb - 1])?;
        }
        let e = img.encoder();
        e.write_tag(Tag::Unknown(42112), xml.as_str())?;
        e.write_tag(Tag::GdalNodata, "nan")?;
        if let Some(crs) = crs {
            let (dir, doubles, ascii) = geokeys(crs);
            e.write_tag(Tag::GeoKeyDirectoryTag, &dir[..])?;
            if !doubles.is_empty() {
                e.write_tag(Tag::GeoDoubleParamsTag, &doubles[..])?;
            }
            e.write_tag(Tag::GeoAsciiParamsTag, ascii.as_str())?;
            match placement {
                Placement::None => {}
                Placement::Affine(g) if g[2] == 0.0 && g[4] == 0.0 => {
                    e.write_tag(Tag::ModelPixelScaleTag, &[g[1], -g[5], 0.0][..])?;
                    e.write_tag(Tag::ModelTiepointTag, &[0.0, 0.0, 0.0, g[0], g[3], 0.0][..])?;
                }
                Placement::Affine(g) => {
                    let m = [
                        g[1], g[2], 0.0, g[0], g[4], g[5], 0.0, g[3], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
                        0.0, 1.0,
                    ];
                    e.write_tag(Tag::ModelTransformationTag, &m[..])?;
                }
                Placement::TiePoints(tp) => {
                    let v: Vec<f64> = tp
                        .iter()
                        .flat_map(|p| [p[0], p[1], 0.0, p[2], p[3], 0.0])
                        .collect();
                    e.write_tag(Tag::ModelTiepointTag, &v[..])?;
                }
            }
        }
        img.write_data(&data)
    })()
    .map_err(|e| encode(e.to_string()))?;
    out.stage(path, |w| {
        std::io::Write::write_all(w, buf.get_ref()).map_err(|e| e.to_string())
    })
}

/// A sample type of a GeoTIFF band (f32 or f64).
pub trait GeoTiffSample: Copy {
    /// The `tiff` crate's colour type of one band of this sample.
    type Color: ColorType<Inner = Self>;
}

impl GeoTiffSample for f32 {
    type Color = Gray32Float;
}

impl GeoTiffSample for f64 {
    type Color = Gray64Float;
}

/// A north-up map grid for a rotated affine transform `gt` (GDAL's order)
/// of a `width`×`height` image: the grid's transform (`[x0, gsd, 0, y0, 0,
/// -gsd]`) and size, covering the image's corners, at the image's finer
/// pixel size (the GSD). `None` where `gt` is north-up already (no
/// rotation terms) or not invertible.
pub fn north_up_grid(gt: [f64; 6], width: u32, height: u32) -> Option<([f64; 6], u32, u32)> {
    let det = gt[1] * gt[5] - gt[2] * gt[4];
    if (gt[2] == 0.0 && gt[4] == 0.0) || !det.is_finite() || det == 0.0 {
        return None;
    }
    let gsd = (gt[1].hypot(gt[4])).min(gt[2].hypot(gt[5]));
    let corner = |c: f64, r: f64| (gt[0] + c * gt[1] + r * gt[2], gt[3] + c * gt[4] + r * gt[5]);
    let (w, h) = (width as f64, height as f64);
    let cs = [
        corner(0.0, 0.0),
        corner(w, 0.0),
        corner(w, h),
        corner(0.0, h),
    ];
    let minx = cs.iter().map(|c| c.0).fold(f64::INFINITY, f64::min);
    let maxx = cs.iter().map(|c| c.0).fold(f64::NEG_INFINITY, f64::max);
    let miny = cs.iter().map(|c| c.1).fold(f64::INFINITY, f64::min);
    let maxy = cs.iter().map(|c| c.1).fold(f64::NEG_INFINITY, f64::max);
    // A relative tolerance keeps an exact fit from gaining a column.
    let n = |span: f64| ((span / gsd) * (1.0 - 1e-12)).ceil().max(1.0) as u32;
    Some((
        [minx, gsd, 0.0, maxy, 0.0, -gsd],
        n(maxx - minx),
        n(maxy - miny),
    ))
}

/// Resamples `data` (a `width`×`height` image placed by the affine `gt`)
/// onto the grid `out_gt` of `out_w`×`out_h` cells: each cell's centre is
/// taken back through the inverse of `gt`; `nearest` (class planes:
/// material, facet, case, DN) takes the image pixel it falls in, otherwise
/// bilinear between the four nearest pixel centres (nearest where one of
/// them is NaN or off the image, at the image's edge half-pixel). Cells
/// outside the image are NaN.
pub fn resample_affine(
    data: &[f32],
    (width, height): (u32, u32),
    gt: [f64; 6],
    out_gt: [f64; 6],
    (out_w, out_h): (u32, u32),
    nearest: bool,
) -> Vec<f32> {
    let det = gt[1] * gt[5] - gt[2] * gt[4];
    let (w, h) = (width as i64, height as i64);
    let at = |c: i64, r: i64| -> f32 {
        if c < 0 || r < 0 || c >= w || r >= h {
            f32::NAN
        } else {
            data[(r * w + c) as usize]
        }
    };
    let mut out = Vec::with_capacity(out_w as usize * out_h as usize);
    for j in 0..out_h {
        for i in 0..out_w {
            let x = out_gt[0] + (i as f64 + 0.5) * out_gt[1] + (j as f64 + 0.5) * out_gt[2];
            let y = out_gt[3] + (i as f64 + 0.5) * out_gt[4] + (j as f64 + 0.5) * out_gt[5];
            let (dx, dy) = (x - gt[0], y - gt[3]);
            let col = (gt[5] * dx - gt[2] * dy) / det;
            let row = (-gt[4] * dx + gt[1] * dy) / det;
            if !(col >= 0.0 && row >= 0.0 && col < width as f64 && row < height as f64) {
                out.push(f32::NAN);
                continue;
            }
            let near = at(col.floor() as i64, row.floor() as i64);
            if nearest {
                out.push(near);
                continue;
            }
            let (u, v) = (col - 0.5, row - 0.5);
            let (c0, r0) = (u.floor() as i64, v.floor() as i64);
            let (fu, fv) = (u - c0 as f64, v - r0 as f64);
            let q = [
                at(c0, r0),
                at(c0 + 1, r0),
                at(c0, r0 + 1),
                at(c0 + 1, r0 + 1),
            ];
            if q.iter().any(|s| s.is_nan()) {
                out.push(near);
            } else {
                let top = q[0] as f64 * (1.0 - fu) + q[1] as f64 * fu;
                let bot = q[2] as f64 * (1.0 - fu) + q[3] as f64 * fu;
                out.push((top * (1.0 - fv) + bot * fv) as f32);
            }
        }
    }
    out
}

/// Planes whose values are classes or counts: resampled by nearest
/// neighbour onto a map grid.
pub fn is_class_plane(name: &str) -> bool {
    matches!(name, "material" | "facet" | "case" | "dn")
}

//! Single-band GeoTIFF rasters (DEMs, land-cover classes), read with the
//! `tiff` crate as the GeoTIFF output is written (pure Rust, no GDAL).
//!
//! The georeferencing is the GeoTIFF 1.1 standard's (OGC 19-008r4):
//!
//! * `GeoKeyDirectoryTag` (34735): `GTModelTypeGeoKey` (1024: 1 projected,
//!   2 geographic), `GTRasterTypeGeoKey` (1025: 1 pixel-is-area, 2
//!   pixel-is-point), `GeographicTypeGeoKey` (2048), `ProjectedCSTypeGeoKey`
//!   (3072), the linear (3076), angular (2054) and vertical (4099) units;
//! * the raster-to-model transform: `ModelTransformationTag` (34264,
//!   a 4×4 matrix), or `ModelPixelScaleTag` (33550) with one
//!   `ModelTiepointTag` (33922). For pixel-is-point rasters the tie point
//!   is a pixel centre and the transform is moved by half a pixel, as GDAL
//!   does (its default `GTIFF_POINT_GEO_IGNORE=NO`), so the corners agree
//!   with `gdalinfo`;
//! * the no-data value: GDAL's `GDAL_NODATA` tag (42113, ASCII).
//!
//! Supported CRSs: WGS 84 geographic (EPSG:4326; x longitude, y latitude,
//! degrees) and WGS 84 / UTM (EPSG:326zz north, 327zz south; metres). Any
//! other is refused with the command that reprojects the file.

use std::io::Cursor;
use std::path::Path;

use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::tags::Tag;

use crate::scene::error::{Location, SceneError};

/// The CRS of a raster.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RasterCrs {
    /// WGS 84 geographic (EPSG:4326): x longitude, y latitude, degrees.
    Geographic,
    /// WGS 84 / UTM zone `zone` (1-60), north or south (EPSG 326zz/327zz):
    /// x easting, y northing, metres.
    Utm {
        /// UTM zone, 1-60.
        zone: u32,
        /// Northern hemisphere (EPSG 326zz), else southern (327zz).
        north: bool,
    },
}

impl RasterCrs {
    /// The EPSG code.
    pub fn epsg(&self) -> u32 {
        match *self {
            RasterCrs::Geographic => 4326,
            RasterCrs::Utm { zone, north: true } => 32600 + zone,
            RasterCrs::Utm { zone, north: false } => 32700 + zone,
        }
    }
}

/// A single-band raster with its georeferencing.
#[derive(Clone, Debug, PartialEq)]
pub struct Raster {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Its coordinate reference system.
    pub crs: RasterCrs,
    /// Pixel → CRS affine transform in GDAL's order (x = g0 + col·g1 +
    /// row·g2, y = g3 + col·g4 + row·g5), (col, row) at pixel corners: the
    /// centre of pixel (i, j) is (i + 0.5, j + 0.5).
    pub geotransform: [f64; 6],
    /// The file's no-data value (`GDAL_NODATA`), if any.
    pub nodata: Option<f64>,
    /// Row-major samples; NaN where the file has its no-data value (or NaN).
    pub data: Vec<f32>,
    /// The inverse transform: CRS → (col, row).
    inverse: [f64; 6],
}

/// A bilinear sample of a raster.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sample {
    /// The interpolated value.
    Value(f64),
    /// A pixel the interpolation needs holds no data: (col, row).
    NoData([u32; 2]),
    /// The point lies outside the raster.
    Outside,
}

/// A GeoKey value (SHORT values in place only; the keys read here are all
/// SHORT).
fn geokeys(dir: &[u16]) -> Result<Vec<(u16, u16)>, String> {
    if dir.len() < 4 {
        return Err(format!(
            "GeoKeyDirectoryTag holds {} values: expected a 4-value header",
            dir.len()
        ));
    }
    let n = dir[3] as usize;
    if dir.len() < 4 + 4 * n {
        return Err(format!(
            "GeoKeyDirectoryTag announces {n} keys but holds {} values",
            dir.len()
        ));
    }
    Ok(dir[4..4 + 4 * n]
        .chunks_exact(4)
        .filter(|k| k[1] == 0)
        .map(|k| (k[0], k[3]))
        .collect())
}

const REPROJECT: &str = "a DEM or land-cover raster must be in WGS 84 geographic coordinates \
     (EPSG:4326) or WGS 84 / UTM (EPSG:326zz north, 327zz south): reproject it, e.g. \
     `gdalwarp -t_srs EPSG:<UTM> in.tif out.tif`";

/// The placeholder of the UTM zone in the reprojection hints, which
/// [`with_site_zone`] fills in.
const UTM_PLACEHOLDER: &str = "EPSG:<UTM> in.tif out.tif`";

/// `e` with its reprojection hint naming the UTM zone of the site at
/// (`lat_deg`, `lon_deg`) (e.g. `EPSG:32614 ... (WGS 84 / UTM zone 14N,
/// the site's zone)`); other errors unchanged.
pub fn with_site_zone(e: SceneError, lat_deg: f64, lon_deg: f64) -> SceneError {
    let crs = crate::scene::georef::CrsInfo::utm(lat_deg, lon_deg);
    let fill = |msg: String| {
        msg.replace(
            UTM_PLACEHOLDER,
            &format!(
                "EPSG:{} in.tif out.tif` ({}, the site's zone)",
                crs.epsg.unwrap_or(4326),
                crs.name
            ),
        )
    };
    match e {
        SceneError::Data { loc, msg } => SceneError::Data {
            loc,
            msg: fill(msg),
        },
        other => other,
    }
}

/// The CRS of a GeoKey directory.
fn crs_of(keys: &[(u16, u16)]) -> Result<RasterCrs, String> {
    let get = |k: u16| keys.iter().find(|x| x.0 == k).map(|x| x.1);
    if let Some(u) = get(3076).filter(|&u| u != 9001) {
        return Err(format!(
            "the projected CRS's linear unit is EPSG:{u}, not the metre (EPSG:9001); {REPROJECT}"
        ));
    }
    if let Some(u) = get(2054).filter(|&u| u != 9102) {
        return Err(format!(
            "the geographic CRS's angular unit is EPSG:{u}, not the degree (EPSG:9102); {REPROJECT}"
        ));
    }
    if let Some(u) = get(4099).filter(|&u| u != 9001) {
        return Err(format!(
            "the heights' unit (VerticalUnitsGeoKey) is EPSG:{u}, not the metre (EPSG:9001): \
             convert them, e.g. feet with `gdal_translate -scale 0 1 0 0.3048 in.tif out.tif` \
             and set the unit"
        ));
    }
    let model = get(1024);
    let projected = get(3072);
    match (model, projected) {
        (Some(1) | None, Some(code)) => match code {
            32601..=32660 => Ok(RasterCrs::Utm {
                zone: (code - 32600) as u32,
                north: true,
            }),
            32701..=32760 => Ok(RasterCrs::Utm {
                zone: (code - 32700) as u32,
                north: false,
            }),
            32767 => Err(format!(
                "a user-defined projected CRS (ProjectedCSTypeGeoKey 32767) is not supported; {REPROJECT}"
            )),
            _ => Err(format!("unsupported CRS EPSG:{code}; {REPROJECT}")),
        },
        (Some(2), _) => match get(2048) {
            Some(4326) => Ok(RasterCrs::Geographic),
            Some(32767) => Err(format!(
                "a user-defined geographic CRS (GeographicTypeGeoKey 32767) is not supported; {REPROJECT}"
            )),
            Some(code) => Err(format!("unsupported CRS EPSG:{code}; {REPROJECT}")),
            None => Err(format!(
                "a geographic raster without GeographicTypeGeoKey; {REPROJECT}"
            )),
        },
        (Some(3), _) => Err(format!(
            "a geocentric CRS (GTModelTypeGeoKey 3) is not supported; {REPROJECT}"
        )),
        (Some(m), _) => Err(format!(
            "GTModelTypeGeoKey = {m} (expected 1 projected or 2 geographic); {REPROJECT}"
        )),
        (None, None) => Err(format!(
            "the GeoKey directory names no CRS (no GTModelTypeGeoKey); {REPROJECT}"
        )),
    }
}

/// Inverse of an affine transform in GDAL's order.
fn invert(g: &[f64; 6]) -> Option<[f64; 6]> {
    let det = g[1] * g[5] - g[2] * g[4];
    if !det.is_finite() || det == 0.0 {
        return None;
    }
    let (a, b, c, d) = (g[5] / det, -g[2] / det, -g[4] / det, g[1] / det);
    let inv = [-(a * g[0] + b * g[3]), a, b, -(c * g[0] + d * g[3]), c, d];
    inv.iter().all(|v| v.is_finite()).then_some(inv)
}

/// Reads a single-band GeoTIFF (a DEM or a land-cover raster).
pub fn read_raster(path: &Path) -> Result<Raster, SceneError> {
    let bytes = SceneError::read_bytes(path, crate::bounds::sizes::MAX_RASTER_FILE_BYTES)?;
    parse_raster(path, &bytes)
}

/// As [`read_raster`], from the file's bytes (`path` names it in errors).
pub fn parse_raster(path: &Path, bytes: &[u8]) -> Result<Raster, SceneError> {
    let err = |msg: String| SceneError::Data {
        loc: Location::file(path),
        msg,
    };
    let tiff_err = |e: tiff::TiffError| err(format!("cannot read the GeoTIFF: {e}"));
    let max_px = crate::bounds::sizes::MAX_RASTER_PIXELS;
    let mut limits = Limits::default();
    limits.decoding_buffer_size = max_px * 8;
    let mut dec = Decoder::new(Cursor::new(bytes))
        .map_err(|e| err(format!("not a TIFF file (expected a GeoTIFF): {e}")))?
        .with_limits(limits);
    let (width, height) = dec.dimensions().map_err(tiff_err)?;
    let pixels = width as usize * height as usize;
    if pixels == 0 || pixels > max_px {
        return Err(err(format!(
            "{width}x{height} pixels: expected 1 to {max_px} pixels; crop it first, e.g. \
             `gdal_translate -projwin ULX ULY LRX LRY in.tif out.tif`"
        )));
    }
    let samples: u16 = dec
        .find_tag_unsigned(Tag::SamplesPerPixel)
        .map_err(tiff_err)?
        .unwrap_or(1);
    if samples != 1 {
        return Err(err(format!(
            "{samples} samples per pixel: expected one band (heights or class ids); \
             extract it with `gdal_translate -b 1 in.tif out.tif`"
        )));
    }
    declared_size_fits(&mut dec, bytes.len() as u64, width, height).map_err(err)?;
    let f64_tag =
        |dec: &mut Decoder<Cursor<&[u8]>>, tag: Tag| -> Result<Option<Vec<f64>>, SceneError> {
            match dec.find_tag(tag).map_err(tiff_err)? {
                Some(v) => v.into_f64_vec().map(Some).map_err(tiff_err),
                None => Ok(None),
            }
        };
    let dir: Vec<u16> = match dec.find_tag(Tag::GeoKeyDirectoryTag).map_err(tiff_err)? {
        Some(v) => v.into_u16_vec().map_err(tiff_err)?,
        None => {
            return Err(err(
                "a TIFF without GeoTIFF tags (no GeoKeyDirectoryTag): expected a georeferenced \
                 GeoTIFF; add the georeferencing with `gdal_translate -a_srs EPSG:... \
                 -a_ullr ULX ULY LRX LRY in.tif out.tif`"
                    .into(),
            ));
        }
    };
    let keys = geokeys(&dir).map_err(err)?;
    let crs = crs_of(&keys).map_err(err)?;
    let point = keys.iter().any(|&(k, v)| k == 1025 && v == 2);
    let matrix = f64_tag(&mut dec, Tag::ModelTransformationTag)?;
    let scale = f64_tag(&mut dec, Tag::ModelPixelScaleTag)?;
    let ties = f64_tag(&mut dec, Tag::ModelTiepointTag)?;
    let mut gt = match (matrix, scale, ties) {
        (Some(m), _, _) => {
            if m.len() < 16 {
                return Err(err(format!(
                    "ModelTransformationTag holds {} values: expected 16",
                    m.len()
                )));
            }
            [m[3], m[0], m[1], m[7], m[4], m[5]]
        }
        (None, Some(s), Some(t)) if s.len() >= 2 && t.len() == 6 => [
            t[3] - t[0] * s[0],
            s[0],
            0.0,
            t[4] + t[1] * s[1],
            0.0,
            -s[1],
        ],
        (None, None, Some(t)) if t.len() > 6 => {
            return Err(err(format!(
                "georeferenced by {} ground control points, not by a transform: warp it \
                 first, e.g. `gdalwarp -t_srs EPSG:<UTM> in.tif out.tif`",
                t.len() / 6
            )));
        }
        _ => {
            return Err(err(
                "no raster-to-model transform: expected ModelTransformationTag, or \
                 ModelPixelScaleTag with one ModelTiepointTag"
                    .into(),
            ));
        }
    };
    if point {
        gt[0] -= 0.5 * (gt[1] + gt[2]);
        gt[3] -= 0.5 * (gt[4] + gt[5]);
    }
    let inverse = invert(&gt).ok_or_else(|| {
        err(format!(
            "the raster-to-model transform {gt:?} is not invertible (zero or non-finite pixel size)"
        ))
    })?;
    let nodata = match dec.find_tag(Tag::GdalNodata).map_err(tiff_err)? {
        Some(v) => {
            let s = v.into_string().map_err(tiff_err)?;
            let s = s.trim_matches(|c: char| c == '\0' || c.is_whitespace());
            Some(s.parse::<f64>().map_err(|_| {
                err(format!(
                    "GDAL_NODATA `{s}` is not a number: expected the no-data value"
                ))
            })?)
        }
        None => None,
    };
    let image = dec.read_image().map_err(|e| {
        if e.to_string().contains("no lzw end code") {
            // image-tiff issue #395: libtiff ends the LZW stream of an edge
            // tile early; fixed upstream after tiff 0.11.3.
            err(format!(
                "cannot decode its LZW-compressed tiles ({e}: the `tiff` crate 0.11 refuses the \
                 edge tiles libtiff writes); recompress it, e.g. `gdal_translate -co \
                 COMPRESS=DEFLATE -co TILED=YES in.tif out.tif`"
            ))
        } else {
            tiff_err(e)
        }
    })?;
    let data = to_f32(image, nodata);
    if data.len() < pixels {
        return Err(err(format!(
            "{} samples decoded: expected {width}x{height}",
            data.len()
        )));
    }
    let mut data = data;
    data.truncate(pixels);
    Ok(Raster {
        width,
        height,
        crs,
        geotransform: gt,
        nodata,
        data,
        inverse,
    })
}

/// The most bytes one compressed byte can decode to, by TIFF compression
/// method (tag 259): none 1; PackBits 64 (a 2-byte run code emits at most
/// 128 bytes, TIFF 6.0 §9); LZW 4096 (a code of at least 9 bits emits at
/// most 4096 bytes, TIFF 6.0 §13; a loose bound); Deflate 1032 (a match of
/// at most 258 bytes per at least 2 bits, RFC 1951 §3.2.5). `None` for a
/// method the decoder does not support (it refuses those itself).
fn max_expansion(compression: u16) -> Option<u64> {
    match compression {
        1 => Some(1),
        32773 => Some(64),
        5 => Some(4096),
        8 | 32946 => Some(1032),
        _ => None,
    }
}

/// The raster's declared decoded size (rows of `width` samples of
/// BitsPerSample bits, padded to bytes, times `height`) checked, before
/// anything is allocated or inflated, against what its compressed strips or
/// tiles can hold: every chunk must lie inside the file, and the declared
/// size may not exceed the chunks' bytes times the method's largest
/// expansion ([`max_expansion`]). A decompression bomb (a few kB of deflate
/// declaring 2²⁷ pixels) is refused here with both sizes; the decoder then
/// inflates no chunk beyond its declared size (it reads exactly that much).
fn declared_size_fits(
    dec: &mut Decoder<Cursor<&[u8]>>,
    file_len: u64,
    width: u32,
    height: u32,
) -> Result<(), String> {
    let tiff_err = |e: tiff::TiffError| format!("cannot read the GeoTIFF: {e}");
    let bits = u64::from(
        dec.find_tag_unsigned::<u16>(Tag::BitsPerSample)
            .map_err(tiff_err)?
            .unwrap_or(1),
    );
    let compression = dec
        .find_tag_unsigned::<u16>(Tag::Compression)
        .map_err(tiff_err)?
        .unwrap_or(1);
    let declared = (u64::from(width) * bits).div_ceil(8) * u64::from(height);
    let tiled = dec
        .find_tag(Tag::TileByteCounts)
        .map_err(tiff_err)?
        .is_some();
    let (what, offsets, counts) = if tiled {
        ("tile", Tag::TileOffsets, Tag::TileByteCounts)
    } else {
        ("strip", Tag::StripOffsets, Tag::StripByteCounts)
    };
    let list = |dec: &mut Decoder<Cursor<&[u8]>>, tag: Tag| -> Result<Vec<u64>, String> {
        match dec.find_tag(tag).map_err(tiff_err)? {
            Some(v) => v.into_u64_vec().map_err(tiff_err),
            None => Err(format!("no {tag:?} tag: expected the {what}s' positions")),
        }
    };
    let (offsets, counts) = (list(dec, offsets)?, list(dec, counts)?);
    let mut compressed = 0u64;
    for (i, (&at, &n)) in offsets.iter().zip(&counts).enumerate() {
        if at.checked_add(n).is_none_or(|end| end > file_len) {
            return Err(format!(
                "{what} {i} ({n} bytes at byte {at}) runs past the end of the {file_len}-byte file"
            ));
        }
        compressed = compressed.saturating_add(n);
    }
    if let Some(k) = max_expansion(compression)
        && declared > compressed.saturating_mul(k)
    {
        return Err(format!(
            "{width}x{height} pixels of {bits} bits declare {declared} bytes, but its {} {what}(s) \
             hold {compressed} bytes of compression method {compression}, which decode to at \
             most {} bytes: a truncated file or a decompression bomb (refused before inflating)",
            counts.len(),
            compressed.saturating_mul(k)
        ));
    }
    Ok(())
}

/// Samples as f32, NaN where equal to the no-data value (compared in the
/// sample type, as GDAL does).
fn to_f32(image: DecodingResult, nodata: Option<f64>) -> Vec<f32> {
    fn conv<T: Copy>(v: Vec<T>, f: impl Fn(T) -> f64, nd: Option<f64>) -> Vec<f32> {
        v.into_iter()
            .map(|x| {
                let x = f(x);
                if nd == Some(x) { f32::NAN } else { x as f32 }
            })
            .collect()
    }
    // The no-data value in a float type: compared as f32 (GDAL_NODATA holds
    // e.g. -3.4028234663852886e+38 for f32 rasters).
    let nd32 = nodata.map(|v| v as f32 as f64);
    match image {
        DecodingResult::U8(v) => conv(v, f64::from, nodata),
        DecodingResult::U16(v) => conv(v, f64::from, nodata),
        DecodingResult::U32(v) => conv(v, f64::from, nodata),
        DecodingResult::U64(v) => conv(v, |x| x as f64, nodata),
        DecodingResult::I8(v) => conv(v, f64::from, nodata),
        DecodingResult::I16(v) => conv(v, f64::from, nodata),
        DecodingResult::I32(v) => conv(v, f64::from, nodata),
        DecodingResult::I64(v) => conv(v, |x| x as f64, nodata),
        DecodingResult::F16(v) => conv(v, |x| x.to_f64(), nd32),
        DecodingResult::F32(v) => conv(v, f64::from, nd32),
        DecodingResult::F64(v) => conv(v, |x| x, nodata),
    }
}

impl Raster {
    /// The (col, row) pixel position (corner convention) of CRS point (x, y).
    pub fn pixel_of(&self, x: f64, y: f64) -> [f64; 2] {
        let g = &self.inverse;
        [g[0] + g[1] * x + g[2] * y, g[3] + g[4] * x + g[5] * y]
    }

    /// The CRS point of pixel position (col, row).
    pub fn crs_of_pixel(&self, col: f64, row: f64) -> [f64; 2] {
        let g = &self.geotransform;
        [
            g[0] + g[1] * col + g[2] * row,
            g[3] + g[4] * col + g[5] * row,
        ]
    }

    /// The corners (upper left, upper right, lower right, lower left) in
    /// the CRS, as `gdalinfo` lists them.
    pub fn corners(&self) -> [[f64; 2]; 4] {
        let (w, h) = (self.width as f64, self.height as f64);
        [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)].map(|(c, r)| self.crs_of_pixel(c, r))
    }

    fn at(&self, i: u32, j: u32) -> f32 {
        self.data[j as usize * self.width as usize + i as usize]
    }

    /// Bilinear interpolation between pixel centres at CRS point (x, y)
    /// (the outer half pixel takes the edge pixels' values); a needed pixel
    /// without data gives [`Sample::NoData`].
    pub fn bilinear(&self, x: f64, y: f64) -> Sample {
        let [c, r] = self.pixel_of(x, y);
        let (w, h) = (self.width as f64, self.height as f64);
        if !(c >= 0.0 && c <= w && r >= 0.0 && r <= h) {
            return Sample::Outside;
        }
        let axis = |p: f64, n: u32| -> (u32, u32, f64) {
            let u = (p - 0.5).clamp(0.0, (n - 1) as f64);
            let i0 = (u.floor() as u32).min(n.saturating_sub(2));
            let i1 = (i0 + 1).min(n - 1);
            (i0, i1, u - i0 as f64)
        };
        let (i0, i1, fx) = axis(c, self.width);
        let (j0, j1, fy) = axis(r, self.height);
        let mut sum = 0.0;
        for (i, wx) in [(i0, 1.0 - fx), (i1, fx)] {
            for (j, wy) in [(j0, 1.0 - fy), (j1, fy)] {
                let wgt = wx * wy;
                if wgt == 0.0 {
                    continue;
                }
                let v = self.at(i, j);
                if v.is_nan() {
                    return Sample::NoData([i, j]);
                }
                sum += wgt * v as f64;
            }
        }
        Sample::Value(sum)
    }

    /// The value of the pixel holding CRS point (x, y) (NaN: no data), or
    /// `None` outside the raster.
    pub fn nearest(&self, x: f64, y: f64) -> Option<f32> {
        let [c, r] = self.pixel_of(x, y);
        if !(c >= 0.0 && c < self.width as f64 && r >= 0.0 && r < self.height as f64) {
            return None;
        }
        Some(self.at(c as u32, r as u32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raster(w: u32, h: u32, data: Vec<f32>) -> Raster {
        let gt = [1000.0, 10.0, 0.0, 2000.0, 0.0, -10.0];
        Raster {
            width: w,
            height: h,
            crs: RasterCrs::Utm {
                zone: 18,
                north: true,
            },
            geotransform: gt,
            nodata: None,
            data,
            inverse: invert(&gt).unwrap(),
        }
    }

    /// Bilinear interpolation reproduces a plane exactly, clamps in the
    /// outer half pixel, refuses points outside and reports no-data pixels.
    #[test]
    fn bilinear_is_exact_on_planes_and_reports_holes() {
        let f = |i: u32, j: u32| 3.0 * i as f32 - 2.0 * j as f32 + 7.0;
        let mut d: Vec<f32> = (0..4).flat_map(|j| (0..5).map(move |i| f(i, j))).collect();
        let r = raster(5, 4, d.clone());
        // pixel centre (i, j) is at x = 1000 + 10 (i + 0.5), y = 2000 - 10 (j + 0.5)
        let at = |c: f64, rr: f64| r.bilinear(1000.0 + 10.0 * c, 2000.0 - 10.0 * rr);
        assert_eq!(at(2.5, 1.5), Sample::Value(f(2, 1) as f64));
        let Sample::Value(v) = at(1.8, 2.1) else {
            panic!()
        };
        assert!((v - (3.0 * 1.3 - 2.0 * 1.6 + 7.0)).abs() < 1e-9, "{v}");
        assert_eq!(at(0.2, 0.2), Sample::Value(f(0, 0) as f64));
        assert_eq!(at(5.0, 4.0), Sample::Value(f(4, 3) as f64));
        assert_eq!(at(-0.01, 1.0), Sample::Outside);
        assert_eq!(at(1.0, 4.01), Sample::Outside);
        d[7] = f32::NAN; // pixel (2, 1)
        let r = raster(5, 4, d);
        let at = |c: f64, rr: f64| r.bilinear(1000.0 + 10.0 * c, 2000.0 - 10.0 * rr);
        assert_eq!(at(2.2, 1.7), Sample::NoData([2, 1]));
        // exactly on a neighbouring centre the hole has zero weight
        assert_eq!(at(3.5, 1.5), Sample::Value(f(3, 1) as f64));
        assert!(r.nearest(1025.0, 1985.0).unwrap().is_nan());
        assert_eq!(r.nearest(999.0, 1985.0), None);
    }

    #[test]
    fn crs_keys_pick_geographic_and_utm_and_refuse_others() {
        assert_eq!(
            crs_of(&[(1024, 2), (2048, 4326)]),
            Ok(RasterCrs::Geographic)
        );
        assert_eq!(
            crs_of(&[(1024, 1), (3072, 32618)]),
            Ok(RasterCrs::Utm {
                zone: 18,
                north: true
            })
        );
        assert_eq!(crs_of(&[(3072, 32734)]).map(|c| c.epsg()), Ok(32734));
        let e = crs_of(&[(1024, 2), (2048, 4269)]).unwrap_err();
        assert!(e.contains("EPSG:4269") && e.contains("gdalwarp"), "{e}");
        let e = crs_of(&[(1024, 1), (3072, 26918)]).unwrap_err();
        assert!(e.contains("EPSG:26918"), "{e}");
        let e = crs_of(&[(1024, 1), (3072, 32618), (4099, 9002)]).unwrap_err();
        assert!(e.contains("feet") || e.contains("9002"), "{e}");
    }
}

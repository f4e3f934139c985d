//! OpenEXR output: one part, one channel per plane, named `layer.channel`
//! in three layers — `radiance` (band and sensor radiance, apparent
//! temperature, DN), `terms` (the radiometric terms of eqs. 1-4) and
//! `truth` (everything else: temperature, material, facet, case, range,
//! angles, ground x/y/z, sun) — OpenEXR's layer naming convention
//! (OpenEXR Technical Introduction, "Layers": `layer.channel`).
//!
//! Float planes are 32-bit float channels; the integer planes (`material`,
//! `facet`, `case`, `dn`) are UINT channels, with [`UINT_NONE`] standing
//! for "no surface" (-1 in the planes) in `truth.material` and
//! `truth.facet`. The header holds every plane's unit
//! (`irsig.units.<channel>`), irsig's version (`irsig.version` and the
//! standard `software`), and what the caller adds (time, sun, band, CRS:
//! [`crate::output::frame::write_rendered`]). docs/render.md lists them.

use std::collections::HashMap;
use std::path::Path;

use exr::meta::attribute::{AttributeValue, Text};
use exr::prelude::{
    AnyChannel, AnyChannels, Blocks, Encoding, FlatSamples, Image, Layer, LayerAttributes,
    LineOrder, read_first_flat_layer_from_file,
};

use super::{OutputError, OutputSet, Plane, Planes};
pub use crate::scene::spec::ExrCompression;

/// The UINT value of "no surface" in `truth.material` and `truth.facet`
/// (the planes' -1).
pub const UINT_NONE: u32 = u32::MAX;

/// Planes whose values are whole numbers, written as UINT channels.
const UINT_PLANES: [&str; 4] = ["material", "facet", "case", "dn"];
/// Integer planes where -1 means "no surface".
const NONE_PLANES: [&str; 2] = ["material", "facet"];
/// Planes of the `radiance` layer.
const RADIANCE: [&str; 4] = [
    "band_radiance",
    "apparent_temperature",
    "sensor_radiance",
    "dn",
];

/// The EXR layer of a plane: `radiance`, `terms` (the
/// [`crate::render::planes::TERM_PLANES`]) or `truth`.
pub fn layer_of(plane: &str) -> &'static str {
    if RADIANCE.contains(&plane) {
        "radiance"
    } else if crate::render::planes::TERM_PLANES.contains(&plane) {
        "terms"
    } else {
        "truth"
    }
}

/// The EXR channel name of a plane: `layer.plane`.
pub fn channel_name(plane: &str) -> String {
    format!("{}.{plane}", layer_of(plane))
}

/// A header attribute's value.
#[derive(Clone, Debug, PartialEq)]
pub enum Attr {
    /// A text attribute.
    Text(String),
    /// A double attribute.
    F64(f64),
}

/// Whether the plane is written as UINT: an integer plane whose every value
/// is a whole number in range (-1 allowed where it means none).
fn is_uint(name: &str, data: &[f32]) -> bool {
    let none = NONE_PLANES.contains(&name);
    UINT_PLANES.contains(&name)
        && data.iter().all(|&v| {
            (none && v == -1.0) || (v >= 0.0 && v.fract() == 0.0 && (v as f64) <= u32::MAX as f64)
        })
}

/// A plane's samples as the EXR writer reads them: borrowed from the plane
/// (no copy of the image), UINT planes converted line by line.
struct PlaneSamples<'a> {
    data: &'a [f32],
    uint: bool,
    /// -1 → [`UINT_NONE`].
    none: bool,
}

/// The line writer of a [`PlaneSamples`].
struct PlaneWriter<'s, 'a> {
    width: usize,
    samples: &'s PlaneSamples<'a>,
}

impl<'s, 'a: 's> exr::image::write::samples::WritableSamples<'s> for PlaneSamples<'a> {
    type Writer = PlaneWriter<'s, 'a>;

    fn sample_type(&self) -> exr::meta::attribute::SampleType {
        if self.uint {
            exr::meta::attribute::SampleType::U32
        } else {
            exr::meta::attribute::SampleType::F32
        }
    }

    fn infer_level_modes(&self) -> (exr::meta::attribute::LevelMode, exr::math::RoundingMode) {
        (
            exr::meta::attribute::LevelMode::Singular,
            exr::math::RoundingMode::Down,
        )
    }

    fn create_samples_writer(&'s self, header: &exr::meta::header::Header) -> Self::Writer {
        PlaneWriter {
            width: header.layer_size.width(),
            samples: self,
        }
    }
}

impl exr::image::write::samples::SamplesWriter for PlaneWriter<'_, '_> {
    fn extract_line(&self, line: exr::block::lines::LineRefMut<'_>) {
        let start = line.location.position.y() * self.width + line.location.position.x();
        let src = &self.samples.data[start..start + line.location.sample_count];
        let written = if self.samples.uint {
            let none = self.samples.none;
            let u: Vec<u32> = src
                .iter()
                .map(|&v| {
                    if none && v == -1.0 {
                        UINT_NONE
                    } else {
                        v as u32
                    }
                })
                .collect();
            line.write_samples_from_slice(&u)
        } else {
            line.write_samples_from_slice(src)
        };
        // The line buffer is sized by the exr crate from the same channel
        // list and sample type, so this cannot fail short of a crate bug.
        written.expect("EXR line buffer matches its channel");
    }
}

/// The exr crate's compression for `c`.
fn exr_compression(c: ExrCompression) -> exr::compression::Compression {
    use exr::compression::Compression as C;
    match c {
        ExrCompression::None => C::Uncompressed,
        ExrCompression::Rle => C::RLE,
        ExrCompression::Zips => C::ZIP1,
        ExrCompression::Zip => C::ZIP16,
        ExrCompression::Piz => C::PIZ,
    }
}

/// Writes all planes as channels of a single-part EXR (lossless
/// `compression`) at `path`, as a file of the output set `out`, with the
/// header attributes `attrs` (each stored as `irsig.<key>`) besides the
/// units and version that every file gets.
pub fn write_exr(
    out: &mut OutputSet,
    path: &Path,
    planes: &Planes,
    attrs: &[(String, Attr)],
    compression: ExrCompression,
) -> Result<(), OutputError> {
    let all: Vec<&Plane> = planes.planes.iter().collect();
    let size = (planes.width, planes.height);
    write_exr_planes(out, path, size, &all, attrs, compression)
}

/// [`write_exr`] of some planes of one size (`size` = width, height).
pub fn write_exr_planes(
    out: &mut OutputSet,
    path: &Path,
    size: (u32, u32),
    planes: &[&Plane],
    attrs: &[(String, Attr)],
    compression: ExrCompression,
) -> Result<(), OutputError> {
    let size = (size.0 as usize, size.1 as usize);
    let mut other: HashMap<Text, AttributeValue> = HashMap::new();
    let mut put = |key: String, value: AttributeValue| {
        other.insert(Text::from(key.as_str()), value);
    };
    put(
        "irsig.version".into(),
        AttributeValue::Text(Text::from(crate::version::LONG_VERSION)),
    );
    let channels: Vec<AnyChannel<PlaneSamples>> = planes
        .iter()
        .map(|p| {
            let name = channel_name(&p.name);
            put(
                format!("irsig.units.{name}"),
                AttributeValue::Text(Text::from(p.unit.as_str())),
            );
            let samples = PlaneSamples {
                data: &p.data,
                uint: is_uint(&p.name, &p.data),
                none: NONE_PLANES.contains(&p.name.as_str()),
            };
            AnyChannel::new(name.as_str(), samples)
        })
        .collect();
    if planes
        .iter()
        .any(|p| NONE_PLANES.contains(&p.name.as_str()))
    {
        put(
            "irsig.uint_none".into(),
            AttributeValue::Text(Text::from(
                format!("{UINT_NONE} in truth.material and truth.facet: no surface").as_str(),
            )),
        );
    }
    for (key, value) in attrs {
        let v = match value {
            Attr::Text(s) => AttributeValue::Text(Text::from(s.as_str())),
            Attr::F64(x) => AttributeValue::F64(*x),
        };
        put(format!("irsig.{key}"), v);
    }
    let mut layer_attrs = LayerAttributes::named("irsig");
    layer_attrs.software_name = Some(Text::from(
        format!("irsig {}", crate::version::LONG_VERSION).as_str(),
    ));
    layer_attrs.other = other;
    let encoding = Encoding {
        compression: exr_compression(compression),
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        size,
        layer_attrs,
        encoding,
        AnyChannels::sort(channels.into_iter().collect()),
    );
    let image = Image::from_layer(layer);
    out.stage(path, |w| {
        encode(&mut *w, &image, compression).map_err(|e| e.to_string())?;
        sort_header_in_file(w).map_err(|e| e.to_string())
    })
}

/// The most bytes of a written EXR read back to sort its header (the
/// header, a few kB of attributes, lies well within it).
const HEADER_READ_LIMIT: u64 = 1 << 22;

/// Sorts the attributes of the EXR header just written to `w` (from the
/// file's start; [`sort_header_attributes`]), in place in the file: the
/// image is encoded straight into the file, not held in memory (issue 29:
/// at 2048² the compressed image, ~90 MB, and its buffer's growth were the
/// render's peak).
fn sort_header_in_file(w: &mut super::set::Sink) -> Result<(), String> {
    use std::io::{Read, Seek, SeekFrom, Write};
    let e = |e: std::io::Error| e.to_string();
    w.flush().map_err(e)?;
    let tap = w.get_mut();
    let end = tap.seek(SeekFrom::End(0)).map_err(e)?;
    let mut head = vec![0u8; end.min(HEADER_READ_LIMIT) as usize];
    tap.seek(SeekFrom::Start(0)).map_err(e)?;
    tap.read_exact(&mut head).map_err(e)?;
    let header_end = sort_header_attributes(&mut head)?;
    tap.seek(SeekFrom::Start(0)).map_err(e)?;
    tap.write_all(&head[..header_end]).map_err(e)?;
    tap.seek(SeekFrom::End(0)).map_err(e)?;
    Ok(())
}

/// Writes the file to `out`: the exr crate's header and block layout, the blocks
/// compressed in parallel on the current rayon pool (so `--threads` holds)
/// a batch at a time and written in increasing line order — the bytes do
/// not depend on the thread count. ZIP and ZIPS blocks are compressed by
/// [`super::exr_zip`] (zlib-rs at a level chosen by measurement), the
/// others by the exr crate.
fn encode<W: std::io::Write + std::io::Seek>(
    out: W,
    image: &Image<Layer<AnyChannels<PlaneSamples<'_>>>>,
    compression: ExrCompression,
) -> exr::error::Result<()> {
    use exr::block::UncompressedBlock;
    use exr::block::chunk::{Chunk, CompressedBlock, CompressedScanLineBlock};
    use exr::block::writer::ChunksWriter;
    use exr::image::write::layers::{LayersWriter, WritableLayers};
    use rayon::prelude::*;
    let headers = image.layer_data.infer_headers(&image.attributes);
    let layers = image.layer_data.create_writer(&headers);
    exr::block::write(out, headers, true, |meta, chunks| {
        let order: Vec<_> = meta.enumerate_ordered_header_block_indices().collect();
        // Bounded memory: a batch of blocks in flight, not the image.
        let batch = 16 * rayon::current_num_threads();
        // Native-endian samples are the little-endian bytes ZIP compresses.
        let zip = matches!(compression, ExrCompression::Zips | ExrCompression::Zip)
            && cfg!(target_endian = "little");
        for part in order.chunks(batch) {
            let done: Vec<exr::error::Result<Chunk>> = part
                .par_iter()
                .map(|&(_, index)| {
                    let data = layers.extract_uncompressed_block(&meta.headers, index);
                    if zip {
                        Ok(Chunk {
                            layer_index: index.layer,
                            compressed_block: CompressedBlock::ScanLine(CompressedScanLineBlock {
                                y_coordinate: i32::try_from(index.pixel_position.y()).map_err(
                                    |_| exr::error::Error::Invalid("image height".into()),
                                )?,
                                compressed_pixels_le: super::exr_zip::compress(
                                    data,
                                    super::exr_zip::ZLIB_LEVEL,
                                ),
                            }),
                        })
                    } else {
                        UncompressedBlock { index, data }.compress_to_chunk(&meta.headers)
                    }
                })
                .collect();
            for (&(at, _), chunk) in part.iter().zip(done) {
                chunks.write_chunk(at, chunk?)?;
            }
        }
        Ok(())
    })
}

/// Sorts the attributes of a single-part EXR's header by name, in place.
///
/// The exr crate keeps custom attributes in a `HashMap` and writes them in
/// its (per-process random) iteration order, so the same image would give
/// different bytes from run to run; irsig's outputs must be bit-identical.
/// A header is the magic number and version (8 bytes), then attributes —
/// name\0, type\0, a little-endian i32 size, the value — ended by a null
/// byte (OpenEXR File Layout, "Header"). Reordering them keeps the header's
/// length, so the offset table after it stays valid. Returns the header
/// attributes' end (the offset of their null terminator).
fn sort_header_attributes(bytes: &mut [u8]) -> Result<usize, String> {
    let bad = || "EXR header: unexpected layout".to_string();
    let mut attrs: Vec<(&[u8], &[u8])> = Vec::new();
    let nul = |from: usize| {
        bytes[from..]
            .iter()
            .position(|&b| b == 0)
            .map(|n| from + n)
            .ok_or_else(bad)
    };
    let mut pos = 8;
    loop {
        if *bytes.get(pos).ok_or_else(bad)? == 0 {
            break;
        }
        let name_end = nul(pos)?;
        let type_end = nul(name_end + 1)?;
        let size_at = type_end + 1;
        let size: [u8; 4] = bytes
            .get(size_at..size_at + 4)
            .ok_or_else(bad)?
            .try_into()
            .map_err(|_| bad())?;
        let size = usize::try_from(i32::from_le_bytes(size)).map_err(|_| bad())?;
        let end = size_at + 4 + size;
        if end > bytes.len() {
            return Err(bad());
        }
        attrs.push((&bytes[pos..name_end], &bytes[pos..end]));
        pos = end;
    }
    attrs.sort_by(|a, b| a.0.cmp(b.0));
    let sorted: Vec<u8> = attrs.iter().flat_map(|(_, a)| a.iter().copied()).collect();
    bytes[8..8 + sorted.len()].copy_from_slice(&sorted);
    Ok(pos)
}

/// Named float channels read back from an EXR.
pub type Channels = Vec<(String, Vec<f32>)>;

/// Reads back the planes of an EXR written by [`write_exr`] (for tests and
/// tools): (width, height, channels), each channel under its plane name
/// (the layer prefix removed) as f32, UINT channels converted back
/// ([`UINT_NONE`] → -1 in `material` and `facet`).
pub fn read_exr(path: &Path) -> Result<(u32, u32, Channels), String> {
    let image =
        read_first_flat_layer_from_file(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.width() as u32, layer.size.height() as u32);
    let chans = layer
        .channel_data
        .list
        .into_iter()
        .map(|c| {
            let full = c.name.to_string();
            let name = full.rsplit('.').next().unwrap_or(&full).to_string();
            let none = NONE_PLANES.contains(&name.as_str());
            let values = match &c.sample_data {
                FlatSamples::U32(u) => u
                    .iter()
                    .map(|&v| {
                        if none && v == UINT_NONE {
                            -1.0
                        } else {
                            v as f32
                        }
                    })
                    .collect(),
                s => s.values_as_f32().collect(),
            };
            (name, values)
        })
        .collect();
    Ok((w, h, chans))
}

/// The header attributes `irsig.*` and `software` of an EXR, as text
/// (doubles formatted with `{}`), for tests and tools.
pub fn read_exr_attributes(path: &Path) -> Result<Vec<(String, String)>, String> {
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let header = meta
        .headers
        .first()
        .ok_or_else(|| format!("{}: no header", path.display()))?;
    let text = |v: &AttributeValue| match v {
        AttributeValue::Text(t) => Some(t.to_string()),
        AttributeValue::F64(x) => Some(format!("{x}")),
        AttributeValue::F32(x) => Some(format!("{x}")),
        AttributeValue::I32(x) => Some(format!("{x}")),
        _ => None,
    };
    let mut out: Vec<(String, String)> = header
        .own_attributes
        .other
        .iter()
        .filter_map(|(k, v)| text(v).map(|t| (k.to_string(), t)))
        .collect();
    if let Some(s) = &header.own_attributes.software_name {
        out.push(("software".into(), s.to_string()));
    }
    out.sort();
    Ok(out)
}

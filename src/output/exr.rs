//! OpenEXR output: one part, one 32-bit float channel per plane, channel
//! names `<plane>` (e.g. `band_radiance`, `apparent_temperature`), units in
//! the header's `irsig.units` text attribute is not portable across readers,
//! so units are documented by name and in the JSON stats instead.

use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer, LayerAttributes, WritableImage,
    read_first_flat_layer_from_file,
};

use super::{OutputError, OutputSet, Planes};

/// Writes all planes as float channels of a single-part EXR (ZIP
/// compression, lossless) at `path`, as a file of the output set `out`.
pub fn write_exr(out: &mut OutputSet, path: &Path, planes: &Planes) -> Result<(), OutputError> {
    let size = (planes.width as usize, planes.height as usize);
    let channels: Vec<AnyChannel<FlatSamples>> = planes
        .planes
        .iter()
        .map(|p| AnyChannel::new(p.name.as_str(), FlatSamples::F32(p.data.clone())))
        .collect();
    let layer = Layer::new(
        size,
        LayerAttributes::named("irsig"),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels.into_iter().collect()),
    );
    let image = Image::from_layer(layer);
    out.stage(path, |w| {
        let mut cursor = std::io::Cursor::new(Vec::new());
        image
            .write()
            .non_parallel()
            .to_buffered(&mut cursor)
            .map_err(|e| e.to_string())?;
        std::io::Write::write_all(w, cursor.get_ref()).map_err(|e| e.to_string())
    })
}

/// Named float channels read back from an EXR.
pub type Channels = Vec<(String, Vec<f32>)>;

/// Reads back the named float channels of an EXR written by [`write_exr`]
/// (for tests and tools): (width, height, channels).
pub fn read_exr(path: &Path) -> Result<(u32, u32, Channels), String> {
    let image =
        read_first_flat_layer_from_file(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.width() as u32, layer.size.height() as u32);
    let chans = layer
        .channel_data
        .list
        .into_iter()
        .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
        .collect();
    Ok((w, h, chans))
}

//! ENVI output: a band-sequential (BSQ) little-endian cube plus an `.hdr`
//! text header (ENVI Header Format, L3Harris ENVI documentation): band
//! names, the sample type (byte, uint16, float32, float64) and any further
//! header fields (wavelengths, map info, class names, ...) the caller
//! gives. GDAL, spectral's `open_image` and ENVI read it.

use std::io::Write;
use std::path::Path;

use super::{OutputError, OutputSet, Planes};

/// A sample type of an ENVI cube and its `data type` code.
pub trait EnviSample: Copy {
    /// ENVI `data type`: 1 byte, 12 uint16, 4 float32, 5 float64.
    const DATA_TYPE: u32;
    /// Writes the sample little-endian (ENVI `byte order = 0`).
    fn write_le(self, w: &mut dyn Write) -> std::io::Result<()>;
}

impl EnviSample for u8 {
    const DATA_TYPE: u32 = 1;
    fn write_le(self, w: &mut dyn Write) -> std::io::Result<()> {
        w.write_all(&[self])
    }
}

impl EnviSample for u16 {
    const DATA_TYPE: u32 = 12;
    fn write_le(self, w: &mut dyn Write) -> std::io::Result<()> {
        w.write_all(&self.to_le_bytes())
    }
}

impl EnviSample for f32 {
    const DATA_TYPE: u32 = 4;
    fn write_le(self, w: &mut dyn Write) -> std::io::Result<()> {
        w.write_all(&self.to_le_bytes())
    }
}

impl EnviSample for f64 {
    const DATA_TYPE: u32 = 5;
    fn write_le(self, w: &mut dyn Write) -> std::io::Result<()> {
        w.write_all(&self.to_le_bytes())
    }
}

/// An ENVI list value `{a, b, c}` of `items`.
pub fn list<T: std::fmt::Display>(items: impl IntoIterator<Item = T>) -> String {
    let v: Vec<String> = items.into_iter().map(|x| x.to_string()).collect();
    format!("{{{}}}", v.join(", "))
}

/// Writes an ENVI cube `path` (e.g. `x.img`) of `bands` (name, samples;
/// each (`width`, `height`), row-major) and its header `path` with extension
/// `.hdr`: `file type` (e.g. `ENVI Standard`, `ENVI Classification`),
/// `description`, then `fields` (key, value) as given (values are written
/// as they are: braces for lists are the caller's); both files are staged
/// in the output set `out` (the header last).
pub fn write_cube<T: EnviSample>(
    out: &mut OutputSet,
    path: &Path,
    (width, height): (u32, u32),
    bands: &[(&str, &[T])],
    file_type: &str,
    description: &str,
    fields: &[(String, String)],
) -> Result<(), OutputError> {
    let npx = width as usize * height as usize;
    if let Some((name, d)) = bands.iter().find(|(_, d)| d.len() != npx) {
        return Err(OutputError::Encode {
            path: path.to_path_buf(),
            msg: format!(
                "band {name} has {} samples, expected {width}x{height}",
                d.len()
            ),
        });
    }
    out.stage(path, |w| {
        for (_, data) in bands {
            for &v in *data {
                v.write_le(w).map_err(|e| e.to_string())?;
            }
        }
        Ok(())
    })?;
    let clean = |s: &str| s.replace(['{', '}'], "").replace(',', ";");
    let mut hdr = String::from("ENVI\n");
    hdr += &format!(
        "description = {{{}}}\n",
        description.replace(['{', '}'], "")
    );
    hdr += &format!(
        "samples = {width}\nlines = {height}\nbands = {}\nheader offset = 0\n\
         file type = {file_type}\ndata type = {}\ninterleave = bsq\nbyte order = 0\n",
        bands.len(),
        T::DATA_TYPE
    );
    hdr += &format!(
        "band names = {}\n",
        list(bands.iter().map(|(n, _)| clean(n)))
    );
    for (k, v) in fields {
        hdr += &format!("{k} = {v}\n");
    }
    out.stage(&path.with_extension("hdr"), |w| {
        w.write_all(hdr.as_bytes()).map_err(|e| e.to_string())
    })
}

/// Writes `planes` as an ENVI float32 BSQ cube `path` with band names
/// `name [unit]` and, when given, one wavelength (µm) per plane, both
/// files of the output set `out`.
pub fn write_envi(
    out: &mut OutputSet,
    path: &Path,
    planes: &Planes,
    wavelengths_um: Option<&[f64]>,
    description: &str,
) -> Result<(), OutputError> {
    let names: Vec<String> = planes
        .planes
        .iter()
        .map(|p| format!("{} [{}]", p.name, p.unit))
        .collect();
    let bands: Vec<(&str, &[f32])> = names
        .iter()
        .zip(&planes.planes)
        .map(|(n, p)| (n.as_str(), p.data.as_slice()))
        .collect();
    let mut fields = Vec::new();
    if let Some(wl) = wavelengths_um {
        fields.push(("wavelength units".into(), "Micrometers".into()));
        fields.push((
            "wavelength".into(),
            list(wl.iter().map(|x| format!("{x:.6}"))),
        ));
    }
    write_cube(
        out,
        path,
        (planes.width, planes.height),
        &bands,
        "ENVI Standard",
        description,
        &fields,
    )
}

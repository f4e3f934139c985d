//! ENVI output: band-sequential (BSQ) little-endian float32 cube plus an
//! `.hdr` text header (ENVI Header Format, L3Harris ENVI documentation),
//! with band names and, for spectral cubes, wavelengths in micrometres.

use std::io::Write;
use std::path::Path;

use super::{OutputError, OutputSet, Planes};

/// Writes `planes` as an ENVI BSQ cube `path` (e.g. `x.img`) and its header
/// `path` with extension `.hdr`, both files of the output set `out` (the
/// header staged last). `wavelengths_um`, when given, must have one entry
/// per plane.
pub fn write_envi(
    out: &mut OutputSet,
    path: &Path,
    planes: &Planes,
    wavelengths_um: Option<&[f64]>,
    description: &str,
) -> Result<(), OutputError> {
    out.stage(path, |w| {
        for p in &planes.planes {
            for v in &p.data {
                w.write_all(&v.to_le_bytes()).map_err(|e| e.to_string())?;
            }
        }
        Ok(())
    })?;
    let mut hdr = String::from("ENVI\n");
    hdr += &format!(
        "description = {{{}}}\n",
        description.replace(['{', '}'], "")
    );
    hdr += &format!(
        "samples = {}\nlines = {}\nbands = {}\nheader offset = 0\nfile type = ENVI Standard\n",
        planes.width,
        planes.height,
        planes.planes.len()
    );
    hdr += "data type = 4\ninterleave = bsq\nbyte order = 0\n";
    let names: Vec<String> = planes
        .planes
        .iter()
        .map(|p| format!("{} [{}]", p.name, p.unit))
        .collect();
    hdr += &format!("band names = {{{}}}\n", names.join(", "));
    if let Some(wl) = wavelengths_um {
        let list: Vec<String> = wl.iter().map(|x| format!("{x:.6}")).collect();
        hdr += &format!(
            "wavelength units = Micrometers\nwavelength = {{{}}}\n",
            list.join(", ")
        );
    }
    out.stage(&path.with_extension("hdr"), |w| {
        w.write_all(hdr.as_bytes()).map_err(|e| e.to_string())
    })
}

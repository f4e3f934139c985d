//! One material of a library file, by name (what `irsig therm --materials
//! … --material NAME` and `irsig.therm.series` take). A scene-side lookup:
//! the thermal layer below takes the slab and never reads a scene file.

use std::path::Path;

use anyhow::bail;

use crate::therm::slab::SlabMaterial;

/// The slab of material `name` in the material library at `path` (the
/// scene format's `[[material]]` tables); an unknown name is an error that
/// lists the library's names and the closest one.
pub fn load_material(path: &Path, name: &str) -> anyhow::Result<SlabMaterial> {
    let lib = super::material::load_library(path)?;
    match lib.iter().find(|m| m.name == name) {
        Some(m) => Ok(m.construction),
        None => bail!(
            "{}: no material `{name}`{}; the library defines: {}",
            path.display(),
            super::error::closest(name, lib.iter().map(|m| m.name.as_str()))
                .map(|s| format!(" (did you mean `{s}`?)"))
                .unwrap_or_default(),
            lib.iter()
                .map(|m| m.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

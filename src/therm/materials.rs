//! Interim materials file for `irsig therm` (the scene's material library
//! will replace it; the lead unifies the formats).
//!
//! Format: TOML, one `[materials.NAME]` table per material whose keys are
//! the fields of [`SlabMaterial`] (SI units, names carry the unit):
//!
//! ```toml
//! [materials.concrete]
//! density_kg_m3 = 2300.0
//! specific_heat_j_kgk = 880.0
//! conductivity_w_mk = 1.4
//! thickness_m = 0.2
//! solar_absorptivity = 0.65     # DIRSIG VISIBLE_EMISSIVITY
//! thermal_emissivity = 0.92
//! back = "insulated"            # or { exposed_to_air = { area_factor = 1.0 } }
//!                               # or { deep_ground = { temp_k = 288.0 } } / { deep_ground = {} }
//! internal_power_w_m2 = 0.0     # optional
//! ground_albedo = 0.2           # optional
//! ```

use std::collections::BTreeMap;

use serde::Deserialize;
use thiserror::Error;

use super::slab::SlabMaterial;

/// Errors reading a materials file; every variant names the file.
#[derive(Debug, Error)]
pub enum MaterialsError {
    #[error("{file}: {err}")]
    Io { file: String, err: std::io::Error },
    /// TOML syntax or a wrong/missing/unknown key (the message has the line
    /// and column and what was expected).
    #[error("{file}: {msg}")]
    Parse { file: String, msg: String },
    #[error("{file}: material '{name}': {msg}")]
    Invalid {
        file: String,
        name: String,
        msg: String,
    },
    #[error("{file}: no material '{name}' (materials in the file: {known})")]
    Unknown {
        file: String,
        name: String,
        known: String,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialsFile {
    materials: BTreeMap<String, SlabMaterial>,
}

/// Parses the text of a materials file; `file` is used in messages.
pub fn parse_materials_toml(
    text: &str,
    file: &str,
) -> Result<BTreeMap<String, SlabMaterial>, MaterialsError> {
    let parsed: MaterialsFile = toml::from_str(text).map_err(|e| MaterialsError::Parse {
        file: file.to_owned(),
        msg: e.to_string(),
    })?;
    for (name, m) in &parsed.materials {
        m.validate().map_err(|e| MaterialsError::Invalid {
            file: file.to_owned(),
            name: name.clone(),
            msg: e.to_string(),
        })?;
    }
    Ok(parsed.materials)
}

/// Reads a materials file and returns the named material.
pub fn load_material(path: &std::path::Path, name: &str) -> Result<SlabMaterial, MaterialsError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|err| MaterialsError::Io {
        file: file.clone(),
        err,
    })?;
    let mats = parse_materials_toml(&text, &file)?;
    mats.get(name)
        .copied()
        .ok_or_else(|| MaterialsError::Unknown {
            file,
            name: name.to_owned(),
            known: mats.keys().cloned().collect::<Vec<_>>().join(", "),
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::therm::slab::BackBoundary;

    const GOOD: &str = r#"
[materials.concrete]
density_kg_m3 = 2300.0
specific_heat_j_kgk = 880.0
conductivity_w_mk = 1.4
thickness_m = 0.2
solar_absorptivity = 0.65
thermal_emissivity = 0.92
back = "insulated"

[materials.skin]
density_kg_m3 = 2700.0
specific_heat_j_kgk = 900.0
conductivity_w_mk = 200.0
thickness_m = 0.0005
solar_absorptivity = 0.5
thermal_emissivity = 0.85
back = { exposed_to_air = { area_factor = 1.0 } }
internal_power_w_m2 = 5.0

[materials.soil]
density_kg_m3 = 1600.0
specific_heat_j_kgk = 1300.0
conductivity_w_mk = 1.0
thickness_m = 1.0
solar_absorptivity = 0.78
thermal_emissivity = 0.97
back = { deep_ground = {} }
"#;

    #[test]
    fn parses_all_back_boundaries() {
        let m = parse_materials_toml(GOOD, "m.toml").unwrap();
        assert_eq!(m["concrete"].back, BackBoundary::Insulated);
        assert_eq!(
            m["skin"].back,
            BackBoundary::ExposedToAir { area_factor: 1.0 }
        );
        assert_eq!(m["skin"].internal_power_w_m2, 5.0);
        assert_eq!(m["soil"].back, BackBoundary::DeepGround { temp_k: None });
        assert_eq!(m["concrete"].ground_albedo, None);
    }

    #[test]
    fn errors_name_file_line_and_field() {
        let bad = GOOD.replace("thickness_m = 0.2", "thickness_m = \"thick\"");
        let e = parse_materials_toml(&bad, "m.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("m.toml") && e.contains("line 6"), "{e}");
        let bad = GOOD.replace("back = \"insulated\"", "back = \"open\"");
        let e = parse_materials_toml(&bad, "m.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 9") && e.contains("insulated"), "{e}");
        let bad = GOOD.replace("solar_absorptivity = 0.65", "solar_absorptivity = 1.65");
        let e = parse_materials_toml(&bad, "m.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("concrete") && e.contains("solar_absorptivity"),
            "{e}"
        );
        let bad = GOOD.replace("thickness_m = 0.2", "thicknes_m = 0.2");
        let e = parse_materials_toml(&bad, "m.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("thicknes_m"), "{e}");
    }
}

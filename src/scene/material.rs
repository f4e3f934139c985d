//! Materials: the thermal and optical properties of a facet (docs/models.md, "Thermal model";
//! DIRSIG's MASS_DENSITY, SPECIFIC_HEAT, THERMAL_CONDUCTIVITY, thickness,
//! VISIBLE_EMISSIVITY, THERMAL_EMISSIVITY, EXPOSED_AREA, SPECULARITY and
//! internal power). Library files hold `[material.NAME]` tables.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::error::{Location, SceneError};
use super::tomlsrc::{Seg, TomlSource};
use crate::bounds::{Bound, material as M};
use crate::therm::aero::Canopy;
pub use crate::therm::slab::BackBoundary;
use crate::therm::slab::SlabMaterial;
use crate::therm::surface::{DEFAULT_SOLID_ROUGHNESS_M, SurfaceKind, WaterBody};

/// A material library file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialLibrary {
    /// Materials by name.
    pub material: BTreeMap<String, MaterialSpec>,
}

/// One `[material.NAME]` table as written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Free text (what it is, where the values come from).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// Mass density ρ, kg/m³ (> 0).
    pub density_kg_m3: f64,
    /// Specific heat c, J/(kg·K) (> 0).
    pub specific_heat_j_kgk: f64,
    /// Thermal conductivity k, W/(m·K) (> 0).
    pub conductivity_w_mk: f64,
    /// Slab thickness L, m (> 0).
    pub thickness_m: f64,
    /// Solar (0.3-3 µm) absorptivity α_s, [0, 1] (DIRSIG VISIBLE_EMISSIVITY).
    pub solar_absorptivity: f64,
    /// Hemispherical thermal-infrared emissivity ε, [0, 1], used by the
    /// thermal model (and by the radiometry when `emissivity = "constant"`).
    pub thermal_emissivity: f64,
    /// Back-face boundary condition of the slab.
    #[serde(default)]
    pub back: BackBoundary,
    /// Internal heat source, W per m² of facet (>= 0 typical; any finite).
    #[serde(default)]
    pub internal_power_w_m2: f64,
    /// Fraction of the reflectance that is specular, [0, 1] (0 diffuse,
    /// 1 mirror-like).
    #[serde(default)]
    pub specularity: f64,
    /// Directional spectral emissivity model for the radiometry.
    #[serde(default)]
    pub emissivity: EmissivitySpec,
    /// What the surface is for the energy balance (default `solid`).
    #[serde(default)]
    pub kind: KindSpec,
    /// Solid: water held before runoff, mm (default 0: never wet).
    pub water_capacity_mm: Option<f64>,
    /// Solid and water: roughness length for momentum, m.
    pub roughness_m: Option<f64>,
    /// Vegetation: canopy height, m (required).
    pub canopy_height_m: Option<f64>,
    /// Vegetation: leaf area index (required).
    pub lai: Option<f64>,
    /// Vegetation: relative available soil water 0 (wilting) … 1 (field
    /// capacity) (required).
    pub soil_moisture: Option<f64>,
    /// Vegetation: minimum stomatal resistance per unit LAI, s/m.
    pub min_stomatal_resistance_s_m: Option<f64>,
    /// Vegetation: cuticular (largest) resistance, s/m.
    pub max_stomatal_resistance_s_m: Option<f64>,
    /// Vegetation: the radiation parameter R_gl of the Jarvis F₁, W/m².
    pub radiation_limit_w_m2: Option<f64>,
    /// Vegetation: the vapour-deficit parameter h_s of F₂, (kg/kg)⁻¹.
    pub vpd_coeff: Option<f64>,
    /// Water: Beer-Lambert extinction coefficient, 1/m (required).
    pub extinction_per_m: Option<f64>,
    /// Water: fraction of absorbed shortwave absorbed at the surface.
    pub shortwave_surface_fraction: Option<f64>,
    /// Water: eddy diffusivity of a stable column, m²/s.
    pub eddy_diffusivity_m2_s: Option<f64>,
    /// Water: diffusivity of a convectively unstable column, m²/s.
    pub convective_diffusivity_m2_s: Option<f64>,
}

/// `kind = "solid" | "vegetation" | "water"`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum KindSpec {
    #[default]
    Solid,
    Vegetation,
    Water,
}

/// Emissivity model as written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum EmissivitySpec {
    /// ε(θ, λ) = thermal_emissivity.
    #[default]
    Constant,
    /// A CSV table of ε(θ, λ) (relative to the library file).
    TableFile(PathBuf),
    /// Fresnel reflectance of a smooth surface with complex refractive index
    /// n + ik (wavelength-independent), ε = 1 − R(θ).
    Fresnel {
        /// Real part of the refractive index (> 0).
        n: f64,
        /// Imaginary part (extinction coefficient, >= 0).
        k: f64,
    },
}

/// Emissivity model, resolved (table files read).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Emissivity {
    Constant,
    Table(EmissivityTable),
    Fresnel { n: f64, k: f64 },
}

/// ε(θ, λ) on a grid: `values[i_wavelength * angles_deg.len() + i_angle]`.
/// Bilinear interpolation inside, clamped at the edges.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EmissivityTable {
    /// Strictly increasing wavelengths, µm.
    pub wavelengths_um: Vec<f64>,
    /// Strictly increasing angles from the surface normal, degrees, in [0, 90].
    pub angles_deg: Vec<f64>,
    /// Emissivities in [0, 1], row-major by wavelength.
    pub values: Vec<f64>,
}

/// A material ready for the model: the one model description of a material,
/// built in one place ([`load_library`]) from its `[material.NAME]` table.
/// It carries the thermal construction the heat-flow model marches (with the
/// surface's solar absorptivity and thermal emissivity, its back boundary,
/// internal power and surface kind) and the optics the radiometry uses.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Material {
    pub name: String,
    pub description: Option<String>,
    /// The thermal construction (today one homogeneous slab): what
    /// `therm` solves, exactly as the scene gave it (a deep-ground back face
    /// without `temp_c` takes the site's deep-ground temperature at render time).
    pub construction: SlabMaterial,
    /// Fraction of the reflectance that is specular, [0, 1].
    pub specularity: f64,
    /// Directional spectral emissivity model of the radiometry.
    pub emissivity: Emissivity,
    /// The library file that defined it.
    pub library: PathBuf,
}

impl Material {
    /// Whether any of its reflectance is specular.
    pub fn is_specular(&self) -> bool {
        self.specularity > 0.0
    }
}

/// Checks a value and reports it at its TOML location.
pub(crate) struct Check<'a> {
    pub src: &'a TomlSource,
}

impl Check<'_> {
    /// Requires `lo <= v <= hi` (and finite).
    pub fn range(
        &self,
        path: &[Seg],
        name: &str,
        v: f64,
        lo: f64,
        hi: f64,
        unit: &str,
    ) -> Result<(), SceneError> {
        if v.is_finite() && v >= lo && v <= hi {
            return Ok(());
        }
        Err(self.src.invalid(
            path,
            format!("`{name}` = {v} is out of range: expected {lo} <= {name} <= {hi}{unit}"),
        ))
    }
    /// Requires `v` inside its [`Bound`] (crate::bounds).
    pub fn bound(&self, path: &[Seg], b: &Bound, v: f64) -> Result<(), SceneError> {
        b.check(v).map(drop).map_err(|m| self.src.invalid(path, m))
    }
    /// Requires `v > 0` (and finite).
    pub fn positive(&self, path: &[Seg], name: &str, v: f64, unit: &str) -> Result<(), SceneError> {
        if v.is_finite() && v > 0.0 {
            return Ok(());
        }
        Err(self.src.invalid(
            path,
            format!("`{name}` = {v} is out of range: expected a finite number > 0{unit}"),
        ))
    }
    /// Requires a finite number.
    pub fn finite(&self, path: &[Seg], name: &str, v: f64) -> Result<(), SceneError> {
        if v.is_finite() {
            return Ok(());
        }
        Err(self
            .src
            .invalid(path, format!("`{name}` = {v}: expected a finite number")))
    }
}

/// Reads and validates one material library file.
pub fn load_library(path: &Path) -> Result<Vec<Material>, SceneError> {
    load_library_source(path, TomlSource::read(path)?)
}

/// As [`load_library`], from the file's text (emissivity tables it names are
/// still read from beside `path`).
pub fn load_library_text(path: &Path, text: String) -> Result<Vec<Material>, SceneError> {
    load_library_source(path, TomlSource::from_text(path, text))
}

fn load_library_source(path: &Path, src: TomlSource) -> Result<Vec<Material>, SceneError> {
    let lib: MaterialLibrary = src.parse()?;
    let c = Check { src: &src };
    let mut out = Vec::with_capacity(lib.material.len());
    for (name, m) in lib.material {
        let p = |k: &'static str| {
            [
                Seg::Key("material".into()),
                Seg::Key(name.clone()),
                Seg::Key(k.into()),
            ]
        };
        for (b, v) in [
            (M::DENSITY, m.density_kg_m3),
            (M::SPECIFIC_HEAT, m.specific_heat_j_kgk),
            (M::CONDUCTIVITY, m.conductivity_w_mk),
            (M::THICKNESS, m.thickness_m),
            (M::SOLAR_ABSORPTIVITY, m.solar_absorptivity),
            (M::THERMAL_EMISSIVITY, m.thermal_emissivity),
            (M::INTERNAL_POWER, m.internal_power_w_m2),
            (M::SPECULARITY, m.specularity),
        ] {
            c.bound(&p(b.key), &b, v)?;
        }
        // (`deep_ground.temp_c` is range-checked as it is read, in °C.)
        if let BackBoundary::ExposedToAir { area_factor } = m.back {
            let mut bp = p("back").to_vec();
            bp.extend([Seg::Key("air".into()), Seg::Key("exposed_area".into())]);
            c.bound(&bp, &M::EXPOSED_AREA, area_factor)?;
        }
        let emissivity = match &m.emissivity {
            EmissivitySpec::Constant => Emissivity::Constant,
            EmissivitySpec::Fresnel { n, k } => {
                let mut bp = p("emissivity").to_vec();
                bp.push(Seg::Key("fresnel".into()));
                let mut np = bp.clone();
                np.push(Seg::Key("n".into()));
                c.bound(&np, &M::FRESNEL_N, *n)?;
                let mut kp = bp;
                kp.push(Seg::Key("k".into()));
                c.bound(&kp, &M::FRESNEL_K, *k)?;
                Emissivity::Fresnel { n: *n, k: *k }
            }
            EmissivitySpec::TableFile(f) => {
                // The path policy: a library reads files in its own folder tree.
                let folder = path.parent().unwrap_or(Path::new(""));
                let file = crate::files::within(folder, f, &[]).map_err(|why| {
                    let mut at = p("emissivity").to_vec();
                    at.push(Seg::Key("table_file".into()));
                    c.src.invalid(
                        &at,
                        format!(
                            "emissivity table `{}` {why}: a material library reads files in its \
                             own folder tree",
                            f.display()
                        ),
                    )
                })?;
                Emissivity::Table(read_emissivity_table(&file)?)
            }
        };
        let surface = surface_kind(&c, &name, &m)?;
        out.push(Material {
            name: name.clone(),
            description: m.description.clone(),
            construction: SlabMaterial {
                density_kg_m3: m.density_kg_m3,
                specific_heat_j_kgk: m.specific_heat_j_kgk,
                conductivity_w_mk: m.conductivity_w_mk,
                thickness_m: m.thickness_m,
                solar_absorptivity: m.solar_absorptivity,
                thermal_emissivity: m.thermal_emissivity,
                back: m.back,
                internal_power_w_m2: m.internal_power_w_m2,
                ground_albedo: None,
                surface,
            },
            specularity: m.specularity,
            emissivity,
            library: path.to_path_buf(),
        });
    }
    Ok(out)
}

/// Defaults of the optional surface parameters, with their sources.
pub mod surface_defaults {
    /// Jarvis/Noah R_gl for grass and crops, W/m² (Noilhan & Planton 1989;
    /// Noah VEGPARM "grassland" 100).
    pub const RADIATION_LIMIT_W_M2: f64 = 100.0;
    /// Noah's cuticular resistance r_s,max, s/m (Chen et al. 1996).
    pub const MAX_STOMATAL_RESISTANCE_S_M: f64 = 5000.0;
    /// Noah's h_s for grass and crops, (kg/kg)⁻¹ (Noah VEGPARM 36.35).
    pub const VPD_COEFF: f64 = 36.35;
    /// FAO-56's bulk stomatal resistance of a well-illuminated leaf, s/m
    /// (FAO-56 eq. 5: r_l = 100 s/m).
    pub const MIN_STOMATAL_RESISTANCE_S_M: f64 = 100.0;
    /// Near-infrared share of absorbed sunlight taken by a water skin
    /// (Henderson-Sellers 1986; Hostetler & Bartlein 1990: 0.4).
    pub const SHORTWAVE_SURFACE_FRACTION: f64 = 0.4;
    /// Eddy diffusivity of a stably stratified small pond, m²/s (1e-6-1e-4
    /// in small lakes, Hondzo & Stefan 1993): 2e-5.
    pub const EDDY_DIFFUSIVITY_M2_S: f64 = 1.0e-4;
    /// Convective overturning, m²/s: fast enough to mix a 1 m column in
    /// minutes.
    pub const CONVECTIVE_DIFFUSIVITY_M2_S: f64 = 1.0e-2;
    /// Roughness length of a water surface at light winds, m (Charnock
    /// z₀ = 0.011·u*²/g ≈ 1e-4 m at u* = 0.3 m/s; Garratt 1992, Table A6).
    pub const WATER_ROUGHNESS_M: f64 = 2.0e-4;
}

/// The surface kind of one `[material.NAME]` table: checks that the keys
/// its kind needs are there and in range, and that no key of another kind
/// is given.
fn surface_kind(c: &Check, name: &str, m: &MaterialSpec) -> Result<SurfaceKind, SceneError> {
    use surface_defaults as d;
    let p = |k: &str| {
        [
            Seg::Key("material".into()),
            Seg::Key(name.to_string()),
            Seg::Key(k.into()),
        ]
    };
    let kind_name = match m.kind {
        KindSpec::Solid => "solid",
        KindSpec::Vegetation => "vegetation",
        KindSpec::Water => "water",
    };
    let all: [(&str, Option<f64>, &[KindSpec]); 13] = [
        ("water_capacity_mm", m.water_capacity_mm, &[KindSpec::Solid]),
        (
            "roughness_m",
            m.roughness_m,
            &[KindSpec::Solid, KindSpec::Water],
        ),
        (
            "canopy_height_m",
            m.canopy_height_m,
            &[KindSpec::Vegetation],
        ),
        ("lai", m.lai, &[KindSpec::Vegetation]),
        ("soil_moisture", m.soil_moisture, &[KindSpec::Vegetation]),
        (
            "min_stomatal_resistance_s_m",
            m.min_stomatal_resistance_s_m,
            &[KindSpec::Vegetation],
        ),
        (
            "max_stomatal_resistance_s_m",
            m.max_stomatal_resistance_s_m,
            &[KindSpec::Vegetation],
        ),
        (
            "radiation_limit_w_m2",
            m.radiation_limit_w_m2,
            &[KindSpec::Vegetation],
        ),
        ("vpd_coeff", m.vpd_coeff, &[KindSpec::Vegetation]),
        ("extinction_per_m", m.extinction_per_m, &[KindSpec::Water]),
        (
            "shortwave_surface_fraction",
            m.shortwave_surface_fraction,
            &[KindSpec::Water],
        ),
        (
            "eddy_diffusivity_m2_s",
            m.eddy_diffusivity_m2_s,
            &[KindSpec::Water],
        ),
        (
            "convective_diffusivity_m2_s",
            m.convective_diffusivity_m2_s,
            &[KindSpec::Water],
        ),
    ];
    for (key, v, kinds) in all {
        if v.is_some() && !kinds.contains(&m.kind) {
            return Err(c.src.invalid(
                &p(key),
                format!(
                    "`{key}` does not apply to kind = \"{kind_name}\" (it is a parameter of {})",
                    kinds
                        .iter()
                        .map(|k| format!("{k:?}").to_lowercase())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
    }
    let need = |key: &str, v: Option<f64>| {
        v.ok_or_else(|| {
            c.src.invalid(
                &[Seg::Key("material".into()), Seg::Key(name.to_string())],
                format!("kind = \"{kind_name}\" needs `{key}` (see docs/scene-format.md, \"Surface kinds\")"),
            )
        })
    };
    let range = |b: Bound, v: f64| c.bound(&p(b.key), &b, v);
    // a range whose lower end is another key of the same material
    let above = |b: Bound, v: f64, lo: f64| c.bound(&p(b.key), &Bound { lo, ..b }, v);
    Ok(match m.kind {
        KindSpec::Solid => {
            let cap = m.water_capacity_mm.unwrap_or(0.0);
            range(M::WATER_CAPACITY, cap)?;
            let z0 = m.roughness_m.unwrap_or(DEFAULT_SOLID_ROUGHNESS_M);
            range(M::SOLID_ROUGHNESS, z0)?;
            SurfaceKind::Solid {
                water_capacity_mm: cap,
                roughness_m: z0,
            }
        }
        KindSpec::Vegetation => {
            let height_m = need("canopy_height_m", m.canopy_height_m)?;
            range(M::CANOPY_HEIGHT, height_m)?;
            let lai = need("lai", m.lai)?;
            range(M::LAI, lai)?;
            let soil_moisture = need("soil_moisture", m.soil_moisture)?;
            range(M::SOIL_MOISTURE, soil_moisture)?;
            let rmin = m
                .min_stomatal_resistance_s_m
                .unwrap_or(d::MIN_STOMATAL_RESISTANCE_S_M);
            range(M::MIN_STOMATAL_RESISTANCE, rmin)?;
            let rmax = m
                .max_stomatal_resistance_s_m
                .unwrap_or(d::MAX_STOMATAL_RESISTANCE_S_M);
            above(M::MAX_STOMATAL_RESISTANCE, rmax, rmin)?;
            let rgl = m.radiation_limit_w_m2.unwrap_or(d::RADIATION_LIMIT_W_M2);
            range(M::RADIATION_LIMIT, rgl)?;
            let hs = m.vpd_coeff.unwrap_or(d::VPD_COEFF);
            range(M::VPD_COEFF, hs)?;
            SurfaceKind::Vegetation(Canopy {
                height_m,
                lai,
                min_resistance_s_m: rmin,
                max_resistance_s_m: rmax,
                radiation_limit_w_m2: rgl,
                vpd_coeff: hs,
                soil_moisture,
            })
        }
        KindSpec::Water => {
            let eta = need("extinction_per_m", m.extinction_per_m)?;
            range(M::EXTINCTION, eta)?;
            let beta = m
                .shortwave_surface_fraction
                .unwrap_or(d::SHORTWAVE_SURFACE_FRACTION);
            range(M::SHORTWAVE_SURFACE_FRACTION, beta)?;
            let ke = m.eddy_diffusivity_m2_s.unwrap_or(d::EDDY_DIFFUSIVITY_M2_S);
            range(M::EDDY_DIFFUSIVITY, ke)?;
            let kc = m
                .convective_diffusivity_m2_s
                .unwrap_or(d::CONVECTIVE_DIFFUSIVITY_M2_S);
            above(M::CONVECTIVE_DIFFUSIVITY, kc, ke)?;
            let z0 = m.roughness_m.unwrap_or(d::WATER_ROUGHNESS_M);
            range(M::WATER_ROUGHNESS, z0)?;
            SurfaceKind::Water(WaterBody {
                surface_fraction: beta,
                extinction_per_m: eta,
                eddy_diffusivity_m2_s: ke,
                convective_diffusivity_m2_s: kc,
                roughness_m: z0,
            })
        }
    })
}

/// Splits a CSV data line into numbers; `Err(column)` (1-based) on a bad field.
pub(crate) fn parse_csv_numbers(line: &str) -> Result<Vec<f64>, (usize, String)> {
    line.split(',')
        .enumerate()
        .map(|(i, f)| {
            let f = f.trim();
            match f.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err((i + 1, f.to_string())),
            }
        })
        .collect()
}

/// Reads an ε(θ, λ) table: `#` comments and blank lines ignored; the first
/// data line is `wavelength_um, θ1, θ2, ...` (angles from the normal,
/// degrees); then one line per wavelength: `λ, ε(θ1), ε(θ2), ...`.
pub fn read_emissivity_table(file: &Path) -> Result<EmissivityTable, SceneError> {
    let text = SceneError::read_text(file)?;
    parse_emissivity_table(file, &text)
}

/// As [`read_emissivity_table`], from the file's text (`file` names it in
/// errors).
pub fn parse_emissivity_table(file: &Path, text: &str) -> Result<EmissivityTable, SceneError> {
    let data_err = |line: usize, msg: String| SceneError::Data {
        loc: Location::line(file, line),
        msg,
    };
    let mut angles: Option<Vec<f64>> = None;
    let mut wl = Vec::new();
    let mut values = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let ln = i + 1;
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        match &angles {
            None => {
                let mut it = line.split(',');
                let first = it.next().unwrap_or("").trim();
                if first != "wavelength_um" {
                    return Err(data_err(
                        ln,
                        format!(
                            "expected the header `wavelength_um, angle_deg, ...`, found `{first}`"
                        ),
                    ));
                }
                let rest: Vec<&str> = it.collect();
                let a = parse_csv_numbers(&rest.join(",")).map_err(|(c, f)| {
                    data_err(
                        ln,
                        format!("column {}: `{f}` is not an angle in degrees", c + 1),
                    )
                })?;
                for x in &a {
                    crate::bounds::data::EMISSIVITY_ANGLE
                        .check(*x)
                        .map_err(|m| data_err(ln, m))?;
                }
                if a.is_empty() || a.windows(2).any(|w| w[1] <= w[0]) {
                    return Err(data_err(
                        ln,
                        "angles must be strictly increasing degrees in [0, 90]".to_string(),
                    ));
                }
                angles = Some(a);
            }
            Some(a) => {
                let row = parse_csv_numbers(line).map_err(|(c, f)| {
                    data_err(ln, format!("column {c}: `{f}` is not a finite number"))
                })?;
                if row.len() != a.len() + 1 {
                    return Err(data_err(
                        ln,
                        format!(
                            "expected {} columns (wavelength + {} angles), found {}",
                            a.len() + 1,
                            a.len(),
                            row.len()
                        ),
                    ));
                }
                crate::bounds::data::WAVELENGTH_UM
                    .check(row[0])
                    .map_err(|m| data_err(ln, m))?;
                if wl.last().is_some_and(|&l| row[0] <= l) {
                    return Err(data_err(
                        ln,
                        format!(
                            "wavelength {} µm: wavelengths must be strictly increasing",
                            row[0]
                        ),
                    ));
                }
                for e in &row[1..] {
                    crate::bounds::data::EMISSIVITY
                        .check(*e)
                        .map_err(|m| data_err(ln, m))?;
                }
                wl.push(row[0]);
                values.extend_from_slice(&row[1..]);
            }
        }
    }
    let Some(angles_deg) = angles else {
        return Err(data_err(
            0,
            "empty table: expected a header and at least one row".to_string(),
        ));
    };
    if wl.is_empty() {
        return Err(data_err(
            0,
            "no data rows: expected at least one wavelength row".to_string(),
        ));
    }
    Ok(EmissivityTable {
        wavelengths_um: wl,
        angles_deg,
        values,
    })
}

impl EmissivityTable {
    /// ε at (angle from normal, wavelength), bilinear, clamped at the edges.
    pub fn eval(&self, angle_deg: f64, wavelength_um: f64) -> f64 {
        let (i0, i1, fa) = bracket(&self.angles_deg, angle_deg);
        let (j0, j1, fw) = bracket(&self.wavelengths_um, wavelength_um);
        let n = self.angles_deg.len();
        let v = |j: usize, i: usize| self.values[j * n + i];
        let a = v(j0, i0) * (1.0 - fa) + v(j0, i1) * fa;
        let b = v(j1, i0) * (1.0 - fa) + v(j1, i1) * fa;
        a * (1.0 - fw) + b * fw
    }
}

/// Indices and fraction for linear interpolation in a sorted grid (clamped).
fn bracket(grid: &[f64], x: f64) -> (usize, usize, f64) {
    let n = grid.len();
    if n == 1 || x <= grid[0] {
        return (0, 0, 0.0);
    }
    if x >= grid[n - 1] {
        return (n - 1, n - 1, 0.0);
    }
    let hi = grid.partition_point(|&g| g <= x).min(n - 1);
    let lo = hi - 1;
    (lo, hi, (x - grid[lo]) / (grid[hi] - grid[lo]))
}

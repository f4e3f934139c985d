//! Materials: the thermal and optical properties of a facet (docs/models.md, "Thermal model";
//! DIRSIG's MASS_DENSITY, SPECIFIC_HEAT, THERMAL_CONDUCTIVITY, thickness,
//! VISIBLE_EMISSIVITY, THERMAL_EMISSIVITY, EXPOSED_AREA, SPECULARITY and
//! internal power). Library files hold `[material.NAME]` tables.
//!
//! A table's keys are described once, by the part of the material they
//! fill: the thermal construction ([`SlabMaterial`], rows in
//! [`crate::therm::slab::keys`]), its surface kind
//! ([`SurfaceSpec`], rows in [`crate::therm::surface::keys`]) and the
//! optics ([`OpticsSpec`], rows in [`keys`] here). Each part deserialises
//! itself from the same table (serde on the type itself, reading only its
//! own keys, so a type, unknown-key or missing-key error keeps its
//! file:line:col), and every numeric row marked `as_written` is checked
//! against its range on the value as written. Nothing here names a
//! construction key: a new one is its field and its row in
//! `therm/slab/material.rs`, then the physics that reads it.

use std::collections::BTreeMap;
use std::marker::PhantomData;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use serde::de::{self, DeserializeOwned, DeserializeSeed, IntoDeserializer, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};

use super::error::SceneError;
use super::tomlsrc::{Seg, TomlSource};
use crate::bounds::{Bound, Key, KeyError};
pub use crate::radiometry::EmissivityTable;
pub use crate::therm::slab::BackBoundary;
use crate::therm::slab::SlabMaterial;
use crate::therm::surface::SurfaceKind;
pub use crate::therm::surface::{KindSpec, SurfaceSpec, surface_defaults};

/// The keys of a `[material.NAME]` table that the scene reads itself: the
/// description and the optics, one row each (with the construction's and
/// the surface's rows in [`library_keys`]).
pub mod keys {
    use crate::bounds::{Bound, Key};
    pub use crate::therm::slab::keys::*;
    pub use crate::therm::surface::keys::*;

    /// `specularity`: the specular fraction of the reflectance.
    pub const SPECULARITY: Bound = Bound::new("specularity", 0.0, 1.0, "");
    /// `emissivity = { fresnel = { n } }`: the refractive index.
    pub const FRESNEL_N: Bound = Bound::new("n", 1e-6, 1e4, "");
    /// `emissivity = { fresnel = { k } }`: the extinction coefficient.
    pub const FRESNEL_K: Bound = Bound::new("k", 0.0, 1e4, "");

    /// The description and optics keys, in the order the docs list them.
    pub const OPTICS: &[Key] = &[
        Key::number(
            &["specularity"],
            "0",
            SPECULARITY,
            "specular fraction of the reflectance (0 diffuse, 1 mirror)",
        ),
        Key::text(
            &["emissivity"],
            "",
            "`\"constant\"`",
            "`\"constant\"` (ε = thermal_emissivity), `{ table_file = \"e.csv\" }`, \
             `{ fresnel = { n = 1.5, k = 0.02 } }` (smooth surface, ε(θ) = 1 − R_Fresnel(θ; n + ik))",
        ),
        Key::number(
            &["emissivity", "fresnel", "n"],
            "",
            FRESNEL_N,
            "in `emissivity = { fresnel = { n, k } }`",
        ),
        Key::number(
            &["emissivity", "fresnel", "k"],
            "",
            FRESNEL_K,
            "in `emissivity = { fresnel = { n, k } }`",
        ),
    ];

    /// `description`, free text.
    pub const DESCRIPTION: Key = Key::text(&["description"], "text", "none", "");
}

/// Every key of a `[material.NAME]` table, in the order
/// docs/scene-format.md lists them (the table there is generated from these
/// rows by `tests/bounds_docs.rs`).
pub fn library_keys() -> Vec<Key> {
    let mut v = vec![keys::DESCRIPTION];
    v.extend_from_slice(crate::therm::slab::keys::CONSTRUCTION);
    v.extend_from_slice(keys::OPTICS);
    v.extend_from_slice(crate::therm::surface::keys::SURFACE);
    v
}

/// The description and optics of one `[material.NAME]` table as written.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OpticsSpec {
    /// Free text (what it is, where the values come from).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// Fraction of the reflectance that is specular, [0, 1] (0 diffuse,
    /// 1 mirror-like).
    #[serde(default)]
    pub specularity: f64,
    /// Directional spectral emissivity model for the radiometry.
    #[serde(default)]
    pub emissivity: EmissivitySpec,
}

// --- One table, three parts ---------------------------------------------

/// A part of a material, read from the `[material.NAME]` table by its own
/// `Deserialize` (only the keys it owns; the others' are skipped).
trait Part: DeserializeOwned {
    /// The table keys this part reads: its fields.
    fn keys() -> Vec<&'static str> {
        fields_of::<Self>().to_vec()
    }
}

impl Part for SlabMaterial {
    fn keys() -> Vec<&'static str> {
        let not = SlabMaterial::NOT_LIBRARY_KEYS;
        fields_of::<Self>()
            .iter()
            .copied()
            .filter(|k| !not.contains(k))
            .collect()
    }
}
impl Part for SurfaceSpec {}
impl Part for OpticsSpec {}

/// Every key a material table may hold (for the unknown-key message and
/// its "did you mean").
fn all_keys() -> &'static [&'static str] {
    static ALL: OnceLock<Vec<&'static str>> = OnceLock::new();
    ALL.get_or_init(|| {
        [
            SlabMaterial::keys(),
            SurfaceSpec::keys(),
            OpticsSpec::keys(),
        ]
        .concat()
    })
}

/// The field names a derived `Deserialize` of a struct asks for.
fn fields_of<T: DeserializeOwned>() -> &'static [&'static str] {
    match T::deserialize(FieldNames) {
        Err(Fields(f)) => f,
        Ok(_) => &[],
    }
}

#[derive(Debug)]
struct Fields(&'static [&'static str]);

impl std::fmt::Display for Fields {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "fields {:?}", self.0)
    }
}
impl std::error::Error for Fields {}
impl de::Error for Fields {
    fn custom<T: std::fmt::Display>(_: T) -> Self {
        Fields(&[])
    }
}

/// A deserializer that only answers which fields a struct has.
struct FieldNames;

impl<'de> Deserializer<'de> for FieldNames {
    type Error = Fields;
    fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Fields> {
        Err(Fields(&[]))
    }
    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        fields: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Fields> {
        Err(Fields(fields))
    }
    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf option unit unit_struct newtype_struct seq tuple
        tuple_struct map enum identifier ignored_any
    }
}

/// A material library file read as one part of each material.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, bound = "T: Part")]
struct Library<T> {
    material: BTreeMap<String, Table<T>>,
}

/// One `[material.NAME]` table read as the part `T`.
struct Table<T>(T);

impl<'de, T: Part> Deserialize<'de> for Table<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T>(PhantomData<T>);
        impl<'de, T: Part> Visitor<'de> for V<T> {
            type Value = Table<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a material table")
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Table<T>, A::Error> {
                let own = OwnKeys {
                    map,
                    own: T::keys(),
                };
                T::deserialize(de::value::MapAccessDeserializer::new(own)).map(Table)
            }
        }
        d.deserialize_map(V(PhantomData))
    }
}

/// The table's entries that belong to one part; the other parts' keys are
/// skipped, a key of no part is refused (at the key) listing every key.
struct OwnKeys<A> {
    map: A,
    own: Vec<&'static str>,
}

impl<'de, A: MapAccess<'de>> MapAccess<'de> for OwnKeys<A> {
    type Error = A::Error;
    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, A::Error> {
        let mut seed = Some(seed);
        loop {
            let route = Route {
                seed: &mut seed,
                own: &self.own,
            };
            match self.map.next_key_seed(route)? {
                None => return Ok(None),
                Some(Some(k)) => return Ok(Some(k)),
                Some(None) => {
                    self.map.next_value::<de::IgnoredAny>()?;
                }
            }
        }
    }
    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, A::Error> {
        self.map.next_value_seed(seed)
    }
}

/// Reads one key: the part's own (`Some`, handed to the part's field
/// visitor), another part's (`None`, skipped) or an unknown one (an error).
struct Route<'a, K> {
    seed: &'a mut Option<K>,
    own: &'a [&'static str],
}

impl<'de, K: DeserializeSeed<'de>> DeserializeSeed<'de> for Route<'_, K> {
    type Value = Option<K::Value>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        let key = String::deserialize(d)?;
        if !self.own.contains(&key.as_str()) {
            return if all_keys().contains(&key.as_str()) {
                Ok(None)
            } else {
                Err(de::Error::unknown_field(&key, all_keys()))
            };
        }
        let seed = self.seed.take().expect("one key per call");
        seed.deserialize(IntoDeserializer::<D::Error>::into_deserializer(key))
            .map(Some)
    }
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
    /// Grey and Lambertian: the construction's `thermal_emissivity`.
    Constant,
    /// A table ε(θ, λ) read from its file.
    Table(EmissivityTable),
    /// From the Fresnel equations of a complex index n + ik.
    Fresnel {
        /// Refractive index.
        n: f64,
        /// Extinction coefficient.
        k: f64,
    },
}

/// A material ready for the model: the one model description of a material,
/// built in one place ([`load_library`]) from its `[material.NAME]` table.
/// It carries the thermal construction the heat-flow model marches (with the
/// surface's solar absorptivity and thermal emissivity, its back boundary,
/// internal power and surface kind) and the optics the radiometry uses.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Material {
    /// The material's name (its `[material.NAME]`).
    pub name: String,
    /// Its `description`, if given.
    pub description: Option<String>,
    /// The thermal construction (one homogeneous or layered slab): what
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

/// The materials of a scene: every library's, later libraries overriding
/// earlier ones of the same name (index = material id).
pub(crate) struct SceneMaterials {
    pub materials: Vec<Material>,
    /// The library files, in the scene's order.
    pub files: Vec<PathBuf>,
    pub by_name: std::collections::HashMap<String, u32>,
}

impl SceneMaterials {
    /// Reads the libraries `libs` named at the scene key `materials`
    /// (each checked against the path policy `allow`).
    pub fn load(
        src: &TomlSource,
        libs: &[PathBuf],
        allow: &[PathBuf],
    ) -> Result<SceneMaterials, SceneError> {
        let mut materials: Vec<Material> = Vec::new();
        let mut files = Vec::new();
        for (i, lib) in libs.iter().enumerate() {
            let at = [Seg::Key("materials".into()), Seg::Index(i)];
            let file = super::paths::referenced_file(src, allow, lib, &at, "material library")?;
            for m in load_library(&file)? {
                match materials.iter().position(|x| x.name == m.name) {
                    Some(j) => materials[j] = m,
                    None => materials.push(m),
                }
            }
            files.push(file);
        }
        let by_name = (materials.iter().enumerate())
            .map(|(i, m)| (m.name.clone(), i as u32))
            .collect();
        Ok(SceneMaterials {
            materials,
            files,
            by_name,
        })
    }

    /// The id of the material `name` named at key `at` of `src`, or the
    /// error naming it there, the libraries and the closest name.
    pub fn id(&self, src: &TomlSource, at: &[Seg], name: &str) -> Result<u32, SceneError> {
        self.by_name
            .get(name)
            .copied()
            .ok_or_else(|| SceneError::UndefinedMaterial {
                loc: src.loc_of(at),
                name: name.to_string(),
                libraries: self.files.clone().into(),
                suggestion: super::error::closest(
                    name,
                    self.materials.iter().map(|m| m.name.as_str()),
                ),
            })
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
    // Each part reads its own keys of every table; the first pass refuses
    // keys of no part.
    let slabs: Library<SlabMaterial> = src.parse()?;
    let surfaces: Library<SurfaceSpec> = src.parse()?;
    let optics: Library<OpticsSpec> = src.parse()?;
    let written: toml::Table = src.parse()?;
    let rows = library_keys();
    let c = Check { src: &src };
    let mut out = Vec::with_capacity(slabs.material.len());
    let parts = slabs
        .material
        .into_iter()
        .zip(surfaces.material.into_values())
        .zip(optics.material.into_values());
    for (((name, Table(slab)), Table(surface)), Table(o)) in parts {
        let at = |path: &[&str]| -> Vec<Seg> {
            [Seg::Key("material".into()), Seg::Key(name.clone())]
                .into_iter()
                .chain(path.iter().map(|k| Seg::Key(k.to_string())))
                .collect()
        };
        let key_err = |e: KeyError| c.src.invalid(&at(&e.path), e.msg);
        // Every number with a range, as written.
        let table = written.get("material").and_then(|m| m.get(name.as_str()));
        for row in rows.iter().filter(|r| r.as_written) {
            let (Some(b), Some(v)) = (row.range, table.and_then(|t| written_number(t, row))) else {
                continue;
            };
            c.bound(&at(row.path), &b, v)?;
        }
        check_layers(&c, &at(&["layers"]), table.and_then(|t| t.get("layers")))?;
        let slab = slab_or_layers(&c, &at, table, slab)?;
        let emissivity = match &o.emissivity {
            EmissivitySpec::Constant => Emissivity::Constant,
            EmissivitySpec::Fresnel { n, k } => Emissivity::Fresnel { n: *n, k: *k },
            EmissivitySpec::TableFile(f) => {
                // The path policy: a library reads files in its own folder tree.
                let folder = path.parent().unwrap_or(Path::new(""));
                let file = crate::files::within(folder, f, &[]).map_err(|why| {
                    c.src.invalid(
                        &at(&["emissivity", "table_file"]),
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
        let surface = surface.build().map_err(key_err)?;
        if !slab.layers.is_empty() && matches!(surface, SurfaceKind::Water(_)) {
            return Err(c.src.invalid(
                &at(&["layers"]),
                "a water body is one mixed column: `layers` are not for kind = \"water\"".into(),
            ));
        }
        out.push(Material {
            name: name.clone(),
            description: o.description,
            construction: SlabMaterial { surface, ..slab },
            specularity: o.specularity,
            emissivity,
            library: path.to_path_buf(),
        });
    }
    Ok(out)
}

/// A construction gives the four keys of one slab or `layers`, not both;
/// a layered one takes its ρ, c, k (the top layer's) and L (the total)
/// from its layers. `at(&[])` is the material's table.
fn slab_or_layers(
    c: &Check,
    at: &dyn Fn(&[&str]) -> Vec<Seg>,
    table: Option<&toml::Value>,
    slab: SlabMaterial,
) -> Result<SlabMaterial, SceneError> {
    let given = |k: &str| table.and_then(|t| t.get(k)).is_some();
    let four = [
        keys::DENSITY.key,
        keys::SPECIFIC_HEAT.key,
        keys::CONDUCTIVITY.key,
        keys::THICKNESS.key,
    ];
    if !given("layers") {
        return match four.iter().find(|k| !given(k)) {
            Some(k) => Err(c.src.invalid(
                &at(&[]),
                format!("missing field `{k}` (or give the slab as `layers`)"),
            )),
            None => Ok(slab),
        };
    }
    if slab.layers.is_empty() {
        return Err(c.src.invalid(
            &at(&["layers"]),
            "`layers` is empty: give at least one layer".into(),
        ));
    }
    if let Some(k) = four.iter().find(|k| given(k)) {
        return Err(c.src.invalid(
            &at(&[k]),
            format!("`{k}` and `layers` both given: a layered slab gives its layers only"),
        ));
    }
    Ok(slab.filled_from_layers())
}

/// Checks every key of every `layers` entry (at `at`) as written against
/// its range ([`keys::LAYER`]), and the layers' total thickness against the
/// slab's (`thickness_m`).
fn check_layers(c: &Check, at: &[Seg], layers: Option<&toml::Value>) -> Result<(), SceneError> {
    let Some(toml::Value::Array(layers)) = layers else {
        return Ok(());
    };
    let mut total_m = 0.0;
    for (i, entry) in layers.iter().enumerate() {
        for b in keys::LAYER {
            let v = match entry.get(b.key) {
                Some(toml::Value::Float(x)) => *x,
                Some(toml::Value::Integer(n)) => *n as f64,
                _ => continue,
            };
            let path: Vec<Seg> = at
                .iter()
                .cloned()
                .chain([Seg::Index(i), Seg::Key(b.key.into())])
                .collect();
            c.bound(&path, &b, v)?;
            if b.key == keys::THICKNESS.key {
                total_m += v;
            }
        }
    }
    let b = keys::THICKNESS;
    if total_m > b.hi {
        return Err(c.src.invalid(
            at,
            format!(
                "the layers are {total_m} m thick in all: a slab is at most {} m ({})",
                b.hi, b.key
            ),
        ));
    }
    Ok(())
}

/// The number at `row`'s path in a material table as written (an integer
/// read as a number), if it is there.
fn written_number(table: &toml::Value, row: &Key) -> Option<f64> {
    let mut v = table;
    for k in row.path {
        v = v.get(k)?;
    }
    match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

/// Reads an ε(θ, λ) table (`emissivity = { table_file }`) with the one
/// reader, [`EmissivityTable::from_csv_str`] (its format and messages).
pub fn read_emissivity_table(file: &Path) -> Result<EmissivityTable, SceneError> {
    let text = SceneError::read_text(file)?;
    parse_emissivity_table(file, &text)
}

/// As [`read_emissivity_table`], from the file's text (`file` names it in
/// errors): the reader's message at `file:line`.
pub fn parse_emissivity_table(file: &Path, text: &str) -> Result<EmissivityTable, SceneError> {
    EmissivityTable::from_csv_str(text, &file.display().to_string())
        .map_err(|e| SceneError::from_data(file, e))
}

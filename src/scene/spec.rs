//! The scene file as plain data: what `scene.toml` says, after defaults.
//! The TOML keys are the field names; docs/scene-format.md is the
//! reference page (every key, its unit and its default).

use std::path::PathBuf;

use chrono::{NaiveDateTime, TimeZone};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// `[files]`: the path policy's allowances.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilesSpec {
    /// Folders outside the scene file's folder tree from which the scene may
    /// read files (relative to the scene file, or absolute), e.g. `[".."]`
    /// for a material library beside the scene's folder; `["/"]` allows
    /// any path (a scene you trust).
    #[serde(default)]
    pub allow: Vec<PathBuf>,
}

impl FilesSpec {
    fn is_default(&self) -> bool {
        self.allow.is_empty()
    }
}

/// A whole scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Material library files (TOML), relative to the scene file. A material
    /// defined in a later file replaces one of the same name in an earlier.
    pub materials: Vec<PathBuf>,
    /// Geographic site; local ENU frame origin (x east, y north, z up).
    pub site: Site,
    /// Image acquisition time.
    pub time: TimeSpec,
    /// Weather history driving the thermal model.
    pub weather: WeatherSpec,
    /// Atmosphere for the radiative-transfer tables.
    #[serde(default)]
    pub atmosphere: AtmosphereSpec,
    /// Sensor: pose, field of view, pixels, band, PSF, noise, quantisation.
    pub sensor: SensorSpec,
    /// Render (accuracy/speed) options.
    #[serde(default)]
    pub render: RenderOptions,
    /// Output file options.
    #[serde(default)]
    pub output: OutputOptions,
    /// Objects placed in the scene (`[[object]]` tables).
    #[serde(rename = "object", default)]
    pub objects: Vec<ObjectSpec>,
    /// Terrain meshed from DEMs (`[[terrain]]` tables).
    #[serde(rename = "terrain", default, skip_serializing_if = "Vec::is_empty")]
    pub terrain: Vec<crate::scene::terrain::spec::TerrainSpec>,
    /// Where the files the scene refers to may lie (the path policy,
    /// docs/reliability.md): by default inside the scene file's folder tree.
    #[serde(default, skip_serializing_if = "FilesSpec::is_default")]
    pub files: FilesSpec,
}

/// `[site]`: where the scene stands ([`crate::sun::Site`], the one site
/// type: the keys `latitude_deg`, `longitude_deg` and `elevation_m` are its
/// fields), the local clock and the outputs' map CRS. Read and written by
/// hand so the location's keys stand in the table beside the others (serde's
/// `flatten` cannot refuse unknown keys).
#[derive(Clone, Debug, PartialEq)]
pub struct Site {
    /// Free-text site name (`name`).
    pub name: Option<String>,
    /// Geodetic latitude (`latitude_deg`, degrees, north positive,
    /// [-90, 90]), longitude (`longitude_deg`, degrees, east positive,
    /// [-180, 180]) and the elevation of the local frame origin (z = 0)
    /// above sea level (`elevation_m`, metres, default 0). Latitude and
    /// longitude may be left out with a weather file that gives its
    /// station's (NaN until [`crate::scene::load`] fills them from it).
    pub location: crate::sun::Site,
    /// Offset of the local clock from UTC, hours (e.g. -4 for EDT), [-14, 14].
    pub utc_offset_h: f64,
    /// The map CRS of the outputs' georeferencing: `"utm"` (default, the
    /// WGS 84 / UTM zone of the site) or `"enu"` (the local frame: an
    /// orthographic projection centred on the site). See
    /// [`crate::scene::georef`].
    pub crs: OutputCrs,
}

/// The keys of `[site]`, in the order they are written.
const SITE_KEYS: &[&str] = &[
    "name",
    "latitude_deg",
    "longitude_deg",
    "elevation_m",
    "utc_offset_h",
    "crs",
];

impl Serialize for Site {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let loc = &self.location;
        let mut st = s.serialize_struct("Site", 5 + usize::from(self.name.is_some()))?;
        match &self.name {
            Some(n) => st.serialize_field("name", n)?,
            None => st.skip_field("name")?,
        }
        st.serialize_field("latitude_deg", &loc.latitude_deg)?;
        st.serialize_field("longitude_deg", &loc.longitude_deg)?;
        st.serialize_field("elevation_m", &loc.elevation_m)?;
        st.serialize_field("utc_offset_h", &self.utc_offset_h)?;
        st.serialize_field("crs", &self.crs)?;
        st.end()
    }
}

impl<'de> Deserialize<'de> for Site {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::{Error, MapAccess, Visitor};
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Site;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("struct Site")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Site, A::Error> {
                /// A key of `[site]`: read inside the map's key step, so an
                /// unknown key is refused at the key (its file:line:col).
                #[derive(Deserialize)]
                #[serde(field_identifier, rename_all = "snake_case")]
                enum Key {
                    Name,
                    LatitudeDeg,
                    LongitudeDeg,
                    ElevationM,
                    UtcOffsetH,
                    Crs,
                }
                fn once<T, E: Error>(
                    slot: &mut Option<T>,
                    key: &'static str,
                    v: T,
                ) -> Result<(), E> {
                    match slot.replace(v) {
                        Some(_) => Err(E::duplicate_field(key)),
                        None => Ok(()),
                    }
                }
                let (mut name, mut lat, mut lon, mut elev, mut utc, mut crs) =
                    (None, None, None, None, None, None);
                while let Some(k) = map.next_key::<Key>()? {
                    match k {
                        Key::Name => once(&mut name, "name", map.next_value::<Option<String>>()?)?,
                        Key::LatitudeDeg => once(&mut lat, "latitude_deg", map.next_value()?)?,
                        Key::LongitudeDeg => once(&mut lon, "longitude_deg", map.next_value()?)?,
                        Key::ElevationM => once(&mut elev, "elevation_m", map.next_value()?)?,
                        Key::UtcOffsetH => once(&mut utc, "utc_offset_h", map.next_value()?)?,
                        Key::Crs => once(&mut crs, "crs", map.next_value()?)?,
                    }
                }
                Ok(Site {
                    name: name.flatten(),
                    location: crate::sun::Site {
                        latitude_deg: lat.unwrap_or_else(unset_deg),
                        longitude_deg: lon.unwrap_or_else(unset_deg),
                        elevation_m: elev.unwrap_or_default(),
                    },
                    utc_offset_h: utc.ok_or_else(|| A::Error::missing_field("utc_offset_h"))?,
                    crs: crs.unwrap_or_default(),
                })
            }
        }
        d.deserialize_struct("Site", SITE_KEYS, V)
    }
}

/// A site coordinate not given in the file (NaN until [`crate::scene::load`]
/// fills it from the weather file's station).
fn unset_deg() -> f64 {
    f64::NAN
}

/// `site.crs`: the map CRS of the outputs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OutputCrs {
    /// WGS 84 / UTM zone of the site (EPSG 326zz / 327zz).
    #[default]
    Utm,
    /// The scene's local east-north-up frame (orthographic at the site).
    Enu,
}

/// `[time]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// Local clock date and time of the image (TOML local date-time,
    /// e.g. `2001-08-08T12:00:00`, or the same as a string).
    #[serde(serialize_with = "ser_datetime", deserialize_with = "de_datetime")]
    pub local: NaiveDateTime,
}

impl TimeSpec {
    /// The image time in UTC for a site's clock offset.
    pub fn utc(&self, site: &Site) -> chrono::DateTime<chrono::Utc> {
        let offset_s = (site.utc_offset_h * 3600.0).round() as i64;
        let utc_naive = self.local - chrono::Duration::seconds(offset_s);
        chrono::Utc.from_utc_datetime(&utc_naive)
    }
}

fn ser_datetime<S: Serializer>(t: &NaiveDateTime, s: S) -> Result<S::Ok, S::Error> {
    use chrono::{Datelike, Timelike};
    let dt = toml::value::Datetime {
        date: Some(toml::value::Date {
            year: t.year() as u16,
            month: t.month() as u8,
            day: t.day() as u8,
        }),
        time: Some(toml::value::Time {
            hour: t.hour() as u8,
            minute: t.minute() as u8,
            second: t.second() as u8,
            nanosecond: t.nanosecond(),
        }),
        offset: None,
    };
    dt.serialize(s)
}

fn de_datetime<'de, D: Deserializer<'de>>(d: D) -> Result<NaiveDateTime, D::Error> {
    struct V;
    const EXPECT: &str = "a local date-time such as 2001-08-08T12:00:00 (no time-zone offset: \
                          the site's utc_offset_h applies)";
    fn parse<E: serde::de::Error>(s: &str) -> Result<NaiveDateTime, E> {
        let s = s.trim();
        for fmt in [
            "%Y-%m-%dT%H:%M:%S%.f",
            "%Y-%m-%d %H:%M:%S%.f",
            "%Y-%m-%dT%H:%M",
            "%Y-%m-%d %H:%M",
        ] {
            if let Ok(t) = NaiveDateTime::parse_from_str(s, fmt) {
                // the sun and weather support 1900-2200; far outside,
                // chrono's arithmetic overflowed (year 262142)
                use chrono::Datelike;
                return crate::bounds::time::YEAR
                    .check(t.year().into())
                    .map(|_| t)
                    .map_err(|m| E::custom(format!("date-time `{s}`: {m}")));
            }
        }
        Err(E::custom(format!(
            "invalid date-time `{s}`: expected {EXPECT}"
        )))
    }
    impl<'de> serde::de::Visitor<'de> for V {
        type Value = NaiveDateTime;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str(EXPECT)
        }
        fn visit_str<E: serde::de::Error>(self, s: &str) -> Result<NaiveDateTime, E> {
            parse(s)
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            map: A,
        ) -> Result<NaiveDateTime, A::Error> {
            let dt = toml::value::Datetime::deserialize(
                serde::de::value::MapAccessDeserializer::new(map),
            )?;
            if dt.offset.is_some() {
                return Err(serde::de::Error::custom(format!(
                    "date-time `{dt}` has a time-zone offset: expected {EXPECT}"
                )));
            }
            if dt.date.is_none() || dt.time.is_none() {
                return Err(serde::de::Error::custom(format!(
                    "`{dt}` is not a full date and time: expected {EXPECT}"
                )));
            }
            parse(&dt.to_string())
        }
    }
    d.deserialize_any(V)
}

/// One `[[object]]`: a mesh file placed by a transform, once or several
/// times (`instances`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Object name (default: the mesh file stem).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Mesh file (OBJ, glTF or GLB), relative to the scene file.
    pub file: PathBuf,
    /// Material for faces that come before any `usemtl` in the OBJ.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// The mesh file's up axis (default: the format's, [`crate::scene::mesh::Mesh::default_up`]:
    /// z, irsig's frame, for OBJ; y for glTF). A Y-up model is turned into
    /// Z-up before the transform.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up_axis: Option<UpAxis>,
    /// Object transform: scale, then rotate, then translate.
    #[serde(default)]
    pub translate_m: [f64; 3],
    /// Rotation angles about the x, then y, then z axes (world axes,
    /// right-handed: +90 about z turns east into north), degrees.
    #[serde(default)]
    pub rotate_deg: [f64; 3],
    /// Scale factor, one number or [sx, sy, sz] (dimensionless, > 0).
    #[serde(default)]
    pub scale: Scale,
    /// `"terrain"`: stand it on the terrain ([`crate::scene::placement`]);
    /// the z of `translate_m` is then the anchor's height above the ground.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<ZRef>,
    /// With `z = "terrain"`: the point that stands on the ground
    /// (default `"base"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor: Option<Anchor>,
    /// With `z = "terrain"`: `"slope"` tilts it to the terrain's slope
    /// (default `"none"`: upright).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub align: Option<Align>,
    /// Repeated placements; each instance transform is applied first, then
    /// the object transform above. Empty: one instance (identity).
    /// Mesh material names mapped to library materials (`"*"`: every name
    /// not listed and not a library material, and faces with no material
    /// when `material` is not set).
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub materials: std::collections::BTreeMap<String, String>,
    /// Repeated placements (`[[object.instance]]`), each applied before the object's own transform.
    #[serde(default, skip_serializing_if = "Vec::is_empty", rename = "instance")]
    pub instances: Vec<Transform>,
}

/// A placement: scale, then rotate (x, y, z world axes), then translate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    /// Translation, metres (x east, y north, z up).
    #[serde(default)]
    pub translate_m: [f64; 3],
    /// Rotation about x, then y, then z, degrees.
    #[serde(default)]
    pub rotate_deg: [f64; 3],
    /// Scale factor (uniform or per axis), > 0.
    #[serde(default)]
    pub scale: Scale,
    /// `"terrain"`: stand this instance on the terrain ([`crate::scene::placement`]);
    /// the z of `translate_m` is then the anchor's height above the ground (the object's
    /// z added).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<ZRef>,
    /// With `z = "terrain"`: the point that stands on the ground
    /// (default `"base"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor: Option<Anchor>,
    /// With `z = "terrain"`: `"slope"` tilts it to the terrain's slope
    /// (default `"none"`: upright).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub align: Option<Align>,
}

/// `z = "terrain"`: what an object's height is taken from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ZRef {
    /// The meshed terrain under the object (every `[[terrain]]`).
    Terrain,
}

/// `anchor`: the point of an object that stands on the terrain.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Anchor {
    /// The centre of the bottom of its bounding box; its lowest point on
    /// the lowest ground under its footprint.
    #[default]
    Base,
    /// The model's origin (0, 0, 0), on the ground under it.
    Origin,
}

/// `align`: whether an object standing on the terrain tilts with it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Align {
    /// Upright: the model's up stays +z.
    #[default]
    #[serde(rename = "none")]
    Upright,
    /// The model's up turned to the terrain's normal under it.
    #[serde(rename = "slope")]
    Slope,
}

impl Transform {
    /// The affine map (scale, rotate x→y→z, translate) in double precision.
    pub fn affine(&self) -> glam::DAffine3 {
        let [rx, ry, rz] = self.rotate_deg.map(f64::to_radians);
        let rot = glam::DQuat::from_euler(glam::EulerRot::ZYX, rz, ry, rx);
        glam::DAffine3::from_scale_rotation_translation(
            glam::DVec3::from_array(self.scale.xyz()),
            rot,
            glam::DVec3::from_array(self.translate_m),
        )
    }
}

impl ObjectSpec {
    /// The object-level transform (without instances).
    pub fn transform(&self) -> Transform {
        Transform {
            translate_m: self.translate_m,
            rotate_deg: self.rotate_deg,
            scale: self.scale,
            z: self.z,
            anchor: self.anchor,
            align: self.align,
        }
    }
    /// World transforms of every instance (object ∘ instance) of a mesh
    /// whose format's up axis is `default_up` (used when `up_axis` is not
    /// set).
    pub fn world_transforms(&self, default_up: UpAxis) -> Vec<glam::DAffine3> {
        self.local_transforms([0.0; 3], default_up)
    }

    /// Transforms of every instance (object ∘ instance) into the frame
    /// whose origin is `origin_m` (world coordinates): the origin is taken
    /// off the object's translation before anything else, so an object
    /// and an origin moved together give the same local transform.
    pub fn local_transforms(&self, origin_m: [f64; 3], default_up: UpAxis) -> Vec<glam::DAffine3> {
        let mut t = self.transform();
        t.translate_m = std::array::from_fn(|i| t.translate_m[i] - origin_m[i]);
        let obj = t.affine();
        let up = self.up_axis.unwrap_or(default_up).to_z_up();
        let place = |m: glam::DAffine3| up.map_or(m, |u| m * u);
        if self.instances.is_empty() {
            vec![place(obj)]
        } else {
            self.instances
                .iter()
                .map(|i| place(obj * i.affine()))
                .collect()
        }
    }
}

/// The up axis of a mesh file's coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum UpAxis {
    /// +y up (most modelling tools' OBJ exports).
    Y,
    /// +z up: irsig's frame (x east, y north).
    #[default]
    Z,
}

impl UpAxis {
    /// The rotation into irsig's Z-up frame applied before the object's
    /// transform: none for Z; for Y, +90° about x, (x, y, z) → (x, −z, y)
    /// (the model's +y becomes up, its +z south, its −z north).
    pub fn to_z_up(self) -> Option<glam::DAffine3> {
        match self {
            UpAxis::Z => None,
            UpAxis::Y => Some(glam::DAffine3::from_cols_array(&[
                1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0,
            ])),
        }
    }
}

/// Scale: uniform (one number) or per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scale {
    /// One factor for all three axes.
    Uniform(f64),
    /// A factor per axis (x, y, z).
    PerAxis([f64; 3]),
}

impl Default for Scale {
    fn default() -> Self {
        Scale::Uniform(1.0)
    }
}

impl Scale {
    /// The factor on each axis.
    pub fn xyz(&self) -> [f64; 3] {
        match *self {
            Scale::Uniform(s) => [s; 3],
            Scale::PerAxis(v) => v,
        }
    }
}

impl Serialize for Scale {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Scale::Uniform(v) => v.serialize(s),
            Scale::PerAxis(v) => v.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Scale {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Scale;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a scale factor: one number, or [sx, sy, sz]")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Scale, E> {
                Ok(Scale::Uniform(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Scale, E> {
                Ok(Scale::Uniform(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Scale, E> {
                Ok(Scale::Uniform(v as f64))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Scale, A::Error> {
                let mut v = [0.0; 3];
                for (i, slot) in v.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?;
                }
                if seq.next_element::<f64>()?.is_some() {
                    return Err(serde::de::Error::invalid_length(4, &self));
                }
                Ok(Scale::PerAxis(v))
            }
        }
        d.deserialize_any(V)
    }
}

/// `[weather]`: one of `[weather.file]` or `[weather.constant]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum WeatherSpec {
    /// A weather record file.
    File {
        /// Path, relative to the scene file.
        path: PathBuf,
        /// File format.
        format: WeatherFormat,
        /// A typical year (TMY3, most EPW: each month from a different
        /// source year): laid on the years of the render, wrapping from
        /// 31 December to the file's own 1 January.
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        typical_year: bool,
        /// The file's station stands in for the site on purpose (a
        /// surrogate record): its distance from the site is not warned
        /// about (nor refused by `--strict`).
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        stand_in: bool,
    },
    /// Constant conditions repeated every day of the history.
    Constant(ConstantWeather),
}

/// Weather file formats: the weather layer's own type (its readers).
pub use crate::weather::WeatherFormat;

/// Constant weather (`[weather.constant]`): the weather layer's own type.
pub use crate::weather::ConstantWeather;

/// `[atmosphere]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtmosphereSpec {
    /// `"auto"` (the standard atmosphere that fits the weather), a standard
    /// model atmosphere, or `{ table_file = "..." }`.
    #[serde(default)]
    pub model: AtmosphereModel,
    /// Meteorological range (surface visibility), km (> 0). Rural aerosol.
    #[serde(default = "default_visibility_km")]
    pub visibility_km: f64,
    /// Adjust the table to the weather at the image time (temperature,
    /// humidity, and a sky consistent with the thermal model's); see
    /// `atmos::adjust`. false: the table as computed.
    #[serde(default = "default_true")]
    pub follow_weather: bool,
}

impl Default for AtmosphereSpec {
    fn default() -> Self {
        Self {
            model: AtmosphereModel::default(),
            visibility_km: default_visibility_km(),
            follow_weather: true,
        }
    }
}

fn default_true() -> bool {
    true
}

fn default_visibility_km() -> f64 {
    23.0
}

/// LOWTRAN-7 model atmospheres, or a precomputed table file.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum AtmosphereModel {
    /// The standard atmosphere that best fits the weather of the 24 h
    /// before the scene's time and the site's latitude (`atmos::standard`).
    #[default]
    Auto,
    /// LOWTRAN-7 tropical.
    Tropical,
    /// LOWTRAN-7 mid-latitude summer.
    MidLatitudeSummer,
    /// LOWTRAN-7 mid-latitude winter.
    MidLatitudeWinter,
    /// LOWTRAN-7 subarctic summer.
    SubarcticSummer,
    /// LOWTRAN-7 subarctic winter.
    SubarcticWinter,
    /// LOWTRAN-7 US Standard 1976.
    UsStandard1976,
    /// A table file (relative to the scene file).
    #[serde(rename = "table_file")]
    TableFile(PathBuf),
}

impl AtmosphereModel {
    /// The model as written in a scene file (`mid-latitude-summer`, or the
    /// table file's path).
    pub fn id(&self) -> String {
        match self {
            AtmosphereModel::TableFile(p) => format!("table_file {}", p.display()),
            m => serde_json::to_value(m)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default(),
        }
    }
}

/// `[sensor]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSpec {
    /// Image width, pixels (>= 1).
    pub width_px: u32,
    /// Image height, pixels (>= 1).
    pub height_px: u32,
    /// Full horizontal field of view, degrees, (0, 170].
    pub fov_h_deg: f64,
    /// Full vertical field of view, degrees; default: square pixels,
    /// 2·atan(tan(fov_h/2)·height/width).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fov_v_deg: Option<f64>,
    /// Spectral band.
    pub band: Band,
    /// Point-spread function.
    #[serde(default)]
    pub psf: Psf,
    /// Detector noise.
    #[serde(default)]
    pub noise: NoiseSpec,
    /// Quantisation to digital counts; absent: floating-point radiance out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quantisation: Option<Quantisation>,
    /// Where the sensor is and where it looks.
    pub pose: SensorPose,
}

impl SensorSpec {
    /// Vertical FOV, degrees (given, or from square pixels).
    pub fn fov_v_deg(&self) -> f64 {
        self.fov_v_deg.unwrap_or_else(|| {
            let half = (self.fov_h_deg.to_radians() / 2.0).tan() * self.height_px as f64
                / self.width_px.max(1) as f64;
            2.0 * half.atan().to_degrees()
        })
    }
}

/// Sensor pose: exactly one of `[sensor.pose.look_at]`,
/// `[sensor.pose.altitude]`, `[sensor.pose.slant_range]`.
///
/// `azimuth_deg` is the direction from the target to the sensor, clockwise
/// from north (180: the sensor is south of the target, looking north).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum SensorPose {
    /// `[sensor.pose.look_at]`: a position and a target.
    LookAt {
        /// Sensor position, metres (local ENU).
        position_m: [f64; 3],
        /// Point the optical axis goes through, metres.
        target_m: [f64; 3],
        /// Direction that is "up" in the image (default: +z, or north
        /// when looking straight down or up).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        up: Option<[f64; 3]>,
    },
    /// `[sensor.pose.altitude]`: a height above the ground, a view zenith
    /// and azimuth at the target.
    Altitude {
        /// Sensor height above z = 0, metres (> target z).
        altitude_m: f64,
        /// Angle of the line of sight from the vertical at the target,
        /// degrees, [0, 89].
        view_zenith_deg: f64,
        /// Direction target→sensor, clockwise from north, degrees.
        azimuth_deg: f64,
        /// Target point, metres.
        #[serde(default)]
        target_m: [f64; 3],
    },
    /// `[sensor.pose.slant_range]`: a distance from the target, a view
    /// zenith and azimuth at it.
    SlantRange {
        /// Distance sensor→target, metres (> 0).
        slant_range_m: f64,
        /// Angle of the line of sight from the vertical at the target,
        /// degrees, [0, 90).
        view_zenith_deg: f64,
        /// Direction target→sensor, clockwise from north, degrees.
        azimuth_deg: f64,
        /// Target point, metres.
        #[serde(default)]
        target_m: [f64; 3],
    },
}

impl SensorPose {
    /// The point the camera looks at (world coordinates), m.
    pub fn target_m(&self) -> [f64; 3] {
        match self {
            SensorPose::LookAt { target_m, .. }
            | SensorPose::Altitude { target_m, .. }
            | SensorPose::SlantRange { target_m, .. } => *target_m,
        }
    }

    /// The pose with every point moved by `-origin_m` (into the frame
    /// whose origin that is); directions, angles and `altitude_m` (which
    /// the frame's z origin 0 leaves as is) unchanged.
    pub fn shifted(&self, origin_m: [f64; 3]) -> SensorPose {
        let sub = |p: &[f64; 3]| -> [f64; 3] { std::array::from_fn(|i| p[i] - origin_m[i]) };
        let mut p = self.clone();
        match &mut p {
            SensorPose::LookAt {
                position_m,
                target_m,
                ..
            } => {
                *position_m = sub(position_m);
                *target_m = sub(target_m);
            }
            SensorPose::Altitude { target_m, .. } | SensorPose::SlantRange { target_m, .. } => {
                *target_m = sub(target_m)
            }
        }
        p
    }
}

/// Spectral band: `"lwir"` (ideal 8-14 µm), `"mwir"` (ideal 3-5 µm),
/// `{ range_um = [lo, hi] }` (ideal), or `{ response_file = "r.csv" }`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Band {
    /// Ideal 8-14 µm.
    Lwir,
    /// Ideal 3-5 µm.
    Mwir,
    /// Ideal over [lo, hi] µm.
    RangeUm([f64; 2]),
    /// A relative spectral response read from a CSV file.
    ResponseFile(PathBuf),
}

/// Point-spread function: `"none"`, `{ gaussian = { sigma_px = 0.7 } }`,
/// or `{ kernel_file = "k.csv" }`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Psf {
    /// No blur.
    #[default]
    None,
    /// A Gaussian blur.
    Gaussian {
        /// Standard deviation, output pixels (> 0).
        sigma_px: f64,
    },
    /// A square, odd-sized kernel of weights (CSV rows), normalised to sum 1.
    KernelFile(PathBuf),
}

/// `[sensor.noise]`: detector noise in band-averaged radiance units.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseSpec {
    /// Standard deviation of white Gaussian noise, W m⁻² sr⁻¹ µm⁻¹ (>= 0).
    #[serde(default)]
    pub random_sigma_w_m2_sr_um: f64,
    /// Periodic (banding) noise, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub periodic: Option<PeriodicNoise>,
    /// Random seed (the same seed gives the same noise).
    #[serde(default)]
    pub seed: u64,
}

impl Default for NoiseSpec {
    fn default() -> Self {
        Self {
            random_sigma_w_m2_sr_um: 0.0,
            periodic: None,
            seed: 0,
        }
    }
}

/// Sinusoidal pattern noise.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeriodicNoise {
    /// Amplitude, W m⁻² sr⁻¹ µm⁻¹ (>= 0).
    pub amplitude_w_m2_sr_um: f64,
    /// Period, pixels (>= 2).
    pub period_px: f64,
    /// Direction in which the pattern varies.
    #[serde(default)]
    pub direction: NoiseDirection,
    /// Phase, degrees.
    #[serde(default)]
    pub phase_deg: f64,
}

/// `"rows"`: varies from row to row (horizontal stripes); `"columns"`:
/// from column to column (vertical stripes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum NoiseDirection {
    /// The pattern varies from row to row (horizontal bands).
    #[default]
    Rows,
    /// The pattern varies from column to column (vertical stripes).
    Columns,
}

/// `[sensor.quantisation]`: counts = round(gain·L + offset), clipped to
/// [0, 2^bits − 1]. Without gain/offset the range is stretched to the image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Quantisation {
    /// Bits per pixel, 1-16.
    pub bits: u32,
    /// Counts per W m⁻² sr⁻¹ µm⁻¹ (> 0); absent: automatic stretch.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gain_counts_per_w_m2_sr_um: Option<f64>,
    /// Counts at zero radiance; absent: automatic stretch.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset_counts: Option<f64>,
}

/// `[output]`: how the output files are written (what is written is the
/// command's: `-o`, `--exr`, `--geotiff`, `--planes`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputOptions {
    /// The EXR's lossless compression: none, rle, zips (default), zip,
    /// piz; a command's `--exr-compression` overrides it.
    #[serde(default)]
    pub exr_compression: ExrCompression,
}

/// `[render]`: accuracy/speed knobs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderOptions {
    /// Samples per pixel along each axis (n×n per pixel, or per refined
    /// pixel with adaptive sampling), 1-16. Absent: 16 with adaptive
    /// sampling (the default), 4 with uniform sampling
    /// ([`RenderOptions::supersample`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub supersample: Option<u32>,
    /// Spectral integration step, cm⁻¹ (0.1-100).
    #[serde(default = "d_spectral_step")]
    pub spectral_step_cm1: f64,
    /// Thermal model time step, minutes (1/60 to 60: 1 s to 1 h).
    #[serde(default = "d_thermal_step")]
    pub thermal_step_min: f64,
    /// Local error tolerance of the adaptive thermal steps, K (1e-6 to 1).
    #[serde(default = "d_thermal_tol")]
    pub thermal_tol_k: f64,
    /// Sun/shadow history sampling interval, minutes (0 < interval <= 120).
    #[serde(default = "d_shadow_interval")]
    pub shadow_interval_min: f64,
    /// Time resolution of the sun/shadow transitions, minutes [0.5, 120]:
    /// between two history samples (`shadow_interval_min` apart) whose
    /// flags differ, the transition is found by bisection to this
    /// resolution. Default 20 (with the default 60-min interval: a history
    /// on a 20-min grid at ~40 % of its rays); ≥ the interval: no
    /// bisection.
    #[serde(
        default = "d_shadow_resolution",
        skip_serializing_if = "Option::is_none"
    )]
    pub shadow_resolution_min: Option<f64>,
    /// Hours before the image time within which the thermal cache keys a
    /// history's transitions at full resolution, (0, 240]; an older
    /// transition is keyed (and solved) on a grid that doubles with each
    /// doubling of its age beyond this. Default 1 h (session 19, airfield
    /// 256²: against 240 h, 0.007 K RMS, p99 0.028, max 0.19 K at LWIR 18:00
    /// with 4,052 solves instead of 31,776; 0.5 h would also pass the knob
    /// rule but at 7x the RMS in MWIR, 0.027 K, for 25 % fewer solves); 240
    /// keys every transition of any history at full resolution.
    #[serde(
        default = "d_shadow_key_recent_h",
        skip_serializing_if = "Option::is_none"
    )]
    pub shadow_key_recent_h: Option<f64>,
    /// Trace the sun/shadow history of each pixel's 4 corner samples
    /// first, and of its other samples only where the corners differ (in
    /// facet or history) or a sample misses the facet or is specular;
    /// otherwise they take the corners' history. Needs supersample ≥ 3
    /// dividing 16 (4, 8, 16); otherwise every sample is traced.
    #[serde(default)]
    pub adaptive_histories: bool,
    /// Where samples go: `"adaptive"` (the default): one sample per pixel
    /// first (the grid sample nearest its centre), then, in the pixels
    /// whose coarse sample differs from one of its 8 neighbours' in being a
    /// surface or not, material, plane, sunlit flag, specular background,
    /// or surface temperature by more than `refine_threshold_k`, 4×4 cells
    /// of the `supersample`² grid, each refined to all its samples where an
    /// edge crosses it ([`crate::render::adaptive`]); or `"uniform"`,
    /// `supersample`² per pixel.
    #[serde(default)]
    pub sampling: Sampling,
    /// Adaptive sampling: the surface-temperature difference between
    /// neighbouring coarse samples above which both pixels are refined, K
    /// (0.001-100).
    #[serde(default = "d_refine_threshold")]
    pub refine_threshold_k: f64,
    /// Hours of history before the image time (spin-up), (0, 240].
    #[serde(default = "d_history_hours")]
    pub history_hours: f64,
    /// Ray-tracing backend.
    #[serde(default)]
    pub tracer: TracerKind,
    /// Largest estimated peak memory a render may need, MiB; a render whose
    /// estimate ([`crate::render::memory`]) exceeds it is refused before
    /// anything is allocated. Absent: the machine's physical memory.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_memory_mib: Option<f64>,
}

// The defaults below are chosen from the accuracy curves of
// `irsig bench accuracy` (BENCHMARKS.md, "Run time against error" and "The
// default render"): each is the cheapest setting whose own error against
// its converged value (the other knobs at their defaults) on the airfield,
// MWIR and LWIR, is within 0.1 K RMS, 0.1 K at the 99th percentile over all
// pixels and 0.5 K max over the shadow-edge pixels; together (adaptive
// 16×16 sampling, 48 h, transitions keyed at full
// resolution for 1 h, 0.1 K step tolerance at the image time (growing with age: render::prepare::THERMAL_TOL_AGE_S), 60-min traced shadow samples
// bisected to 20 min) they meet issue #29's rule
// against a 16×16 / 10-min / 72-h / 0.005 K reference: apparent temperature
// RMS ≤ 0.05 K, p99 ≤ 0.15 K, max ≤ 0.75 K. The shadow sampling is what the
// max sets: 60 min leaves 0.9 K at shadow edges (512², 18:00), 30 min
// 0.74 K, 20 min 0.41 K; the history the 99th percentile: 36 h leaves
// 0.13 K at 03:00, 48 h 0.09 K.
fn d_spectral_step() -> f64 {
    20.0
}
fn d_thermal_step() -> f64 {
    60.0
}
fn d_thermal_tol() -> f64 {
    0.1
}
fn d_shadow_interval() -> f64 {
    60.0
}
fn d_shadow_resolution() -> Option<f64> {
    Some(20.0)
}
fn d_history_hours() -> f64 {
    48.0
}
fn d_shadow_key_recent_h() -> Option<f64> {
    Some(1.0)
}
fn d_refine_threshold() -> f64 {
    0.05
}

/// `render.sampling`: `"adaptive"` (default) or `"uniform"`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    /// `supersample`² samples in every pixel.
    Uniform,
    /// One sample per pixel first, refined where neighbours differ.
    #[default]
    Adaptive,
}

impl RenderOptions {
    /// Samples per pixel along each axis: `render.supersample`, or absent
    /// 16 with adaptive sampling (a refined pixel's grid; most pixels take
    /// one sample) and 4 with uniform sampling (every pixel's grid).
    pub fn supersample(&self) -> u32 {
        self.supersample.unwrap_or(match self.sampling {
            Sampling::Adaptive => 16,
            Sampling::Uniform => 4,
        })
    }
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            supersample: None,
            spectral_step_cm1: d_spectral_step(),
            thermal_step_min: d_thermal_step(),
            thermal_tol_k: d_thermal_tol(),
            shadow_interval_min: d_shadow_interval(),
            shadow_resolution_min: d_shadow_resolution(),
            shadow_key_recent_h: d_shadow_key_recent_h(),
            adaptive_histories: false,
            sampling: Sampling::default(),
            refine_threshold_k: d_refine_threshold(),
            history_hours: d_history_hours(),
            tracer: TracerKind::default(),
            max_memory_mib: None,
        }
    }
}

/// `"embree"` (default) or `"bvh"` (obvhs, pure Rust).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum TracerKind {
    /// Intel Embree (packets of 16 rays).
    #[default]
    Embree,
    /// obvhs, pure Rust.
    Bvh,
}

/// The compression of an EXR's pixel blocks (OpenEXR Technical
/// Introduction, "Data Compression"). Only the options that are lossless
/// for irsig's 32-bit float and UINT channels are offered: PXR24 rounds
/// float channels to 24 bits, B44/B44A are lossy for half floats (and
/// leave 32-bit channels uncompressed), DWAA/DWAB are lossy — all refused.
/// The default is chosen by measurement (BENCHMARKS.md, "EXR compression").
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum ExrCompression {
    /// Uncompressed.
    None,
    /// Run-length encoding, one scan line per block.
    Rle,
    /// zlib (deflate) of one scan line per block (OpenEXR's ZIPS), at
    /// `output::exr_zip::ZLIB_LEVEL`: the default, the fastest to write of
    /// all (2048² airfield, 2 threads: 0.52 s for a file 0.22 of the
    /// samples; `none` 0.55 s; BENCHMARKS.md, "EXR compression").
    #[default]
    Zips,
    /// zlib of 16 scan lines per block (OpenEXR's ZIP).
    Zip,
    /// Wavelet + Huffman (PIZ), 32 scan lines per block.
    Piz,
}

impl ExrCompression {
    /// Every option, in the order the help lists them.
    pub const ALL: [ExrCompression; 5] = [
        ExrCompression::None,
        ExrCompression::Rle,
        ExrCompression::Zips,
        ExrCompression::Zip,
        ExrCompression::Piz,
    ];

    /// The option's name on the command line and in the scene.
    pub fn name(self) -> &'static str {
        match self {
            ExrCompression::None => "none",
            ExrCompression::Rle => "rle",
            ExrCompression::Zips => "zips",
            ExrCompression::Zip => "zip",
            ExrCompression::Piz => "piz",
        }
    }
}

impl std::fmt::Display for ExrCompression {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for ExrCompression {
    type Err = String;

    /// Parses a name of [`ExrCompression::ALL`]; the error lists them (and
    /// says why the lossy OpenEXR options are not among them).
    fn from_str(s: &str) -> Result<Self, String> {
        let names: Vec<&str> = Self::ALL.iter().map(|c| c.name()).collect();
        Self::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| {
                let why = if ["pxr24", "b44", "b44a", "dwaa", "dwab"].contains(&s) {
                    " (lossy for irsig's 32-bit float planes)"
                } else {
                    ""
                };
                format!(
                    "unknown EXR compression {s:?}{why}; expected one of {}",
                    names.join(", ")
                )
            })
    }
}

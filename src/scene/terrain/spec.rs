//! The `[[terrain]]` table as the scene file writes it ([`TerrainSpec`]).
//! It sits below the terrain loader and the scene spec, which both import
//! it, so imports run one way (`scene/spec.rs` → here, never back).

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// One `[[terrain]]`: a DEM meshed over an extent of the scene frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TerrainSpec {
    /// Object name (default: the DEM file stem).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The DEM: a single-band GeoTIFF (EPSG:4326 or WGS 84 / UTM), heights
    /// in metres; relative to the scene file.
    pub file: PathBuf,
    /// The part of the scene frame to mesh, metres: a number (the side of
    /// a square centred on the site) or `[x_min, y_min, x_max, y_max]`.
    pub extent_m: Extent,
    /// Mesh spacing, m: cells are at most this wide.
    pub resolution_m: f64,
    /// The material of the whole terrain (or `land_cover`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// A land-cover raster and its class → material table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub land_cover: Option<LandCover>,
    /// What DEM pixels without data inside the extent do: `"error"`
    /// (default) or `"hole"` (the cells that need them are left out).
    #[serde(default)]
    pub nodata: NoData,
}

/// `extent_m`: a square centred on the site, or a box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Extent {
    /// Side of a square centred on the scene origin, m.
    Square(f64),
    /// `[x_min, y_min, x_max, y_max]`, m.
    Box([f64; 4]),
}

impl Extent {
    /// `[x_min, y_min, x_max, y_max]`, m.
    pub fn bbox(&self) -> [f64; 4] {
        match *self {
            Extent::Square(s) => [-s / 2.0, -s / 2.0, s / 2.0, s / 2.0],
            Extent::Box(b) => b,
        }
    }
}

impl Serialize for Extent {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Extent::Square(v) => v.serialize(s),
            Extent::Box(v) => v.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Extent {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Extent;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "an extent in metres: one number (the side of a square centred on the \
                     site), or [x_min, y_min, x_max, y_max]",
                )
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Extent, E> {
                Ok(Extent::Square(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Extent, E> {
                Ok(Extent::Square(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Extent, E> {
                Ok(Extent::Square(v as f64))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Extent, A::Error> {
                let mut v = [0.0; 4];
                for (i, slot) in v.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?;
                }
                if seq.next_element::<f64>()?.is_some() {
                    return Err(serde::de::Error::invalid_length(5, &self));
                }
                Ok(Extent::Box(v))
            }
        }
        d.deserialize_any(V)
    }
}

/// `[terrain.land_cover]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LandCover {
    /// A single-band GeoTIFF of integer class ids (any grid, EPSG:4326 or
    /// WGS 84 / UTM); relative to the scene file.
    pub file: PathBuf,
    /// Class id (as a string, e.g. `"41"`) → material name; `"*"`: the
    /// material of every other class and of no-data pixels.
    pub classes: BTreeMap<String, String>,
}

/// `nodata`: what DEM pixels without data inside the extent do.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoData {
    /// An error naming the pixel.
    #[default]
    Error,
    /// The cells that need the pixel are left out (a hole in the terrain).
    Hole,
}

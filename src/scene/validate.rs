//! Checks of every scene value after parsing, each reported at its TOML
//! location. Every range is a row of [`crate::bounds::scene_keys::ALL`]
//! (key path, [`crate::bounds::Bound`]), checked on the values as written,
//! so `tests/bounds_docs.rs` holds the docs to each; what stays here are
//! the checks that are not a fixed range: one key against another
//! (`air_max_c >= air_min_c`, `dew_point_c <= air_min_c`, `range_um`
//! increasing), `> 0` and finite numbers, the terrains' extents, and a
//! pose the camera can be built from.

use crate::bounds::scene_keys;
use crate::scene::camera::camera_geometry;
use crate::scene::error::{Location, SceneError};
use crate::scene::material::Check;
use crate::scene::spec::{Band, Scene, SensorPose, WeatherSpec};
use crate::scene::terrain;
use crate::scene::tomlsrc::{Seg, TomlSource};

/// A key path segment.
fn key(k: &str) -> Seg {
    Seg::Key(k.to_string())
}

/// Checks of every scene value, reported at its TOML location.
pub(super) fn validate(src: &TomlSource, s: &Scene) -> Result<(), SceneError> {
    let c = Check { src };
    let p = |a: &[&str]| a.iter().map(|k| key(k)).collect::<Vec<_>>();
    // The ranges, on the values as written.
    let written = toml::Value::Table(src.parse()?);
    for (path, b) in scene_keys::ALL {
        let mut err = None;
        each_number(&written, path, Vec::new(), &mut |at, v| {
            if err.is_none() {
                err = c.bound(&at, b, v).err();
            }
        });
        if let Some(e) = err {
            return Err(e);
        }
    }
    if s.objects.is_empty() && s.terrain.is_empty() {
        return Err(SceneError::Invalid {
            loc: Location::file(&src.path),
            msg: "no objects: expected at least one `[[object]]` or `[[terrain]]` table".into(),
        });
    }
    for (i, t) in s.terrain.iter().enumerate() {
        terrain::validate(&c, i, t)?;
    }
    if let WeatherSpec::Constant(w) = &s.weather {
        let q = |k: &str| p(&["weather", "constant", k]);
        c.range(
            &q("air_max_c"),
            "air_max_c",
            w.air_max_c,
            w.air_min_c,
            scene_keys::AIR_MAX.hi,
            " °C (air_min_c <= air_max_c)",
        )?;
        c.range(
            &q("dew_point_c"),
            "dew_point_c",
            w.dew_point_c,
            scene_keys::DEW_POINT.lo,
            w.air_min_c,
            " °C (the dew point cannot exceed the air temperature)",
        )?;
    }
    let sn = &s.sensor;
    if let SensorPose::SlantRange { slant_range_m, .. } = &sn.pose {
        let at = p(&["sensor", "pose", "slant_range", "slant_range_m"]);
        c.positive(&at, "slant_range_m", *slant_range_m, " m")?;
    }
    camera_geometry(sn).map_err(|m| src.invalid(&p(&["sensor", "pose"]), m))?;
    if let Band::RangeUm([lo, hi]) = sn.band {
        c.range(
            &p(&["sensor", "band", "range_um"]),
            "range_um[1]",
            hi,
            lo + 1e-6,
            scene_keys::RANGE_UM.hi,
            " µm (above range_um[0])",
        )?;
    }
    if let Some(pn) = &sn.noise.periodic {
        let at = p(&["sensor", "noise", "periodic", "phase_deg"]);
        c.finite(&at, "phase_deg", pn.phase_deg)?;
    }
    if let Some(qz) = &sn.quantisation {
        let q = |k: &str| p(&["sensor", "quantisation", k]);
        if let Some(g) = qz.gain_counts_per_w_m2_sr_um {
            c.positive(
                &q("gain_counts_per_w_m2_sr_um"),
                "gain_counts_per_w_m2_sr_um",
                g,
                "",
            )?;
        }
        if let Some(o) = qz.offset_counts {
            c.finite(&q("offset_counts"), "offset_counts", o)?;
        }
    }
    Ok(())
}

/// Calls `f(location, number)` for each number at `path` under `v` as
/// written (an integer read as a number): a `*` segment goes into every
/// entry of an array, and a number array at the end has each element
/// checked at its index.
fn each_number(v: &toml::Value, path: &[&str], at: Vec<Seg>, f: &mut dyn FnMut(Vec<Seg>, f64)) {
    let number = |v: &toml::Value| match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    };
    match path.split_first() {
        None => match v {
            toml::Value::Array(a) => {
                for (i, e) in a.iter().enumerate() {
                    if let Some(x) = number(e) {
                        let mut at = at.clone();
                        at.push(Seg::Index(i));
                        f(at, x);
                    }
                }
            }
            _ => {
                if let Some(x) = number(v) {
                    f(at, x);
                }
            }
        },
        Some((&"*", rest)) => {
            if let toml::Value::Array(a) = v {
                for (i, e) in a.iter().enumerate() {
                    let mut at = at.clone();
                    at.push(Seg::Index(i));
                    each_number(e, rest, at, f);
                }
            }
        }
        Some((k, rest)) => {
            if let Some(e) = v.get(*k) {
                let mut at = at;
                at.push(key(k));
                each_number(e, rest, at, f);
            }
        }
    }
}

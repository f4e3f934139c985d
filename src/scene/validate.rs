//! Range checks of every scene value after parsing, each reported at its
//! TOML location (moved out of `scene/mod.rs`; the checks are unchanged).

use super::material::Check;
use super::tomlsrc::{Seg, TomlSource};
use super::{
    Band, Location, MAX_COORD_M, Psf, Scale, Scene, SceneError, SensorPose, Transform, WeatherSpec,
    camera_geometry, key, terrain,
};

/// Range checks of every scene value, reported at its TOML location.
pub(super) fn validate(src: &TomlSource, s: &Scene) -> Result<(), SceneError> {
    let c = Check { src };
    let p = |a: &[&str]| a.iter().map(|k| key(k)).collect::<Vec<_>>();
    // The keys of `bounds::scene_keys`, on the values as written.
    let written: toml::Table = src.parse()?;
    for (path, b) in crate::bounds::scene_keys::ALL {
        if let Some(v) = number_at(&written, path) {
            c.bound(&p(path), b, v)?;
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
    let check_xf = |base: Vec<Seg>, t: &Transform| -> Result<(), SceneError> {
        for (k, v) in [("translate_m", t.translate_m), ("rotate_deg", t.rotate_deg)] {
            for (i, x) in v.iter().enumerate() {
                let mut at = base.clone();
                at.extend([key(k), Seg::Index(i)]);
                c.range(&at, k, *x, -MAX_COORD_M, MAX_COORD_M, "")?;
            }
        }
        for (i, x) in t.scale.xyz().iter().enumerate() {
            let mut at = base.clone();
            at.push(key("scale"));
            if matches!(t.scale, Scale::PerAxis(_)) {
                at.push(Seg::Index(i));
            }
            c.range(&at, "scale", *x, 1e-9, 1e9, "")?;
        }
        Ok(())
    };
    for (i, o) in s.objects.iter().enumerate() {
        let base = vec![key("object"), Seg::Index(i)];
        check_xf(base.clone(), &o.transform())?;
        for (k, inst) in o.instances.iter().enumerate() {
            let mut b = base.clone();
            b.extend([key("instance"), Seg::Index(k)]);
            check_xf(b, inst)?;
        }
    }
    if let WeatherSpec::Constant(w) = &s.weather {
        let q = |k: &str| p(&["weather", "constant", k]);
        c.range(&q("wind_m_s"), "wind_m_s", w.wind_m_s, 0.0, 100.0, " m/s")?;
        c.range(
            &q("air_min_c"),
            "air_min_c",
            w.air_min_c,
            -90.0,
            60.0,
            " °C",
        )?;
        c.range(
            &q("air_max_c"),
            "air_max_c",
            w.air_max_c,
            w.air_min_c,
            60.0,
            " °C (air_min_c <= air_max_c)",
        )?;
        c.range(
            &q("dew_point_c"),
            "dew_point_c",
            w.dew_point_c,
            -100.0,
            w.air_min_c,
            " °C (the dew point cannot exceed the air temperature)",
        )?;
        c.range(
            &q("cloud_fraction"),
            "cloud_fraction",
            w.cloud_fraction,
            0.0,
            1.0,
            "",
        )?;
        c.range(
            &q("pressure_pa"),
            "pressure_pa",
            w.pressure_pa,
            30_000.0,
            110_000.0,
            " Pa",
        )?;
    }
    let sn = &s.sensor;
    // View zenith (up to `vz_max`), azimuth and target of the altitude and
    // slant-range poses, under `sensor.pose.<pose>`.
    let view_angles_and_target =
        |pose: &str, vz: f64, vz_max: f64, az: f64, target: &[f64; 3]| -> Result<(), SceneError> {
            let q = |k: &str| p(&["sensor", "pose", pose, k]);
            c.range(
                &q("view_zenith_deg"),
                "view_zenith_deg",
                vz,
                0.0,
                vz_max,
                " degrees",
            )?;
            c.range(
                &q("azimuth_deg"),
                "azimuth_deg",
                az,
                -360.0,
                360.0,
                " degrees",
            )?;
            for (i, x) in target.iter().enumerate() {
                let mut at = q("target_m");
                at.push(Seg::Index(i));
                c.range(&at, "target_m", *x, -1e8, 1e8, " m")?;
            }
            Ok(())
        };
    match &sn.pose {
        SensorPose::LookAt {
            position_m,
            target_m,
            up,
        } => {
            for (k, v) in [
                ("position_m", Some(position_m)),
                ("target_m", Some(target_m)),
                ("up", up.as_ref()),
            ] {
                if let Some(v) = v {
                    for (i, x) in v.iter().enumerate() {
                        let mut at = p(&["sensor", "pose", "look_at", k]);
                        at.push(Seg::Index(i));
                        c.range(&at, k, *x, -1e8, 1e8, "")?;
                    }
                }
            }
        }
        SensorPose::Altitude {
            altitude_m,
            view_zenith_deg,
            azimuth_deg,
            target_m,
        } => {
            let q = |k: &str| p(&["sensor", "pose", "altitude", k]);
            c.range(&q("altitude_m"), "altitude_m", *altitude_m, -1e3, 1e8, " m")?;
            view_angles_and_target("altitude", *view_zenith_deg, 89.0, *azimuth_deg, target_m)?;
        }
        SensorPose::SlantRange {
            slant_range_m,
            view_zenith_deg,
            azimuth_deg,
            target_m,
        } => {
            let q = |k: &str| p(&["sensor", "pose", "slant_range", k]);
            c.positive(&q("slant_range_m"), "slant_range_m", *slant_range_m, " m")?;
            c.range(
                &q("slant_range_m"),
                "slant_range_m",
                *slant_range_m,
                0.0,
                1e8,
                " m",
            )?;
            view_angles_and_target(
                "slant_range",
                *view_zenith_deg,
                89.999,
                *azimuth_deg,
                target_m,
            )?;
        }
    }
    camera_geometry(sn).map_err(|m| src.invalid(&p(&["sensor", "pose"]), m))?;
    if let Band::RangeUm([lo, hi]) = sn.band {
        let at = p(&["sensor", "band", "range_um"]);
        c.range(&at, "range_um[0]", lo, 0.2, 100.0, " µm")?;
        c.range(
            &at,
            "range_um[1]",
            hi,
            lo + 1e-6,
            100.0,
            " µm (above range_um[0])",
        )?;
    }
    if let Psf::Gaussian { sigma_px } = sn.psf {
        c.range(
            &p(&["sensor", "psf", "gaussian", "sigma_px"]),
            "sigma_px",
            sigma_px,
            1e-6,
            100.0,
            " pixels",
        )?;
    }
    c.range(
        &p(&["sensor", "noise", "random_sigma_w_m2_sr_um"]),
        "random_sigma_w_m2_sr_um",
        sn.noise.random_sigma_w_m2_sr_um,
        0.0,
        1e6,
        " W m⁻² sr⁻¹ µm⁻¹",
    )?;
    if let Some(pn) = &sn.noise.periodic {
        let q = |k: &str| p(&["sensor", "noise", "periodic", k]);
        c.range(
            &q("amplitude_w_m2_sr_um"),
            "amplitude_w_m2_sr_um",
            pn.amplitude_w_m2_sr_um,
            0.0,
            1e6,
            " W m⁻² sr⁻¹ µm⁻¹",
        )?;
        c.range(
            &q("period_px"),
            "period_px",
            pn.period_px,
            2.0,
            1e6,
            " pixels",
        )?;
        c.finite(&q("phase_deg"), "phase_deg", pn.phase_deg)?;
    }
    if let Some(qz) = &sn.quantisation {
        let q = |k: &str| p(&["sensor", "quantisation", k]);
        c.range(&q("bits"), "bits", qz.bits as f64, 1.0, 16.0, "")?;
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
    let r = &s.render;
    let q = |k: &str| p(&["render", k]);
    if let Some(m) = r.max_memory_mib {
        c.bound(&q("max_memory_mib"), &crate::bounds::render::MAX_MEMORY, m)?;
    }
    c.range(
        &q("supersample"),
        "supersample",
        r.supersample() as f64,
        1.0,
        16.0,
        "",
    )?;
    c.range(
        &q("spectral_step_cm1"),
        "spectral_step_cm1",
        r.spectral_step_cm1,
        0.1,
        100.0,
        " cm⁻¹",
    )?;
    c.range(
        &q("thermal_step_min"),
        "thermal_step_min",
        r.thermal_step_min,
        1.0 / 60.0,
        60.0,
        " minutes",
    )?;
    c.range(
        &q("refine_threshold_k"),
        "refine_threshold_k",
        r.refine_threshold_k,
        0.001,
        100.0,
        " K",
    )?;
    c.range(
        &q("thermal_tol_k"),
        "thermal_tol_k",
        r.thermal_tol_k,
        1e-6,
        1.0,
        " K",
    )?;
    c.range(
        &q("shadow_interval_min"),
        "shadow_interval_min",
        r.shadow_interval_min,
        1.0,
        120.0,
        " minutes",
    )?;
    if let Some(res) = r.shadow_resolution_min {
        c.range(
            &q("shadow_resolution_min"),
            "shadow_resolution_min",
            res,
            0.5,
            120.0,
            " minutes",
        )?;
    }
    if let Some(h) = r.shadow_key_recent_h {
        c.range(
            &q("shadow_key_recent_h"),
            "shadow_key_recent_h",
            h,
            0.1,
            240.0,
            " hours",
        )?;
    }
    c.range(
        &q("history_hours"),
        "history_hours",
        r.history_hours,
        1.0,
        240.0,
        " hours",
    )?;
    Ok(())
}

/// The number at `path` in the file as written (an integer read as a
/// number), if it is there.
fn number_at(table: &toml::Table, path: &[&str]) -> Option<f64> {
    let (first, rest) = path.split_first()?;
    let mut v = table.get(*first)?;
    for k in rest {
        v = v.get(k)?;
    }
    match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

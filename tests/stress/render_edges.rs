//! Renders with extreme but valid inputs (issue 17, item 2): each bound of
//! the materials and the main scene keys at both ends of its range
//! (crate::bounds and the scene's own checks), on the plate scene at 8x8
//! pixels. Every render must succeed and every output plane must be finite
//! (the NaN-by-design surface planes only where no surface was seen); the
//! render also checks this itself (render::pixel::check_finite), so a
//! failure here is an error from the render, not a silent NaN.

use std::path::{Path, PathBuf};

use irsig::render::pixel::SURFACE_PLANES;
use irsig::scene::material::keys as M;

/// The plate scene and its materials copied into `tmp`, the concrete of the
/// ground (most pixels) with `key = value`.
fn plate_with(tmp: &Path, key: &str, value: f64) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let dir = tmp.join("plate");
    std::fs::create_dir_all(dir.join("obj")).unwrap();
    for f in ["ground.obj", "plate.obj"] {
        std::fs::copy(root.join("plate/obj").join(f), dir.join("obj").join(f)).unwrap();
    }
    std::fs::copy(root.join("plate/scene.toml"), dir.join("scene.toml")).unwrap();
    let lib = std::fs::read_to_string(root.join("materials.toml")).unwrap();
    let start = lib.find("[material.concrete]\n").unwrap();
    let end = start + lib[start..].find("\n\n").unwrap();
    let mut block: Vec<String> = lib[start..end]
        .lines()
        .filter(|l| !l.starts_with(&format!("{key} ")))
        .map(str::to_string)
        .collect();
    if !key.is_empty() {
        block.insert(1, format!("{key} = {value:e}"));
    }
    let lib = format!("{}{}{}", &lib[..start], block.join("\n"), &lib[end..]);
    std::fs::write(tmp.join("materials.toml"), lib).unwrap();
    dir.join("scene.toml")
}

fn render(scene: &Path, sets: &[(&str, String)], what: &str) {
    let mut kv: Vec<(String, String)> = [
        ("sensor.width_px", "8"),
        ("sensor.height_px", "8"),
        ("render.supersample", "1"),
        ("render.history_hours", "12"),
    ]
    .iter()
    .map(|(k, v)| (k.to_string(), v.to_string()))
    .collect();
    kv.extend(sets.iter().map(|(k, v)| (k.to_string(), v.clone())));
    let s = irsig::scene::load_with_overrides(scene, &kv)
        .unwrap_or_else(|e| panic!("{what}: refused: {e}"));
    let r = irsig::render::render_scene(s, None, None)
        .unwrap_or_else(|e| panic!("{what}: render failed: {e:#}"));
    let planes = &r.frame.planes;
    let material = &planes.get("material").unwrap().data;
    for p in &planes.planes {
        let nan_ok = SURFACE_PLANES.contains(&p.name.as_str());
        for (i, v) in p.data.iter().enumerate() {
            assert!(
                v.is_finite() || (nan_ok && material[i] < 0.0),
                "{what}: {} = {v} at pixel {i}",
                p.name
            );
        }
    }
}

#[test]
fn material_bounds_at_both_ends_render_finite_planes() {
    for b in [
        M::DENSITY,
        M::SPECIFIC_HEAT,
        M::CONDUCTIVITY,
        M::THICKNESS,
        M::SOLAR_ABSORPTIVITY,
        M::THERMAL_EMISSIVITY,
        M::INTERNAL_POWER,
        M::SPECULARITY,
        M::WATER_CAPACITY,
    ] {
        for v in [b.lo, b.hi] {
            let tmp = tempfile::tempdir().unwrap();
            let scene = plate_with(tmp.path(), b.key, v);
            render(&scene, &[], &format!("concrete {} = {v}", b.key));
        }
    }
}

#[test]
fn scene_keys_at_both_ends_render_finite_planes() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = plate_with(tmp.path(), "", 0.0);
    let s = |v: &str| v.to_string();
    let cases: Vec<Vec<(&str, String)>> = vec![
        vec![
            ("site.latitude_deg", s("90")),
            ("site.longitude_deg", s("180")),
        ],
        vec![
            ("site.latitude_deg", s("-90")),
            ("site.longitude_deg", s("-180")),
        ],
        vec![("site.elevation_m", s("-500"))],
        vec![("site.elevation_m", s("9000"))],
        vec![
            ("site.utc_offset_h", s("14")),
            ("time.local", s("1900-01-01T00:00:00")),
        ],
        vec![
            ("site.utc_offset_h", s("-14")),
            ("time.local", s("2200-12-31T23:59:59")),
        ],
        vec![("weather.constant.wind_m_s", s("0"))],
        vec![("weather.constant.wind_m_s", s("100"))],
        vec![
            ("weather.constant.air_min_c", s("-90")),
            ("weather.constant.air_max_c", s("-90")),
            ("weather.constant.dew_point_c", s("-100")),
        ],
        vec![
            ("weather.constant.air_min_c", s("60")),
            ("weather.constant.air_max_c", s("60")),
            ("weather.constant.dew_point_c", s("60")),
            ("weather.constant.cloud_fraction", s("1")),
        ],
        vec![("weather.constant.pressure_pa", s("30000"))],
        vec![("weather.constant.pressure_pa", s("110000"))],
        vec![("sensor.fov_h_deg", s("1e-6"))],
        vec![("sensor.fov_h_deg", s("170"))],
        vec![("sensor.band", s("{ range_um = [0.25, 0.3] }"))],
        vec![("sensor.band", s("{ range_um = [19.5, 20] }"))],
        vec![("sensor.psf", s("{ gaussian = { sigma_px = 100 } }"))],
        vec![("sensor.noise.random_sigma_w_m2_sr_um", s("1e6"))],
        vec![("render.supersample", s("16"))],
        vec![("render.spectral_step_cm1", s("0.1"))],
        vec![("render.spectral_step_cm1", s("100"))],
        vec![("render.thermal_tol_k", s("1e-6"))],
        vec![("render.thermal_tol_k", s("1"))],
        vec![("render.shadow_interval_min", s("1"))],
        vec![("render.shadow_interval_min", s("120"))],
        vec![("render.history_hours", s("1"))],
        vec![("render.history_hours", s("240"))],
        vec![("render.thermal_step_min", s("60"))],
    ];
    for sets in cases {
        let what = format!("{sets:?}");
        render(&scene, &sets, &what);
    }
}

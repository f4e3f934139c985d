//! One campaign per parser entry point.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

use irsig::bounds::{self, Bound};
use irsig::radiometry::{Band, SpectralGrid, SpectralResponse};
use irsig::weather::{
    ReadOptions, WeatherFile, parse_epw, parse_plain_csv, parse_psm3, parse_pvgis_csv, parse_tmy2,
    parse_tmy3,
};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

use crate::mutate::{INTERESTING, apply, campaign, mutation};
use crate::require;

type R = Result<(), TestCaseError>;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn read(rel: &str) -> Vec<u8> {
    std::fs::read(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The first `n` lines of a file (seeds stay small: fast cases); bytes
/// that are not UTF-8 (a Latin-1 ® in SolarAnywhere's header) replaced, as
/// the readers do.
fn head(rel: &str, n: usize) -> Vec<u8> {
    let text = String::from_utf8_lossy(&read(rel)).into_owned();
    let mut s: String = text.lines().take(n).collect::<Vec<_>>().join("\n");
    s.push('\n');
    s.into_bytes()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// An error must be a message naming the input file.
fn names_file(e: &str, file: &str) -> R {
    require!(e.contains(file), "error does not name the file {file}: {e}");
    Ok(())
}

fn in_bound(b: &Bound, v: f64, what: &str) -> R {
    require!(
        b.contains(v),
        "accepted {what} {} = {v} outside {}",
        b.key,
        b.expected()
    );
    Ok(())
}

/// Accepted weather: finite samples inside the bounds, sorted years inside
/// 1900-2200.
fn weather_ok(w: &WeatherFile) -> R {
    use chrono::Datelike;
    use irsig::bounds::weather as B;
    let h = &w.history;
    require!(!h.samples.is_empty(), "empty history accepted");
    for (t, s) in h.times.iter().zip(&h.samples) {
        in_bound(&bounds::time::YEAR, t.year() as f64, "time")?;
        in_bound(&B::AIR_TEMP, s.air_temp_k - 273.15, "sample")?;
        in_bound(&B::DEW_POINT, s.dew_point_k - 273.15, "sample")?;
        in_bound(&B::WIND, s.wind_speed_m_s, "sample")?;
        in_bound(&B::PRESSURE, s.pressure_pa / 100.0, "sample")?;
        in_bound(&B::CLOUD, s.cloud_fraction.unwrap_or(0.0), "sample")?;
        in_bound(&B::PRECIPITATION, s.precip_mm_h, "sample")?;
        for v in [s.ghi_w_m2, s.dni_w_m2, s.dhi_w_m2].into_iter().flatten() {
            in_bound(&B::IRRADIANCE, v, "sample")?;
        }
        if let Some(t) = s.sky_temp_k {
            in_bound(&B::SKY_TEMP, t - 273.15, "sample")?;
        }
    }
    require!(
        h.times.windows(2).all(|w| w[0] < w[1]),
        "unsorted times accepted"
    );
    Ok(())
}

type WeatherParser =
    fn(&str, &str, &ReadOptions) -> Result<WeatherFile, irsig::weather::WeatherError>;

fn weather_campaign(target: &str, seeds: Vec<Vec<u8>>, parse: WeatherParser, file: &str) {
    let opts = [
        ReadOptions::default(),
        ReadOptions {
            typical_year: Some(irsig::weather::YearSpan {
                first: 2000,
                last: 2001,
            }),
            ..ReadOptions::default()
        },
    ];
    campaign(target, mutation(seeds.len()), |(k, edits), tally| {
        let t = text(&apply(&seeds[k], &edits));
        for o in &opts {
            match parse(&t, file, o) {
                Ok(w) => {
                    tally.ok();
                    weather_ok(&w)?;
                }
                Err(e) => {
                    tally.err();
                    names_file(&e.to_string(), file)?;
                }
            }
        }
        Ok(())
    });
}

#[test]
fn weather_plain_csv() {
    weather_campaign(
        "weather-csv",
        vec![
            head("tests/data/stations/bon-19950510.csv", 40),
            head("tests/data/stations/bnd-19980725.csv", 40),
            head("tests/data/stations/slv-20160101.csv", 40),
        ],
        parse_plain_csv,
        "wx.csv",
    );
}

#[test]
fn weather_tmy3() {
    weather_campaign(
        "weather-tmy3",
        vec![
            head("tests/data/tmy3_723170_greensboro_jun18-22.csv", 30),
            head(
                "scenes/airfield/weather/greensboro-nc-tmy3-2001-08-04_09.csv",
                30,
            ),
            head(
                "tests/data/wild/weather/solaranywhere_tmy3_burlington_jan1-3.csv",
                30,
            ),
            head("tests/data/wild/weather/tmy3_723170_yearend.csv", 30),
        ],
        parse_tmy3,
        "tmy3.csv",
    );
}

#[test]
fn weather_epw() {
    weather_campaign(
        "weather-epw",
        vec![
            head("tests/data/epw_amsterdam_iwec_jun18-22.epw", 36),
            head("tests/data/wild/weather/pvgis_tmy_45N_8E_jan1-3.epw", 36),
        ],
        parse_epw,
        "wx.epw",
    );
}

#[test]
fn weather_tmy2() {
    weather_campaign(
        "weather-tmy2",
        vec![head(
            "tests/data/wild/weather/tmy2_12839_miami_jan1-3.tm2",
            30,
        )],
        parse_tmy2,
        "wx.tm2",
    );
}

#[test]
fn weather_psm3() {
    weather_campaign(
        "weather-psm3",
        vec![head(
            "tests/data/wild/weather/psm3_401182_2017_jan1-3.csv",
            40,
        )],
        parse_psm3,
        "psm3.csv",
    );
}

#[test]
fn weather_pvgis_csv() {
    weather_campaign(
        "weather-pvgis-csv",
        vec![read("tests/data/wild/weather/pvgis_tmy_45N_8E_jan1-3.csv")],
        parse_pvgis_csv,
        "pvgis.csv",
    );
}

#[test]
fn forcing_csv() {
    let seeds = [head("tests/data/therm_ref_forcing.csv", 40)];
    let path = Path::new("forcing.csv");
    campaign("forcing-csv", mutation(seeds.len()), |(k, edits), tally| {
        let t = text(&apply(&seeds[k], &edits));
        match irsig::therm::forcing_csv::parse_forcing_csv(path, &t) {
            Ok(f) => {
                tally.ok();
                for r in &f {
                    let v = [
                        r.t_s,
                        r.air_temp_k,
                        r.sky_temp_k,
                        r.wind_speed_m_s,
                        r.dni_w_m2,
                        r.dhi_w_m2,
                        r.ghi_w_m2,
                    ];
                    require!(v.iter().all(|x| x.is_finite()), "non-finite forcing {v:?}");
                }
            }
            Err(e) => {
                tally.err();
                names_file(&format!("{e:#}"), "forcing.csv")?;
            }
        }
        Ok(())
    });
}

/// A small valid IRSIG-ATMOS table (4 wavenumbers, 2 nodes per axis).
fn tiny_table(byteplanes: bool) -> Vec<u8> {
    let mut h = String::from(
        "IRSIG-ATMOS 1\nname tiny\ndescription fuzz seed\ncommand none\nwavenumber_cm1 500 20 4\n",
    );
    let mut n_values = 0;
    for (q, axes) in irsig::atmos::table::REQUIRED {
        let mut line = format!("quantity {q} unit=W_m-2");
        for a in *axes {
            line += &format!(" {a}=0,45");
        }
        h += &line;
        h.push('\n');
        n_values += 4 << axes.len();
    }
    h += if byteplanes {
        "data f32le-byteplanes\n"
    } else {
        "data f32le\n"
    };
    let mut b = h.into_bytes();
    // Per quantity (in header order), its values 0.5 + i·1e-3 (physical
    // for every quantity), as f32le or split into byte planes.
    let mut i = 0;
    for (_, axes) in irsig::atmos::table::REQUIRED {
        let n = 4 << axes.len();
        let vals: Vec<[u8; 4]> = (i..i + n)
            .map(|k| (0.5f32 + k as f32 * 1e-3).to_le_bytes())
            .collect();
        i += n;
        if byteplanes {
            for plane in 0..4 {
                b.extend(vals.iter().map(|v| v[plane]));
            }
        } else {
            b.extend(vals.iter().flatten());
        }
    }
    assert_eq!(i, n_values);
    b
}

#[test]
fn atmosphere_table() {
    let seeds = [tiny_table(false), tiny_table(true)];
    assert!(irsig::atmos::AtmosTable::from_bytes(&seeds[0], "t.atm").is_ok());
    assert!(irsig::atmos::AtmosTable::from_bytes(&seeds[1], "t.atm").is_ok());
    campaign("atmos-table", mutation(seeds.len()), |(k, edits), tally| {
        let b = apply(&seeds[k], &edits);
        match irsig::atmos::AtmosTable::from_bytes(&b, "t.atm") {
            Ok(t) => {
                tally.ok();
                for w in &t.wavenumber_cm1 {
                    in_bound(&bounds::atmos_table::WAVENUMBER, *w, "table")?;
                }
                for q in &t.quantities {
                    require!(
                        q.data.iter().all(|v| v.is_finite()),
                        "non-finite table data"
                    );
                    // Issue 33: every accepted value is physical.
                    if let Some(b) = bounds::atmos_table::range_of(&q.name) {
                        require!(
                            q.data.iter().all(|v| b.contains(*v)),
                            "{}: a value outside {}",
                            q.name,
                            b.expected()
                        );
                    }
                    require!(
                        q.data.len() == q.n_spectra() * t.wavenumber_cm1.len(),
                        "table size mismatch"
                    );
                }
            }
            Err(e) => {
                tally.err();
                names_file(&e.to_string(), "t.atm")?;
            }
        }
        Ok(())
    });
}

/// Renders that the scene targets may do (each costs ~0.1-1 s):
/// `IRSIG_FUZZ_RENDERS` (default 8) per target.
fn render_budget() -> u32 {
    std::env::var("IRSIG_FUZZ_RENDERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(8)
}

/// Accepted scene: materials inside their bounds, finite camera; some are
/// rendered small (8x8, no supersampling) and every plane is checked.
fn scene_ok(s: &irsig::scene::LoadedScene, text: &str, renders: &AtomicU32) -> R {
    use irsig::scene::material::keys as M;
    for m in &s.materials {
        for (b, v) in [
            (M::DENSITY, m.construction.density_kg_m3),
            (M::SPECIFIC_HEAT, m.construction.specific_heat_j_kgk),
            (M::CONDUCTIVITY, m.construction.conductivity_w_mk),
            (M::THICKNESS, m.construction.thickness_m),
            (M::SOLAR_ABSORPTIVITY, m.construction.solar_absorptivity),
            (M::THERMAL_EMISSIVITY, m.construction.thermal_emissivity),
            (M::INTERNAL_POWER, m.construction.internal_power_w_m2),
        ] {
            in_bound(&b, v, &m.name)?;
        }
    }
    require!(
        s.camera.position_m.iter().all(|v| v.is_finite()),
        "non-finite camera position accepted"
    );
    if renders.fetch_add(1, Ordering::Relaxed) < render_budget() {
        let small = [
            ("sensor.width_px", "8"),
            ("sensor.height_px", "8"),
            ("render.supersample", "1"),
        ]
        .map(|(k, v)| (k.to_string(), v.to_string()));
        let t = irsig::scene::apply_overrides(&s.path, text, &small)
            .map_err(|e| TestCaseError::fail(format!("small overrides refused: {e}")))?;
        let small = irsig::scene::load_text(&s.path, t)
            .map_err(|e| TestCaseError::fail(format!("small scene refused: {e}")))?;
        // the render itself checks every plane (render::pixel::check_finite)
        if let Ok(r) = irsig::render::render_scene(small, None, None) {
            for p in &r.frame.planes.planes {
                let may_be_nan = irsig::render::pixel::SURFACE_PLANES.contains(&p.name.as_str());
                require!(
                    may_be_nan || p.data.iter().all(|v| v.is_finite()),
                    "non-finite {} plane from an accepted scene",
                    p.name
                );
            }
        }
    }
    Ok(())
}

fn scene_seeds() -> Vec<(PathBuf, Vec<u8>)> {
    [
        "scenes/plate/scene.toml",
        "scenes/airfield/scene-constant.toml",
    ]
    .iter()
    .map(|p| (root().join(p), read(p)))
    .collect()
}

#[test]
fn scene_toml() {
    let seeds = scene_seeds();
    let renders = AtomicU32::new(0);
    campaign("scene-toml", mutation(seeds.len()), |(k, edits), tally| {
        let (path, seed) = &seeds[k];
        let t = text(&apply(seed, &edits));
        match irsig::scene::load_text(path, t.clone()) {
            Ok(s) => {
                tally.ok();
                scene_ok(&s, &t, &renders)?;
            }
            Err(e) => {
                tally.err();
                names_file(&e.to_string(), "scene")?;
            }
        }
        Ok(())
    });
}

/// Scene keys that `--set` may override.
const KEYS: &[&str] = &[
    "site.latitude_deg",
    "site.longitude_deg",
    "site.elevation_m",
    "site.utc_offset_h",
    "time.local",
    "weather.constant.wind_m_s",
    "weather.constant.air_min_c",
    "weather.constant.air_max_c",
    "weather.constant.dew_point_c",
    "weather.constant.cloud_fraction",
    "weather.constant.pressure_pa",
    "atmosphere.model",
    "atmosphere.visibility_km",
    "sensor.width_px",
    "sensor.height_px",
    "sensor.fov_h_deg",
    "sensor.fov_v_deg",
    "sensor.band",
    "sensor.psf",
    "sensor.noise.random_sigma_w_m2_sr_um",
    "sensor.quantisation.bits",
    "sensor.pose.slant_range.slant_range_m",
    "sensor.pose.slant_range.view_zenith_deg",
    "sensor.pose.slant_range.azimuth_deg",
    "render.supersample",
    "render.spectral_step_cm1",
    "render.thermal_step_min",
    "render.thermal_tol_k",
    "render.shadow_interval_min",
    "render.history_hours",
    "render.max_memory_mib",
    "object",
    "materials",
    "no.such.key",
];

/// Override values: the interesting numbers plus structured values.
const VALUES: &[&str] = &[
    "\"lwir\"",
    "\"mwir\"",
    "{ range_um = [0.2, 100] }",
    "{ range_um = [1e-10, 1] }",
    "{ gaussian = { sigma_px = 1e-6 } }",
    "\"tropical\"",
    "1900-01-01T00:00:00",
    "2200-12-31T23:59:59",
    "\"+262142-12-31T23:00:00\"",
    "[1, 2]",
    "true",
    "\"\"",
    "{",
];

#[test]
fn scene_overrides() {
    let plate = root().join("scenes/plate/scene.toml");
    let base = String::from_utf8(read("scenes/plate/scene.toml")).unwrap();
    let value = prop_oneof![
        (0..INTERESTING.len()).prop_map(|i| INTERESTING[i].to_string()),
        (0..VALUES.len()).prop_map(|i| VALUES[i].to_string()),
    ];
    let set = prop::collection::vec(((0..KEYS.len()).prop_map(|i| KEYS[i]), value), 1..4);
    let renders = AtomicU32::new(0);
    campaign("scene-set", set, |sets, tally| {
        let kv: Vec<(String, String)> = sets
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect();
        let text = irsig::scene::apply_overrides(&plate, &base, &kv);
        match text.and_then(|t| irsig::scene::load_text(&plate, t.clone()).map(|s| (s, t))) {
            Ok((s, t)) => {
                tally.ok();
                scene_ok(&s, &t, &renders)?;
            }
            Err(e) => {
                tally.err();
                names_file(&e.to_string(), "scene.toml")?;
            }
        }
        Ok(())
    });
}

#[test]
fn material_library() {
    let seeds = [read("scenes/materials.toml")];
    let path = root().join("scenes/mats.toml");
    campaign("materials", mutation(seeds.len()), |(k, edits), tally| {
        let t = text(&apply(&seeds[k], &edits));
        match irsig::scene::material::load_library_text(&path, t) {
            Ok(ms) => {
                tally.ok();
                use irsig::scene::material::keys as M;
                for m in &ms {
                    for (b, v) in [
                        (M::DENSITY, m.construction.density_kg_m3),
                        (M::SPECIFIC_HEAT, m.construction.specific_heat_j_kgk),
                        (M::CONDUCTIVITY, m.construction.conductivity_w_mk),
                        (M::THICKNESS, m.construction.thickness_m),
                        (M::INTERNAL_POWER, m.construction.internal_power_w_m2),
                        (M::SPECULARITY, m.specularity),
                    ] {
                        in_bound(&b, v, &m.name)?;
                    }
                    require!(
                        m.construction.validate().is_ok(),
                        "{}: slab refused",
                        m.name
                    );
                }
            }
            Err(e) => {
                tally.err();
                names_file(&e.to_string(), "mats.toml")?;
            }
        }
        Ok(())
    });
}

#[test]
fn obj_mesh() {
    let seeds = [
        read("scenes/plate/obj/plate.obj"),
        read("scenes/plate/obj/ground.obj"),
        read("scenes/meshes/mixed.obj"),
        read("tests/data/wild/meshes/assimp/concave_polygon.obj"),
        read("tests/data/wild/meshes/assimp/cube_usemtl.obj"),
        read("tests/data/wild/meshes/assimp/box_UTF16BE.obj"),
    ];
    let path = Path::new("m.obj");
    campaign("obj", mutation(seeds.len()), |(k, edits), tally| {
        let bytes = apply(&seeds[k], &edits);
        let t = irsig::scene::mesh::decode_text(&bytes);
        match irsig::scene::mesh::obj::parse_obj(path, &t).and_then(|mut m| {
            m.triangulate()?;
            Ok(m)
        }) {
            Ok(m) => {
                tally.ok();
                mesh_is_sound(&m)?;
                require!(
                    m.tri_face.iter().all(|&f| (f as usize) < m.faces.len()),
                    "triangle's face out of range"
                );
            }
            Err(e) => {
                tally.err();
                names_file(&e.to_string(), "m.obj")?;
            }
        }
        Ok(())
    });
}

/// The oracle shared by the mesh readers: an accepted mesh has finite
/// vertices and triangles that index them.
fn mesh_is_sound(m: &irsig::scene::mesh::Mesh) -> R {
    require!(
        m.positions.iter().flatten().all(|v| v.is_finite()),
        "non-finite vertex accepted"
    );
    require!(
        m.triangles
            .iter()
            .flatten()
            .all(|&i| (i as usize) < m.positions.len()),
        "triangle index out of range"
    );
    Ok(())
}

const RESPONSES: &[&str] = &[
    "# a filter curve\nwavelength_um,response\n7.5,0\n8,0.5\n9,0.95\n12,0.9\n13.5,0.3\n14,0\n",
    "3.0,0\n3.2,1\n4.8,1\n5.0,0\n",
    "wavelength_um;response\n0.25;0\n1;1\n19.9;1\n20;0\n",
];

/// The shipped tables' grid (500-40000 cm⁻¹ every 20).
fn table_grid() -> SpectralGrid {
    SpectralGrid::uniform(500.0, 20.0, 1976)
}

fn band_ok(r: &SpectralResponse) -> R {
    for w in &r.wavelength_um {
        in_bound(&bounds::data::WAVELENGTH_UM, *w, "response")?;
    }
    if let Ok(b) = Band::new(&table_grid(), r) {
        let s: f64 = b.weights.iter().sum();
        require!(
            b.weights.iter().all(|w| w.is_finite()) && (s - 1.0).abs() < 1e-9,
            "band weights not finite / not normalised: sum {s}"
        );
        let l = b.planck_w_m2_sr_um(300.0);
        require!(l.is_finite() && l >= 0.0, "band radiance {l} at 300 K");
    }
    Ok(())
}

#[test]
fn response_csv() {
    let seeds: Vec<Vec<u8>> = RESPONSES.iter().map(|s| s.as_bytes().to_vec()).collect();
    let path = Path::new("resp.csv");
    campaign(
        "response-csv",
        mutation(seeds.len()),
        |(k, edits), tally| {
            let b = apply(&seeds[k], &edits);
            // the radiometry's reader (irsig atmos show --band FILE)
            match SpectralResponse::from_csv_str(&text(&b), "r.csv") {
                Ok(r) => {
                    tally.ok();
                    band_ok(&r)?;
                }
                Err(e) => {
                    tally.err();
                    names_file(&e.to_string(), "r.csv")?;
                }
            }
            // the scene's reader (sensor.band = { response_file })
            match irsig::scene::parse_response(path, &text(&b)) {
                Ok(r) => {
                    tally.ok();
                    band_ok(&r)?;
                }
                Err(e) => {
                    tally.err();
                    names_file(&e.to_string(), "resp.csv")?;
                }
            }
            Ok(())
        },
    );
}

const EMISSIVITIES: &[&str] = &[
    "# grass\nwavelength_um, 0, 60, 85\n8.0, 0.96, 0.94, 0.80\n12.0, 0.98, 0.96, 0.84\n",
    "wavelength_um,0,30,60,89\n3,0.9,0.9,0.85,0.5\n5,0.92,0.91,0.86,0.52\n10,0.95,0.94,0.9,0.6\n",
];

#[test]
fn emissivity_table() {
    let seeds: Vec<Vec<u8>> = EMISSIVITIES.iter().map(|s| s.as_bytes().to_vec()).collect();
    let path = Path::new("eps.csv");
    campaign(
        "emissivity-csv",
        mutation(seeds.len()),
        |(k, edits), tally| {
            let t = text(&apply(&seeds[k], &edits));
            match irsig::scene::material::parse_emissivity_table(path, &t) {
                Ok(t) => {
                    tally.ok();
                    for (a, w) in [(0.0, 0.1), (45.0, 10.0), (90.0, 1e3), (-5.0, 4.0)] {
                        let e = t.at(a, w);
                        require!((0.0..=1.0).contains(&e), "ε({a}°, {w} µm) = {e}");
                    }
                }
                Err(e) => {
                    tally.err();
                    names_file(&e.to_string(), "eps.csv")?;
                }
            }
            Ok(())
        },
    );
}

const KERNELS: &[&str] = &[
    "# 3x3\n0.05,0.1,0.05\n0.1,0.4,0.1\n0.05,0.1,0.05\n",
    "0,0,1,0,0\n0,1,2,1,0\n1,2,4,2,1\n0,1,2,1,0\n0,0,1,0,0\n",
];

#[test]
fn psf_kernel() {
    let seeds: Vec<Vec<u8>> = KERNELS.iter().map(|s| s.as_bytes().to_vec()).collect();
    let path = Path::new("k.csv");
    campaign("kernel-csv", mutation(seeds.len()), |(k, edits), tally| {
        let t = text(&apply(&seeds[k], &edits));
        match irsig::scene::parse_kernel(path, &t) {
            Ok(kn) => {
                tally.ok();
                let s: f64 = kn.weights.iter().sum();
                require!(
                    kn.size % 2 == 1
                        && kn.weights.len() == kn.size * kn.size
                        && kn.weights.iter().all(|w| w.is_finite() && *w >= 0.0)
                        && (s - 1.0).abs() < 1e-9,
                    "kernel {}x{} sum {s}",
                    kn.size,
                    kn.size
                );
            }
            Err(e) => {
                tally.err();
                names_file(&e.to_string(), "k.csv")?;
            }
        }
        Ok(())
    });
}

/// Applies [`word_edits`]: each little-endian 16-bit (`wide` false) or
/// 32-bit value written over the bytes at its position (modulo the length).
fn overwrite_words(b: &mut [u8], words: &[(usize, u32, bool)]) {
    for &(p, v, wide) in words {
        let n = if wide { 4 } else { 2 };
        if b.len() >= n {
            let p = p % (b.len() - n + 1);
            b[p..p + n].copy_from_slice(&v.to_le_bytes()[..n]);
        }
    }
}

/// Overwrites of 2 or 4 bytes at a position with values that break binary
/// readers (TIFF, GLB: counts, offsets, lengths, types, dimensions, tag
/// values).
fn word_edits() -> impl Strategy<Value = Vec<(usize, u32, bool)>> {
    let value = prop_oneof![
        Just(0u32),
        Just(1),
        Just(2),
        Just(7),
        Just(0xFFFF),
        Just(0x7FFF_FFFF),
        Just(0xFFFF_FFFF),
        Just(65_536),
        Just(32_767),
        Just(4326),
        Just(32_618),
        Just(26_918),
        any::<u32>(),
    ];
    prop::collection::vec((any::<usize>(), value, any::<bool>()), 0..3)
}

/// GeoTIFF DEMs (issue 14): mutated seeds written by GDAL (tests/data/dem,
/// tools/ref_dem.sh: geographic Int16 tiled deflate pixel-is-point with
/// no-data; UTM Float32 LZW strips) through the raster reader; accepted
/// rasters sample finitely, and the first accepted ones of each seed are
/// meshed as a scene's `[[terrain]]` (accepted scenes hold finite
/// vertices; refusals name the DEM or the scene).
#[test]
fn dem_geotiff() {
    use irsig::scene::terrain::raster::{Sample, parse_raster};
    let seeds = [
        read("tests/data/dem/geo-i16-point.tif"),
        read("tests/data/dem/utm18n-f32-lzw.tif"),
    ];
    // (latitude, longitude) of each seed's centre: the scene's site
    let sites = [(43.16333, -77.61556), (43.15457, -77.61532)];
    let dir = tempfile::tempdir().unwrap();
    let scenes = AtomicU32::new(0);
    for s in &seeds {
        assert!(parse_raster(Path::new("d.tif"), s).is_ok());
    }
    let strategy = (mutation(seeds.len()), word_edits());
    campaign("dem-geotiff", strategy, |((k, edits), words), tally| {
        let mut b = apply(&seeds[k], &edits);
        overwrite_words(&mut b, &words);
        let r = match parse_raster(Path::new("d.tif"), &b) {
            Ok(r) => r,
            Err(e) => {
                tally.err();
                return names_file(&e.to_string(), "d.tif");
            }
        };
        tally.ok();
        require!(
            r.data.len() == r.width as usize * r.height as usize,
            "{} samples for {}x{}",
            r.data.len(),
            r.width,
            r.height
        );
        require!(
            r.geotransform.iter().all(|v| v.is_finite()),
            "non-finite transform {:?}",
            r.geotransform
        );
        for c in r.corners() {
            for f in [0.0, 0.5, 1.0, 1.5] {
                let [x, y] = r.corners()[0];
                let p = [x + f * (c[0] - x), y + f * (c[1] - y)];
                if let Sample::Value(v) = r.bilinear(p[0], p[1]) {
                    require!(v.is_finite(), "non-finite sample {v} at {p:?}");
                }
                let _ = r.nearest(p[0], p[1]);
            }
        }
        // A scene over the DEM (8 per seed stream at most: file writes).
        if scenes.fetch_add(1, Ordering::Relaxed) < 16 {
            let dem = dir.path().join(format!("m{k}.tif"));
            std::fs::write(&dem, &b).unwrap();
            let (lat, lon) = sites[k];
            let text = format!(
                "materials = [\"{}\"]\n[files]\nallow = [\"/\"]\n[site]\nlatitude_deg = {lat}\nlongitude_deg = {lon}\n\
                 elevation_m = 150.0\nutc_offset_h = -4.0\n[time]\nlocal = 2001-08-08T14:00:00\n\
                 [weather.constant]\nwind_m_s = 3.0\nair_min_c = 17.0\nair_max_c = 29.0\n\
                 dew_point_c = 14.0\n[sensor]\nwidth_px = 8\nheight_px = 8\nfov_h_deg = 30.0\n\
                 band = \"lwir\"\n[sensor.pose.altitude]\naltitude_m = 500.0\nview_zenith_deg = 0.0\n\
                 azimuth_deg = 0.0\ntarget_m = [0.0, 0.0, 0.0]\n[[terrain]]\nfile = \"{}\"\n\
                 extent_m = 300.0\nresolution_m = 30.0\nnodata = \"hole\"\nmaterial = \"grass_irrigated\"\n",
                root().join("scenes/materials.toml").display(),
                dem.display()
            );
            let file = dir.path().join(format!("m{k}.toml"));
            std::fs::write(&file, text).unwrap();
            match irsig::scene::load(&file) {
                Ok(s) => require!(
                    s.positions.iter().flatten().all(|c| c.is_finite()),
                    "non-finite terrain vertex"
                ),
                Err(e) => {
                    let e = e.to_string();
                    require!(
                        e.contains(&format!("m{k}.tif")) || e.contains(&format!("m{k}.toml")),
                        "error names neither the DEM nor the scene: {e}"
                    );
                }
            }
        }
        Ok(())
    });
}

/// glTF 2.0 meshes (issue 14 item 3): the corpus's GLB files (Khronos Box,
/// gltf-rs box_sparse with a morph target and sparse accessor, trimesh's
/// scene with a node tree and a mirror) and `.gltf` JSON (external `.bin`,
/// embedded base64 buffers, a sparse POSITION accessor, cameras) mutated by
/// byte, number, token and line edits plus overwritten 16/32-bit words (GLB
/// lengths, offsets, counts, indices, floats). Accepted meshes hold finite
/// positions, triangles whose vertices exist, faces with a place and a
/// known material; refusals name the file.
#[test]
fn gltf_mesh() {
    let dir = "tests/data/wild/meshes";
    let seeds = [
        read(&format!("{dir}/khronos/Box.glb")),
        read(&format!("{dir}/gltf-rs/box_sparse.glb")),
        read(&format!("{dir}/trimesh/scene.glb")),
        read(&format!("{dir}/khronos/Box.gltf")),
        read(&format!("{dir}/khronos/SimpleSparseAccessor.gltf")),
        read(&format!("{dir}/khronos/Cameras.gltf")),
        read(&format!("{dir}/khronos/SimpleMeshes.gltf")),
    ];
    // beside Box0.bin, so that Box.gltf's buffer resolves
    let path = root().join(dir).join("khronos/m.gltf");
    for s in &seeds {
        assert!(irsig::scene::mesh::gltf::parse_gltf(&path, s).is_ok());
    }
    let strategy = (mutation(seeds.len()), word_edits());
    campaign("gltf", strategy, |((k, edits), words), tally| {
        let mut b = apply(&seeds[k], &edits);
        overwrite_words(&mut b, &words);
        match irsig::scene::mesh::gltf::parse_gltf(&path, &b).and_then(|mut m| {
            m.triangulate()?;
            Ok(m)
        }) {
            Ok(m) => {
                tally.ok();
                mesh_is_sound(&m)?;
                require!(
                    m.faces.iter().all(|f| f.verts.len() == 3
                        && f.src < m.parts.len()
                        && f.material
                            .is_none_or(|k| (k as usize) < m.material_names.len())),
                    "a face without a place or a known material"
                );
            }
            Err(e) => {
                tally.err();
                names_file(&e.to_string(), "m.gltf")?;
            }
        }
        Ok(())
    });
}

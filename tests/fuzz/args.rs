//! Campaigns of issue 33 beyond the file parsers: hostile argument values
//! into the library calls the CLI flags and Python arguments feed (the
//! `irsig therm` march, the time and step parsers), and the path policy of
//! files a model refers to. Same runner and tallies as the parser targets.

use std::path::Path;

use irsig::bounds::args;
use irsig::scene::lookup::load_material;
use irsig::therm::series::{FacetRun, ForcingSource, facet_series, parse_time};
use proptest::prelude::*;

use crate::mutate::{INTERESTING, campaign};
use crate::require;

/// A hostile number: one of the interesting spellings, or a random f64 of
/// any magnitude and sign (bit pattern), or a value near a bound's edge.
fn hostile() -> impl Strategy<Value = f64> {
    prop_oneof![
        prop::sample::select(INTERESTING.to_vec())
            .prop_map(|s| s.parse::<f64>().unwrap_or(f64::NAN)),
        any::<u64>().prop_map(f64::from_bits),
        (
            prop::sample::select(args::ALL.to_vec()),
            -2.0..2.0f64,
            any::<bool>()
        )
            .prop_map(|(a, d, lo)| if lo { a.bound.lo + d } else { a.bound.hi + d }),
    ]
}

const MATS: &str = "[material.asphalt]\ndensity_kg_m3 = 2100.0\nspecific_heat_j_kgk = 920.0\n\
conductivity_w_mk = 0.75\nthickness_m = 0.3\nsolar_absorptivity = 0.9\nthermal_emissivity = 0.93\n\
back = { deep_ground = { temp_c = 16.85 } }\n";

/// `irsig therm` / `irsig.therm`: one to three arguments replaced by
/// hostile values. Nothing may panic or abort; a refusal names the
/// argument (never a CLI flag); an accepted run whose step count is small
/// enough to march here (≤ 20 000) gives finite temperatures.
#[test]
fn arguments_therm() {
    let dir = tempfile::tempdir().unwrap();
    let mats = dir.path().join("m.toml");
    std::fs::write(&mats, MATS).unwrap();
    let material = load_material(&mats, "asphalt").unwrap();
    let weather = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/tmy3_723170_greensboro_jun18-22.csv");
    let base = FacetRun {
        material_name: "asphalt".into(),
        material,
        forcing: ForcingSource::Weather {
            path: weather,
            typical_year: false,
            stand_in: false,
        },
        site: irsig::sun::Site {
            latitude_deg: 36.1,
            longitude_deg: -79.95,
            elevation_m: 0.0,
        },
        orientation: irsig::therm::balance::Orientation {
            slope_deg: 0.0,
            aspect_deg: 180.0,
        },
        from: parse_time("1989-06-19T05:00:00Z").unwrap(),
        to: parse_time("1989-06-19T07:00:00Z").unwrap(),
        step_min: 15.0,
        spin_up_h: 2.0,
        spin_up_start: irsig::therm::slab::SpinUpStart::MeanForcing,
        convection: irsig::therm::balance::Convection::mcadams(),
        facet_height_m: 0.0,
        shadow: Vec::new(),
        sky_view: None,
    };
    let strategy = prop::collection::vec((0usize..9, hostile()), 1..4);
    campaign("arguments-therm", strategy, |edits, tally| {
        let mut run = base.clone();
        for (k, v) in &edits {
            match k {
                0 => run.step_min = *v,
                1 => run.spin_up_h = *v,
                2 => run.facet_height_m = *v,
                3 => run.site.latitude_deg = *v,
                4 => run.site.longitude_deg = *v,
                5 => run.site.elevation_m = *v,
                6 => run.orientation.slope_deg = *v,
                7 => run.orientation.aspect_deg = *v,
                _ => run.sky_view = Some(*v),
            }
        }
        let steps = (2.0 + run.spin_up_h) * 60.0 / run.step_min;
        let valid = [
            (args::THERM_STEP_MIN, run.step_min),
            (args::THERM_SPIN_UP_H, run.spin_up_h),
            (args::THERM_FACET_HEIGHT, run.facet_height_m),
            (args::LAT, run.site.latitude_deg),
            (args::LON, run.site.longitude_deg),
            (args::ELEVATION, run.site.elevation_m),
            (args::SLOPE, run.orientation.slope_deg),
            (args::ASPECT, run.orientation.aspect_deg),
            (args::SKY_VIEW, run.sky_view.unwrap_or(0.0)),
        ]
        .iter()
        .all(|(a, v)| a.bound.contains(*v))
            && run
                .sky_view
                .is_none_or(|f| f <= run.orientation.sky_view_factor() + 1e-12);
        if valid && steps > 20_000.0 {
            // In range but long: marched by the long run only.
            tally.ok();
            return Ok(());
        }
        match facet_series(&run) {
            Ok(s) => {
                tally.ok();
                require!(valid, "accepted out-of-range arguments {edits:?}");
                require!(
                    s.rows.iter().all(|r| r.rec.surface_temp_k.is_finite()),
                    "non-finite temperature for {edits:?}"
                );
            }
            Err(e) => {
                tally.err();
                let e = format!("{e:#}");
                require!(!e.contains("--"), "a CLI flag in a library error: {e}");
            }
        }
        Ok(())
    });
}

/// Time words: sequence steps, local times and RFC 3339 times (the
/// `--step`/`step=`, `--from`/`start=`, `time=` arguments), random text
/// built from time-like pieces. No panic; an accepted step is 1 s to a
/// year; an accepted time lies in 1900-2200; a range gives at most
/// `MAX_FRAMES` frames.
#[test]
fn arguments_time() {
    use irsig::render::sequence::{
        MAX_FRAMES, TimeNames, parse_local_time, parse_step_s_named, time_steps_named,
    };
    let piece = prop::sample::select(vec![
        "1",
        "0",
        "-1",
        "1e308",
        "1e-320",
        "nan",
        "inf",
        "99999999999999999999",
        ".",
        "..",
        "h",
        "min",
        "m",
        "s",
        "hours",
        " ",
        "0.5",
        "262143",
        "9999",
        "1899",
        "2201",
        "2001",
        "-",
        ":",
        "T",
        "Z",
        "+14:00",
        "-12:00",
        "12",
        "60",
        "24",
        "08",
        "31",
        "02",
        "29",
    ]);
    let word = prop::collection::vec(piece, 1..8).prop_map(|v| v.concat());
    let date = chrono::NaiveDate::from_ymd_opt(2001, 8, 8).unwrap();
    campaign(
        "arguments-time",
        (word.clone(), word.clone(), word),
        |(a, b, c), tally| {
            let mut ok = 0;
            if let Ok(s) = parse_step_s_named("step", &a) {
                ok += 1;
                require!((1..=366 * 86_400).contains(&s), "step {a:?} = {s} s");
            }
            for w in [&a, &b, &c] {
                if let Ok(t) = irsig::sun::report::parse_time(w) {
                    use chrono::Datelike;
                    require!((1900..=2200).contains(&t.year()), "time {w:?}");
                }
            }
            let f = parse_local_time("start", &b, date);
            let t = parse_local_time("stop", &c, date);
            if let (Ok(f), Ok(t), Ok(s)) = (f, t, parse_step_s_named("step", &a)) {
                ok += 1;
                if let Ok(v) = time_steps_named(TimeNames::PYTHON, f, t, s) {
                    require!(v.len() <= MAX_FRAMES, "{} frames", v.len());
                }
            }
            if ok > 0 {
                tally.ok()
            } else {
                tally.err()
            }
            Ok(())
        },
    );
}

/// The path policy of files a model refers to: random relative and
/// absolute paths from path pieces (`..`, `.`, `/`, `%2E`, `file:`,
/// symbolic links in and out of the folder). An accepted path must resolve
/// (canonically, when it exists) inside the model's folder; no error may
/// hold a byte of the secret file outside it.
#[test]
fn path_policy() {
    let d = tempfile::tempdir().unwrap();
    let m = d.path().join("model");
    std::fs::create_dir_all(m.join("sub/deep")).unwrap();
    std::fs::write(m.join("in.bin"), [1u8; 36]).unwrap();
    std::fs::write(
        d.path().join("secret.bin"),
        b"SECRET-BYTES-0123456789abcdefghijklmn",
    )
    .unwrap();
    std::os::unix::fs::symlink(d.path().join("secret.bin"), m.join("out-link")).unwrap();
    std::os::unix::fs::symlink(d.path(), m.join("sub/up-link")).unwrap();
    std::os::unix::fs::symlink(m.join("in.bin"), m.join("sub/in-link")).unwrap();
    let canon = m.canonicalize().unwrap();
    let piece = prop::sample::select(vec![
        "..",
        ".",
        "sub",
        "deep",
        "in.bin",
        "secret.bin",
        "out-link",
        "up-link",
        "in-link",
        "model",
        "%2E%2E",
        "%2e",
        "/",
        "//",
        "\\",
        "C:",
        "file:",
        "file://",
        "etc",
        "passwd",
        "%00",
        "~",
    ]);
    let path = prop::collection::vec(piece, 1..7).prop_map(|v| v.join("/"));
    campaign("path-policy", path, |p, tally| {
        let rel = percent_encoding::percent_decode_str(&p)
            .decode_utf8_lossy()
            .into_owned();
        match irsig::files::within(&m, Path::new(&rel), &[]) {
            Ok(f) => {
                tally.ok();
                if let Ok(c) = f.canonicalize() {
                    require!(c.starts_with(&canon), "{p:?} accepted, resolves to {c:?}");
                }
            }
            Err(_) => tally.err(),
        }
        // Through the glTF loader: never a byte of the secret.
        let gltf = format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":36,"uri":{}}}],"bufferViews":[{{"buffer":0,"byteLength":36}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#,
            serde_json::to_string(&p).unwrap()
        );
        if let Err(e) = irsig::scene::mesh::gltf::parse_gltf(&m.join("m.gltf"), gltf.as_bytes()) {
            let e = e.to_string();
            require!(!e.contains("SECRET") && !e.contains("83, 69"), "{p:?}: {e}");
        }
        Ok(())
    });
}

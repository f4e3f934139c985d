//! `irsig probe` reproduces what `irsig render` writes for a pixel: its
//! terms add up to the pixel's band radiance in the EXR, for sunlit ground,
//! shadow, an aircraft and the specular hangar roof, with the right case;
//! and the render is bit-identical for 1 and 2 threads.

mod common;

use common::{Img, airfield, material_index, render, run, sets};
use serde_json::Value;

const SIZE: [&str; 2] = ["sensor.width_px=128", "sensor.height_px=128"];

fn probe(x: u32, y: u32) -> Value {
    let mut args = vec![
        "probe".to_string(),
        airfield().display().to_string(),
        "--pixel".into(),
        format!("{x},{y}"),
        "--json".into(),
    ];
    args.extend(sets(&SIZE));
    serde_json::from_str(&run(&args)).expect("probe JSON")
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn terms_total(t: &Value) -> f64 {
    t.as_object().expect("terms").values().map(f).sum()
}

/// First pixel that satisfies `pred`, interior (3x3 neighbourhood of the
/// same material) when `interior`.
fn find(img: &Img, what: &str, interior: bool, pred: impl Fn(u32, u32) -> bool) -> (u32, u32) {
    let m = img.plane("material");
    for y in 1..img.h - 1 {
        for x in 1..img.w - 1 {
            let c = m[(y * img.w + x) as usize];
            let inside =
                (0..3).all(|j| (0..3).all(|i| m[((y + j - 1) * img.w + x + i - 1) as usize] == c));
            if (inside || !interior) && pred(x, y) {
                return (x, y);
            }
        }
    }
    panic!("no {what} pixel in the image");
}

/// Checks the probe of (x, y) against the rendered planes; returns the
/// probe's single sample.
fn check(img: &Img, (x, y): (u32, u32), what: &str) -> Value {
    let p = probe(x, y);
    eprintln!(
        "{what}: pixel ({x}, {y}), case {}",
        p["pixel_result"]["case"]
    );
    let pr = &p["pixel_result"];
    let exr = img.at("band_radiance", x, y) as f64;
    let sum = terms_total(&pr["terms"]);
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-30);
    assert!(
        rel(sum, exr) < 1e-5,
        "{what} ({x},{y}): probe terms sum to {sum}, EXR band_radiance {exr}"
    );
    assert!(rel(f(&pr["band_radiance_w_m2_sr_um"]), exr) < 1e-5);
    assert_eq!(
        f(&pr["band_radiance_f32"]) as f32,
        exr as f32,
        "{what}: f32 radiance"
    );
    // Each term against its own plane (absolute floor for near-zero terms).
    let t = &pr["terms"];
    for (plane, v) in [
        ("emitted", f(&t["emitted"])),
        ("reflected_solar", f(&t["reflected_solar"])),
        (
            "reflected_sky",
            f(&t["reflected_sky_thermal"]) + f(&t["reflected_sky_scattered"]),
        ),
        (
            "reflected_background",
            f(&t["reflected_background_emitted"]) + f(&t["reflected_background_solar"]),
        ),
        ("path_thermal", f(&t["path_thermal"])),
        ("path_scattered", f(&t["path_scattered"])),
    ] {
        let e = img.at(plane, x, y) as f64;
        assert!(
            (v - e).abs() <= 1e-5 * exr,
            "{what} ({x},{y}): {plane} probe {v}, EXR {e}"
        );
    }
    let t_app = f(&pr["apparent_temperature_k"]);
    assert!(
        (t_app - img.at("apparent_temperature", x, y) as f64).abs() < 1e-3,
        "{what}: apparent temperature {t_app} vs {}",
        img.at("apparent_temperature", x, y)
    );
    // The centre sample (the categorical planes' sample; the only one of a
    // pixel that kept its coarse sample under adaptive sampling).
    let n = p["supersample"].as_u64().expect("supersample") as usize;
    let s = &p["samples"][(n / 2) * n + n / 2];
    let hit = &s["hit"];
    let t_s = f(&hit["thermal"]["surface_temp_k"]);
    assert!(
        rel(
            f(&pr["surface_temperature_k"]),
            img.at("surface_temperature", x, y) as f64
        ) < 1e-6,
        "{what}: surface temperature (mean over the pixel's samples)"
    );
    // The series ends at the image time, at the same temperature.
    let series = hit["thermal"]["series"].as_array().expect("series");
    assert!(
        series.len() > 24,
        "{what}: a thermal series over the history"
    );
    assert!((f(&series[series.len() - 1]["surface_temp_k"]) - t_s).abs() < 1e-9);
    // Issue #30: the point's own sky view factor and the stability function
    // at the image time are reported, and agree with the series' last step
    // and with the library's F(Ri).
    let last = &series[series.len() - 1];
    let th = &hit["thermal"];
    let sky = f(&th["sky_view"]);
    assert!((0.0..=1.0).contains(&sky), "{what}: sky view {sky}");
    assert_eq!(sky, f(&last["sky_view"]), "{what}: sky view");
    let ri = f(&th["richardson"]);
    assert_eq!(ri, f(&last["surface"]["richardson"]), "{what}: Ri");
    assert!(
        (f(&th["stability_factor"]) - irsig::therm::aero::stability_factor(ri)).abs() < 1e-12,
        "{what}: F(Ri)"
    );
    // Issue #30: a vegetated point reports its canopy/soil split; the flux
    // from the canopy skin into the soil is the skin conductance times
    // their temperature difference.
    if let Some(veg) = th["surface"].get("vegetation") {
        let lambda = f(&veg["skin_conductance_w_m2k"]);
        let (skin, soil) = (f(&last["surface_temp_k"]), f(&last["soil_surface_temp_k"]));
        let q = f(&last["conduction_into_slab_w_m2"]);
        eprintln!(
            "{what}: canopy skin {skin:.2} K over soil {soil:.2} K, {q:.1} W/m2 into the soil"
        );
        assert!(skin != soil, "{what}: skin and soil are two temperatures");
        assert!(
            (q - lambda * (skin - soil)).abs() < 1e-9 * q.abs().max(1.0),
            "{what}: skin-to-soil flux {q} vs {lambda}·({skin} − {soil})"
        );
    }
    // Hit, case and history agree with the planes.
    assert_eq!(
        f(&hit["triangle"]) as f32,
        img.at("facet", x, y),
        "{what}: facet"
    );
    assert_eq!(f(&hit["material_index"]) as f32, img.at("material", x, y));
    assert_eq!(f(&pr["case"]) as f32, img.at("case", x, y), "{what}: case");
    let h = &hit["history"];
    let flags = h["sunlit"].as_str().expect("sunlit string");
    assert_eq!(
        flags.len(),
        145,
        "48 h at 20 min (60-min samples bisected), both ends"
    );
    // The mean-valued planes are means over the pixel's samples.
    let all = p["samples"].as_array().expect("samples");
    let mean_of = |get: &dyn Fn(&Value) -> Option<f64>| {
        let v: Vec<f64> = all.iter().filter_map(get).collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let sun_now = mean_of(&|s| {
        (s["hit"]["history"]["sunlit"].as_str()).map(|f| f.ends_with('1') as u8 as f64)
    });
    assert!(
        (sun_now - img.at("sun_now", x, y) as f64).abs() < 1e-6,
        "{what}: sun now"
    );
    let hours = mean_of(&|s| s["hit"]["history"]["hours_sunlit"].as_f64());
    assert!((hours - img.at("hours_sunlit", x, y) as f64).abs() < 1e-4);
    let view = mean_of(&|s| s["angles"]["view_angle_deg"].as_f64());
    assert!((view - img.at("view_angle", x, y) as f64).abs() < 1e-3);
    // The sample's own terms add up to its radiance.
    let r = &s["radiometry"];
    assert!(rel(terms_total(&r["terms"]), f(&r["band_radiance_w_m2_sr_um"])) < 1e-12);
    s.clone()
}

#[test]
fn probe_terms_add_up_to_the_rendered_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let scene = airfield();
    let img = render(dir.path(), &scene, "noon", &SIZE);
    let ground = [
        material_index(&scene, "concrete"),
        material_index(&scene, "asphalt"),
        material_index(&scene, "grass_irrigated"),
    ];
    let skin = material_index(&scene, "aircraft_skin");
    let roof = material_index(&scene, "painted_steel_roof");
    let is = |x, y, m: &[f32]| m.contains(&img.at("material", x, y));

    let lit = find(&img, "sunlit ground", true, |x, y| {
        is(x, y, &ground) && img.at("sun_now", x, y) == 1.0
    });
    let s = check(&img, lit, "sunlit ground");
    assert_eq!(s["radiometry"]["case"], 1);
    assert!(f(&s["radiometry"]["terms"]["reflected_solar"]) > 0.0);

    let shade = find(&img, "shadowed ground", true, |x, y| {
        is(x, y, &ground) && img.at("sun_now", x, y) == 0.0
    });
    let s = check(&img, shade, "shadowed ground");
    assert_eq!(s["radiometry"]["case"], 1);
    assert_eq!(f(&s["radiometry"]["terms"]["reflected_solar"]), 0.0);
    assert!(
        s["hit"]["history"]["reason"]
            .as_str()
            .unwrap()
            .ends_with('s')
    );

    let plane = find(&img, "aircraft", false, |x, y| is(x, y, &[skin]));
    let s = check(&img, plane, "aircraft");
    assert!(s["hit"]["object"].as_str().unwrap().starts_with("aircraft"));

    let r = find(&img, "hangar roof", true, |x, y| is(x, y, &[roof]));
    let s = check(&img, r, "hangar roof");
    // Specular: the bounce leaves for the sky (case 2) or meets a facet
    // (case 3), and the case says which.
    let target = s["bounce"]["target"].as_str().expect("a specular bounce");
    let case = s["radiometry"]["case"].as_u64().unwrap();
    assert_eq!(case, if target == "sky" { 2 } else { 3 }, "roof case");
    assert!(f(&s["radiometry"]["terms"]["reflected_sky_thermal"]) > 0.0 || case == 3);

    // A specular pixel whose bounce meets the scene (case 3): a background
    // surface with its own history and temperature.
    let bg = find(&img, "specular-to-background", false, |x, y| {
        img.at("case", x, y) == 3.0
    });
    let s = check(&img, bg, "specular to background");
    let b = &s["bounce"];
    match b["target"].as_str().unwrap() {
        "surface" => {
            let t = f(&b["background"]["thermal"]["surface_temp_k"]);
            assert!(t > 250.0 && t < 350.0, "background temperature {t}");
            assert!(
                !b["background"]["history"]["sunlit"]
                    .as_str()
                    .unwrap()
                    .is_empty()
            );
        }
        "ground plane" => assert!(b["background"].is_null()),
        other => panic!("case 3 with a bounce to {other}"),
    }
    assert!(f(&s["radiometry"]["terms"]["reflected_background_emitted"]) > 0.0);
}

#[test]
fn render_is_identical_for_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let scene = airfield();
    let mut imgs = Vec::new();
    // One band of samples (the default), then bands of 16 and 32 sample
    // rows (the render streams a frame band by band): the same bits.
    for (threads, band) in [
        ("1", None),
        ("2", None),
        ("2", Some("1536")),
        ("1", Some("6144")),
    ] {
        let exr = dir.path().join(format!("t{threads}-{band:?}.exr"));
        let mut args = vec![
            "render".to_string(),
            scene.display().to_string(),
            "-o".into(),
            exr.display().to_string(),
            "--threads".into(),
            threads.into(),
        ];
        args.extend(sets(&[
            "sensor.width_px=96",
            "sensor.height_px=96",
            "render.supersample=2",
        ]));
        let mut cmd = common::irsig();
        cmd.args(&args);
        if let Some(b) = band {
            cmd.env("IRSIG_BAND_SAMPLES", b);
        }
        let out = cmd.output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        imgs.push((format!("{threads} threads, band {band:?}"), Img::read(&exr)));
    }
    let (la, a) = &imgs[0];
    assert!(a.planes.len() >= 15, "every plane written");
    for (lb, b) in &imgs[1..] {
        assert_eq!((a.w, a.h), (b.w, b.h));
        assert_eq!(a.planes.len(), b.planes.len());
        for (name, pa) in &a.planes {
            let pb = &b.planes[name];
            let same = pa.iter().zip(pb).all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(same, "plane {name} differs between {la} and {lb}");
        }
    }
}

/// Issue #30: the sky view factor varies within a triangle (per point),
/// so one grass facet shows no step at 03:00 LWIR where one of its two
/// triangles has its centroid under a decal. Pixels 45-55 of row 92 of the
/// full-size airfield (the issue's example: 49 and 50 lie on triangles 495
/// and 494 of grass facet 247; F_sky was 0.00 against 1.00, 2.5 K apart):
/// adjacent pixels on one level facet of one material with one sun history
/// differ by at most 0.5 K in surface and apparent temperature.
#[test]
fn adjacent_pixels_of_one_surface_have_no_sky_view_step() {
    let probe_full = |x: u32| -> Value {
        let args: Vec<String> = [
            "probe",
            &airfield().display().to_string(),
            "--pixel",
            &format!("{x},92"),
            "--json",
            "--set",
            "sensor.band=lwir",
            "--set",
            "time.local=2001-08-08T03:00:00",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        serde_json::from_str(&run(&args)).expect("probe JSON")
    };
    let probes: Vec<Value> = (45..=55).map(probe_full).collect();
    let mut pairs = 0;
    for w in probes.windows(2) {
        let (a, b) = (&w[0]["samples"][0]["hit"], &w[1]["samples"][0]["hit"]);
        let same = a["material"] == b["material"]
            && a["slope_deg"] == b["slope_deg"]
            && a["history"] == b["history"]
            && f(&a["slope_deg"]) == 0.0;
        if !same {
            continue;
        }
        pairs += 1;
        let key = |p: &Value, k: &str| f(&p["pixel_result"][k]);
        for k in ["surface_temperature_k", "apparent_temperature_k"] {
            let d = (key(&w[0], k) - key(&w[1], k)).abs();
            assert!(
                d <= 0.5,
                "{k}: {} vs {} ({} and {})",
                key(&w[0], k),
                key(&w[1], k),
                a["triangle"],
                b["triangle"]
            );
        }
    }
    assert!(pairs >= 5, "only {pairs} comparable pairs");
}

/// Issue #30's acceptance over the whole image: the airfield at 03:00
/// (LWIR, the scene's own size and sampling), every pair of horizontally
/// or vertically adjacent pixels of one material on one level surface
/// (ground heights within 5 mm) with the same hours of sun differs by at
/// most 0.5 K in surface and apparent temperature. Before, the visible
/// edges of grass triangles that run under the apron slab or a hangar took
/// the sky of their one unseen sample (none) and stood 2-2.8 K warm (58
/// pairs over 0.5 K).
#[test]
fn adjacent_pixels_of_one_level_surface_agree_at_night() {
    let dir = tempfile::tempdir().unwrap();
    let img = render(
        dir.path(),
        &airfield(),
        "night",
        &["sensor.band=\"lwir\"", "time.local=2001-08-08T03:00:00"],
    );
    let (m, z, sun) = (
        img.plane("material"),
        img.plane("ground_z"),
        img.plane("hours_sunlit"),
    );
    let mut pairs = 0;
    for name in ["surface_temperature", "apparent_temperature"] {
        let t = img.plane(name);
        let mut worst = (0.0f32, 0, 0);
        for y in 0..img.h {
            for x in 0..img.w {
                let a = (y * img.w + x) as usize;
                for b in [
                    (x + 1 < img.w).then(|| a + 1),
                    (y + 1 < img.h).then(|| a + img.w as usize),
                ]
                .into_iter()
                .flatten()
                {
                    if m[a] < 0.0 || m[a] != m[b] || sun[a] != sun[b] || (z[a] - z[b]).abs() > 0.005
                    {
                        continue;
                    }
                    pairs += 1;
                    let d = (t[a] - t[b]).abs();
                    if d > worst.0 {
                        worst = (d, x, y);
                    }
                }
            }
        }
        assert!(
            worst.0 <= 0.5,
            "{name}: {} K at pixel ({}, {})",
            worst.0,
            worst.1,
            worst.2
        );
    }
    assert!(pairs > 100_000, "only {pairs} comparable pairs");
}

fn terrain_km() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/terrain-km/scene.toml")
}

/// The probe of the centre pixel of a 41×41 nadir view of the terrain
/// scene from `altitude_m`, with `fov_h_deg`, one ray per pixel, aimed at
/// a point inside a terrain cell (not on a vertex) clear of the vehicles.
fn nadir_probe(altitude_m: f64, fov_h_deg: f64) -> Value {
    let mut args = vec![
        "probe".to_string(),
        terrain_km().display().to_string(),
        "--pixel".into(),
        "20,20".into(),
        "--json".into(),
    ];
    args.extend(sets(&[
        &format!("sensor.pose.altitude.altitude_m={altitude_m}"),
        "sensor.pose.altitude.view_zenith_deg=0",
        "sensor.pose.altitude.target_m=[113.3,-206.7,0]",
        "sensor.width_px=41",
        "sensor.height_px=41",
        &format!("sensor.fov_h_deg={fov_h_deg}"),
        "render.supersample=1",
    ]));
    serde_json::from_str(&run(&args)).expect("probe JSON")
}

/// A Landsat-like view (705 km, nadir, 100 m pixels over the terrain
/// scene) renders, and `irsig check` with the same overrides passes;
/// its path is the top-of-atmosphere path of the tables (100 km): the
/// centre pixel's emitted term ε L_T τ₂ and path terms equal those of a
/// 100-km sensor looking at the same point (so τ₂ is equal), and differ
/// from a 20-km sensor's.
#[test]
fn a_705_km_nadir_view_sees_the_top_of_atmosphere_path() {
    // 41 px of 100 m at 705 km (the target's terrain is within metres of z = 0)
    let fov = |range_m: f64| 2.0 * (20.5 * 100.0 / range_m).atan().to_degrees();
    let kv = [
        "sensor.pose.altitude.altitude_m=705000".to_string(),
        "sensor.pose.altitude.view_zenith_deg=0".into(),
        "sensor.width_px=41".into(),
        "sensor.height_px=41".into(),
        format!("sensor.fov_h_deg={}", fov(705_000.0)),
        "render.supersample=1".into(),
    ];
    let kv: Vec<&str> = kv.iter().map(|s| s.as_str()).collect();
    let mut check = vec!["check".to_string(), terrain_km().display().to_string()];
    check.extend(sets(&kv));
    let out = run(&check);
    assert!(out.contains("GSD"), "{out}");
    let dir = tempfile::tempdir().unwrap();
    let img = render(dir.path(), &terrain_km(), "landsat", &kv);
    assert!(
        img.plane("band_radiance")
            .iter()
            .all(|v| v.is_finite() && *v > 0.0)
    );
    // 100 m pixels: ground_x steps by 100 m ± 1 % along a row
    // (the image is turned by the pose's azimuth: the step is a distance)
    let (gx, gy) = (img.plane("ground_x"), img.plane("ground_y"));
    let (a, b) = (20 * 41 + 10, 20 * 41 + 30);
    let step = ((gx[b] - gx[a]) as f64).hypot((gy[b] - gy[a]) as f64) / 20.0;
    assert!((step - 100.0).abs() < 1.0, "GSD {step} m");

    let p705 = nadir_probe(705_000.0, fov(705_000.0));
    let p100 = nadir_probe(100_000.0, fov(100_000.0));
    let p20 = nadir_probe(20_000.0, fov(20_000.0));
    let hit = |p: &Value| p["samples"][0]["hit"]["triangle"].clone();
    assert_eq!(hit(&p705), hit(&p100));
    let (a, b) = (&p705["pixel_result"], &p100["pixel_result"]);
    assert_eq!(a["surface_temperature_k"], b["surface_temperature_k"]);
    for term in [
        "emitted",
        "path_thermal",
        "path_scattered",
        "reflected_sky_thermal",
    ] {
        assert_eq!(a["terms"][term], b["terms"][term], "{term}");
        assert!(f(&a["terms"][term]).is_finite());
    }
    let c = &p20["pixel_result"];
    assert_eq!(a["surface_temperature_k"], c["surface_temperature_k"]);
    assert!(f(&a["terms"]["path_thermal"]) > f(&c["terms"]["path_thermal"]));
    assert!(f(&a["terms"]["emitted"]) < f(&c["terms"]["emitted"]));
}

/// `irsig check` refuses what the render refuses before tracing, with the
/// render's message (one validation, `render::prepare::validate`): here
/// the memory limit.
#[test]
fn check_refuses_what_the_render_refuses() {
    let dir = tempfile::tempdir().unwrap();
    let scene = airfield().display().to_string();
    let set = ["--set", "render.max_memory_mib=1"];
    let (rc, _, check_err) = common::irsig_out(&[&["check", &scene][..], &set].concat());
    let exr = dir.path().join("x.exr").display().to_string();
    let (rr, _, render_err) =
        common::irsig_out(&[&["render", &scene, "-o", &exr][..], &set].concat());
    assert!(rc != 0 && rr != 0, "{check_err}\n{render_err}");
    let msg = |e: &str| {
        e.lines()
            .find(|l| l.contains("more than"))
            .map(|l| l.trim_start_matches("error: ").to_string())
    };
    assert!(msg(&check_err).is_some(), "{check_err}");
    assert_eq!(msg(&check_err), msg(&render_err));
}

/// `probe` and `render` take `--unset` as `sequence`/`sweep` do: switching
/// the airfield's altitude pose to the same view given as a slant range
/// (range = altitude above the target / cos θ, here θ = 0) probes the same.
#[test]
fn probe_and_render_take_unset() {
    let scene = airfield().display().to_string();
    let s = irsig::scene::load(&airfield()).unwrap();
    let irsig::scene::spec::SensorPose::Altitude {
        altitude_m,
        target_m,
        ..
    } = s.scene.sensor.pose
    else {
        panic!("the airfield's pose is [sensor.pose.altitude]");
    };
    let base = [
        "--pixel",
        "10,10",
        "--json",
        "--set",
        "sensor.width_px=16",
        "--set",
        "sensor.height_px=16",
        "--set",
        "sensor.pose.altitude.view_zenith_deg=0",
    ];
    let (rc, a, e) = common::irsig_out(&[&["probe", &scene][..], &base].concat());
    assert_eq!(rc, 0, "{e}");
    let range = format!(
        "sensor.pose.slant_range.slant_range_m={}",
        altitude_m - target_m[2]
    );
    let target = format!("sensor.pose.slant_range.target_m={target_m:?}");
    let switch = [
        "--unset",
        "sensor.pose.altitude",
        "--set",
        &range,
        "--set",
        "sensor.pose.slant_range.view_zenith_deg=0",
        "--set",
        "sensor.pose.slant_range.azimuth_deg=180",
        "--set",
        &target,
    ];
    let (rc, b, e) = common::irsig_out(&[&["probe", &scene][..], &base[..7], &switch].concat());
    assert_eq!(rc, 0, "{e}");
    let (a, b): (Value, Value) = (
        serde_json::from_str(&a).unwrap(),
        serde_json::from_str(&b).unwrap(),
    );
    // (the same camera to rounding: the altitude pose's range is computed
    // on the Earth's sphere)
    let (ra, rb) = (
        f(&a["pixel_result"]["band_radiance_w_m2_sr_um"]),
        f(&b["pixel_result"]["band_radiance_w_m2_sr_um"]),
    );
    assert!((ra - rb).abs() <= 1e-6 * ra, "{ra} {rb}");
    assert_eq!(
        a["samples"][0]["hit"]["triangle"],
        b["samples"][0]["hit"]["triangle"]
    );
    // render: an --unset of a key the scene lacks is refused, naming it
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("u.exr").display().to_string();
    let (rc, _, e) = common::irsig_out(&[
        "render",
        &scene,
        "-o",
        &exr,
        "--unset",
        "sensor.pose.look_at",
    ]);
    assert!(rc != 0 && e.contains("unset `sensor.pose.look_at`"), "{e}");
}

/// `irsig probe` of the centre pixel of a 41×41 nadir view of the terrain
/// scene from 2 km (one ray per pixel) with both land-cover classes set to
/// `cover` and the overrides `extra`; JSON with `json`.
fn terrain_cover_probe(cover: &str, extra: &[&str], json: bool) -> String {
    let classes = format!(r#"terrain.terrain.land_cover.classes={{"1"="{cover}","2"="{cover}"}}"#);
    let base = [
        "sensor.pose.altitude.altitude_m=2000",
        "sensor.pose.altitude.view_zenith_deg=0",
        "sensor.pose.altitude.target_m=[113.3,-206.7,0]",
        "sensor.width_px=41",
        "sensor.height_px=41",
        "sensor.fov_h_deg=5",
        "render.supersample=1",
        &classes,
    ];
    let mut args = vec![
        "probe".to_string(),
        terrain_km().display().to_string(),
        "--pixel".into(),
        "20,20".into(),
    ];
    if json {
        args.push("--json".into());
    }
    args.extend(sets(&[&base[..], extra].concat()));
    run(&args)
}

/// `irsig probe` shows the snow state (issue #30): the terrain scene with
/// its land cover set to `snow`, probed at the nadir centre pixel. In the
/// scene's August weather the snow is held at 0 °C and melts (text:
/// "snow: melting at 0 °C"; JSON: `melt_w_m2` > 0, T_s = 273.15 K); in
/// winter air (−12 to −3 °C) at 03:00 it is frozen (melt 0, T_s below
/// 0 °C) and the stable night's stability factor shows the floor of snow
/// (`aero::SNOW_STABLE_FLOOR`), above Louis's value at the same Ri.
#[test]
fn probe_shows_the_snow_state() {
    let cold = [
        "weather.constant.air_min_c=-12",
        "weather.constant.air_max_c=-3",
        "weather.constant.dew_point_c=-14",
        "time.local=2001-08-08T03:00:00",
    ];
    let probe = |extra: &[&str], json: bool| terrain_cover_probe("snow", extra, json);
    let thermal = |extra: &[&str]| -> Value {
        let v: Value = serde_json::from_str(&probe(extra, true)).expect("probe JSON");
        let s = v["samples"].as_array().expect("samples");
        s[s.len() / 2]["hit"]["thermal"].clone()
    };

    let text = probe(&[], false);
    assert!(text.contains("snow: melting at 0 °C"), "{text}");
    let warm = thermal(&[]);
    assert!(warm["surface"]["snow"].is_object(), "{warm}");
    let last = warm["series"].as_array().unwrap().last().unwrap().clone();
    assert!(f(&last["melt_w_m2"]) > 0.0, "{last}");
    assert!((f(&warm["surface_temp_k"]) - 273.15).abs() < 1e-6);

    let text = probe(&cold, false);
    assert!(text.contains("snow: frozen, melt 0.0 W m-2"), "{text}");
    let frozen = thermal(&cold);
    let last = frozen["series"].as_array().unwrap().last().unwrap().clone();
    assert_eq!(f(&last["melt_w_m2"]), 0.0);
    assert!(f(&frozen["surface_temp_k"]) < 273.15 - 5.0, "{frozen}");
    let (ri, sf) = (f(&frozen["richardson"]), f(&frozen["stability_factor"]));
    assert!(ri > 0.0, "a stable night: Ri {ri}");
    assert!(
        sf >= irsig::therm::aero::SNOW_STABLE_FLOOR
            && sf > irsig::therm::aero::stability_factor(ri),
        "F {sf} at Ri {ri}"
    );
    assert_eq!(
        f(&last["surface"]["stability_floor"]),
        irsig::therm::aero::SNOW_STABLE_FLOOR
    );
}

/// `irsig probe` shows the slab under the surface (issue #30: the layered
/// `sand_desert`): the terrain scene with its land cover set to
/// `sand_desert`, probed at the nadir centre pixel, reports the two layers
/// of the library's table (read here with `toml`, not irsig's reader), top
/// first, with its optical constants and a resolved deep-ground back; the
/// text names them.
#[test]
fn probe_shows_the_layers_of_the_slab() {
    let probe = |json: bool| terrain_cover_probe("sand_desert", &[], json);
    let lib: toml::Table = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/materials.toml"),
    )
    .unwrap()
    .parse()
    .unwrap();
    let want = lib["material"]["sand_desert"]["layers"].as_array().unwrap();
    let v: Value = serde_json::from_str(&probe(true)).expect("probe JSON");
    let s = v["samples"].as_array().expect("samples");
    let hit = &s[s.len() / 2]["hit"];
    assert_eq!(hit["material"], "sand_desert", "{hit}");
    let slab = &hit["thermal"]["slab"];
    let got = slab["layers"].as_array().expect("layers");
    assert_eq!(got.len(), 2, "{slab}");
    for (g, w) in got.iter().zip(want) {
        for k in [
            "thickness_m",
            "conductivity_w_mk",
            "density_kg_m3",
            "specific_heat_j_kgk",
        ] {
            assert_eq!(f(&g[k]), w[k].as_float().unwrap(), "{k}: {slab}");
        }
    }
    let t = |k: &str| lib["material"]["sand_desert"][k].as_float().unwrap();
    assert_eq!(f(&slab["solar_absorptivity"]), t("solar_absorptivity"));
    assert_eq!(f(&slab["thermal_emissivity"]), t("thermal_emissivity"));
    let deep = f(&slab["back"]["deep_ground"]["temp_c"]);
    assert!(
        (-40.0..60.0).contains(&deep),
        "a resolved deep ground: {slab}"
    );
    let text = probe(false);
    assert!(
        text.contains("slab, 2 layers top first: 0.015 m k 0.240 W m-1 K-1"),
        "{text}"
    );
}

//! `irsig sequence` and `irsig sweep` end to end, on small images and short
//! histories: frames, the contact sheet under one common stretch, the index,
//! the paper's Fig. 13 phenomenon (contrast falls with wind speed, steeply
//! first), Fig. 14 (contrast falls with view zenith), and clear errors.

use std::path::Path;

use irsig::output::exr::read_exr;
use irsig::output::quicklook::{Stretch, percentile_stretch, to_grey};

const CONSTANT: &str = "scenes/airfield/scene-constant.toml";
const SMALL: [&str; 6] = [
    "--set",
    "sensor.width_px=64",
    "--set",
    "sensor.height_px=64",
    "--set",
    "render.history_hours=6",
];

mod common;
use common::irsig_out as irsig;

fn index(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("index.json")).unwrap()).unwrap()
}

/// (width, height, grey pixels, Description text) of an 8-bit grey PNG.
fn read_png(path: &Path) -> (u32, u32, Vec<u8>, String) {
    let dec = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut r = dec.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size()];
    let info = r.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    let text = r
        .info()
        .uncompressed_latin1_text
        .iter()
        .find(|t| t.keyword == "Description")
        .map(|t| t.text.clone())
        .unwrap_or_default();
    (info.width, info.height, buf, text)
}

fn plane(exr: &Path, name: &str) -> Vec<f32> {
    let (_, _, chans) = read_exr(exr).unwrap();
    chans
        .into_iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("{}: no {name}", exr.display()))
        .1
}

fn std_app_temp(ix: &serde_json::Value) -> Vec<f64> {
    ix["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["apparent_temperature_k"]["std"].as_f64().unwrap())
        .collect()
}

#[test]
fn sequence_writes_frames_and_a_common_stretch_contact_sheet() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("seq");
    let mut args = vec![
        "sequence",
        CONSTANT,
        "--from",
        "09:00",
        "--to",
        "2001-08-08T13:00",
        "--step",
        "2h",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "sensor.band=mwir",
        "--threads",
        "2",
        // the plain 2-98 % stretch, so that the sheet's pixels can be
        // compared with the frames' values below (the widened stretch:
        // `sheets_get_a_colour_bar_and_the_minimum_span`)
        "--quicklook-min-span-k",
        "0",
    ];
    args.extend(SMALL);
    let (rc, stdout, err) = irsig(&args);
    assert_eq!(rc, 0, "{stdout}\n{err}");
    let ix = index(&out);
    assert_eq!(ix["command"], "sequence");
    let frames = ix["frames"].as_array().unwrap();
    let stems = ["frame_0900", "frame_1100", "frame_1300"];
    assert_eq!(frames.len(), 3);
    for (f, stem) in frames.iter().zip(stems) {
        for ext in ["exr", "png", "json"] {
            assert!(out.join(format!("{stem}.{ext}")).is_file(), "{stem}.{ext}");
        }
        assert_eq!(f["exr"], format!("{stem}.exr"));
        let r = &f["band_radiance_w_m2_sr_um"];
        let (lo, mean, hi) = (
            r["min"].as_f64().unwrap(),
            r["mean"].as_f64().unwrap(),
            r["max"].as_f64().unwrap(),
        );
        assert!(lo <= mean && mean <= hi && lo > 0.0, "{r}");
        // The static part is prepared once: every later frame shares it.
        assert_eq!(f["reused"]["geometry"], f["index"] != 0);
    }
    // Local 09:00 EDT = 13:00 UTC (RFC 3339 with Z, as in every JSON).
    assert_eq!(frames[0]["image_time_utc"], "2001-08-08T13:00:00Z");
    // The sun climbs from 09:00 to 13:00 (EDT; solar noon ~13:15).
    let zen: Vec<f64> = frames
        .iter()
        .map(|f| f["sun_zenith_deg"].as_f64().unwrap())
        .collect();
    assert!(zen[0] > zen[1] && zen[1] > zen[2], "{zen:?}");

    // The contact sheet: 2x2 cells of 64 px with 4 px gaps, one stretch =
    // the 2-98 percentile of all frames' sensor_radiance together.
    let sheet = &ix["contact_sheet"];
    let (cols, gap) = (
        sheet["columns"].as_u64().unwrap() as u32,
        sheet["gap_px"].as_u64().unwrap() as u32,
    );
    assert_eq!((cols, sheet["rows"].as_u64().unwrap()), (2, 2));
    let data: Vec<Vec<f32>> = stems
        .iter()
        .map(|s| plane(&out.join(format!("{s}.exr")), "sensor_radiance"))
        .collect();
    let all: Vec<f32> = data.iter().flatten().copied().collect();
    let s = percentile_stretch(&all);
    let stated = Stretch {
        lo: sheet["stretch_lo"].as_f64().unwrap() as f32,
        hi: sheet["stretch_hi"].as_f64().unwrap() as f32,
    };
    assert_eq!(s, stated);
    // A common stretch differs from each frame's own (brightness comparable).
    assert!(
        data.iter().any(|d| percentile_stretch(d) != s),
        "frames have identical stretches: the test cannot tell"
    );
    // An RGB quicklook as a single render's: the sheet at the top left, a
    // colour bar with the stretch's ends below it.
    let (w, h, rgb, text) = read_png(&out.join("contact_sheet.png"));
    assert!(w >= 2 * 64 + gap && h > 2 * 64 + gap + 10, "{w}x{h}");
    assert_eq!(rgb.len() as u32, 3 * w * h);
    assert!(
        text.contains(&format!("{} .. {}", s.lo, s.hi)),
        "stretch not stated in the PNG text: {text}"
    );
    for (k, d) in data.iter().enumerate() {
        let (x0, y0) = (
            (k as u32 % cols) * (64 + gap),
            (k as u32 / cols) * (64 + gap),
        );
        let want = to_grey(d, s);
        for y in 0..64 {
            for x in 0..64 {
                let i = 3 * ((y0 + y) * w + x0 + x) as usize;
                let want = want[(y * 64 + x) as usize] as i32;
                for c in 0..3 {
                    assert!(
                        (rgb[i + c] as i32 - want).abs() <= 1,
                        "frame {k} pixel ({x},{y}): {} vs {want}",
                        rgb[i + c]
                    );
                }
            }
        }
    }
    // the colour bar, black (the stretch's low end) to white
    let bar_y = 2 * 64 + gap + 4 + 5;
    let at = |x: u32| rgb[3 * (bar_y * w + x) as usize];
    assert!(at(2) < 5 && at(w - 3) > 250, "{} {}", at(2), at(w - 3));
    // Frame JSON says which frame it is.
    let fj: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("frame_1100.json")).unwrap())
            .unwrap();
    assert_eq!(fj["frame"]["local_time"], "2001-08-08T11:00:00");
}

/// The paper's Fig. 13: at 0/10/20/30 mph the thermal contrast falls with
/// wind speed, and falls faster first (convection h ~ 5.7 + 3.8 v: the
/// surface-air coupling grows linearly, the temperature excess as 1/h).
#[test]
fn wind_sweep_contrast_falls_steeply_first() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("wind");
    let mut args = vec![
        "sweep",
        CONSTANT,
        "--key",
        "weather.constant.wind_m_s",
        "--values",
        "0,4.47,8.94,13.41",
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend(SMALL);
    let (rc, stdout, err) = irsig(&args);
    assert_eq!(rc, 0, "{stdout}\n{err}");
    let ix = index(&out);
    assert_eq!(ix["key"], "weather.constant.wind_m_s");
    let v: Vec<f64> = ix["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["value_number"].as_f64().unwrap())
        .collect();
    assert_eq!(v, [0.0, 4.47, 8.94, 13.41]);
    let s = std_app_temp(&ix);
    assert!(s[0] > 1.0, "no contrast at 0 mph: {s:?}");
    for k in 1..4 {
        assert!(s[k] < s[k - 1], "contrast does not fall with wind: {s:?}");
    }
    assert!(
        s[0] - s[1] > 2.0 * (s[2] - s[3]),
        "contrast drop 0->10 mph not much larger than 20->30 mph: {s:?}"
    );
    // The band-radiance contrast follows.
    let r: Vec<f64> = ix["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["band_radiance_w_m2_sr_um"]["std"].as_f64().unwrap())
        .collect();
    assert!(r[0] > r[1] && r[1] > r[2] && r[2] > r[3], "{r:?}");
    // A weather key shares the whole static part.
    for f in &ix["frames"].as_array().unwrap()[1..] {
        assert_eq!(f["reused"]["geometry"], true);
        assert_eq!(f["reused"]["atmosphere"], true);
    }
    let names = ["00_wind_m_s_0", "03_wind_m_s_13.41"];
    for n in names {
        assert!(out.join(format!("{n}.exr")).is_file(), "{n}");
    }
}

/// Fig. 14: the same target at 10 km slant range seen from ever lower
/// elevations loses contrast (longer path: lower transmission, more path
/// radiance). Also exercises --unset to switch pose tables; the BVH is shared.
#[test]
fn view_zenith_sweep_loses_contrast_and_shares_geometry() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("vz");
    let args = [
        "sweep",
        CONSTANT,
        "--unset",
        "sensor.pose.altitude",
        "--set",
        "sensor.pose.slant_range.slant_range_m=10000",
        "--set",
        "sensor.pose.slant_range.azimuth_deg=180",
        "--key",
        "sensor.pose.slant_range.view_zenith_deg",
        "--values",
        "0,45,75",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "sensor.width_px=48",
        "--set",
        "sensor.height_px=48",
        "--set",
        "render.history_hours=6",
    ];
    let (rc, stdout, err) = irsig(&args);
    assert_eq!(rc, 0, "{stdout}\n{err}");
    let ix = index(&out);
    let s = std_app_temp(&ix);
    // Nadir keeps the most contrast. (The frames' content differs too: at
    // 75° the specular hangar roof turns dark against the warm ground, a
    // contrast of its own, so 45° vs 75° is not ordered by the path alone.)
    assert!(s[0] > s[1] && s[0] > s[2], "{s:?}");
    for f in &ix["frames"].as_array().unwrap()[1..] {
        assert_eq!(f["reused"]["geometry"], true, "{f}");
    }
}

#[test]
fn bad_flags_give_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bad");
    let o = out.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &[
                "sequence", CONSTANT, "--from", "25:00", "--to", "15:00", "--step", "1h", "-o", o,
            ],
            "--from \"25:00\": expected a local clock time",
        ),
        (
            &[
                "sequence", CONSTANT, "--from", "08:00", "--to", "07:00", "--step", "1h", "-o", o,
            ],
            "is before --from",
        ),
        (
            &[
                "sequence", CONSTANT, "--from", "08:00", "--to", "09:00", "--step", "soon", "-o", o,
            ],
            "--step \"soon\"",
        ),
        (
            &[
                "sweep",
                CONSTANT,
                "--key",
                "weather.constant.wind_ms",
                "--values",
                "1,2",
                "-o",
                o,
            ],
            "unknown field `wind_ms`",
        ),
        (
            &[
                "sweep",
                CONSTANT,
                "--key",
                "weather.constant.wind_m_s",
                "--values",
                "",
                "-o",
                o,
            ],
            "--values is empty",
        ),
        (
            &[
                "sweep",
                CONSTANT,
                "--key",
                "sensor.pose.slant_range.view_zenith_deg",
                "--values",
                "0,30",
                "-o",
                o,
            ],
            "--unset sensor.pose.altitude",
        ),
        (
            &[
                "sweep",
                CONSTANT,
                "--unset",
                "sensor.nothing",
                "--key",
                "sensor.width_px",
                "--values",
                "8",
                "-o",
                o,
            ],
            "unset `sensor.nothing`",
        ),
    ];
    for (args, want) in cases {
        let (rc, _, err) = irsig(args);
        assert_ne!(rc, 0, "{args:?} succeeded");
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
        assert!(err.contains(want), "{args:?}: expected {want:?} in: {err}");
    }
    // Nothing was rendered or written.
    assert!(!out.join("index.json").exists());
}

/// `derive_static` shares the geometry/BVH and atmosphere exactly when the
/// new scene leaves them unchanged.
#[test]
fn derive_static_shares_what_is_unchanged() {
    use irsig::render::{derive_static, prepare_static};
    use irsig::scene::{load_with_overrides, remove_keys};
    let path = Path::new(CONSTANT);
    let ov = |kv: &[(&str, &str)]| -> Vec<(String, String)> {
        kv.iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect()
    };
    let base = prepare_static(load_with_overrides(path, &[]).unwrap(), None).unwrap();
    // A new pose: geometry, BVH and atmosphere shared.
    let posed =
        load_with_overrides(path, &ov(&[("sensor.pose.altitude.view_zenith_deg", "30")])).unwrap();
    let (st, r) = derive_static(Some(&base), posed, None).unwrap();
    assert!(r.geometry && r.atmosphere, "{r:?}");
    assert!(std::sync::Arc::ptr_eq(&st.geometry, &base.geometry));
    // Another band: geometry shared, atmosphere rebuilt over the new bins.
    let mwir = load_with_overrides(path, &ov(&[("sensor.band", "mwir")])).unwrap();
    let (st2, r) = derive_static(Some(&st), mwir, None).unwrap();
    assert!(r.geometry && !r.atmosphere, "{r:?}");
    assert_ne!(st2.band.wavenumber_cm1, base.band.wavenumber_cm1);
    // Another tracer backend: the BVH is rebuilt.
    let bvh = load_with_overrides(path, &ov(&[("render.tracer", "bvh")])).unwrap();
    let (_, r) = derive_static(Some(&st2), bvh, None).unwrap();
    assert!(!r.geometry, "{r:?}");
    // remove_keys drops a whole table; a missing key is an error.
    let text = std::fs::read_to_string(path).unwrap();
    let t = remove_keys(path, &text, &["sensor.pose.altitude".into()]).unwrap();
    assert!(!t.contains("[sensor.pose.altitude]") && t.contains("[sensor.noise]"));
    assert!(remove_keys(path, &text, &["sensor.pose.nope".into()]).is_err());
}

/// Issue 32 acceptance, "a sweep over an object's position renders": the
/// plate scene's plate (`object[1]`: its entries have no `name`; its
/// `translate_m`, not in the file, set first) swept from x = -6 to +6 m.
/// Seen from the south (north up, east right) at about 2 m per pixel, its
/// pixels in the `material` plane move right by 12 m / GSD (6 px, ±1.5).
#[test]
fn sweep_over_an_objects_position_moves_it_in_the_image() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pos");
    let scene = "scenes/plate/scene.toml";
    let args = [
        "sweep",
        scene,
        "--key",
        "object[1].translate_m[0]",
        "--values=-6,6",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "object[1].translate_m=[0, 0, 0]",
        "--set",
        "sensor.width_px=16",
        "--set",
        "sensor.height_px=16",
        "--set",
        "render.history_hours=6",
    ];
    let (rc, stdout, err) = irsig(&args);
    assert_eq!(rc, 0, "{stdout}\n{err}");
    let ix = index(&out);
    let frames = ix["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 2);
    let steel = common::material_index(Path::new(scene), "painted_steel_roof");
    let centre: Vec<f64> = frames
        .iter()
        .map(|f| {
            let m = plane(&out.join(f["exr"].as_str().unwrap()), "material");
            assert_eq!(m.len(), 256);
            let cols: Vec<f64> = (0..256)
                .filter(|&i| m[i] == steel)
                .map(|i| (i % 16) as f64)
                .collect();
            assert!(cols.len() >= 2, "{f}: plate covers {} px", cols.len());
            cols.iter().sum::<f64>() / cols.len() as f64
        })
        .collect();
    let shift = centre[1] - centre[0];
    assert!((4.5..=7.5).contains(&shift), "plate columns {centre:?}");
}

/// Issue 32: a contact sheet is drawn as a single render's quicklook (a
/// colour bar with the stretch's ends and unit, the colour map chosen),
/// under the common stretch widened to `--quicklook-min-span-k` kelvin of
/// apparent temperature; the flag has the bound of `irsig render`'s.
#[test]
fn sheets_get_a_colour_bar_and_the_minimum_span() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("wide");
    let mut args = vec![
        "sweep",
        CONSTANT,
        "--key",
        "weather.constant.wind_m_s",
        "--values",
        "2,3",
        "-o",
        out.to_str().unwrap(),
        "--colormap",
        "inferno",
        "--quicklook-min-span-k",
        "50",
    ];
    args.extend(SMALL);
    let (rc, stdout, err) = irsig(&args);
    assert_eq!(rc, 0, "{stdout}\n{err}");
    let ix = index(&out);
    let sheet = &ix["contact_sheet"];
    let stated = Stretch {
        lo: sheet["stretch_lo"].as_f64().unwrap() as f32,
        hi: sheet["stretch_hi"].as_f64().unwrap() as f32,
    };
    // 50 K about the frames' median apparent temperature, in band
    // radiance (Planck over the scene's LWIR band, 8-14 um): wider than
    // the frames' own 2-98 % spread, centred on it
    let exrs: Vec<_> = ix["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| out.join(f["exr"].as_str().unwrap()))
        .collect();
    let all: Vec<f32> = exrs
        .iter()
        .flat_map(|e| plane(e, "sensor_radiance"))
        .collect();
    let s = percentile_stretch(&all);
    let temps: Vec<f32> = exrs
        .iter()
        .flat_map(|e| plane(e, "apparent_temperature"))
        .collect();
    let mut t = temps.clone();
    t.sort_by(f32::total_cmp);
    let med = t[t.len() / 2] as f64;
    let band = |k: f64| irsig::radiometry::planck::planck_band_integral_w_m2_sr(8.0, 14.0, k) / 6.0;
    let want = band(med + 25.0) - band(med - 25.0);
    let span = (stated.hi - stated.lo) as f64;
    assert!(span > (s.hi - s.lo) as f64, "{stated:?} vs {s:?}");
    assert!(
        (span / want - 1.0).abs() < 0.02,
        "span {span} vs 50 K = {want}"
    );
    let centre = 0.5 * (stated.lo + stated.hi) - 0.5 * (s.lo + s.hi);
    assert!(centre.abs() < 1e-3 * span as f32, "{stated:?} vs {s:?}");
    assert!(
        sheet["stretch"].as_str().unwrap().contains("inferno"),
        "{sheet}"
    );
    // inferno: the bar's ends are near black and pale yellow, not grey
    let (w, h, rgb, text) = read_png(&out.join("contact_sheet.png"));
    assert!(
        text.contains("Inferno") && text.contains("sensor_radiance"),
        "{text}"
    );
    let gap = sheet["gap_px"].as_u64().unwrap() as u32;
    let cols = sheet["columns"].as_u64().unwrap() as u32;
    let rows = sheet["rows"].as_u64().unwrap() as u32;
    let bar_y = rows * 64 + (rows - 1) * gap + 4 + 5;
    assert!(bar_y < h && cols * 64 <= w);
    let px = |x: u32| &rgb[3 * (bar_y * w + x) as usize..3 * (bar_y * w + x) as usize + 3];
    let hi = px(w - 3);
    assert!(hi[0] > 200 && hi[1] > 200 && hi[2] < 200, "{hi:?}");
    // the frames' own quicklooks use the same options
    let fpng = out.join(ix["frames"][0]["png"].as_str().unwrap());
    let (_, _, _, ftext) = read_png(&fpng);
    assert!(ftext.contains("Inferno"), "{ftext}");

    // the flag's bound, shared with irsig render
    let (rc, _, err) = irsig(&[
        "sweep",
        CONSTANT,
        "--key",
        "weather.constant.wind_m_s",
        "--values",
        "2",
        "-o",
        dir.path().join("x").to_str().unwrap(),
        "--quicklook-min-span-k",
        "1e9",
    ]);
    assert_eq!(rc, 1, "{err}");
    assert!(
        err.contains("--quicklook-min-span-k 1e9: out of range") && err.contains("1000"),
        "{err}"
    );
}

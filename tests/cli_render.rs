//! `irsig render` end to end: EXR, PNG, JSON and ENVI in MWIR and LWIR,
//! nothing partial left behind, clear errors for bad flags.

mod common;
use common::succeed;

use std::path::Path;
use std::process::Command;

fn irsig() -> Command {
    Command::new(env!("CARGO_BIN_EXE_irsig"))
}

fn scene() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/airfield/scene.toml")
}

/// Renders the airfield scene into `exr` at `w`×`h` pixels with the flags
/// `extra`; panics with its stderr unless it succeeds.
fn render_airfield(exr: &Path, (w, h): (u32, u32), extra: &[&str]) {
    let size = [
        format!("sensor.width_px={w}"),
        format!("sensor.height_px={h}"),
    ];
    succeed(
        irsig()
            .arg("render")
            .arg(scene())
            .arg("-o")
            .arg(exr)
            .args(["--set", &size[0], "--set", &size[1]])
            .args(extra),
    );
}

#[test]
fn render_writes_exr_png_json_and_envi_in_both_bands() {
    let dir = tempfile::tempdir().unwrap();
    for band in ["mwir", "lwir"] {
        let exr = dir.path().join(format!("a-{band}.exr"));
        let set_band = format!("sensor.band={band}");
        render_airfield(&exr, (48, 48), &["--envi", "--stats", "--set", &set_band]);
        let (w, h, chans) = irsig::output::exr::read_exr(&exr).unwrap();
        assert_eq!((w, h), (48, 48));
        let names: Vec<&str> = chans.iter().map(|(n, _)| n.as_str()).collect();
        for want in [
            "band_radiance",
            "apparent_temperature",
            "surface_temperature",
            "material",
            "facet",
            "sun_now",
            "hours_sunlit",
            "range",
            "view_angle",
            "emitted",
            "reflected_solar",
            "path_thermal",
            "sensor_radiance",
            "dn",
        ] {
            assert!(names.contains(&want), "{want} missing from {names:?}");
        }
        // The ENVI radiance cube holds the planes at the sensor's band.
        let img = std::fs::metadata(exr.with_extension("img")).unwrap().len();
        let hdr = std::fs::read_to_string(exr.with_extension("hdr")).unwrap();
        let nb = [
            "band_radiance",
            "sensor_radiance",
            "emitted",
            "path_thermal",
        ]
        .iter()
        .filter(|n| hdr.contains(&format!("{n} [")))
        .count();
        assert_eq!(nb, 4, "{hdr}");
        let bands: u64 = hdr
            .lines()
            .find_map(|l| l.strip_prefix("bands = "))
            .unwrap()
            .parse()
            .unwrap();
        assert_eq!(img, bands * 48 * 48 * 4);
        assert!(
            !hdr.contains("surface_temperature"),
            "truth is in x_truth.img: {hdr}"
        );
        // Radiances only: every band name carries the radiance unit.
        let names = hdr
            .lines()
            .find_map(|l| l.strip_prefix("band names = {"))
            .unwrap();
        assert_eq!(
            names.matches("[W m-2 sr-1 um-1]").count() as u64,
            bands,
            "{hdr}"
        );
        // Temperatures go to the truth cube (with units); DN to its own.
        let truth =
            std::fs::read_to_string(dir.path().join(format!("a-{band}_truth.hdr"))).unwrap();
        assert!(truth.contains("apparent_temperature [K]"), "{truth}");
        assert!(truth.contains("band units = {index"), "{truth}");
        let dn_hdr = std::fs::read_to_string(dir.path().join(format!("a-{band}_dn.hdr"))).unwrap();
        assert!(dn_hdr.contains("band names = {dn [counts]}"), "{dn_hdr}");
        assert!(dn_hdr.contains("data units = counts"), "{dn_hdr}");
        let dn_img = std::fs::read(dir.path().join(format!("a-{band}_dn.img"))).unwrap();
        let dn = &chans.iter().find(|c| c.0 == "dn").unwrap().1;
        if dn_hdr.contains("data type = 12") {
            let got: Vec<f32> = dn_img
                .chunks(2)
                .map(|b| u16::from_le_bytes([b[0], b[1]]) as f32)
                .collect();
            assert_eq!(&got, dn);
        } else {
            assert_eq!(dn_img.len(), 48 * 48 * 4);
        }
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(exr.with_extension("json")).unwrap())
                .unwrap();
        assert!(json["stats"]["primary_rays"].as_u64().unwrap() >= 48 * 48);
        assert!(json["quicklook"].as_str().unwrap().contains("percentile"));
        assert!(std::fs::metadata(exr.with_extension("png")).unwrap().len() > 100);
        // Apparent temperatures are physical (a summer noon scene).
        let (_, t) = chans
            .iter()
            .find(|(n, _)| n == "apparent_temperature")
            .unwrap();
        assert!(t.iter().all(|v| v.is_finite() && *v > 250.0 && *v < 360.0));
    }
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".irsig-partial"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn render_bad_flags_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        let out = irsig().args(args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(!err.contains("panicked"), "{err}");
        (out.status.success(), err)
    };
    let png = dir.path().join("x.png");
    let (ok, err) = run(&[
        "render",
        scene().to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--set",
        "sensor.width_px=8",
        "--set",
        "sensor.height_px=8",
    ]);
    assert!(
        !ok && err.contains("must be an .exr or a .tif path"),
        "{err}"
    );
    assert!(!png.exists());
    let exr = dir.path().join("x.exr");
    let (ok, err) = run(&[
        "render",
        scene().to_str().unwrap(),
        "-o",
        exr.to_str().unwrap(),
        "--set",
        "nonsense",
    ]);
    assert!(!ok && err.contains("expected KEY=VALUE"), "{err}");
    let (ok, err) = run(&["render", "/no/such/scene.toml", "-o", exr.to_str().unwrap()]);
    assert!(!ok && err.contains("/no/such/scene.toml"), "{err}");
    let (ok, err) = run(&[
        "render",
        scene().to_str().unwrap(),
        "-o",
        exr.to_str().unwrap(),
        "--set",
        "sensor.widht_px=8",
    ]);
    assert!(
        !ok && err.contains("widht_px") && err.contains("width_px"),
        "{err}"
    );
    assert!(!exr.exists());
}

/// `--tracer bvh` renders the same image as Embree, up to the rare pixels
/// where the backends resolve an edge tie differently (see the cross-check).
#[test]
fn bvh_backend_renders_the_same_image() {
    let dir = tempfile::tempdir().unwrap();
    let mut planes = Vec::new();
    for tracer in ["embree", "bvh"] {
        let exr = dir.path().join(format!("{tracer}.exr"));
        render_airfield(&exr, (64, 64), &["--tracer", tracer]);
        let (_, _, chans) = irsig::output::exr::read_exr(&exr).unwrap();
        planes.push(
            chans
                .into_iter()
                .find(|(n, _)| n == "band_radiance")
                .unwrap()
                .1,
        );
    }
    let differ = planes[0]
        .iter()
        .zip(&planes[1])
        .filter(|(a, b)| ((*a - *b) / *a).abs() > 1e-6)
        .count();
    assert!(differ <= 64 * 64 / 200, "{differ} of 4096 pixels differ");
}

/// `--planes` keeps only the named planes in the EXR and the GeoTIFF (and
/// the JSON's plane list); every plane a render makes is one `--planes`
/// may name; an unknown name is refused before the render, listing them.
#[test]
fn planes_flag_selects_the_written_planes() {
    use irsig::render::planes::PLANE_NAMES;
    let dir = tempfile::tempdir().unwrap();
    // Renders the airfield at 24x16 px to `out` with `extra` flags.
    let render = |out: &Path, extra: &[&str]| {
        irsig()
            .arg("render")
            .arg(scene())
            .arg("-o")
            .arg(out)
            .args(extra)
            .args([
                "--set",
                "sensor.width_px=24",
                "--set",
                "sensor.height_px=16",
            ])
            .output()
            .unwrap()
    };
    let ok = |o: &std::process::Output| {
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr))
    };
    let full = dir.path().join("full.exr");
    ok(&render(&full, &[]));
    let (_, _, chans) = irsig::output::exr::read_exr(&full).unwrap();
    let names: Vec<&str> = chans.iter().map(|(n, _)| n.as_str()).collect();
    // The airfield quantises, so its render makes every plane.
    let mut want = PLANE_NAMES.to_vec();
    want.sort();
    let mut got = names.clone();
    got.sort();
    assert_eq!(got, want);

    let sel = dir.path().join("sel.tif");
    ok(&render(
        &sel,
        &["--exr", "--planes", "apparent_temperature,material"],
    ));
    let (_, _, chans) = irsig::output::exr::read_exr(&sel.with_extension("exr")).unwrap();
    let mut got: Vec<&str> = chans.iter().map(|(n, _)| n.as_str()).collect();
    got.sort();
    assert_eq!(got, ["apparent_temperature", "material"]);
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(sel.with_extension("json")).unwrap())
            .unwrap();
    assert_eq!(j["planes"].as_array().unwrap().len(), 2);
    // The selected planes equal the full render's, bit for bit.
    let (_, _, all) = irsig::output::exr::read_exr(&full).unwrap();
    for (n, d) in &chans {
        let f = &all.iter().find(|(m, _)| m == n).unwrap().1;
        assert!(
            f.iter().zip(d).all(|(a, b)| a.to_bits() == b.to_bits()),
            "{n}"
        );
    }
    let tif = std::process::Command::new("gdalinfo")
        .arg(&sel)
        .output()
        .expect("gdalinfo (gdal-bin, installed by scripts/setup.sh)");
    let info = String::from_utf8_lossy(&tif.stdout);
    assert!(
        info.contains("Band 2") && !info.contains("Band 3"),
        "{info}"
    );

    let bad = dir.path().join("bad.exr");
    let out = render(&bad, &["--planes", "apparent_temprature"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--planes apparent_temprature: no such plane")
            && err.contains("band_radiance"),
        "{err}"
    );
    assert!(!bad.exists() && !bad.with_extension("json").exists());
}

#[test]
fn envi_band_centre_and_fwhm_are_the_responses() {
    // An asymmetric triangle 8-9-12 um: centroid (8 + 9 + 12)/3 um (a
    // triangle's centre of mass), half-maximum crossings at 8.5 and 10.5 um.
    let tri =
        irsig::radiometry::SpectralResponse::from_csv_str("8,0\n9,1\n12,0\n", "t.csv").unwrap();
    assert!((tri.centroid_um() - 29.0 / 3.0).abs() < 1e-12);
    assert!((tri.fwhm_um() - 2.0).abs() < 1e-12);
    let lwir = irsig::radiometry::SpectralResponse::lwir();
    assert!((lwir.centroid_um() - 11.0).abs() < 1e-9 && (lwir.fwhm_um() - 6.0).abs() < 1e-8);
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("tri.csv");
    std::fs::write(&csv, "wavelength_um,response\n8,0\n9,1\n12,0\n").unwrap();
    let exr = dir.path().join("t.exr");
    let set_band = format!("sensor.band={{ response_file = \"{}\" }}", csv.display());
    render_airfield(
        &exr,
        (16, 12),
        &[
            "--envi",
            "-q",
            "--set",
            "files.allow=[\"/\"]",
            "--set",
            &set_band,
        ],
    );
    let hdr = std::fs::read_to_string(exr.with_extension("hdr")).unwrap();
    let field = |k: &str| -> Vec<f64> {
        let line = hdr
            .lines()
            .find(|l| l.starts_with(&format!("{k} =")))
            .unwrap_or_else(|| panic!("no {k} in {hdr}"));
        line.split_once('{')
            .unwrap()
            .1
            .trim_end_matches('}')
            .split(',')
            .map(|v| v.trim().parse().unwrap())
            .collect()
    };
    let (wl, fwhm) = (field("wavelength"), field("fwhm"));
    assert!(wl.len() > 3 && wl.len() == fwhm.len());
    assert!(wl.iter().all(|&c| (c - 29.0 / 3.0).abs() < 1e-6), "{wl:?}");
    assert!(fwhm.iter().all(|&w| (w - 2.0).abs() < 1e-6), "{fwhm:?}");
}

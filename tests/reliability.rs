//! Regression tests of issue 17: each input that the fuzzing campaign found
//! to panic, abort, yield non-finite planes or be accepted though absurd
//! (docs/reliability.md) now gets a clear error naming the file, the line,
//! the key, the value and its range (crate::bounds). Library-level checks
//! plus, where the bug showed through the CLI, the exit status and message
//! of `irsig` itself (exit 1 = error, never 101 = panic or 134 = abort).

mod common;

use std::path::{Path, PathBuf};

use irsig::weather::{ReadOptions, parse_epw, parse_tmy3};

fn plate_dir(tmp: &Path) -> PathBuf {
    // The plate scene with its materials, copied so that data files can be
    // written beside it; 8x8 pixels keep the renders fast.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let dir = tmp.join("plate");
    std::fs::create_dir_all(dir.join("obj")).unwrap();
    for f in ["ground.obj", "plate.obj"] {
        std::fs::copy(root.join("plate/obj").join(f), dir.join("obj").join(f)).unwrap();
    }
    std::fs::copy(root.join("materials.toml"), tmp.join("materials.toml")).unwrap();
    let text = std::fs::read_to_string(root.join("plate/scene.toml"))
        .unwrap()
        .replace("width_px = 256", "width_px = 8")
        .replace("height_px = 256", "height_px = 8");
    std::fs::write(dir.join("scene.toml"), text).unwrap();
    dir
}

/// Runs irsig; returns (exit code, stderr).
fn irsig(args: &[&str]) -> (i32, String) {
    let out = common::irsig()
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Renders the plate copy `dir` with `--set` overrides that must be
/// refused: asserts exit status 1, no panic and no output; returns stderr.
fn refused_render(tmp: &Path, dir: &Path, sets: &[&str]) -> String {
    let scene = dir.join("scene.toml").display().to_string();
    let out = tmp.join("refused.exr");
    let o = out.display().to_string();
    let mut args = vec!["render", &scene, "-o", &o];
    for s in sets {
        args.extend(["--set", s]);
    }
    let (code, err) = irsig(&args);
    assert_eq!(code, 1, "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists());
    err
}

/// An IRSIG-ATMOS header whose size fields overflow usize when multiplied
/// out (the fuzzed headers that panicked in the table-size computation).
fn overflowing_table() -> Vec<u8> {
    let axis = |n: usize| (0..n).map(|i| i.to_string()).collect::<Vec<_>>().join(",");
    let big = axis(100_000);
    let mut h = String::from("IRSIG-ATMOS 1\nname x\nwavenumber_cm1 500 0.01 1000000\n");
    h += &format!("quantity tau_path altitude_km={big} view_zenith_deg={big}\n");
    h += &format!("quantity l_ue altitude_km={big} view_zenith_deg={big}\n");
    h += &format!(
        "quantity l_us sun_zenith_deg={big} rel_azimuth_deg={big} altitude_km={big} view_zenith_deg={big}\n"
    );
    h += "quantity l_de sky_zenith_deg=0\n";
    h += "quantity l_ds sun_zenith_deg=0 rel_azimuth_deg=0 sky_zenith_deg=0\n";
    h += "quantity tau_sun sun_zenith_deg=0\nquantity e_sun_exo\ndata f32le\n";
    h.into_bytes()
}

#[test]
fn atmosphere_header_size_overflow_is_an_error_not_a_panic() {
    let e = irsig::atmos::AtmosTable::from_bytes(&overflowing_table(), "big.atm")
        .unwrap_err()
        .to_string();
    assert!(e.contains("big.atm: header line 4"), "{e}");
    assert!(e.contains("tau_path") && e.contains("GiB"), "{e}");
    // the same table through the CLI and as a scene's table file
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("big.atm");
    std::fs::write(&path, overflowing_table()).unwrap();
    let p = path.display().to_string();
    let (code, err) = irsig(&["atmos", "show", &p, "--altitude", "1", "--zenith", "0"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("big.atm: header line 4") && !err.contains("panicked"),
        "{err}"
    );
    let dir = plate_dir(tmp.path());
    let set = format!("atmosphere.model={{ table_file = \"{p}\" }}");
    let err = refused_render(tmp.path(), &dir, &["files.allow=[\"/\"]", &set]);
    assert!(err.contains("big.atm: header line 4"), "{err}");
}

#[test]
fn tiny_response_wavelength_is_refused_before_any_allocation() {
    // `1e-10,1` made the band grid 5e12 bins: the allocation aborted (134).
    let e = irsig::radiometry::SpectralResponse::from_csv_str("1e-10,1\n1e-9,1\n", "r.csv")
        .unwrap_err()
        .to_string();
    assert!(e.contains("r.csv: line 1:"), "{e}");
    assert!(
        e.contains("`wavelength_um` = 1e-10 is out of range: expected 0.2 <= wavelength_um <= 100"),
        "{e}"
    );
    let tmp = tempfile::tempdir().unwrap();
    let dir = plate_dir(tmp.path());
    std::fs::write(dir.join("tiny.csv"), "# tiny\n1e-10,1\n1e-9,1\n").unwrap();
    let err = refused_render(
        tmp.path(),
        &dir,
        &["sensor.band={ response_file = \"tiny.csv\" }"],
    );
    assert!(
        err.contains("tiny.csv:2") && err.contains("wavelength_um"),
        "{err}"
    );
    // the band's bin count is bounded too: the widest legal band at the
    // finest legal step is refused with the memory it would need
    std::fs::write(dir.join("wide.csv"), "0.2,1\n100,1\n").unwrap();
    let err = refused_render(
        tmp.path(),
        &dir,
        &[
            "sensor.band={ response_file = \"wide.csv\" }",
            "render.spectral_step_cm1=0.1",
        ],
    );
    assert!(
        err.contains("spectral bins") && err.contains("MiB"),
        "{err}"
    );
}

#[test]
fn huge_responses_cannot_overflow_the_band_normalisation() {
    // Responses of 1e300 summed to ∞ in the band weights: NaN band radiance.
    let e = irsig::radiometry::SpectralResponse::from_csv_str("8,0\n9,1e300\n14,0\n", "r.csv")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("r.csv: line 2:") && e.contains("`response` = 1e300"),
        "{e}"
    );
    // the largest legal response renders finite planes (the render checks
    // every plane itself; the EXR is read back to be sure)
    let tmp = tempfile::tempdir().unwrap();
    let dir = plate_dir(tmp.path());
    std::fs::write(dir.join("big.csv"), "8,0\n8.5,1e6\n13.5,1e6\n14,0\n").unwrap();
    let img = common::render(
        tmp.path(),
        &dir.join("scene.toml"),
        "big",
        &["sensor.band={ response_file = \"big.csv\" }"],
    );
    for p in ["band_radiance", "apparent_temperature", "sensor_radiance"] {
        assert!(img.plane(p).iter().all(|v| v.is_finite()), "{p}");
    }
    // and the kernel weights are bounded the same way
    std::fs::write(dir.join("k.csv"), "0,0,0\n0,1e300,0\n0,0,0\n").unwrap();
    let err = refused_render(
        tmp.path(),
        &dir,
        &["sensor.psf={ kernel_file = \"k.csv\" }"],
    );
    assert!(
        err.contains("k.csv:2") && err.contains("`weight` = 1e300"),
        "{err}"
    );
}

/// A layered slab's bad entries (issue 30): each refused naming the file,
/// the line of the entry (or of the material) and the key.
#[test]
fn bad_layers_are_refused_at_their_line_and_key() {
    let lib = |layer2: &str, extra: &str| {
        format!(
            "[material.s]\n\
             layers = [\n  \
             {{ thickness_m = 0.015, conductivity_w_mk = 0.24, density_kg_m3 = 1600.0, \
             specific_heat_j_kgk = 800.0 }},\n  \
             {layer2},\n]\n\
             solar_absorptivity = 0.7\n\
             thermal_emissivity = 0.94\n{extra}"
        )
    };
    let good = "{ thickness_m = 0.485, conductivity_w_mk = 1.03, density_kg_m3 = 1645.0, \
                specific_heat_j_kgk = 892.0 }";
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("m.toml");
    let load = |text: &str| {
        std::fs::write(&path, text).unwrap();
        irsig::scene::material::load_library(&path)
    };
    let m = load(&lib(good, "")).unwrap();
    let c = m[0].construction;
    assert_eq!(c.layer_list().len(), 2);
    assert!((c.thickness_m - 0.5).abs() < 1e-12 && c.conductivity_w_mk == 0.24);
    for (layer2, extra, line, want) in [
        (
            "{ thickness_m = 0.485, conductivity_w_mk = 1.03, density_kg_m3 = 1645.0 }",
            "",
            4,
            "missing field `specific_heat_j_kgk`",
        ),
        (
            "{ thickness_m = 0.485, conductivity_w_mk = -1.0, density_kg_m3 = 1645.0, \
             specific_heat_j_kgk = 892.0 }",
            "",
            4,
            "`conductivity_w_mk` = -1 is out of range",
        ),
        (
            "{ thickness_m = 0.0, conductivity_w_mk = 1.03, density_kg_m3 = 1645.0, \
             specific_heat_j_kgk = 892.0 }",
            "",
            4,
            "`thickness_m` = 0 is out of range",
        ),
        (
            "{ thicknes_m = 0.485, conductivity_w_mk = 1.03, density_kg_m3 = 1645.0, \
             specific_heat_j_kgk = 892.0 }",
            "",
            4,
            "unknown field `thicknes_m`",
        ),
        (
            good,
            "thickness_m = 0.5\n",
            8,
            "`thickness_m` and `layers` both given",
        ),
        (
            good,
            "kind = \"water\"\nextinction_per_m = 1.0\n",
            2,
            "`layers` are not for kind = \"water\"",
        ),
    ] {
        let e = load(&lib(layer2, extra)).unwrap_err().to_string();
        assert!(
            e.contains(&format!("m.toml:{line}:")) && e.contains(want),
            "want {want} at line {line}: {e}"
        );
    }
    let five = format!("[material.s]\nlayers = [{}]\n", [good; 5].join(", "));
    for (text, line, want) in [
        (
            "[material.s]\nlayers = []\n".to_string(),
            2,
            "`layers` is empty",
        ),
        (five, 2, "`layers` has 5 layers: at most 4"),
    ] {
        let e = load(&format!(
            "{text}solar_absorptivity = 0.7\nthermal_emissivity = 0.9\n"
        ))
        .unwrap_err()
        .to_string();
        assert!(
            e.contains(&format!("m.toml:{line}:")) && e.contains(want),
            "want {want} at line {line}: {e}"
        );
    }
    let e = load("[material.s]\nsolar_absorptivity = 0.7\nthermal_emissivity = 0.9\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("m.toml:1:")
            && e.contains("missing field `density_kg_m3` (or give the slab as `layers`)"),
        "{e}"
    );
}

#[test]
fn absurd_materials_are_refused_with_key_value_and_range() {
    // Mutated libraries that rendered thousands of kelvin (one key each).
    let base = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/materials.toml"),
    )
    .unwrap();
    let tmp = tempfile::tempdir().unwrap();
    for (from, to, key) in [
        (
            "conductivity_w_mk = 1.4",
            "conductivity_w_mk = 1e30",
            "conductivity_w_mk",
        ),
        ("thickness_m = 0.3", "thickness_m = 1e-12", "thickness_m"),
        (
            "density_kg_m3 = 2300.0",
            "density_kg_m3 = 1e-3",
            "density_kg_m3",
        ),
        (
            "specific_heat_j_kgk = 880.0",
            "specific_heat_j_kgk = 1e9",
            "specific_heat_j_kgk",
        ),
        (
            "internal_power_w_m2 = 300.0",
            "internal_power_w_m2 = 1e7",
            "internal_power_w_m2",
        ),
    ] {
        assert!(base.contains(from), "{from} not in the sample library");
        let text = base.replacen(from, to, 1);
        let line = text.lines().position(|l| l.starts_with(to)).unwrap() + 1;
        let path = tmp.path().join("m.toml");
        std::fs::write(&path, &text).unwrap();
        let e = irsig::scene::material::load_library(&path)
            .unwrap_err()
            .to_string();
        let b = irsig::scene::material::library_keys()
            .iter()
            .filter_map(|k| k.range)
            .find(|b| b.key == key)
            .unwrap();
        assert!(e.contains(&format!("m.toml:{line}:")), "{key}: {e}");
        assert!(
            e.contains(&format!("`{key}` = ")) && e.contains(&b.expected()),
            "{key}: {e}"
        );
    }
}

/// Minimal EPW text: the LOCATION line, 7 header lines, one record.
fn epw(tz: &str, year: &str, hour: &str) -> String {
    let mut s = format!("LOCATION,X,-,-,src,0,52.3,4.77,{tz},-2.0\n");
    for _ in 0..7 {
        s += "HEADER\n";
    }
    let mut f: Vec<String> = vec!["0".into(); 35];
    f[0] = year.into();
    f[1] = "12".into();
    f[2] = "31".into();
    f[3] = hour.into();
    f[4] = "60".into();
    f[6] = "10".into();
    f[7] = "5".into();
    f[8] = "70".into();
    f[9] = "101325".into();
    f[22] = "5".into();
    s += &f.join(",");
    s + "\n"
}

#[test]
fn weather_dates_outside_1900_2200_are_refused() {
    let o = ReadOptions::default();
    // year 262143, hour 24 and a negative offset overflowed chrono
    for (tz, year) in [
        ("-12.0", "262143"),
        ("14.0", "262143"),
        ("-12", "-262144"),
        ("0", "2201"),
        ("0", "1899"),
    ] {
        let e = parse_epw(&epw(tz, year, "24"), "w.epw", &o)
            .unwrap_err()
            .to_string();
        assert!(e.contains("w.epw:9") && e.contains("year"), "{e}");
        assert!(e.contains("1900 to 2200"), "{e}");
    }
    assert!(parse_epw(&epw("-12.0", "2200", "24"), "w.epw", &o).is_ok());
    // TMY3: a four-digit year past the range, hour 24:00, offset -12
    let tmy = |date: &str| {
        let cols = [
            "Date (MM/DD/YYYY)",
            "Time (HH:MM)",
            "GHI (W/m^2)",
            "DNI (W/m^2)",
            "DHI (W/m^2)",
            "Dry-bulb (C)",
            "Dew-point (C)",
            "RHum (%)",
            "Pressure (mbar)",
            "Wspd (m/s)",
            "TotCld (tenths)",
        ];
        format!(
            "1,\"X\",NC,-12.0,36.1,-79.9,273\n{}\n{date},24:00,0,0,0,10,5,70,1013,2,5\n",
            cols.join(",")
        )
    };
    let e = parse_tmy3(&tmy("12/31/9999"), "t.csv", &o)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("t.csv:3") && e.contains("year") && e.contains("1900 to 2200"),
        "{e}"
    );
    match parse_tmy3(&tmy("12/31/2000"), "t.csv", &o) {
        Ok(_) => {}
        Err(e) => assert!(!e.to_string().contains("year"), "{e}"),
    }
}

#[test]
fn scene_times_outside_1900_2200_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = plate_dir(tmp.path());
    let scene = dir.join("scene.toml");
    for (local, offset) in [
        ("\"+262142-12-31T23:00:00\"", "-14"),
        ("\"9999-12-31T23:00:00\"", "-14"),
        ("1899-12-31T23:59:59", "14"),
        ("2201-01-01T00:00:00", "0"),
    ] {
        let e = irsig::scene::load_with_overrides(
            &scene,
            &[
                ("time.local".into(), local.into()),
                ("site.utc_offset_h".into(), offset.into()),
            ],
        )
        .err()
        .unwrap_or_else(|| panic!("{local} accepted"))
        .to_string();
        assert!(
            e.contains("`year` =") && e.contains("expected 1900 <= year <= 2200"),
            "{local}: {e}"
        );
    }
    // the ends of the range load, and convert to UTC without overflow
    for (local, offset) in [
        ("1900-01-01T00:00:00", "14"),
        ("2200-12-31T23:59:59", "-14"),
    ] {
        let s = irsig::scene::load_with_overrides(
            &scene,
            &[
                ("time.local".into(), local.into()),
                ("site.utc_offset_h".into(), offset.into()),
            ],
        )
        .unwrap();
        let _ = s.scene.time.utc(&s.scene.site);
    }
    // through the CLI: exit 1 with the scene's line, no panic
    let s = scene.display().to_string();
    let (code, err) = irsig(&["check", &s]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&scene)
        .unwrap()
        .replace(
            "local = 2001-08-08T13:00:00",
            "local = \"+262142-12-31T23:00:00\"",
        )
        .replace("utc_offset_h = -4.0", "utc_offset_h = -14");
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, text).unwrap();
    let (code, err) = irsig(&["check", &bad.display().to_string()]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("bad.toml:24:") && err.contains("year"),
        "{err}"
    );
    // and the sun's --time (RFC 3339 allows years up to 9999)
    let (code, err) = irsig(&[
        "sun",
        "--lat",
        "0",
        "--lon",
        "0",
        "--time",
        "9999-06-21T12:00:00Z",
    ]);
    assert_ne!(code, 0, "{err}");
    assert!(
        err.contains("`year` = 9999 is out of range: expected 1900 <= year <= 2200"),
        "{err}"
    );
}

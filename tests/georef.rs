//! Georeferenced outputs read by GDAL (`gdalinfo`, `gdal_translate`,
//! `gdaltransform`, `gdallocationinfo`, from Debian's gdal-bin as
//! scripts/setup.sh installs it): the CRS, the corner coordinates against
//! the scene footprint of `irsig check` projected by PROJ (through
//! `gdaltransform`, independent of irsig's own conversion), the band names
//! and units, the ENVI headers and classification, the GCPs and the
//! float64 geolocation of an oblique view. Tolerances: half a pixel for the
//! corners (the acceptance criterion; the achieved error is millimetres),
//! 1e-7° (1 cm) for latitude and longitude.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::{gdalinfo, run_command as run};

fn irsig() -> Command {
    Command::new(env!("CARGO_BIN_EXE_irsig"))
}

fn plate() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/plate/scene.toml")
}

/// `gdaltransform` from `s_srs` to `t_srs` of (x, y) points.
fn transform(s_srs: &str, t_srs: &str, pts: &[[f64; 2]]) -> Vec<[f64; 2]> {
    common::gdaltransform(&["-s_srs", s_srs, "-t_srs", t_srs, "-output_xy"], pts)
        .iter()
        .map(|v| [v[0], v[1]])
        .collect()
}

const ORTHO: &str =
    "+proj=ortho +lat_0=43.1566 +lon_0=-77.6088 +x_0=0 +y_0=0 +datum=WGS84 +units=m";

fn corners(info: &serde_json::Value) -> Vec<[f64; 2]> {
    ["upperLeft", "upperRight", "lowerRight", "lowerLeft"]
        .iter()
        .map(|k| {
            let c = &info["cornerCoordinates"][k];
            [c[0].as_f64().unwrap(), c[1].as_f64().unwrap()]
        })
        .collect()
}

#[test]
fn nadir_geotiff_and_envi_are_georeferenced_in_utm() {
    let dir = tempfile::tempdir().unwrap();
    let tif = dir.path().join("n.tif");
    // Straight down from 60 m, image top towards the north-east (a rotated
    // image), 40x24 pixels (not square: catches swapped axes).
    let pose = "sensor.pose={altitude={altitude_m=61.5,view_zenith_deg=0.0,azimuth_deg=225.0,target_m=[0.0,0.0,1.5]}}";
    let set = [
        "--set",
        "sensor.width_px=40",
        "--set",
        "sensor.height_px=24",
        "--set",
        pose,
    ];
    run(irsig()
        .args(["render", plate().to_str().unwrap(), "-o"])
        .arg(&tif)
        .args(["--envi", "--exr"])
        .args(set));
    let check: serde_json::Value = serde_json::from_str(&run(irsig()
        .args(["check", plate().to_str().unwrap(), "--json"])
        .args(set)))
    .unwrap();
    let gsd = check["centre_gsd_m"][0].as_f64().unwrap();
    let fp: Vec<[f64; 2]> = check["footprint_m"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()])
        .collect();
    let want = transform(ORTHO, "EPSG:32618", &fp);
    let info = gdalinfo(&tif);
    let wkt = info["coordinateSystem"]["wkt"].as_str().unwrap();
    assert!(
        wkt.contains("UTM zone 18N") && wkt.contains("32618"),
        "{wkt}"
    );
    // The corner coordinates gdalinfo computes from the GeoTIFF's transform
    // are the footprint's, within half a pixel.
    for (got, want) in corners(&info).iter().zip(&want) {
        let d = (got[0] - want[0]).hypot(got[1] - want[1]);
        assert!(
            d < 0.5 * gsd,
            "corner {got:?} vs {want:?}: {d} m (GSD {gsd} m)"
        );
        assert!(d < 0.01, "corner {got:?} vs {want:?}: {d} m");
    }
    // Bands: one per plane, named, with units, NaN as no-data.
    let bands = info["bands"].as_array().unwrap();
    let names: Vec<&str> = bands
        .iter()
        .map(|b| b["description"].as_str().unwrap())
        .collect();
    for want in [
        "band_radiance",
        "apparent_temperature",
        "material",
        "ground_x",
        "lat",
    ]
    .iter()
    .filter(|n| **n != "lat")
    {
        assert!(names.contains(want), "{want} missing: {names:?}");
    }
    let t = bands
        .iter()
        .find(|b| b["description"] == "apparent_temperature")
        .unwrap();
    assert_eq!(t["unit"], "K");
    assert_eq!(t["type"], "Float32");
    assert!(
        t["noDataValue"]
            .as_str()
            .is_some_and(|s| s.eq_ignore_ascii_case("nan")),
        "{t}"
    );
    // A cloud-optimised GeoTIFF made from it keeps CRS and corners.
    let cog = dir.path().join("n_cog.tif");
    run(Command::new("gdal_translate")
        .args(["-of", "COG"])
        .arg(&tif)
        .arg(&cog));
    let ci = gdalinfo(&cog);
    assert_eq!(ci["metadata"]["IMAGE_STRUCTURE"]["LAYOUT"], "COG");
    assert_eq!(corners(&ci), corners(&info));
    // The ENVI radiance cube: the same CRS and corners through `map info`
    // with its rotation, wavelength and fwhm of the band, sun and time.
    let ei = gdalinfo(&dir.path().join("n.img"));
    assert!(
        ei["coordinateSystem"]["wkt"]
            .as_str()
            .unwrap()
            .contains("UTM zone 18N")
    );
    for (a, b) in corners(&ei).iter().zip(corners(&info).iter()) {
        assert!(
            (a[0] - b[0]).abs() < 1e-3 && (a[1] - b[1]).abs() < 1e-3,
            "{a:?} {b:?}"
        );
    }
    assert_eq!(ei["bands"][0]["noDataValue"], -9999.0, "{ei}");
    let hdr = std::fs::read_to_string(dir.path().join("n.hdr")).unwrap();
    for want in [
        "wavelength units = Micrometers",
        "wavelength = {11.000000, 11.000000",
        "fwhm = {6.000000",
        "acquisition time = 2001-08-08T17:00:00Z",
        "sun azimuth = ",
        "sun elevation = ",
        "data ignore value = -9999",
        "data units = W m-2 sr-1 um-1",
        "default stretch = ",
        "band names = {band_radiance [W m-2 sr-1 um-1]",
    ] {
        assert!(hdr.contains(want), "{want} missing from\n{hdr}");
    }
    // The classification: class names and colours (GDAL's categories).
    let cl = gdalinfo(&dir.path().join("n_class.img"));
    let cats: Vec<&str> = cl["bands"][0]["categories"]
        .as_array()
        .expect("categories")
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert_eq!(cats[0], "no surface");
    assert!(
        cats.contains(&"concrete") && cats.contains(&"painted_steel"),
        "{cats:?}"
    );
    assert!(cl["bands"][0]["colorTable"]["count"].as_u64().unwrap() >= cats.len() as u64);
    // The JSON states the CRS, footprint and GSD.
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("n.json")).unwrap()).unwrap();
    assert_eq!(j["georef"]["crs"]["epsg"], 32618);
    assert_eq!(j["georef"]["nadir"], true);
    assert!((j["georef"]["centre_gsd_m"][0].as_f64().unwrap() - gsd).abs() < 1e-9);
}

/// An oblique view: no affine transform but GCPs on the hit points, and a
/// float64 geolocation whose latitude and longitude agree with PROJ's.
#[test]
fn oblique_view_has_gcps_and_a_float64_geolocation() {
    let dir = tempfile::tempdir().unwrap();
    let tif = dir.path().join("o.tif");
    run(irsig()
        .args(["render", plate().to_str().unwrap(), "-o"])
        .arg(&tif)
        .args([
            "--set",
            "sensor.width_px=24",
            "--set",
            "sensor.height_px=20",
        ])
        .args(["--set", "site.crs=enu"]));
    let info = gdalinfo(&tif);
    assert!(
        info.get("geoTransform").is_none(),
        "an oblique view has no affine transform"
    );
    let gcps = info["gcps"]["gcpList"].as_array().expect("GCPs");
    assert!(gcps.len() >= 50, "{}", gcps.len());
    let wkt = info["gcps"]["coordinateSystem"]["wkt"].as_str().unwrap();
    assert!(wkt.contains("Orthographic"), "{wkt}");
    let band = |name: &str| -> usize {
        info["bands"]
            .as_array()
            .unwrap()
            .iter()
            .position(|b| b["description"] == name)
            .unwrap()
            + 1
    };
    let value = |file: &Path, b: usize, col: u32, row: u32| -> f64 {
        run(Command::new("gdallocationinfo")
            .args(["-valonly", "-b", &b.to_string()])
            .arg(file)
            .args([col.to_string(), row.to_string()]))
        .trim()
        .parse()
        .unwrap()
    };
    // In the local CRS a GCP's map coordinates are the hit point's scene x, y.
    for g in gcps.iter().step_by(7) {
        let (c, r) = (g["pixel"].as_f64().unwrap(), g["line"].as_f64().unwrap());
        let (c, r) = (c.floor() as u32, r.floor() as u32);
        let gx = value(&tif, band("ground_x"), c, r);
        let gy = value(&tif, band("ground_y"), c, r);
        assert!((g["x"].as_f64().unwrap() - gx).abs() < 0.01, "{g} {gx}");
        assert!((g["y"].as_f64().unwrap() - gy).abs() < 0.01, "{g} {gy}");
        // lat/lon of the float64 geolocation vs PROJ's inverse orthographic.
        let geo = dir.path().join("o_geo.tif");
        let lat = value(&geo, 1, c, r);
        let lon = value(&geo, 2, c, r);
        let want = transform(ORTHO, "+proj=longlat +datum=WGS84", &[[gx, gy]])[0];
        assert!(
            (lon - want[0]).abs() < 1e-7 && (lat - want[1]).abs() < 1e-7,
            "{lat} {lon} {want:?}"
        );
    }
    let gi = gdalinfo(&dir.path().join("o_geo.tif"));
    assert_eq!(gi["bands"][0]["type"], "Float64");
    assert_eq!(gi["bands"][0]["description"], "lat");
}

/// `irsig check --json` lists each object with its triangle count, bounds,
/// footprint size and base centre in the scene frame and on the map; the
/// map coordinates are the base's latitude/longitude projected to UTM by
/// `gdaltransform` (independent), to 10 cm: the helper passes degrees
/// with 6 decimals (0.11 m of latitude), which sets the agreement
/// (measured: at most 5.4 cm).
#[test]
fn check_lists_each_object_with_its_bounds_and_map_position() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/terrain-km/scene.toml");
    let out = run(irsig().arg("check").arg(&scene).arg("--json"));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let list = v["object_list"].as_array().unwrap();
    assert_eq!(list.len() as u64, v["objects"].as_u64().unwrap());
    assert_eq!(v["map_crs"], "WGS 84 / UTM zone 18N");
    let tri: u64 = list.iter().map(|o| o["triangles"].as_u64().unwrap()).sum();
    assert_eq!(tri, v["triangles"].as_u64().unwrap());
    let f = |x: &serde_json::Value| x.as_f64().unwrap();
    let mut ll = Vec::new();
    for o in list {
        let (lo, hi) = (&o["bounds_min_m"], &o["bounds_max_m"]);
        for k in 0..3 {
            assert!((f(&o["size_m"][k]) - (f(&hi[k]) - f(&lo[k]))).abs() < 1e-9);
        }
        assert_eq!(f(&o["base_centre_m"][2]), f(&lo[2]));
        ll.push([
            f(&o["base_centre_lat_lon_deg"][1]),
            f(&o["base_centre_lat_lon_deg"][0]),
        ]);
    }
    let want = transform("+proj=longlat +datum=WGS84", "EPSG:32618", &ll);
    for (o, w) in list.iter().zip(&want) {
        let m = &o["base_centre_map_m"];
        assert!(
            (f(&m[0]) - w[0]).abs() < 0.1 && (f(&m[1]) - w[1]).abs() < 0.1,
            "{}: {m} vs {w:?}",
            o["name"]
        );
    }
    // the text lists them too
    let text = run(irsig().arg("check").arg(&scene));
    assert!(text.contains("vehicle#1") && text.contains("map"), "{text}");
}

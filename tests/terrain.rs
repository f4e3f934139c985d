//! Terrain from a DEM (`[[terrain]]`, issue 14 item 4), against GDAL and
//! PROJ (Debian's gdal-bin, as scripts/setup.sh installs it):
//!
//! * the GeoTIFFs are written by `gdal_translate` from ESRI ASCII grids this
//!   test writes (geographic and UTM, Int16/Float32/Float64, strips and
//!   tiles, deflate and LZW with predictors, pixel-is-area and
//!   pixel-is-point, no-data values); irsig's reader must give `gdalinfo`'s
//!   corner coordinates (to 1e-9 of the pixel size) and CRS, and the
//!   written values;
//! * a rendered DEM scene's `range` plane: each pixel's hit point
//!   (camera position + range · direction) is converted to UTM and
//!   ellipsoidal height by PROJ (`gdaltransform -ct`, a topocentric →
//!   geocentric → UTM pipeline, independent of irsig's own conversion);
//!   its height must equal the DEM's bilinear height there (the test's own
//!   interpolation of the values it wrote) within the mesh's linear
//!   interpolation bound (stated in `dem_scene_range_agrees_with_the_dem`);
//! * bad inputs give errors naming the file, the key and what was expected.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::{gdalinfo, run_command as run};

use irsig::scene::terrain::raster::{RasterCrs, read_raster};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A north-up grid: `values[row][col]`, row 0 at the top (north).
struct Grid {
    x0: f64,
    /// Top edge (y of the upper left corner).
    y_top: f64,
    cell: f64,
    values: Vec<Vec<f64>>,
}

impl Grid {
    fn from_fn(
        x0: f64,
        y_top: f64,
        cell: f64,
        cols: usize,
        rows: usize,
        f: impl Fn(f64, f64) -> f64,
    ) -> Grid {
        let values = (0..rows)
            .map(|r| {
                (0..cols)
                    .map(|c| {
                        f(
                            x0 + (c as f64 + 0.5) * cell,
                            y_top - (r as f64 + 0.5) * cell,
                        )
                    })
                    .collect()
            })
            .collect();
        Grid {
            x0,
            y_top,
            cell,
            values,
        }
    }
    fn rows(&self) -> usize {
        self.values.len()
    }
    fn cols(&self) -> usize {
        self.values[0].len()
    }

    /// Writes the grid as an ESRI ASCII grid (NaN as -9999) and converts it
    /// with `gdal_translate` (`args`: type, CRS, creation options).
    fn write_tif(&self, dir: &Path, name: &str, args: &[&str]) -> PathBuf {
        let asc = dir.join(format!("{name}.asc"));
        let mut s = format!(
            "ncols {}\nnrows {}\nxllcorner {:.10}\nyllcorner {:.10}\ncellsize {:.12}\nNODATA_value -9999\n",
            self.cols(),
            self.rows(),
            self.x0,
            self.y_top - self.rows() as f64 * self.cell,
            self.cell
        );
        for row in &self.values {
            let r: Vec<String> = row
                .iter()
                .map(|v| {
                    if v.is_nan() {
                        "-9999".into()
                    } else {
                        format!("{v:.6}")
                    }
                })
                .collect();
            s += &r.join(" ");
            s.push('\n');
        }
        std::fs::write(&asc, s).unwrap();
        let tif = dir.join(format!("{name}.tif"));
        run(Command::new("gdal_translate")
            .arg("-q")
            .args(args)
            .arg(&asc)
            .arg(&tif));
        tif
    }

    /// Bilinear interpolation between pixel centres at (x, y) (edge pixels
    /// repeated in the outer half pixel).
    fn bilinear(&self, x: f64, y: f64) -> f64 {
        let u = ((x - self.x0) / self.cell - 0.5).clamp(0.0, (self.cols() - 1) as f64);
        let v = ((self.y_top - y) / self.cell - 0.5).clamp(0.0, (self.rows() - 1) as f64);
        let (i, j) = (
            (u.floor() as usize).min(self.cols() - 2),
            (v.floor() as usize).min(self.rows() - 2),
        );
        let (fx, fy) = (u - i as f64, v - j as f64);
        let z = &self.values;
        (1.0 - fy) * ((1.0 - fx) * z[j][i] + fx * z[j][i + 1])
            + fy * ((1.0 - fx) * z[j + 1][i] + fx * z[j + 1][i + 1])
    }
}

#[test]
fn dem_corners_crs_and_values_match_gdal() {
    let dir = tempfile::tempdir().unwrap();
    let f = |x: f64, y: f64| 100.0 + (x * 0.37).sin() * 20.0 + (y * 0.11).cos() * 7.0;
    // (name, grid, gdal_translate options, expected CRS)
    let utm = Grid::from_fn(287_010.0, 4_782_500.0, 30.0, 23, 17, |x, y| {
        f(x / 30.0, y / 30.0)
    });
    let geo = Grid::from_fn(-77.62, 43.17, 1.0 / 3600.0, 31, 19, |x, y| {
        f(x * 3600.0, y * 3600.0).round()
    });
    let mut geo_nd = Grid::from_fn(-77.62, 43.17, 1.0 / 3600.0, 31, 19, |x, y| {
        f(x * 3600.0, y * 3600.0).round()
    });
    geo_nd.values[3][5] = f64::NAN;
    geo_nd.values[18][30] = f64::NAN;
    let south = Grid::from_fn(261_000.5, 6_243_000.25, 2.5, 40, 9, f);
    let cases: Vec<(&str, &Grid, Vec<&str>, RasterCrs)> = vec![
        (
            "utm-f32-deflate",
            &utm,
            vec![
                "-a_srs",
                "EPSG:32618",
                "-ot",
                "Float32",
                "-co",
                "COMPRESS=DEFLATE",
                "-co",
                "PREDICTOR=3",
            ],
            RasterCrs::Utm {
                zone: 18,
                north: true,
            },
        ),
        (
            "geo-i16-deflate-tiled-point",
            &geo_nd,
            vec![
                "-a_srs",
                "EPSG:4326",
                "-ot",
                "Int16",
                "-co",
                "COMPRESS=DEFLATE",
                "-co",
                "PREDICTOR=2",
                "-co",
                "TILED=YES",
                "-co",
                "BLOCKXSIZE=16",
                "-co",
                "BLOCKYSIZE=16",
                "-mo",
                "AREA_OR_POINT=Point",
            ],
            RasterCrs::Geographic,
        ),
        (
            "geo-u16-plain",
            &geo,
            vec!["-a_srs", "EPSG:4326", "-ot", "UInt16"],
            RasterCrs::Geographic,
        ),
        (
            "geo-i16-lzw-strips",
            &geo_nd,
            vec![
                "-a_srs",
                "EPSG:4326",
                "-ot",
                "Int16",
                "-a_nodata",
                "-9999",
                "-co",
                "COMPRESS=LZW",
                "-co",
                "PREDICTOR=2",
                "-co",
                "BLOCKYSIZE=4",
            ],
            RasterCrs::Geographic,
        ),
        (
            "utm-south-f64",
            &south,
            vec![
                "-a_srs",
                "EPSG:32734",
                "-ot",
                "Float64",
                "-co",
                "COMPRESS=LZW",
            ],
            RasterCrs::Utm {
                zone: 34,
                north: false,
            },
        ),
    ];
    // Tiled LZW as libtiff writes it: the `tiff` crate 0.11.3 stops at the
    // edge tiles (image-tiff issue 395); refused with the way out.
    let tif = geo.write_tif(
        dir.path(),
        "lzw-tiled",
        &[
            "-a_srs",
            "EPSG:4326",
            "-ot",
            "Int16",
            "-co",
            "COMPRESS=LZW",
            "-co",
            "TILED=YES",
            "-co",
            "BLOCKXSIZE=16",
            "-co",
            "BLOCKYSIZE=16",
        ],
    );
    match read_raster(&tif) {
        Ok(r) => assert_eq!(r.data[0] as f64, geo.values[0][0]),
        Err(e) => {
            let e = e.to_string();
            assert!(
                e.contains("lzw-tiled.tif") && e.contains("COMPRESS=DEFLATE"),
                "{e}"
            );
        }
    }
    for (name, grid, args, crs) in cases {
        let tif = grid.write_tif(dir.path(), name, &args);
        let r = read_raster(&tif).unwrap_or_else(|e| panic!("{name}: {e}"));
        let info = gdalinfo(&tif);
        assert_eq!(r.crs, crs, "{name}");
        assert_eq!(
            info["stac"]["proj:epsg"].as_u64(),
            Some(r.crs.epsg() as u64),
            "{name}"
        );
        assert_eq!(
            (r.width as usize, r.height as usize),
            (grid.cols(), grid.rows())
        );
        for (k, c) in ["upperLeft", "upperRight", "lowerRight", "lowerLeft"]
            .iter()
            .enumerate()
        {
            // gdalinfo prints corners to 1e-7° and 1e-3 m
            let tol = if crs == RasterCrs::Geographic {
                1e-7
            } else {
                1e-3
            };
            let want = &info["cornerCoordinates"][c];
            let got = r.corners()[k];
            for a in 0..2 {
                let d = (got[a] - want[a].as_f64().unwrap()).abs();
                assert!(d <= tol, "{name} {c}: {got:?} vs {want}");
            }
        }
        // and its affine transform in full precision
        for (a, want) in info["geoTransform"].as_array().unwrap().iter().enumerate() {
            let d = (r.geotransform[a] - want.as_f64().unwrap()).abs();
            assert!(
                d <= 1e-9 * grid.cell,
                "{name} geotransform {:?} vs {}",
                r.geotransform,
                info["geoTransform"]
            );
        }
        let integer = args.contains(&"Int16") || args.contains(&"UInt16");
        for (j, row) in grid.values.iter().enumerate() {
            for (i, &v) in row.iter().enumerate() {
                let got = r.data[j * grid.cols() + i];
                if v.is_nan() {
                    assert!(got.is_nan(), "{name} ({i}, {j}): {got}, expected no data");
                } else {
                    let tol = if integer {
                        0.0
                    } else {
                        1e-6 * v.abs().max(1.0)
                    };
                    assert!(
                        (got as f64 - v).abs() <= tol,
                        "{name} ({i}, {j}): {got} vs {v}"
                    );
                }
            }
        }
    }
}

// ------------------------------------------------------------ DEM scenes

/// Site of the DEM scenes: Rochester NY, UTM zone 18N.
const LAT: f64 = 43.1566;
const LON: f64 = -77.6088;
const ELEV: f64 = 150.0;

/// A scene of one `[[terrain]]` (the table's keys as given) seen by
/// `pose`, 40x30 pixels, one sample per pixel.
fn scene_text(terrain: &str, pose: &str) -> String {
    format!(
        "materials = [\"{}\"]\n[files]\nallow = [\"/\"]\n\
         [site]\nlatitude_deg = {LAT}\nlongitude_deg = {LON}\nelevation_m = {ELEV}\nutc_offset_h = -4.0\n\
         [time]\nlocal = 2001-08-08T14:00:00\n\
         [weather.constant]\nwind_m_s = 3.0\nair_min_c = 17.0\nair_max_c = 29.0\ndew_point_c = 14.0\n\
         [atmosphere]\nmodel = \"mid-latitude-summer\"\n\
         [sensor]\nwidth_px = 40\nheight_px = 30\nfov_h_deg = 50.0\nband = \"lwir\"\n\
         {pose}\n\
         [render]\nsupersample = 1\nhistory_hours = 6.0\nshadow_interval_min = 60.0\n\
         [[terrain]]\n{terrain}\n",
        root().join("scenes/materials.toml").display()
    )
}

/// The UTM 18N easting, northing and ellipsoidal height of scene points
/// (PROJ: topocentric at the site → geocentric → UTM).
fn scene_to_utm(pts: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let ct = format!(
        "+proj=pipeline +step +inv +proj=topocentric +ellps=WGS84 +lat_0={LAT} +lon_0={LON} \
         +h_0={ELEV} +step +inv +proj=cart +ellps=WGS84 +step +proj=utm +zone=18 +ellps=WGS84"
    );
    common::gdaltransform(&["-ct", &ct], pts)
        .iter()
        .map(|v| [v[0], v[1], v[2]])
        .collect()
}

/// UTM 18N coordinates of the site (PROJ).
fn site_utm() -> [f64; 3] {
    scene_to_utm(&[[0.0, 0.0, 0.0]])[0]
}

/// The upper left corner of a grid reaching `margin_m` west and north of
/// the site (on whole 10 m).
fn upper_left(margin_m: f64) -> (f64, f64) {
    let s = site_utm();
    (
        (s[0] / 10.0).round() * 10.0 - margin_m,
        (s[1] / 10.0).round() * 10.0 + margin_m,
    )
}

/// Renders `text` and returns, per pixel with a hit, the scene point
/// camera + range · direction and the ground_x/y/z point.
fn hits(dir: &Path, text: &str) -> Vec<([f64; 3], [f64; 3])> {
    let file = dir.join("scene.toml");
    std::fs::write(&file, text).unwrap();
    let scene = irsig::scene::load(&file).unwrap_or_else(|e| panic!("{e}"));
    let cam = scene.local_camera;
    let origin = scene.frame.origin_m;
    let r = irsig::render::render_scene(scene, None, None).unwrap();
    let p = &r.frame.planes;
    let plane = |n: &str| &p.get(n).unwrap_or_else(|| panic!("plane {n}")).data;
    let (range, gx, gy, gz) = (
        plane("range"),
        plane("ground_x"),
        plane("ground_y"),
        plane("ground_z"),
    );
    let mut out = Vec::new();
    for y in 0..p.height {
        for x in 0..p.width {
            let k = (y * p.width + x) as usize;
            if !range[k].is_finite() {
                continue;
            }
            let d = cam.direction(x as f64 + 0.5, y as f64 + 0.5);
            let c = cam.position();
            let hit = [0, 1, 2].map(|a| c[a] + range[k] as f64 * d[a] + origin[a]);
            let g = [gx[k], gy[k], gz[k]].map(f64::from);
            let ground = [0, 1, 2].map(|a| g[a] + r.georef.ground_origin_m[a]);
            out.push((hit, ground));
        }
    }
    out
}

/// The largest |second difference| of a grid (along rows, columns and both
/// diagonals), per pixel² — the DEM's |h''| — in metres per m².
fn max_curvature(g: &Grid) -> f64 {
    let z = &g.values;
    let mut m: f64 = 0.0;
    for j in 1..g.rows() - 1 {
        for i in 1..g.cols() - 1 {
            for (di, dj, len2) in [(1, 0, 1.0), (0, 1, 1.0), (1, 1, 2.0), (1, -1, 2.0)] {
                let a = z[(j as i64 - dj) as usize][i - di];
                let b = z[(j as i64 + dj) as usize][i + di];
                m = m.max((a - 2.0 * z[j][i] + b).abs() / len2);
            }
        }
    }
    m / (g.cell * g.cell)
}

/// For a nadir and an oblique view of a DEM scene, every pixel's hit point
/// (camera position + range · direction, in the scene frame) lies on the
/// DEM: its ellipsoidal height (PROJ) equals the DEM's bilinear height at
/// its UTM easting and northing. Tolerance: a plane DEM is meshed exactly,
/// so 1 cm (single-precision positions and ranges within 1 km: < 1 mm);
/// for hills, the mesh is linear between vertices r apart (cells r × r,
/// longest edge d = r√2) while the bilinear surface bends with |h''| ≤ M
/// (its second differences, plus a kink per pixel p): |error| ≤
/// M·(d + p)·d/2 + 1 cm. ground_x/y/z hold the same points (1 mm).
#[test]
fn dem_scene_range_agrees_with_the_dem() {
    let dir = tempfile::tempdir().unwrap();
    let s = site_utm();
    let (e0, n0) = upper_left(900.0);
    let plane = Grid::from_fn(e0, n0, 20.0, 90, 90, |e, n| {
        ELEV + 0.04 * (e - s[0]) - 0.025 * (n - s[1]) + 3.0
    });
    let hills = Grid::from_fn(e0, n0, 20.0, 90, 90, |e, n| {
        let (x, y) = (e - s[0], n - s[1]);
        ELEV + 25.0 * (x / 160.0).sin() * (y / 210.0).cos() + 0.02 * x
    });
    let poses = [
        "[sensor.pose.altitude]\naltitude_m = 700.0\nview_zenith_deg = 0.0\nazimuth_deg = 0.0\ntarget_m = [0.0, 0.0, 0.0]",
        "[sensor.pose.altitude]\naltitude_m = 500.0\nview_zenith_deg = 45.0\nazimuth_deg = 230.0\ntarget_m = [40.0, -30.0, 0.0]",
    ];
    for (name, grid, res) in [("plane", &plane, 25.0), ("hills", &hills, 15.0)] {
        let tif = grid.write_tif(
            dir.path(),
            name,
            &["-a_srs", "EPSG:32618", "-ot", "Float32"],
        );
        let d = res * 2f64.sqrt();
        let tol = if name == "plane" {
            0.01
        } else {
            max_curvature(grid) * (d + grid.cell) * d / 2.0 + 0.01
        };
        for pose in poses {
            let terrain = format!(
                "file = \"{}\"\nextent_m = 1600.0\nresolution_m = {res}\nmaterial = \"grass_irrigated\"",
                tif.display()
            );
            let h = hits(dir.path(), &scene_text(&terrain, pose));
            assert!(h.len() >= 40 * 30 * 9 / 10, "{name}: {} hits", h.len());
            let utm = scene_to_utm(&h.iter().map(|p| p.0).collect::<Vec<_>>());
            let mut worst: f64 = 0.0;
            for ((hit, ground), u) in h.iter().zip(&utm) {
                let dz = u[2] - grid.bilinear(u[0], u[1]);
                worst = worst.max(dz.abs());
                for a in 0..3 {
                    assert!(
                        (hit[a] - ground[a]).abs() < 1e-3,
                        "{name}: {hit:?} vs ground {ground:?}"
                    );
                }
            }
            eprintln!(
                "{name}, r = {res} m: max |height - DEM| = {worst:.4} m (tolerance {tol:.3} m)"
            );
            assert!(worst <= tol, "{name} {pose}: {worst} m > {tol} m");
        }
    }
}

// ------------------------------------------------------------ land cover, holes

/// A land-cover raster in another CRS (geographic) than the DEM (UTM):
/// each cell gets the material of the class under its centre.
#[test]
fn land_cover_maps_classes_to_materials_and_holes_stay_open() {
    let dir = tempfile::tempdir().unwrap();
    let (e0, n0) = upper_left(600.0);
    let mut dem = Grid::from_fn(e0, n0, 20.0, 60, 60, |_, _| ELEV);
    let dem_tif = dem.write_tif(
        dir.path(),
        "flat",
        &["-a_srs", "EPSG:32618", "-ot", "Float32"],
    );
    // class 1 west of the site's meridian, 2 east of it (0.0001° pixels)
    let cover = Grid::from_fn(LON - 0.01, LAT + 0.01, 1e-4, 200, 200, |lon, _| {
        if lon < LON { 1.0 } else { 2.0 }
    });
    let cover_tif = cover.write_tif(dir.path(), "cover", &["-a_srs", "EPSG:4326", "-ot", "Byte"]);
    let pose = "[sensor.pose.altitude]\naltitude_m = 700.0\nview_zenith_deg = 0.0\nazimuth_deg = 0.0\ntarget_m = [0.0, 0.0, 0.0]";
    let terrain = |dem: &Path, extra: &str| {
        format!(
            "file = \"{}\"\nextent_m = 800.0\nresolution_m = 20.0\n{extra}\n[terrain.land_cover]\nfile = \"{}\"\nclasses = {{ \"1\" = \"grass_irrigated\", \"2\" = \"soil_bare\" }}\n",
            dem.display(),
            cover_tif.display()
        )
    };
    let file = dir.path().join("lc.toml");
    std::fs::write(&file, scene_text(&terrain(&dem_tif, ""), pose)).unwrap();
    let sc = irsig::scene::load(&file).unwrap_or_else(|e| panic!("{e}"));
    let (grass, soil) = (
        sc.material_index("grass_irrigated").unwrap() as u32,
        sc.material_index("soil_bare").unwrap() as u32,
    );
    assert_eq!(sc.triangles.len(), 2 * 40 * 40);
    for (t, tri) in sc.triangles.iter().enumerate() {
        let cx: f64 = tri
            .iter()
            .map(|&i| sc.positions[i as usize][0] as f64)
            .sum::<f64>()
            / 3.0
            + sc.frame.origin_m[0];
        // a cell's centre is at most 10√2 m from its triangles' centroids
        if cx.abs() > 15.0 {
            let want = if cx < 0.0 { grass } else { soil };
            assert_eq!(sc.tri_material[t], want, "triangle {t} at x = {cx}");
        }
    }
    // A no-data pixel: an error naming the DEM, the pixel and the key;
    // with nodata = "hole", the cells that need it are left out.
    dem.values[30][30] = f64::NAN;
    let holed = dem.write_tif(
        dir.path(),
        "holed",
        &["-a_srs", "EPSG:32618", "-ot", "Float32"],
    );
    std::fs::write(&file, scene_text(&terrain(&holed, ""), pose)).unwrap();
    let e = irsig::scene::load(&file).unwrap_err().to_string();
    assert!(
        e.contains("holed.tif")
            && e.contains("(col 30, row 30) has no data")
            && e.contains("nodata = \"hole\""),
        "{e}"
    );
    assert!(e.starts_with(&format!("{}:", file.display())), "{e}");
    std::fs::write(
        &file,
        scene_text(&terrain(&holed, "nodata = \"hole\""), pose),
    )
    .unwrap();
    let sc = irsig::scene::load(&file).unwrap_or_else(|e| panic!("{e}"));
    let o = sc.objects.last().unwrap();
    assert!(
        o.face_count < 40 * 40 && o.face_count >= 40 * 40 - 9,
        "{}",
        o.face_count
    );
    assert_eq!(sc.triangles.len(), 2 * o.face_count as usize);
}

// ------------------------------------------------------------ errors

#[test]
fn bad_dem_inputs_name_the_file_the_key_and_what_was_expected() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (e0, n0) = upper_left(600.0);
    let flat = Grid::from_fn(e0, n0, 20.0, 60, 60, |_, _| ELEV);
    let good = flat.write_tif(d, "good", &["-a_srs", "EPSG:32618", "-ot", "Float32"]);
    let nad83 = flat.write_tif(d, "nad83", &["-a_srs", "EPSG:26918", "-ot", "Float32"]);
    let plain = flat.write_tif(d, "plain", &["-ot", "Float32", "-co", "PROFILE=BASELINE"]);
    let text = d.join("text.tif");
    std::fs::write(&text, "ncols 3\n").unwrap();
    let pose = "[sensor.pose.altitude]\naltitude_m = 700.0\nview_zenith_deg = 0.0\nazimuth_deg = 0.0\ntarget_m = [0.0, 0.0, 0.0]";
    let file = d.join("bad.toml");
    let err = |terrain: String| -> String {
        std::fs::write(&file, scene_text(&terrain, pose)).unwrap();
        match irsig::scene::load(&file) {
            Ok(_) => panic!("accepted: {terrain}"),
            Err(e) => e.to_string(),
        }
    };
    let t = |f: &Path, rest: &str| format!("file = \"{}\"\n{rest}", f.display());
    let ok = "extent_m = 800.0\nresolution_m = 20.0\nmaterial = \"grass_irrigated\"";
    let scene = file.display().to_string();
    // (terrain table, what the message must hold)
    let cases: Vec<(String, Vec<String>)> = vec![
        (
            t(&text, ok),
            vec![
                text.display().to_string(),
                "not a TIFF file (expected a GeoTIFF)".into(),
            ],
        ),
        (
            t(&plain, ok),
            vec![
                plain.display().to_string(),
                "no GeoKeyDirectoryTag".into(),
                "-a_srs".into(),
            ],
        ),
        (
            t(&nad83, ok),
            vec![
                nad83.display().to_string(),
                "unsupported CRS EPSG:26918".into(),
                "EPSG:4326".into(),
                "gdalwarp".into(),
            ],
        ),
        (
            t(
                &good,
                "extent_m = [-100.0, -100.0, 900.0, 100.0]\nresolution_m = 20.0\nmaterial = \"grass_irrigated\"",
            ),
            vec![
                format!("{scene}:"),
                "`extent_m`".into(),
                "reaches outside the DEM".into(),
                good.display().to_string(),
                "it covers scene x".into(),
            ],
        ),
        (
            t(
                &good,
                "extent_m = 800.0\nresolution_m = 0.0\nmaterial = \"grass_irrigated\"",
            ),
            vec![
                format!("{scene}:"),
                "`resolution_m` = 0 is out of range: expected 0.01 <= resolution_m <= 10000 m"
                    .into(),
            ],
        ),
        (
            t(
                &good,
                "extent_m = 800.0\nresolution = 20.0\nmaterial = \"grass_irrigated\"",
            ),
            vec![
                format!("{scene}:"),
                "unknown field `resolution`".into(),
                "did you mean `resolution_m`?".into(),
            ],
        ),
        (
            t(
                &good,
                "extent_m = [100.0, 0.0, -100.0, 50.0]\nresolution_m = 20.0\nmaterial = \"grass_irrigated\"",
            ),
            vec!["x_min < x_max".into()],
        ),
        (
            t(
                &good,
                "extent_m = [0.0, 0.0, 1.0]\nresolution_m = 20.0\nmaterial = \"grass_irrigated\"",
            ),
            vec!["[x_min, y_min, x_max, y_max]".into()],
        ),
        (
            t(
                &good,
                "extent_m = 800.0\nresolution_m = 0.1\nmaterial = \"grass_irrigated\"",
            ),
            vec!["`resolution_m` = 0.1 over `extent_m` gives 64016001 vertices".into()],
        ),
        (
            t(&good, "extent_m = 800.0\nresolution_m = 20.0"),
            vec!["exactly one of `material`".into()],
        ),
        (
            t(
                &good,
                "extent_m = 800.0\nresolution_m = 20.0\nmaterial = \"grass\"",
            ),
            vec!["material `grass` is not defined".into()],
        ),
        (
            t(&d.join("missing.tif"), ok),
            vec![
                format!("{scene}:"),
                "DEM file".into(),
                "missing.tif` not found".into(),
            ],
        ),
        (
            t(
                &good,
                "extent_m = 800.0\nresolution_m = 20.0\nnodata = \"fill\"",
            ),
            vec!["unknown variant `fill`".into()],
        ),
        (
            format!(
                "{}\n[terrain.land_cover]\nfile = \"{}\"\nclasses = {{ \"1\" = \"grass_irrigated\" }}",
                t(&good, "extent_m = 800.0\nresolution_m = 20.0"),
                good.display()
            ),
            vec![
                "land-cover classes 150 of".into(),
                "have no material".into(),
                "\"*\"".into(),
            ],
        ),
        (
            format!(
                "{}\n[terrain.land_cover]\nfile = \"{}\"\nclasses = {{ \"grass\" = \"grass_irrigated\" }}",
                t(&good, "extent_m = 800.0\nresolution_m = 20.0"),
                good.display()
            ),
            vec!["land-cover class `grass`: expected an integer class id".into()],
        ),
    ];
    for (terrain, want) in cases {
        let e = err(terrain.clone());
        for w in &want {
            assert!(e.contains(w.as_str()), "{terrain}\n-> {e}\nmissing: {w}");
        }
    }
    // Key errors point at the scene file's line.
    let e = err(t(
        &good,
        "extent_m = 800.0\nresolution_m = -5.0\nmaterial = \"grass_irrigated\"",
    ));
    let line = scene_text("", pose).lines().count() + 2;
    assert!(e.starts_with(&format!("{scene}:{line}:")), "{e}");
}

// ------------------------------------------------------------ terrain-km

/// The height of the loaded terrain mesh (object `obj`) at world (x, y):
/// the triangle whose xy projection holds the point, interpolated.
fn mesh_z(s: &irsig::scene::LoadedScene, obj: usize, x: f64, y: f64) -> Option<f64> {
    let o = &s.objects[obj];
    let (x, y) = (x - s.frame.origin_m[0], y - s.frame.origin_m[1]);
    let first = o.first_triangle as usize;
    for t in &s.triangles[first..first + o.triangle_count as usize] {
        let p = t.map(|i| s.positions[i as usize].map(f64::from));
        let d =
            (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
        let b1 = ((x - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (y - p[0][1])) / d;
        let b2 = ((p[1][0] - p[0][0]) * (y - p[0][1]) - (x - p[0][0]) * (p[1][1] - p[0][1])) / d;
        if b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 {
            let z = p[0][2] + b1 * (p[1][2] - p[0][2]) + b2 * (p[2][2] - p[0][2]);
            return Some(z + s.frame.origin_m[2]);
        }
    }
    None
}

/// The terrain-km sample is meshed from its DEM and land cover (150 × 150
/// cells of 26.67 m: 45,000 triangles, the soil fields of the former OBJ:
/// 7,340 cells) and every object rests on the terrain mesh: its lowest
/// point is below the ground at its centre and at the four corners of its
/// footprint (nothing floats) and at most 3 m below the highest of them
/// (sunk 0.5 m; the buildings' walls reach 2 m below their base).
#[test]
fn terrain_km_is_meshed_from_its_dem_and_its_objects_rest_on_it() {
    let s = irsig::scene::load(&root().join("scenes/terrain-km/scene.toml")).unwrap();
    let t = s.objects.iter().position(|o| o.name == "terrain").unwrap();
    let o = &s.objects[t];
    assert!(o.file.ends_with("dem/terrain-utm18n.tif"), "{:?}", o.file);
    assert_eq!((o.triangle_count, o.face_count), (45_000, 22_500));
    let soil = s.material_index("soil_bare").unwrap() as u32;
    let first = o.first_triangle as usize;
    let soil_tris = s.tri_material[first..first + 45_000]
        .iter()
        .filter(|&&m| m == soil)
        .count();
    assert_eq!(soil_tris, 2 * 7_340);
    for (k, b) in s.objects.iter().enumerate().filter(|(k, _)| *k != t) {
        let (lo, hi) = (b.bounds_min_m, b.bounds_max_m);
        let pts = [
            [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0],
            [lo[0], lo[1]],
            [hi[0], lo[1]],
            [hi[0], hi[1]],
            [lo[0], hi[1]],
        ];
        let ground: Vec<f64> = pts
            .iter()
            .map(|p| {
                mesh_z(&s, t, p[0], p[1]).unwrap_or_else(|| panic!("object {k} off the terrain"))
            })
            .collect();
        let (gmin, gmax) = ground
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &z| {
                (a.min(z), b.max(z))
            });
        assert!(
            lo[2] <= gmin,
            "{}: floats: base {} m, ground {ground:?}",
            b.name,
            lo[2]
        );
        assert!(
            lo[2] >= gmax - 3.0,
            "{}: buried: base {} m, ground {ground:?}",
            b.name,
            lo[2]
        );
    }
}

/// The reprojection hint of a DEM in an unsupported CRS names the site's
/// own UTM zone (here a site at 99° W, zone 14N), not a fixed one.
#[test]
fn the_reprojection_hint_names_the_sites_utm_zone() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (e0, n0) = upper_left(600.0);
    let flat = Grid::from_fn(e0, n0, 20.0, 60, 60, |_, _| ELEV);
    let nad83 = flat.write_tif(d, "nad83", &["-a_srs", "EPSG:26918", "-ot", "Float32"]);
    let pose = "[sensor.pose.altitude]\naltitude_m = 700.0\nview_zenith_deg = 0.0\nazimuth_deg = 0.0\ntarget_m = [0.0, 0.0, 0.0]";
    let terrain = format!(
        "file = \"{}\"\nextent_m = 800.0\nresolution_m = 20.0\nmaterial = \"grass_irrigated\"",
        nad83.display()
    );
    let file = d.join("zone14.toml");
    let text = scene_text(&terrain, pose);
    let moved = text.replace(&format!("longitude_deg = {LON}"), "longitude_deg = -99.0");
    assert_ne!(moved, text);
    for (t, want) in [
        (
            &text,
            "EPSG:32618 in.tif out.tif` (WGS 84 / UTM zone 18N, the site's zone)",
        ),
        (
            &moved,
            "EPSG:32614 in.tif out.tif` (WGS 84 / UTM zone 14N, the site's zone)",
        ),
    ] {
        std::fs::write(&file, t).unwrap();
        let Err(e) = irsig::scene::load(&file) else {
            panic!("{t}: accepted")
        };
        let e = e.to_string();
        assert!(e.contains(want) && !e.contains("<UTM>"), "{e}");
    }
}

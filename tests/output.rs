//! Output writers: EXR round trip, ENVI header/cube, PNG stretch, atomicity.

use irsig::output::envi::write_envi;
use irsig::output::exr::{ExrCompression, read_exr, write_exr};
use irsig::output::quicklook::{Stretch, percentile_stretch, to_grey, write_png};
use irsig::output::set::remove_stale_partials;
use irsig::output::{OutputSet, Planes, write_atomic};

fn planes() -> Planes {
    let mut p = Planes::new(7, 5);
    p.push(
        "band_radiance",
        "W m-2 sr-1 um-1",
        (0..35).map(|i| i as f32 * 0.5).collect(),
    );
    p.push(
        "apparent_temperature",
        "K",
        (0..35).map(|i| 280.0 + i as f32).collect(),
    );
    p
}

/// The test planes plus integer truth planes (with -1 = none) and a term.
fn planes_with_truth() -> Planes {
    let mut p = planes();
    p.push(
        "material",
        "index (-1 none)",
        (0..35)
            .map(|i| if i % 4 == 0 { -1.0 } else { (i % 3) as f32 })
            .collect(),
    );
    p.push(
        "facet",
        "triangle index (-1 none)",
        (0..35)
            .map(|i| if i % 4 == 0 { -1.0 } else { (i * 1000) as f32 })
            .collect(),
    );
    p.push(
        "case",
        "eq. 1-4 (0 outside)",
        (0..35).map(|i| (i % 5) as f32).collect(),
    );
    p.push("range", "m", (0..35).map(|i| 100.5 + i as f32).collect());
    p.push(
        "emitted",
        "W m-2 sr-1 um-1",
        (0..35).map(|i| i as f32).collect(),
    );
    p
}

#[test]
fn exr_round_trips_every_plane_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.exr");
    let p = planes_with_truth();
    let mut set = OutputSet::new(&path).unwrap();
    write_exr(&mut set, &path, &p, &[], ExrCompression::default()).unwrap();
    set.commit().unwrap();
    let (w, h, chans) = read_exr(&path).unwrap();
    assert_eq!((w, h), (7, 5));
    assert_eq!(chans.len(), p.planes.len());
    for plane in &p.planes {
        let (_, data) = chans
            .iter()
            .find(|(n, _)| n == &plane.name)
            .expect("channel present");
        assert_eq!(data, &plane.data);
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&path).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o644, "outputs are ordinary readable files");
    }
    // No temporary file is left behind.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

/// The EXR layout, read with the exr crate's own metadata reader: grouped
/// `layer.channel` names, UINT integer planes, units and caller attributes
/// in the header. (python/tests/test_exr.py checks the same file type with
/// OpenEXR's reference library.)
#[test]
fn exr_groups_channels_types_integers_and_states_units() {
    use irsig::output::exr::{Attr, read_exr_attributes};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.exr");
    let p = planes_with_truth();
    let mut set = OutputSet::new(&path).unwrap();
    let attrs = [
        (
            "image_time_utc".to_string(),
            Attr::Text("2001-08-08T18:00:00Z".into()),
        ),
        ("sun_zenith_deg".to_string(), Attr::F64(31.25)),
    ];
    write_exr(&mut set, &path, &p, &attrs, ExrCompression::default()).unwrap();
    set.commit().unwrap();
    let meta = exr::meta::MetaData::read_from_file(&path, false).unwrap();
    let chans: Vec<(String, exr::meta::attribute::SampleType)> = meta.headers[0]
        .channels
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_type))
        .collect();
    use exr::meta::attribute::SampleType::{F32, U32};
    assert_eq!(
        chans,
        [
            ("radiance.apparent_temperature".to_string(), F32),
            ("radiance.band_radiance".into(), F32),
            ("terms.emitted".into(), F32),
            ("truth.case".into(), U32),
            ("truth.facet".into(), U32),
            ("truth.material".into(), U32),
            ("truth.range".into(), F32),
        ]
    );
    let a = read_exr_attributes(&path).unwrap();
    let get = |k: &str| {
        a.iter()
            .find(|(n, _)| n == k)
            .map(|(_, v)| v.as_str())
            .unwrap_or_else(|| panic!("{k} missing in {a:?}"))
    };
    assert_eq!(get("irsig.units.truth.range"), "m");
    assert_eq!(get("irsig.units.radiance.band_radiance"), "W m-2 sr-1 um-1");
    assert_eq!(get("irsig.units.truth.material"), "index (-1 none)");
    assert_eq!(get("irsig.image_time_utc"), "2001-08-08T18:00:00Z");
    assert_eq!(get("irsig.sun_zenith_deg"), "31.25");
    assert!(get("irsig.uint_none").starts_with("4294967295"));
    assert_eq!(get("irsig.version"), irsig::version::LONG_VERSION);
    assert!(get("software").starts_with("irsig "));
}

/// The header's attributes come from a hash map in the exr crate, and the
/// blocks are compressed in parallel; the file must still be the same bytes
/// every time and for any thread count (reproducible outputs).
#[test]
fn exr_bytes_are_reproducible() {
    use irsig::output::exr::Attr;
    let dir = tempfile::tempdir().unwrap();
    let attrs: Vec<(String, Attr)> = (0..20)
        .map(|i| (format!("key_{i}"), Attr::F64(i as f64)))
        .collect();
    // Truth planes (UINT channels) and planes of 70 lines: more than one
    // batch of blocks in flight at every thread count.
    for (c, p) in ExrCompression::ALL
        .into_iter()
        .flat_map(|c| [(c, planes_with_truth()), (c, planes_to_compress())])
    {
        let bytes: Vec<Vec<u8>> = (0..3)
            .map(|k| {
                let path = dir.path().join(format!("{c}{}{k}.exr", p.height));
                let mut set = OutputSet::new(&path).unwrap();
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(1 + 2 * k)
                    .build()
                    .unwrap();
                pool.install(|| write_exr(&mut set, &path, &p, &attrs, c))
                    .unwrap();
                set.commit().unwrap();
                std::fs::read(&path).unwrap()
            })
            .collect();
        assert!(bytes[0] == bytes[1] && bytes[1] == bytes[2], "{c}");
        let (_, _, chans) = read_exr(&dir.path().join(format!("{c}{}2.exr", p.height))).unwrap();
        assert_eq!(chans.len(), p.planes.len());
    }
}

/// Planes large enough that every compression shrinks some blocks (flat
/// areas, smooth ramps, noise) and with float values that a lossy or
/// NaN-mangling codec would alter: NaN, ±0, ±inf, subnormals, extremes.
fn planes_to_compress() -> Planes {
    let (w, h) = (97usize, 70usize); // partial blocks of 16 and 32 lines
    let mut p = Planes::new(w as u32, h as u32);
    let special = [
        f32::NAN,
        -0.0,
        0.0,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::MIN_POSITIVE / 8.0,
        f32::MAX,
        f32::MIN,
        f32::EPSILON,
    ];
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut noise = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 40) as f32 / (1u64 << 24) as f32
    };
    let temp: Vec<f32> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            if i % 53 == 0 {
                special[(i / 53) % special.len()]
            } else if y < 20.0 {
                300.0
            } else {
                280.0 + 0.1 * x + 0.05 * y + noise()
            }
        })
        .collect();
    p.push("apparent_temperature", "K", temp);
    p.push(
        "band_radiance",
        "W m-2 sr-1 um-1",
        (0..w * h).map(|_| 1e-3 * noise()).collect(),
    );
    p.push(
        "material",
        "index (-1 none)",
        (0..w * h)
            .map(|i| {
                if i < w * 9 {
                    -1.0
                } else {
                    ((i / 300) % 4) as f32
                }
            })
            .collect(),
    );
    p.push(
        "facet",
        "triangle index (-1 none)",
        (0..w * h)
            .map(|i| {
                if i % 7 == 0 {
                    -1.0
                } else {
                    (i * 7919 % 100_003) as f32
                }
            })
            .collect(),
    );
    p
}

/// Every offered compression is lossless: each plane reads back bit for
/// bit (NaN payloads, signed zeros, infinities and subnormals included),
/// the header names the compression asked for, and the codecs do shrink
/// the file below the uncompressed one (so each one really ran).
#[test]
fn exr_every_compression_round_trips_bit_exactly() {
    use exr::prelude::Compression as C;
    let dir = tempfile::tempdir().unwrap();
    let p = planes_to_compress();
    let mut sizes = Vec::new();
    for (c, header) in
        ExrCompression::ALL
            .into_iter()
            .zip([C::Uncompressed, C::RLE, C::ZIP1, C::ZIP16, C::PIZ])
    {
        let path = dir.path().join(format!("{c}.exr"));
        let mut set = OutputSet::new(&path).unwrap();
        write_exr(&mut set, &path, &p, &[], c).unwrap();
        set.commit().unwrap();
        let meta = exr::meta::MetaData::read_from_file(&path, false).unwrap();
        assert_eq!(meta.headers[0].compression, header, "{c}");
        let (w, h, chans) = read_exr(&path).unwrap();
        assert_eq!((w, h), (p.width, p.height));
        assert_eq!(chans.len(), p.planes.len());
        for plane in &p.planes {
            let (_, data) = chans.iter().find(|(n, _)| n == &plane.name).unwrap();
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert!(bits(data) == bits(&plane.data), "{c}: {}", plane.name);
        }
        sizes.push((c, std::fs::metadata(&path).unwrap().len()));
    }
    let none = sizes[0].1;
    for &(c, size) in &sizes[1..] {
        assert!(size < none, "{c}: {size} B, uncompressed {none} B");
    }
}

#[test]
fn exr_compression_names_parse_and_unknown_ones_are_refused() {
    for c in ExrCompression::ALL {
        assert_eq!(c.name().parse::<ExrCompression>(), Ok(c));
    }
    let e = "zip16".parse::<ExrCompression>().unwrap_err();
    assert_eq!(
        e,
        "unknown EXR compression \"zip16\"; expected one of none, rle, zips, zip, piz"
    );
    let e = "pxr24".parse::<ExrCompression>().unwrap_err();
    assert!(
        e.contains("lossy") && e.ends_with("none, rle, zips, zip, piz"),
        "{e}"
    );
}

#[test]
fn envi_writes_bsq_float32_and_header() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cube.img");
    let p = planes();
    let mut set = OutputSet::new(&path.with_extension("hdr")).unwrap();
    write_envi(&mut set, &path, &p, Some(&[10.0, 11.0]), "test cube").unwrap();
    set.commit().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(bytes.len(), 2 * 35 * 4);
    // Band 2, pixel (x=3, y=1) = index 35 + 10.
    let off = (35 + 10) * 4;
    assert_eq!(
        f32::from_le_bytes(bytes[off..off + 4].try_into().unwrap()),
        290.0
    );
    let hdr = std::fs::read_to_string(dir.path().join("cube.hdr")).unwrap();
    for line in [
        "samples = 7",
        "lines = 5",
        "bands = 2",
        "data type = 4",
        "interleave = bsq",
        "byte order = 0",
    ] {
        assert!(hdr.contains(line), "{line} missing in\n{hdr}");
    }
    assert!(hdr.contains("wavelength = {10.000000, 11.000000}"));
    assert!(
        hdr.contains("band names = {band_radiance [W m-2 sr-1 um-1], apparent_temperature [K]}")
    );
}

#[test]
fn quicklook_stretch_is_the_2_98_percentile() {
    let data: Vec<f32> = (0..=100).map(|i| i as f32).chain([f32::NAN, 1e9]).collect();
    let s = percentile_stretch(&data);
    // 102 finite values 0..100 and 1e9: index round(101·0.02)=2 → 2, round(101·0.98)=99 → 99.
    assert_eq!(s, Stretch { lo: 2.0, hi: 99.0 });
    let g = to_grey(&[2.0, 99.0, 50.5, f32::NAN, -5.0, 500.0], s);
    assert_eq!(g, vec![0, 255, 128, 0, 0, 255]);
    let dir = tempfile::tempdir().unwrap();
    let q = dir.path().join("q.png");
    let mut set = OutputSet::new(&q).unwrap();
    write_png(&mut set, &q, 101, 1, &data[..101], "test").unwrap();
    set.commit().unwrap();
    assert!(std::fs::metadata(dir.path().join("q.png")).unwrap().len() > 50);
}

#[test]
fn failed_write_leaves_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("never.bin");
    let r = write_atomic(&path, |w| {
        std::io::Write::write_all(w, b"half").unwrap();
        Err("interrupted".into())
    });
    assert!(r.unwrap_err().to_string().contains("interrupted"));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// Names in `dir`, sorted.
fn names(dir: &std::path::Path) -> Vec<String> {
    let mut n: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    n.sort();
    n
}

/// A set whose second file fails leaves the previous set exactly as it was
/// and no temporary file; a committed set replaces every file, the marker
/// last.
#[test]
fn a_failed_set_leaves_the_previous_set_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let (a, m) = (dir.path().join("x.bin"), dir.path().join("x.json"));
    let put = |path: &std::path::Path, text: &'static str, set: &mut OutputSet| {
        set.stage(path, |w| {
            std::io::Write::write_all(w, text.as_bytes()).map_err(|e| e.to_string())
        })
    };
    let mut old = OutputSet::new(&m).unwrap();
    put(&a, "old data", &mut old).unwrap();
    put(&m, "old marker", &mut old).unwrap();
    old.commit().unwrap();

    let mut new = OutputSet::new(&m).unwrap();
    put(&a, "new data", &mut new).unwrap();
    let err = new
        .stage(&m, |w| {
            std::io::Write::write_all(w, b"half").unwrap();
            Err("encoder gave up".into())
        })
        .unwrap_err()
        .to_string();
    assert_eq!(
        err,
        format!("cannot encode {}: encoder gave up", m.display())
    );
    drop(new);
    assert_eq!(std::fs::read_to_string(&a).unwrap(), "old data");
    assert_eq!(std::fs::read_to_string(&m).unwrap(), "old marker");
    assert_eq!(names(dir.path()), ["x.bin", "x.json"]);

    // A set without its marker cannot be committed (and changes nothing).
    let mut no_marker = OutputSet::new(&m).unwrap();
    put(&a, "new data", &mut no_marker).unwrap();
    assert!(no_marker.commit().is_err());
    assert_eq!(std::fs::read_to_string(&a).unwrap(), "old data");
    assert_eq!(names(dir.path()), ["x.bin", "x.json"]);

    let mut new = OutputSet::new(&m).unwrap();
    put(&m, "new marker", &mut new).unwrap(); // staged first, renamed last
    put(&a, "new data", &mut new).unwrap();
    new.commit().unwrap();
    assert_eq!(std::fs::read_to_string(&a).unwrap(), "new data");
    assert_eq!(std::fs::read_to_string(&m).unwrap(), "new marker");
    assert_eq!(names(dir.path()), ["x.bin", "x.json"]);
}

/// Temporary files nobody holds (a killed run's) are removed by the next
/// set in the folder; one held by a live writer is left alone.
#[test]
fn stale_partials_are_removed_and_live_ones_kept() {
    let dir = tempfile::tempdir().unwrap();
    let stale = dir.path().join(".irsig-partial-AbC123");
    let live = dir.path().join(".irsig-partial-XyZ789");
    std::fs::write(&stale, b"left by a killed run").unwrap();
    std::fs::write(&live, b"being written").unwrap();
    std::fs::write(dir.path().join("other.txt"), b"not ours").unwrap();
    let holder = std::fs::OpenOptions::new().write(true).open(&live).unwrap();
    holder.lock().unwrap();
    let out = dir.path().join("x.json");
    write_atomic(&out, |w| {
        std::io::Write::write_all(w, b"{}").map_err(|e| e.to_string())
    })
    .unwrap();
    assert_eq!(
        names(dir.path()),
        [".irsig-partial-XyZ789", "other.txt", "x.json"]
    );
    drop(holder);
    assert_eq!(remove_stale_partials(dir.path()).unwrap(), 1);
    assert_eq!(names(dir.path()), ["other.txt", "x.json"]);
}

// North-up map grid (output::geotiff).
use irsig::output::geotiff::{north_up_grid, resample_affine};

/// A rotated grid (30°, 0.5 m pixels): the map grid covers the
/// corners at the pixel size; a plane linear in map x, y comes back
/// exactly (bilinear reproduces a linear field) at every cell whose
/// four neighbours are on the image, and by nearest neighbour it is
/// the value of the pixel the cell centre falls in.
#[test]
fn north_up_grid_resamples_a_linear_field() {
    let (a, s) = (30f64.to_radians(), 0.5);
    let gt = [
        500_000.0,
        s * a.cos(),
        s * a.sin(),
        4_000_000.0,
        s * a.sin(),
        -s * a.cos(),
    ];
    let (w, h) = (40u32, 24u32);
    let (ogt, ow, oh) = north_up_grid(gt, w, h).expect("rotated");
    assert_eq!((ogt[1], ogt[5], ogt[2], ogt[4]), (s, -s, 0.0, 0.0));
    // The extent: the rotated rectangle's bounding box.
    let bw = (w as f64 * a.cos() + h as f64 * a.sin()) * s;
    let bh = (w as f64 * a.sin() + h as f64 * a.cos()) * s;
    assert_eq!(ow, (bw / s).ceil() as u32);
    assert_eq!(oh, (bh / s).ceil() as u32);
    assert!(north_up_grid([0.0, 1.0, 0.0, 0.0, 0.0, -1.0], 4, 4).is_none());
    let centre = |c: f64, r: f64| (gt[0] + c * gt[1] + r * gt[2], gt[3] + c * gt[4] + r * gt[5]);
    let field = |x: f64, y: f64| ((x - 500_000.0) * 0.7 - (y - 4_000_000.0) * 0.3 + 300.0) as f32;
    let data: Vec<f32> = (0..h)
        .flat_map(|r| (0..w).map(move |c| (c, r)))
        .map(|(c, r)| {
            let (x, y) = centre(c as f64 + 0.5, r as f64 + 0.5);
            field(x, y)
        })
        .collect();
    let lin = resample_affine(&data, (w, h), gt, ogt, (ow, oh), false);
    let near = resample_affine(&data, (w, h), gt, ogt, (ow, oh), true);
    let (mut inside, mut exact) = (0, 0);
    for j in 0..oh {
        for i in 0..ow {
            let k = (j * ow + i) as usize;
            let x = ogt[0] + (i as f64 + 0.5) * s;
            let y = ogt[3] - (j as f64 + 0.5) * s;
            let det = gt[1] * gt[5] - gt[2] * gt[4];
            let (dx, dy) = (x - gt[0], y - gt[3]);
            let col = (gt[5] * dx - gt[2] * dy) / det;
            let row = (-gt[4] * dx + gt[1] * dy) / det;
            let on = col >= 0.0 && row >= 0.0 && col < w as f64 && row < h as f64;
            assert_eq!(lin[k].is_nan(), !on, "cell {i},{j}");
            if !on {
                continue;
            }
            inside += 1;
            let (c, r) = (col.floor(), row.floor());
            assert_eq!(near[k], data[(r as u32 * w + c as u32) as usize]);
            if col > 0.5 && row > 0.5 && col < w as f64 - 0.5 && row < h as f64 - 0.5 {
                exact += 1;
                assert!(
                    (lin[k] - field(x, y)).abs() < 1e-3,
                    "{} {}",
                    lin[k],
                    field(x, y)
                );
            }
        }
    }
    // The image covers its own area of the grid (w·h pixels).
    assert!(
        (inside as f64 - (w * h) as f64).abs() < 0.05 * (w * h) as f64,
        "{inside}"
    );
    assert!(exact > inside / 2);
}

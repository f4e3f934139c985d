//! Output writers: EXR round trip, ENVI header/cube, PNG stretch, atomicity.

use irsig::output::envi::write_envi;
use irsig::output::exr::{read_exr, write_exr};
use irsig::output::quicklook::{Stretch, percentile_stretch, to_grey, write_png};
use irsig::output::{Planes, write_atomic};

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

#[test]
fn exr_round_trips_every_plane_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.exr");
    let p = planes();
    write_exr(&path, &p).unwrap();
    let (w, h, chans) = read_exr(&path).unwrap();
    assert_eq!((w, h), (7, 5));
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

#[test]
fn envi_writes_bsq_float32_and_header() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cube.img");
    let p = planes();
    write_envi(&path, &p, Some(&[10.0, 11.0]), "test cube").unwrap();
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
    write_png(&dir.path().join("q.png"), 101, 1, &data[..101], "test").unwrap();
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

//! `irsig atmos` end to end.

mod common;
use common::irsig_out as irsig;

#[test]
fn atmos_list_and_show() {
    let (rc, out, _) = irsig(&["atmos", "list"]);
    assert_eq!(rc, 0);
    for n in ["tropical", "mls", "mlw", "sas", "saw", "us1976"] {
        assert!(out.contains(n), "{out}");
    }
    // the CSV shows LOWTRAN's 10 µm values at a grid geometry (mls_clear, 3 km nadir)
    let (rc, out, err) = irsig(&[
        "atmos",
        "show",
        "mls_clear",
        "--altitude",
        "3",
        "--zenith",
        "0",
        "--band",
        "9.99-10.01",
        "--csv",
    ]);
    assert_eq!(rc, 0, "{err}");
    let row: Vec<f64> = out
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(row[0], 1000.0);
    assert!(
        (row[3] - 0.778).abs() < 0.001
            && (row[4] - 1.82).abs() < 0.01
            && (row[6] - 2.20).abs() < 0.01,
        "{row:?}"
    );
    let (rc, out, _) = irsig(&[
        "atmos",
        "show",
        "mls",
        "--altitude",
        "3",
        "--zenith",
        "30",
        "--band",
        "3-5",
    ]);
    assert_eq!(rc, 0);
    assert!(
        out.contains("tau2") && out.contains("L_UE") && out.contains("L_DE sky dome"),
        "{out}"
    );
}

#[test]
fn atmos_show_errors_are_clear() {
    let (rc, _, err) = irsig(&["atmos", "show", "mls", "--altitude", "0.1", "--zenith", "0"]);
    assert_ne!(rc, 0);
    assert!(
        err.contains("altitude_km = 0.1") && err.contains("no extrapolation"),
        "{err}"
    );
    let (rc, _, err) = irsig(&[
        "atmos",
        "show",
        "nowhere",
        "--altitude",
        "1",
        "--zenith",
        "0",
    ]);
    assert_ne!(rc, 0);
    assert!(
        err.contains("unknown atmosphere") && err.contains("mls"),
        "{err}"
    );
    let (rc, _, err) = irsig(&[
        "atmos",
        "show",
        "mls",
        "--altitude",
        "1",
        "--zenith",
        "0",
        "--band",
        "x-y",
    ]);
    assert_ne!(rc, 0);
    assert!(err.contains("band"), "{err}");
}

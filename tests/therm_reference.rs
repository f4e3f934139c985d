//! The slab solver against a fine-grid numerical reference over 72 h of
//! real TMY3 weather (pvlib's 723170TYA, Greensboro NC, 3-5 May), and the
//! discrete energy balance on the same forcing.
//!
//! Reference: `tools/ref_therm.py` — scipy `solve_ivp` (Radau, rtol 1e-10,
//! atol 1e-8 K) method of lines on a 500-node graded finite-volume mesh; its
//! own 500- vs 250-node difference is < 3e-4 K. It wrote the forcing
//! (`tests/data/therm_ref_forcing.csv`), the cases (`therm_ref_cases.json`)
//! and the surface temperatures (`therm_ref_temps.csv`); this test reads the
//! forcing from the CSV, so it is independent of irsig's weather and sun code.

use irsig::therm::balance::Orientation;
use irsig::therm::forcing::Forcing;
use irsig::therm::slab::{SlabMaterial, SlabModel, SpinUpStart, SunHistory, ThermSettings};
use serde::Deserialize;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");

#[derive(Deserialize)]
struct Case {
    name: String,
    material: SlabMaterial,
    orientation: Orientation,
    shadow: Option<SunHistory>,
}

#[derive(Deserialize)]
struct Cases {
    compare_from_s: f64,
    cases: Vec<Case>,
}

fn csv_rows(name: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(format!("{DATA}{name}")).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap()).collect())
        .collect();
    (header, rows)
}

fn load_forcing() -> Vec<Forcing> {
    let (h, rows) = csv_rows("therm_ref_forcing.csv");
    assert_eq!(h[0], "t_s");
    rows.iter()
        .map(|r| Forcing {
            t_s: r[0],
            air_temp_k: r[1],
            sky_temp_k: r[2],
            wind_speed_m_s: r[3],
            dni_w_m2: r[4],
            dhi_w_m2: r[5],
            ghi_w_m2: r[6],
            sun_dir_enu: [r[7], r[8], r[9]],
            dew_point_k: irsig::therm::forcing::DRY_AIR_DEW_POINT_K,
            pressure_pa: 101_325.0,
            precip_mm_h: 0.0,
            ground_temp_k: None,
        })
        .collect()
}

fn load_cases() -> (Cases, Vec<String>, Vec<Vec<f64>>) {
    let cases: Cases = serde_json::from_str(
        &std::fs::read_to_string(format!("{DATA}therm_ref_cases.json")).unwrap(),
    )
    .unwrap();
    let (h, rows) = csv_rows("therm_ref_temps.csv");
    (cases, h, rows)
}

/// Max |irsig − reference| over the compared window (after the 24 h
/// spin-up) at the given settings, per case.
fn errors(settings: &ThermSettings) -> Vec<(String, f64, usize)> {
    let forcing = load_forcing();
    let (cases, header, rows) = load_cases();
    let mut out = Vec::new();
    for case in &cases.cases {
        let col = header.iter().position(|h| *h == case.name).unwrap();
        // tools/ref_therm.py starts, as THERM does, from the steady state
        // under the first forcing sample.
        let settings = ThermSettings {
            spin_up_start: SpinUpStart::FirstSample,
            ..*settings
        };
        let model = SlabModel::new(&case.material, case.orientation, &settings).unwrap();
        let sol = model.solve(&forcing, case.shadow.as_ref(), true).unwrap();
        assert_eq!(sol.series.len(), rows.len());
        let mut err = 0.0f64;
        for (rec, row) in sol.series.iter().zip(&rows) {
            assert_eq!(rec.t_s, row[0]);
            if rec.t_s >= cases.compare_from_s {
                err = err.max((rec.surface_temp_k - row[col]).abs());
            }
        }
        out.push((
            case.name.clone(),
            err,
            sol.steps_accepted + sol.steps_rejected,
        ));
    }
    out
}

/// Acceptance: concrete wall (vertical, shaded 13-15 h, internal power),
/// asphalt (deep ground), soil (deep ground at mean air) and painted
/// aluminium skin (tilted, back exposed to air) stay within 0.1 K of the
/// reference over 48 h at the default settings.
#[test]
fn tmy3_48h_matches_fine_grid_reference() {
    let errs = errors(&reference_settings());
    for (name, err, steps) in &errs {
        eprintln!("{name}: max |error| {err:.4} K ({steps} steps)");
    }
    assert_eq!(errs.len(), 4);
    for (name, err, _) in &errs {
        assert!(*err < 0.1, "{name}: max error {err} K >= 0.1 K");
    }
}

/// Discrete energy conservation: the time integral of the net surface flux
/// plus the back flux equals the change of stored heat Σ C_i T_i, to 1e-6
/// relative. Two ways: (a) fixed steps equal to the 15-min forcing
/// interval, integrating the per-step flux records in this test; (b) the
/// adaptive default, via the solver's own running integral. Starts from a
/// cold 260 K profile so the stored-energy change is large.
#[test]
fn energy_is_conserved() {
    let forcing = load_forcing();
    let (cases, _, _) = load_cases();
    for case in &cases.cases {
        for adaptive in [false, true] {
            let settings = ThermSettings {
                tol_k: if adaptive {
                    reference_settings().tol_k
                } else {
                    None
                },
                step_s: 900.0,
                ..reference_settings()
            };
            let model = SlabModel::new(&case.material, case.orientation, &settings).unwrap();
            // no shadow switches between samples for (a): every step is one record
            let shadow = if adaptive { case.shadow.as_ref() } else { None };
            let sol = model
                .march(vec![260.0; model.nodes()], &forcing, shadow, true)
                .unwrap();
            let first = sol.series.first().unwrap();
            let last = sol.series.last().unwrap();
            let stored = last.stored_energy_j_m2 - first.stored_energy_j_m2;
            // Independent of the stored-energy bookkeeping: Σ C_i ΔT_i.
            let de: f64 = model
                .mesh
                .cap_j_m2k
                .iter()
                .zip(&sol.profile_k)
                .map(|(c, t)| c * (t - 260.0))
                .sum::<f64>()
                - if model.deep_temp_k(&forcing).is_some() {
                    model.mesh.cap_j_m2k.last().unwrap() * (sol.profile_k.last().unwrap() - 260.0)
                } else {
                    0.0
                };
            let integral = if adaptive {
                last.energy_in_j_m2
            } else {
                sol.series
                    .windows(2)
                    .map(|w| (w[1].t_s - w[0].t_s) * (w[1].surface.net_w_m2 + w[1].back_w_m2))
                    .sum()
            };
            let rel = (integral - de).abs() / de.abs();
            eprintln!(
                "{} adaptive={adaptive}: ΔE {de:.6e} J/m², ∫q dt {integral:.6e} J/m², rel {rel:.1e}",
                case.name
            );
            assert!(de.abs() > 1e4, "test needs a large stored-energy change");
            assert!(rel < 1e-6, "{}: relative imbalance {rel}", case.name);
            if model.deep_temp_k(&forcing).is_none() {
                assert!(((stored - de) / de).abs() < 1e-9);
            }
        }
    }
}

/// The error-vs-cost curve of the numerical knobs on this reference
/// (docs/models.md, "Accuracy and speed are measured"), for choosing the defaults. Not part of the default suite:
/// `cargo test --release --test therm_reference -- --ignored --nocapture`.
#[test]
#[ignore]
fn sweep_settings_error_vs_cost() {
    let base = reference_settings();
    let mut variants: Vec<(String, ThermSettings)> = Vec::new();
    for tol in [None, Some(0.02), Some(0.005), Some(0.002), Some(0.0005)] {
        for step in [60.0, 300.0, 900.0] {
            if tol.is_some() && step != 900.0 {
                continue;
            }
            variants.push((
                format!("tol {tol:?} step {step}"),
                ThermSettings {
                    tol_k: tol,
                    step_s: step,
                    ..base
                },
            ));
        }
    }
    for g in [1.05, 1.1, 1.2, 1.3] {
        for st in [3.0, 30.0, 300.0] {
            variants.push((
                format!("growth {g} surface_time {st}"),
                ThermSettings {
                    max_growth: g,
                    surface_time_s: st,
                    ..base
                },
            ));
        }
    }
    for (label, s) in variants {
        let t0 = std::time::Instant::now();
        let errs = errors(&s);
        let dt = t0.elapsed().as_secs_f64();
        let worst = errs.iter().map(|e| e.1).fold(0.0, f64::max);
        let steps: usize = errs.iter().map(|e| e.2).sum();
        let nodes: Vec<usize> = load_cases()
            .0
            .cases
            .iter()
            .map(|c| {
                SlabModel::new(&c.material, c.orientation, &s)
                    .unwrap()
                    .nodes()
            })
            .collect();
        eprintln!(
            "{label:36} max err {worst:.4} K  steps {steps:6}  nodes {nodes:?}  {:.1} ms",
            dt * 1e3
        );
    }
}

#[test]
#[ignore]
fn tight_settings_errors() {
    for tol in [2e-3, 2e-4, 1e-5] {
        for (g, st) in [(1.2, 30.0), (1.05, 30.0), (1.05, 3.0), (1.03, 3.0)] {
            let s = ThermSettings {
                tol_k: Some(tol),
                max_growth: g,
                surface_time_s: st,
                max_nodes: 400,
                ..reference_settings()
            };
            let e: Vec<String> = errors(&s)
                .iter()
                .map(|(n, e, st)| format!("{n} {e:.4} ({st})"))
                .collect();
            eprintln!("tol {tol} g {g} st {st}: {}", e.join(", "));
        }
    }
}

/// The solver's defaults with the McAdams convection of the reference
/// solver (tools/ref_therm.py): this file tests the numerics.
fn reference_settings() -> ThermSettings {
    ThermSettings {
        convection: irsig::therm::balance::Convection::mcadams(),
        shadow_ramp: false,
        ..ThermSettings::default()
    }
}

//! The surface kinds of the energy balance (vegetation, wet solids, water)
//! against independent references and physical expectations.

use chrono::{DateTime, Utc};
use irsig::scene::material::load_library;
use irsig::sun::Site;
use irsig::therm::balance::Orientation;
use irsig::therm::forcing::{Forcing, build_forcing};
use irsig::therm::slab::{SlabMaterial, SlabModel, ThermSettings};
use irsig::weather::{ReadOptions, read_weather_file_with};

const WEATHER: &str = "scenes/airfield/weather/greensboro-nc-tmy3-2001-08-04_09.csv";
const SITE: Site = Site {
    latitude_deg: 36.1,
    longitude_deg: -79.95,
    elevation_m: 273.0,
};

fn utc(s: &str) -> DateTime<Utc> {
    DateTime::parse_from_rfc3339(s).unwrap().with_timezone(&Utc)
}

/// Forcing from `from` for `hours` at `step_s` from the airfield weather.
fn airfield_forcing(from: &str, hours: f64, step_s: f64) -> Vec<Forcing> {
    let w = read_weather_file_with(std::path::Path::new(WEATHER), &ReadOptions::default())
        .unwrap()
        .history;
    let n = (hours * 3600.0 / step_s).round() as usize;
    build_forcing(&w, &SITE, utc(from), step_s, n).unwrap().0
}

/// A library material as the render maps it.
fn material(name: &str) -> SlabMaterial {
    let lib = load_library(std::path::Path::new("scenes/materials.toml")).unwrap();
    let m = lib.iter().find(|m| m.name == name).unwrap();
    m.construction
}

/// Hourly mean of `f(record)` over hour-ending stamps of a recorded
/// solution (series every `step_s`, starting at `t0`).
fn hourly_means(
    series: &[irsig::therm::slab::StepRecord],
    step_s: f64,
    f: impl Fn(&irsig::therm::slab::StepRecord) -> f64,
) -> Vec<f64> {
    let per_h = (3600.0 / step_s).round() as usize;
    (0..(series.len() - 1) / per_h)
        .map(|h| {
            // trapezoid over the hour
            let seg = &series[h * per_h..=(h + 1) * per_h];
            let n = seg.len() - 1;
            (0..n)
                .map(|k| 0.5 * (f(&seg[k]) + f(&seg[k + 1])))
                .sum::<f64>()
                / n as f64
        })
        .collect()
}

/// Latent heat of the irrigated-grass material (the FAO-56 reference
/// surface: 0.12 m, albedo 0.23, r_l = 100 s/m, LAI 2.88, well watered)
/// against the ASCE standardized hourly reference ET (refet 0.5.0, short
/// reference, computed by tools/ref_et0.py from the same weather,
/// tests/data/ref_et0_greensboro.csv) over Aug 6-9: daily totals within
/// 10 %; hours ending 11:00-17:00 LST within 20 %. The hours after sunrise
/// (ending 08:00-10:00 LST) run 15-41 % below the reference and are only
/// reported: there the model's soil takes up 20-30 % of the net
/// radiation, where ASCE fixes G = 0.1·R_n (an open difference; see
/// docs/energy-balance.md). The reference's net radiation is FAO's
/// estimate, not ours (rn_w_m2 in the CSV).
#[test]
fn irrigated_grass_latent_heat_matches_fao56_reference_et() {
    let step = 300.0;
    // Spin-up from the record's first hour (Aug 4 06:00Z) to Aug 10 05:00Z.
    let f = airfield_forcing("2001-08-04T06:00:00Z", 143.0, step);
    let m = material("grass_irrigated");
    let model = SlabModel::new(&m, Orientation::HORIZONTAL, &ThermSettings::default()).unwrap();
    let sol = model.solve(&f, None, true).unwrap();
    // ET in mm/h = −λE/λ·3600 with the reference's λ = 2.45 MJ/kg.
    let ours = hourly_means(&sol.series, step, |r| -r.surface.latent_w_m2);
    let text = std::fs::read_to_string("tests/data/ref_et0_greensboro.csv").unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|c| *c == n).unwrap();
    let (i_t, i_l, i_e) = (
        col("time_utc_end"),
        col("latent_asce_w_m2"),
        col("eto_asce_mm_h"),
    );
    let mut daily = [(0.0f64, 0.0f64); 4];
    let mut worst = 0.0f64;
    let t0 = utc("2001-08-04T06:00:00Z");
    for l in lines {
        let v: Vec<&str> = l.split(',').collect();
        let end = utc(v[i_t]);
        let h = ((end - t0).num_seconds() / 3600 - 1) as usize;
        let (reference, eto): (f64, f64) = (v[i_l].parse().unwrap(), v[i_e].parse().unwrap());
        let day = ((end - utc("2001-08-06T05:00:00Z")).num_seconds() - 1) / 86400;
        daily[day as usize].0 += ours[h];
        daily[day as usize].1 += reference;
        let lst_end = (end.timestamp() / 3600 - 5).rem_euclid(24);
        if eto > 0.1 {
            let rel = (ours[h] - reference) / reference;
            if (11..=17).contains(&lst_end) {
                worst = worst.max(rel.abs());
            }
            eprintln!(
                "{end}: ours {:.0} W/m², ASCE {reference:.0} W/m² ({:+.0} %)",
                ours[h],
                100.0 * rel
            );
        }
    }
    for (d, (o, r)) in daily.iter().enumerate() {
        let rel = (o - r) / r;
        eprintln!(
            "day {d}: ours {:.2} mm, ASCE {:.2} mm ({:+.1} %)",
            o * 3600.0 / 2.45e6,
            r * 3600.0 / 2.45e6,
            100.0 * rel
        );
        assert!(rel.abs() < 0.10, "day {d}: {:+.1} %", 100.0 * rel);
    }
    assert!(worst < 0.20, "worst hour {:.0} %", 100.0 * worst);
}

/// The pond (1.5 m, Beer-Lambert shortwave, mixing, evaporation) under
/// the airfield's August weather: a diurnal surface range of 0.5-3 K
/// (real small water bodies: 1-3 K) where the old solid slab swung 28 K,
/// and energy closure over the last day to 0.1 % of the absorbed sunlight.
#[test]
fn pond_diurnal_range_and_energy_closure() {
    let step = 900.0;
    let f = airfield_forcing("2001-08-04T06:00:00Z", 96.0, step);
    let m = material("pond");
    let model = SlabModel::new(&m, Orientation::HORIZONTAL, &ThermSettings::default()).unwrap();
    let sol = model.solve(&f, None, true).unwrap();
    let day = &sol.series[sol.series.len() - 97..];
    let (lo, hi) = day.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, r| {
        (a.0.min(r.surface_temp_k), a.1.max(r.surface_temp_k))
    });
    let air = day.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, r| {
        (a.0.min(r.air_temp_k), a.1.max(r.air_temp_k))
    });
    eprintln!(
        "pond range {:.2} K ({:.2}..{:.2} K); air range {:.2} K",
        hi - lo,
        lo,
        hi,
        air.1 - air.0
    );
    assert!((0.5..=3.0).contains(&(hi - lo)), "pond range {} K", hi - lo);
    let (a, b) = (day.first().unwrap(), day.last().unwrap());
    let stored = b.stored_energy_j_m2 - a.stored_energy_j_m2;
    let fluxes = b.energy_in_j_m2 - a.energy_in_j_m2;
    let sun: f64 = day
        .windows(2)
        .map(|w| {
            0.5 * step
                * (w[0].surface.absorbed_direct_w_m2
                    + w[0].surface.absorbed_diffuse_w_m2
                    + w[1].surface.absorbed_direct_w_m2
                    + w[1].surface.absorbed_diffuse_w_m2)
        })
        .sum();
    eprintln!("stored {stored:.0} J/m², fluxes {fluxes:.0} J/m², sun {sun:.0} J/m²");
    assert!(
        (stored - fluxes).abs() < 1e-3 * sun,
        "closure {} J/m²",
        stored - fluxes
    );
    // Evaporation: a net loss over the day (the afternoon air, warmer than
    // the water, is stable and suppresses it; docs/energy-balance.md).
    let mean_latent = day.iter().map(|r| r.surface.latent_w_m2).sum::<f64>() / day.len() as f64;
    eprintln!("pond mean latent {mean_latent:.1} W/m²");
    assert!(mean_latent < -10.0, "mean latent {mean_latent} W/m²");
}

/// A shower on asphalt: 1 h of 4 mm/h rain at 09-10 EDT fills the 1.3 mm
/// store; afterwards the wet pavement is cooler than the same pavement
/// without rain, and a sunlit patch dries before a shaded one.
#[test]
fn wet_pavement_cools_and_dries_sunlit_first() {
    let step = 300.0;
    let f = airfield_forcing("2001-08-07T04:00:00Z", 48.0, step);
    let t_rain = (utc("2001-08-08T13:00:00Z") - utc("2001-08-07T04:00:00Z")).num_seconds() as f64;
    let wet: Vec<Forcing> = f
        .iter()
        .map(|x| Forcing {
            precip_mm_h: if x.t_s >= t_rain && x.t_s <= t_rain + 3600.0 {
                4.0
            } else {
                0.0
            },
            ..*x
        })
        .collect();
    let m = material("asphalt");
    let model = SlabModel::new(&m, Orientation::HORIZONTAL, &ThermSettings::default()).unwrap();
    let dry = model.solve(&f, None, true).unwrap();
    let sun = model.solve(&wet, None, true).unwrap();
    // Shaded all day: a history of 30-min samples, never sunlit.
    let shade = irsig::therm::slab::SunHistory {
        start_s: 0,
        interval_s: 1800,
        sunlit: vec![false; 96],
    };
    let shaded = model.solve(&wet, Some(&shade), true).unwrap();
    let k = |t: f64| (t / step).round() as usize;
    let after = k(t_rain + 5400.0); // 30 min after the rain
    let d = dry.series[after].surface_temp_k - sun.series[after].surface_temp_k;
    eprintln!(
        "30 min after the shower: dry {:.2} K, wet {:.2} K (store {:.2} mm)",
        dry.series[after].surface_temp_k,
        sun.series[after].surface_temp_k,
        sun.series[after].water_store_mm
    );
    assert!(sun.series[after].water_store_mm > 0.0);
    assert!(d > 2.0, "wet pavement only {d} K cooler");
    let dried = |s: &irsig::therm::slab::ThermSolution| {
        s.series[k(t_rain + 3600.0)..]
            .iter()
            .find(|r| r.water_store_mm < 1e-6)
            .map(|r| r.t_s)
    };
    let (ds, dh) = (dried(&sun), dried(&shaded));
    eprintln!(
        "dry again: sunlit {:?} h, shaded {:?} h after the rain",
        ds.map(|t| (t - t_rain) / 3600.0),
        dh.map(|t| (t - t_rain) / 3600.0)
    );
    let ds = ds.expect("the sunlit patch dries");
    assert!(dh.is_none_or(|dh| dh > ds + 1800.0));
}

/// Issue: with h = 5.7 + 3.8 v (which folds radiation into convection)
/// the paper's wind-speed contrast loss was muted. Asphalt against
/// irrigated grass at 15:00 EDT under the airfield weather with the wind
/// held at 0 and then 2 m/s: the convective-only surface layer loses more
/// than twice as much of the contrast from 0 to 2 m/s as McAdams does
/// (measured: 25.5 -> 12.8 K against 25.3 -> 21.0 K).
#[test]
fn wind_takes_more_contrast_than_with_mcadams() {
    use irsig::therm::balance::Convection;
    let f = airfield_forcing("2001-08-07T19:00:00Z", 24.0, 600.0);
    let contrast = |wind: f64, convection: Convection| {
        let f: Vec<Forcing> = f
            .iter()
            .map(|x| Forcing {
                wind_speed_m_s: wind,
                ..*x
            })
            .collect();
        let settings = ThermSettings {
            convection,
            ..ThermSettings::default()
        };
        let t = |name: &str| {
            SlabModel::new(&material(name), Orientation::HORIZONTAL, &settings)
                .unwrap()
                .solve(&f, None, false)
                .unwrap()
                .surface_temp_k
        };
        t("asphalt") - t("grass_irrigated")
    };
    let new = [
        contrast(0.0, Convection::default()),
        contrast(2.0, Convection::default()),
    ];
    let old = [
        contrast(0.0, Convection::mcadams()),
        contrast(2.0, Convection::mcadams()),
    ];
    eprintln!(
        "asphalt - grass at 15:00: surface layer {:.2} K at 0 m/s, {:.2} K at 2 m/s; McAdams {:.2}, {:.2} K",
        new[0], new[1], old[0], old[1]
    );
    assert!(new[0] - new[1] > 2.0 * (old[0] - old[1]));
    assert!(new[0] > new[1] && old[0] > old[1]);
}

/// The `snow` material set of scenes/materials.toml: its conductivity is
/// Sturm et al. (1997)'s fit at its density (within 0.001 W/(m K)), the
/// fit's published range ends (0.023 + 0.234·0.156 = 0.0595 and the
/// quadratic 0.0591 at 0.156 g/cm³: continuous within 0.001), its albedo and
/// emissivity within Warren (1982)'s ranges; and under the same August sun
/// the snow surface stays more than 5 K colder at midday than bare soil
/// (it absorbs a quarter of the sunlight the soil does; measured 9.1 K:
/// 309.6 K against 318.8 K — above 0 °C, since the material set has no
/// melt cap, see docs/energy-balance.md, "Snow").
#[test]
fn snow_material_follows_sturm_and_warren() {
    use irsig::therm::surface::snow_conductivity_w_mk;
    let slab = material("snow");
    let rho = slab.density_kg_m3;
    assert!(
        (100.0..=400.0).contains(&rho),
        "seasonal snow density {rho}"
    );
    assert!((slab.conductivity_w_mk - snow_conductivity_w_mk(rho)).abs() < 1e-3);
    assert!((snow_conductivity_w_mk(155.999) - 0.0595).abs() < 1e-3);
    assert!((snow_conductivity_w_mk(156.0) - 0.0591).abs() < 1e-3);
    assert!((snow_conductivity_w_mk(300.0) - 0.126).abs() < 1e-3);
    assert!((0.05..=0.25).contains(&slab.solar_absorptivity));
    assert!((0.98..=0.99).contains(&slab.thermal_emissivity));
    let step = 300.0;
    let f = airfield_forcing("2001-08-06T06:00:00Z", 54.0, step);
    let run = |name: &str| {
        let m = material(name);
        let model = SlabModel::new(&m, Orientation::HORIZONTAL, &ThermSettings::default()).unwrap();
        model.solve(&f, None, true).unwrap()
    };
    let (snow, soil) = (run("snow"), run("soil_bare"));
    // 2001-08-07 17:00Z (13:00 EDT) is 35 h after the start.
    let k = (35.0 * 3600.0 / step) as usize;
    let (ts, tg) = (snow.series[k].surface_temp_k, soil.series[k].surface_temp_k);
    assert!(tg - ts > 5.0, "midday: snow {ts} K, soil {tg} K");
}

//! The surface kinds of the energy balance (vegetation, wet solids, water)
//! against independent references and physical expectations.

use chrono::{DateTime, Utc};
use irsig::scene::material::load_library;
use irsig::therm::balance::Orientation;
use irsig::therm::forcing::{Forcing, build_forcing};
use irsig::therm::slab::{SlabMaterial, SlabModel, ThermSettings};
use irsig::therm::weather::{ReadOptions, read_weather_file_with};
use irsig::sun::Site;

const WEATHER: &str = "scenes/airfield/weather/greensboro-nc-tmy3-2001-08-04_09.csv";
const SITE: Site = Site {
    lat_deg: 36.1,
    lon_deg: -79.95,
    elevation_m: 273.0,
};

fn utc(s: &str) -> DateTime<Utc> {
    DateTime::parse_from_rfc3339(s).unwrap().with_timezone(&Utc)
}

/// Forcing from `from` for `hours` at `step_s` from the airfield weather.
fn airfield_forcing(from: &str, hours: f64, step_s: f64) -> Vec<Forcing> {
    let w = read_weather_file_with(
        std::path::Path::new(WEATHER),
        &ReadOptions::default(),
    )
    .unwrap()
    .history;
    let n = (hours * 3600.0 / step_s).round() as usize;
    build_forcing(&w, &SITE, utc(from), step_s, n).unwrap().0
}

/// A library material as the render maps it.
fn material(name: &str) -> SlabMaterial {
    let lib = load_library(std::path::Path::new("scenes/materials.toml")).unwrap();
    let m = lib.iter().find(|m| m.name == name).unwrap();
    irsig::render::prepare::slab_of(m)
}

#[test]
fn pond_debug() {
    let f = airfield_forcing("2001-08-05T00:00:00Z", 96.0, 900.0);
    let mut m = material("pond");
    m.back = irsig::therm::slab::BackBoundary::DeepGround { temp_k: Some(298.0) };
    let model = SlabModel::new(&m, Orientation::HORIZONTAL, &ThermSettings::default()).unwrap();
    eprintln!("nodes {}", model.nodes());
    let d = model.drive(&f[0], 1.0);
    eprintln!("{d:?}");
    let r = model.equilibrium(&f[0], 1.0, Some(298.0));
    eprintln!("{r:?}");
    let me = model.mean_equilibrium(&f, None, Some(298.0));
    eprintln!("mean eq {:?}", me.as_ref().map(|v| v[0]));
    for k in [1usize, 2, 4, 8, 16, 32, 64, 96, 200, 384] {
        let me = model.mean_equilibrium(&f[..k.min(f.len())], None, Some(298.0));
        eprintln!("k {k} mean eq {:?}", me.as_ref().map(|v| v[0]));
    }
    let s = model.solve(&f, None, true);
    eprintln!("{:?}", s.as_ref().map(|s| s.surface_temp_k));
}

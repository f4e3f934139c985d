//! `irsig probe <scene> --pixel x,y`: everything about one output pixel —
//! its primary hit, the angles, the sun/shadow history, the temperature and
//! its flux terms over the history, the specular bounce and background, every
//! radiometric term (band-integrated, optionally per bin) and the band result.
//!
//! The computation is the library's [`crate::render::probe`]; this file
//! parses the flags and formats its [`PixelProbe`] as text or JSON.

use std::fmt::Write as _;
use std::path::PathBuf;

use chrono::Duration;

use crate::radiometry::RadianceTerms;
use crate::render::probe::{PixelProbe, SurfaceReport, case_name, probe_scene};
use crate::therm::slab::BackBoundary;
use crate::therm::surface::SurfaceKind;
use crate::trace::Backend;
use crate::units::ZERO_C_K;

#[derive(clap::Args, Debug)]
/// `irsig probe`: everything about one output pixel.
pub struct Args {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// The output pixel, column and row from the top left: `x,y`.
    #[arg(long, value_name = "X,Y")]
    pub pixel: String,
    /// Print JSON (every field, the whole thermal series) instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also report the terms bin by bin over the band.
    #[arg(long)]
    pub spectral: bool,
    /// Override a scene key before loading (as for `irsig render`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Remove a scene key (a value or a whole table) before the `--set`
    /// overrides, e.g. `--unset sensor.pose.altitude` to switch pose
    /// tables, or `--unset 'object[1]'` (repeatable).
    #[arg(long = "unset", value_name = "KEY")]
    pub unset: Vec<String>,
    /// Ray-tracing backend (default: the scene's `render.tracer`).
    #[arg(long, value_enum)]
    pub tracer: Option<Backend>,
}

/// Parses `x,y`.
pub fn parse_pixel(s: &str) -> anyhow::Result<(u32, u32)> {
    let err =
        || anyhow::anyhow!("--pixel {s}: expected two non-negative integers X,Y, e.g. 256,300");
    let (x, y) = s.split_once(',').ok_or_else(err)?;
    Ok((
        x.trim().parse().map_err(|_| err())?,
        y.trim().parse().map_err(|_| err())?,
    ))
}

fn write_terms(o: &mut String, pad: &str, t: &RadianceTerms) {
    let rows = [
        ("emitted", t.emitted),
        ("reflected_solar", t.reflected_solar),
        ("reflected_sky_thermal", t.reflected_sky_thermal),
        ("reflected_sky_scattered", t.reflected_sky_scattered),
        (
            "reflected_background_emitted",
            t.reflected_background_emitted,
        ),
        ("reflected_background_solar", t.reflected_background_solar),
        ("path_thermal", t.path_thermal),
        ("path_scattered", t.path_scattered),
    ];
    let total = t.total();
    for (name, v) in rows {
        let pct = if total != 0.0 { 100.0 * v / total } else { 0.0 };
        let _ = writeln!(o, "{pad}{name:<30} {v:>13.6e}  {pct:6.2} %");
    }
    let _ = writeln!(o, "{pad}{:<30} {total:>13.6e}", "total");
}

/// `MM-DD HH:MM` of `start` (`%Y-%m-%dT%H:%M`) plus `t_s` seconds.
fn local_of(start: &str, t_s: f64) -> String {
    chrono::NaiveDateTime::parse_from_str(start, "%Y-%m-%dT%H:%M")
        .map(|t| {
            (t + Duration::milliseconds((t_s * 1000.0).round() as i64))
                .format("%m-%d %H:%M")
                .to_string()
        })
        .unwrap_or_else(|_| format!("{:.2} h", t_s / 3600.0))
}

fn write_surface(o: &mut String, pad: &str, s: &SurfaceReport, with_series: bool) {
    let _ = writeln!(
        o,
        "{pad}object {} facet {} (triangle {}), material {} (#{}, specularity {})",
        s.object, s.facet, s.triangle, s.material, s.material_index, s.specularity
    );
    let _ = writeln!(
        o,
        "{pad}point [{:.3}, {:.3}, {:.3}] m, normal [{:.4}, {:.4}, {:.4}] (slope {:.2}°, aspect {:.2}°), range {:.2} m",
        s.point_m[0],
        s.point_m[1],
        s.point_m[2],
        s.normal[0],
        s.normal[1],
        s.normal[2],
        s.slope_deg,
        s.aspect_deg,
        s.range_m
    );
    let h = &s.history;
    let _ = writeln!(
        o,
        "{pad}sun history from {} every {} min to the image time ({} h sunlit, sunlit now: {}):",
        h.start_local, h.interval_min, h.hours_sunlit, h.sun_now
    );
    let _ = writeln!(o, "{pad}  sunlit {}", h.sunlit);
    let _ = writeln!(
        o,
        "{pad}  reason {}   (1 sunlit, s shadowed, a facing away, - sun down)",
        h.reason
    );
    let th = &s.thermal;
    let _ = writeln!(
        o,
        "{pad}surface kind {} ({}); ground seen by tilted facets: {} at {:.2} K",
        th.surface.name(),
        serde_json::to_string(&th.surface).unwrap_or_default(),
        th.ground_material
            .as_deref()
            .unwrap_or("none (air temperature)"),
        th.ground_temp_k
    );
    let sl = &th.slab;
    let layers: Vec<String> = sl
        .layers
        .iter()
        .map(|l| {
            format!(
                "{:.3} m k {:.3} W m-1 K-1 rho {:.0} kg m-3 c {:.0} J kg-1 K-1",
                l.thickness_m, l.conductivity_w_mk, l.density_kg_m3, l.specific_heat_j_kgk
            )
        })
        .collect();
    let back = match sl.back {
        BackBoundary::Insulated => "insulated".to_string(),
        BackBoundary::ExposedToAir { area_factor } => {
            format!("exposed to air (exposed area {area_factor})")
        }
        BackBoundary::DeepGround { temp_k: Some(t) } => format!("deep ground at {t:.2} K"),
        BackBoundary::DeepGround { temp_k: None } => "deep ground".to_string(),
    };
    let _ = writeln!(
        o,
        "{pad}slab, {} layer{} top first: {}; back {back}; solar absorptivity {:.3}, emissivity {:.3}",
        layers.len(),
        if layers.len() == 1 { "" } else { "s" },
        layers.join("; "),
        sl.solar_absorptivity,
        sl.thermal_emissivity
    );
    let _ = writeln!(
        o,
        "{pad}surface temperature {:.3} K ({:.2} °C); {} thermal steps ({} rejected)",
        th.surface_temp_k,
        th.surface_temp_k - ZERO_C_K,
        th.steps_accepted,
        th.steps_rejected
    );
    if let (Some(sky), Some(ri), Some(f)) = (th.sky_view, th.richardson, th.stability_factor) {
        let _ = writeln!(
            o,
            "{pad}at the image time: sky view factor {sky:.3} (this point's); \
             stability F(Ri) {f:.3} at Ri {ri:.3} (1 = neutral)"
        );
    }
    if let (SurfaceKind::Vegetation(c), Some(r)) = (&th.surface, th.series.last()) {
        let _ = writeln!(
            o,
            "{pad}canopy over soil: skin {:.2} K, soil surface under it {:.2} K; \
             {:.1} W m-2 from skin to soil (skin conductance {:.1} W m-2 K-1)",
            r.surface_temp_k,
            r.soil_surface_temp_k,
            r.conduction_into_slab_w_m2,
            c.skin_conductance_w_m2k
        );
    }
    if let (SurfaceKind::Snow { .. }, Some(r)) = (&th.surface, th.series.last()) {
        let state = if r.melt_w_m2 > 0.0 {
            "melting at 0 °C"
        } else {
            "frozen"
        };
        let _ = writeln!(
            o,
            "{pad}snow: {state}, melt {:.1} W m-2, latent (sublimation/frost) {:.1} W m-2",
            r.melt_w_m2, r.surface.latent_w_m2
        );
    }
    if with_series && !th.series.is_empty() {
        let _ = writeln!(
            o,
            "{pad}  flux terms, W m-2 (hourly; all steps with --json):\n{pad}  {:>11} {:>8} {:>8} {:>4} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>6} {:>6} {:>5} {:>5}",
            "local",
            "T_s K",
            "T_air K",
            "sun",
            "direct",
            "diffuse",
            "gnd_refl",
            "sky_lw",
            "gnd_lw",
            "emitted",
            "convect",
            "latent",
            "rain",
            "internal",
            "conduct",
            "h_c",
            "store",
            "F_sky",
            "F(Ri)"
        );
        let mut next_h = 0.0;
        let last = th.series.len() - 1;
        for (k, r) in th.series.iter().enumerate() {
            let t_h = r.t_s / 3600.0;
            if t_h + 1e-9 < next_h && k != last {
                continue;
            }
            next_h = t_h.floor() + 1.0;
            let f = &r.surface;
            let _ = writeln!(
                o,
                "{pad}  {:>11} {:>8.2} {:>8.2} {:>4.2} {:>8.1} {:>8.1} {:>8.1} {:>8.1} {:>8.1} {:>8.1} {:>8.1} {:>8.1} {:>8.1} {:>8.1} {:>8.1} {:>6.1} {:>6.2} {:>5.2} {:>5.2}",
                local_of(&th.start_local, r.t_s),
                r.surface_temp_k,
                r.air_temp_k,
                r.sunlit_fraction,
                f.absorbed_direct_w_m2,
                f.absorbed_diffuse_w_m2,
                f.absorbed_ground_reflected_w_m2,
                f.sky_longwave_in_w_m2,
                f.ground_longwave_in_w_m2,
                f.emitted_longwave_w_m2,
                f.convection_w_m2,
                f.latent_w_m2,
                f.rain_w_m2,
                f.internal_w_m2,
                r.conduction_into_slab_w_m2,
                f.convection_coeff_w_m2k,
                r.water_store_mm,
                r.sky_view,
                f.stability_factor()
            );
        }
    }
}

/// The report as text.
pub fn to_text(r: &PixelProbe) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "pixel ({}, {}) of {}\nimage time {} local ({}), band {} ({} bins), {}x{} samples per pixel",
        r.pixel[0],
        r.pixel[1],
        r.scene,
        r.image_time_local,
        r.image_time_utc,
        r.band,
        r.spectral_bins,
        r.supersample,
        r.supersample
    );
    let _ = writeln!(
        o,
        "sun: zenith {:.3}°, azimuth {:.3}°",
        r.sun.zenith_deg, r.sun.azimuth_deg
    );
    for (k, line) in r.atmosphere.lines().iter().enumerate() {
        let _ = writeln!(o, "{}{line}", if k == 0 { "atmosphere: " } else { "  " });
    }
    for s in &r.samples {
        let _ = writeln!(
            o,
            "\nsample ({}, {}): ray [{:.4}, {:.4}, {:.4}]",
            s.sample_px[0], s.sample_px[1], s.ray_dir[0], s.ray_dir[1], s.ray_dir[2]
        );
        match &s.hit {
            None => {
                let _ = writeln!(o, "  no hit");
            }
            Some(h) => write_surface(&mut o, "  ", h, true),
        }
        if let Some(a) = &s.angles {
            let _ = writeln!(
                o,
                "  view angle {:.3}°, view zenith {:.3}° (sensor at azimuth {:.2}°), sun incidence {:.3}°",
                a.view_angle_deg, a.view_zenith_deg, a.view_azimuth_deg, a.sun_incidence_deg
            );
        }
        if let Some(b) = &s.bounce {
            let _ = writeln!(
                o,
                "  specular bounce [{:.4}, {:.4}, {:.4}] (zenith {:.3}°, azimuth {:.2}°) -> {}",
                b.dir[0], b.dir[1], b.dir[2], b.zenith_deg, b.azimuth_deg, b.target
            );
            if let Some(bg) = &b.background {
                write_surface(&mut o, "    ", bg, false);
            }
        }
        let rr = &s.radiometry;
        let _ = writeln!(
            o,
            "  case {}, band emissivity {:.4}; band-integrated terms, W m-2 sr-1 um-1:",
            rr.case_name, rr.emissivity
        );
        write_terms(&mut o, "    ", &rr.terms);
        if let Some(bins) = &rr.spectral {
            let _ = writeln!(
                o,
                "  spectral terms, W m-2 sr-1 um-1:\n  {:>9} {:>8} {:>8} {:>11} {:>11} {:>11} {:>11} {:>11} {:>11} {:>11}",
                "cm-1",
                "um",
                "weight",
                "emitted",
                "refl_sun",
                "refl_sky",
                "refl_bg",
                "path_th",
                "path_sc",
                "total"
            );
            for b in bins {
                let t = &b.terms;
                let _ = writeln!(
                    o,
                    "  {:>9.2} {:>8.4} {:>8.5} {:>11.4e} {:>11.4e} {:>11.4e} {:>11.4e} {:>11.4e} {:>11.4e} {:>11.4e}",
                    b.wavenumber_cm1,
                    b.wavelength_um,
                    b.weight,
                    t.emitted,
                    t.reflected_solar,
                    t.reflected_sky_thermal + t.reflected_sky_scattered,
                    t.reflected_background_emitted + t.reflected_background_solar,
                    t.path_thermal,
                    t.path_scattered,
                    t.total()
                );
            }
        }
    }
    let p = &r.pixel_result;
    let _ = writeln!(o, "\npixel result (as irsig render writes it):");
    let _ = writeln!(o, "  case (centre sample) {}", case_name(p.case));
    write_terms(&mut o, "    ", &p.terms);
    let _ = writeln!(
        o,
        "  band_radiance {:.7e} W m-2 sr-1 um-1 (f32 {:e})",
        p.band_radiance_w_m2_sr_um, p.band_radiance_f32
    );
    let fmt_k = |t: Option<f64>| t.map_or("none".to_string(), |t| format!("{t:.3} K"));
    let _ = writeln!(
        o,
        "  apparent_temperature {}, surface_temperature {}",
        fmt_k(p.apparent_temperature_k),
        fmt_k(p.surface_temperature_k)
    );
    o
}

/// Runs `irsig probe`; returns the process exit code.
pub fn run(a: Args) -> anyhow::Result<i32> {
    let px = parse_pixel(&a.pixel)?;
    let overrides = super::render::parse_overrides(&a.set)?;
    let pool = crate::render::thread_pool(None)?;
    let scene = crate::scene::load_with_edits(&a.scene, &a.unset, &overrides)?;
    super::log::warn_about_frame(&scene);
    let report = pool.install(|| probe_scene(scene, a.tracer, px, a.spectral))?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", to_text(&report));
    }
    Ok(0)
}

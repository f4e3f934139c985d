//! `irsig check <scene> [--json]`: load and validate a scene, then print a
//! summary of what it holds and what rendering it will need.

use std::path::PathBuf;

use serde::Serialize;

use crate::scene::{self, LoadedScene, WeatherSpec};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Facet counts of one material.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct MaterialUse {
    pub name: String,
    pub triangles: usize,
    pub specularity: f64,
    pub internal_power_w_m2: f64,
    pub library: PathBuf,
}

/// What the render will need.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Needs {
    /// Reflected/scattered solar terms in the radiometry: the band reaches
    /// below 5 µm and the sun is up at the image time.
    pub solar_reflection: bool,
    /// Solar heating in the thermal model: the sun is up at some time of
    /// the history (then shadow-history rays are traced).
    pub solar_heating: bool,
    /// Approximate solar elevation at the image time, degrees.
    pub sun_elevation_deg: f64,
    /// Specular-bounce rays: some facet has a material with specularity > 0.
    pub specular_rays: bool,
    pub specular_materials: Vec<String>,
    /// Materials with an internal heat source.
    pub heated_materials: Vec<String>,
    /// Spectral samples in the band at the render's step.
    pub spectral_samples: usize,
    /// Thermal steps of the history and shadow-history samples per pixel.
    pub thermal_steps: usize,
    pub shadow_samples: usize,
}

/// The summary `irsig check` prints.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Summary {
    pub scene: PathBuf,
    pub site: scene::Site,
    pub time_local: String,
    pub time_utc: String,
    pub objects: usize,
    pub faces: usize,
    pub triangles: usize,
    pub vertices: usize,
    pub degenerate_skipped: usize,
    pub materials: Vec<MaterialUse>,
    pub bounds_min_m: [f32; 3],
    pub bounds_max_m: [f32; 3],
    pub camera: scene::CameraGeometry,
    /// Image corners on the plane z = target z (TL, TR, BR, BL); `null`
    /// where a corner ray misses the ground (above the horizon).
    pub footprint_m: [Option<[f64; 3]>; 4],
    /// Ground sample distance at the image centre (across, along), m.
    pub centre_gsd_m: Option<[f64; 2]>,
    pub band_um: (f64, f64),
    pub weather: String,
    pub atmosphere: String,
    pub needs: Needs,
}

/// Builds the summary of a loaded scene.
pub fn summarize(s: &LoadedScene) -> Summary {
    let sc = &s.scene;
    let mut counts = vec![0usize; s.materials.len()];
    for &m in &s.tri_material {
        counts[m as usize] += 1;
    }
    let materials: Vec<MaterialUse> = s
        .materials
        .iter()
        .zip(&counts)
        .map(|(m, &n)| MaterialUse {
            name: m.name.clone(),
            triangles: n,
            specularity: m.specularity,
            internal_power_w_m2: m.internal_power_w_m2,
            library: m.library.clone(),
        })
        .collect();
    let used = |f: &dyn Fn(&scene::Material) -> bool| -> Vec<String> {
        s.materials
            .iter()
            .zip(&counts)
            .filter(|(m, n)| **n > 0 && f(m))
            .map(|(m, _)| m.name.clone())
            .collect()
    };
    let specular_materials = used(&|m| m.is_specular());
    let heated_materials = used(&|m| m.internal_power_w_m2 != 0.0);
    let (lo, hi) = s.bounds_m();
    let ground_z = match &sc.sensor.pose {
        scene::SensorPose::LookAt { target_m, .. }
        | scene::SensorPose::Altitude { target_m, .. }
        | scene::SensorPose::SlantRange { target_m, .. } => target_m[2],
    };
    let band_um = s.response.support_um();
    let t_utc = sc.time.utc(&sc.site);
    let sun_el = approx_sun_elevation_deg(t_utc, sc.site.latitude_deg, sc.site.longitude_deg);
    // Sun up at any time of the history (sampled every 15 min)?
    let n_hist = (sc.render.history_hours * 4.0).ceil() as i64;
    let solar_heating = (0..=n_hist).any(|k| {
        let t = t_utc - chrono::Duration::minutes(15 * k);
        approx_sun_elevation_deg(t, sc.site.latitude_deg, sc.site.longitude_deg) > 0.0
    });
    let (wn_lo, wn_hi) = (1e4 / band_um.1, 1e4 / band_um.0);
    let spectral_samples = ((wn_hi - wn_lo) / sc.render.spectral_step_cm1).floor() as usize + 1;
    let faces = s.objects.iter().map(|o| o.face_count as usize).sum();
    Summary {
        scene: s.path.clone(),
        site: sc.site.clone(),
        time_local: sc.time.local.format("%Y-%m-%d %H:%M:%S").to_string(),
        time_utc: t_utc.format("%Y-%m-%d %H:%M:%S UTC").to_string(),
        objects: s.objects.len(),
        faces,
        triangles: s.triangles.len(),
        vertices: s.positions.len(),
        degenerate_skipped: s.degenerate_skipped,
        materials,
        bounds_min_m: lo,
        bounds_max_m: hi,
        camera: s.camera,
        footprint_m: s.camera.footprint(ground_z),
        centre_gsd_m: s.camera.centre_gsd_m(ground_z),
        band_um,
        weather: match &sc.weather {
            WeatherSpec::File { path, format } => {
                format!("{format:?} file {}", s.resolve(path).display())
            }
            WeatherSpec::Constant(w) => format!(
                "constant: wind {} m/s, air {}..{} °C, dew point {} °C, cloud {}",
                w.wind_m_s, w.air_min_c, w.air_max_c, w.dew_point_c, w.cloud_fraction
            ),
        },
        atmosphere: format!(
            "{:?}, visibility {} km",
            sc.atmosphere.model, sc.atmosphere.visibility_km
        ),
        needs: Needs {
            solar_reflection: band_um.0 < 5.0 && sun_el > 0.0,
            solar_heating,
            sun_elevation_deg: sun_el,
            specular_rays: !specular_materials.is_empty(),
            specular_materials,
            heated_materials,
            spectral_samples,
            thermal_steps: (sc.render.history_hours * 60.0 / sc.render.thermal_step_min).ceil()
                as usize,
            shadow_samples: (sc.render.history_hours * 60.0 / sc.render.shadow_interval_min).ceil()
                as usize,
        },
    }
}

/// Approximate solar elevation (degrees, no refraction) from the NOAA
/// "General Solar Position Calculations" (fractional-year Fourier series
/// for the declination and the equation of time, Spencer 1971), good to
/// about 0.3°. Only used to tell day from night in this summary; the
/// renderer uses `crate::sun` (NREL SPA).
pub fn approx_sun_elevation_deg(
    t: chrono::DateTime<chrono::Utc>,
    lat_deg: f64,
    lon_deg: f64,
) -> f64 {
    use chrono::{Datelike, Timelike};
    let hour = t.hour() as f64 + t.minute() as f64 / 60.0 + t.second() as f64 / 3600.0;
    let days = if t.date_naive().leap_year() {
        366.0
    } else {
        365.0
    };
    let g = 2.0 * std::f64::consts::PI / days * (t.ordinal() as f64 - 1.0 + (hour - 12.0) / 24.0);
    let eqtime_min = 229.18
        * (0.000075 + 0.001868 * g.cos()
            - 0.032077 * g.sin()
            - 0.014615 * (2.0 * g).cos()
            - 0.040849 * (2.0 * g).sin());
    let decl = 0.006918 - 0.399912 * g.cos() + 0.070257 * g.sin() - 0.006758 * (2.0 * g).cos()
        + 0.000907 * (2.0 * g).sin()
        - 0.002697 * (3.0 * g).cos()
        + 0.00148 * (3.0 * g).sin();
    let true_solar_min = hour * 60.0 + eqtime_min + 4.0 * lon_deg;
    let ha = (true_solar_min / 4.0 - 180.0).to_radians();
    let lat = lat_deg.to_radians();
    let cos_zen = lat.sin() * decl.sin() + lat.cos() * decl.cos() * ha.cos();
    90.0 - cos_zen.clamp(-1.0, 1.0).acos().to_degrees()
}

fn fmt3(v: [f64; 3]) -> String {
    format!("({:.1}, {:.1}, {:.1})", v[0], v[1], v[2])
}

/// Human-readable summary.
pub fn render_text(s: &Summary) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let _ = writeln!(o, "scene      {}", s.scene.display());
    let _ = writeln!(
        o,
        "site       {} lat {:.4}° lon {:.4}° elevation {} m, UTC{:+}",
        s.site.name.as_deref().unwrap_or("-"),
        s.site.latitude_deg,
        s.site.longitude_deg,
        s.site.elevation_m,
        s.site.utc_offset_h
    );
    let _ = writeln!(o, "time       {} local ({})", s.time_local, s.time_utc);
    let _ = writeln!(
        o,
        "geometry   {} objects, {} faces, {} triangles, {} vertices, {} degenerate triangles skipped",
        s.objects, s.faces, s.triangles, s.vertices, s.degenerate_skipped
    );
    let _ = writeln!(
        o,
        "bounds     {} .. {} m",
        fmt3(s.bounds_min_m.map(f64::from)),
        fmt3(s.bounds_max_m.map(f64::from))
    );
    let _ = writeln!(
        o,
        "materials  (triangles, specularity, internal power W/m²)"
    );
    for m in &s.materials {
        let _ = writeln!(
            o,
            "  {:<20} {:>7}  {:>4}  {:>6}{}",
            m.name,
            m.triangles,
            m.specularity,
            m.internal_power_w_m2,
            if m.triangles == 0 { "  (unused)" } else { "" }
        );
    }
    let c = &s.camera;
    let _ = writeln!(
        o,
        "sensor     {}x{} px, FOV {:.3}°x{:.3}°, at {} m looking ({:.3}, {:.3}, {:.3})",
        c.width_px,
        c.height_px,
        c.fov_h_deg,
        c.fov_v_deg,
        fmt3(c.position_m),
        c.forward[0],
        c.forward[1],
        c.forward[2]
    );
    let corners: Vec<String> = s
        .footprint_m
        .iter()
        .map(|p| {
            p.map_or("above horizon".to_string(), |p| {
                format!("({:.1}, {:.1})", p[0], p[1])
            })
        })
        .collect();
    let _ = writeln!(o, "footprint  {} m", corners.join(" "));
    if let Some(g) = s.centre_gsd_m {
        let _ = writeln!(
            o,
            "GSD        {:.3} x {:.3} m at the image centre",
            g[0], g[1]
        );
    }
    let _ = writeln!(
        o,
        "band       {:.3}-{:.3} µm, {} spectral samples",
        s.band_um.0, s.band_um.1, s.needs.spectral_samples
    );
    let _ = writeln!(o, "weather    {}", s.weather);
    let _ = writeln!(o, "atmosphere {}", s.atmosphere);
    let yn = |b: bool| if b { "yes" } else { "no" };
    let n = &s.needs;
    let _ = writeln!(o, "needs");
    let _ = writeln!(
        o,
        "  solar reflection terms  {} (band from {:.2} µm, sun elevation {:.1}°)",
        yn(n.solar_reflection),
        s.band_um.0,
        n.sun_elevation_deg
    );
    let _ = writeln!(
        o,
        "  solar heating/shadows   {} ({} shadow samples)",
        yn(n.solar_heating),
        n.shadow_samples
    );
    let _ = writeln!(
        o,
        "  specular bounce rays    {}{}",
        yn(n.specular_rays),
        if n.specular_rays {
            format!(" ({})", n.specular_materials.join(", "))
        } else {
            String::new()
        }
    );
    let _ = writeln!(
        o,
        "  internal heat sources   {}{}",
        yn(!n.heated_materials.is_empty()),
        if n.heated_materials.is_empty() {
            String::new()
        } else {
            format!(" ({})", n.heated_materials.join(", "))
        }
    );
    let _ = writeln!(o, "  thermal steps           {}", n.thermal_steps);
    o
}

pub fn run(a: Args) -> anyhow::Result<i32> {
    let s = scene::load(&a.scene)?;
    let sum = summarize(&s);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&sum)?);
    } else {
        print!("{}", render_text(&sum));
    }
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against NREL SPA (pvlib 0.16, `spa_python`, geometric elevation
    /// without refraction): tests/data/sun_elevation_pvlib.csv, generated
    /// by tools/sun_elevation_ref.py. Tolerance 0.5° (the NOAA series is
    /// good to ~0.3°; day/night only needs the sign away from the horizon).
    #[test]
    fn approximate_sun_elevation_matches_spa() {
        let text = include_str!("../../tests/data/sun_elevation_pvlib.csv");
        let mut n = 0;
        for line in text.lines().skip(1) {
            let f: Vec<&str> = line.split(',').collect();
            let t = chrono::NaiveDateTime::parse_from_str(f[0], "%Y-%m-%dT%H:%M:%S")
                .unwrap()
                .and_utc();
            let (lat, lon, want): (f64, f64, f64) = (
                f[1].parse().unwrap(),
                f[2].parse().unwrap(),
                f[3].parse().unwrap(),
            );
            let got = approx_sun_elevation_deg(t, lat, lon);
            assert!((got - want).abs() < 0.5, "{line}: got {got}");
            n += 1;
        }
        assert_eq!(n, 10);
    }

    #[test]
    fn summary_of_the_airfield() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let s = scene::load(&root.join("scenes/airfield/scene.toml")).unwrap();
        let sum = summarize(&s);
        assert_eq!(sum.objects, 24);
        assert_eq!(sum.triangles, s.triangles.len());
        assert_eq!(
            sum.materials.iter().map(|m| m.triangles).sum::<usize>(),
            sum.triangles
        );
        // MWIR at noon: solar reflection needed; specular roof present
        assert!(sum.needs.solar_reflection && sum.needs.solar_heating && sum.needs.specular_rays);
        assert!(
            sum.needs
                .specular_materials
                .contains(&"painted_steel_roof".to_string())
        );
        assert_eq!(
            sum.needs.heated_materials,
            vec!["vehicle_engine".to_string()]
        );
        // 3-5 µm = 2000-3333.3 cm⁻¹ at 20 cm⁻¹ steps: 67 samples
        assert_eq!(sum.needs.spectral_samples, 67);
        assert_eq!(
            (sum.needs.thermal_steps, sum.needs.shadow_samples),
            (36, 36)
        );
        // footprint contains the target; JSON serialises
        let fp = sum.footprint_m.map(|p| p.unwrap());
        assert!(fp[0][1] > 20.0 && fp[2][1] < 20.0 && fp[0][0] < 0.0 && fp[1][0] > 0.0);
        let json = serde_json::to_string(&sum).unwrap();
        assert!(json.contains("\"solar_reflection\":true"));
        assert!(render_text(&sum).contains("specular bounce rays    yes"));
    }
}

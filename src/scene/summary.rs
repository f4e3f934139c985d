//! A scene's summary (`irsig check`): objects, facets, materials, bounds,
//! the sensor's footprint and what the render will need.

use std::path::PathBuf;

use serde::Serialize;

use super::{LoadedScene, WeatherSpec};

/// Facet counts of one material.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct MaterialUse {
    /// The material's name.
    pub name: String,
    /// Triangles of it in the scene.
    pub triangles: usize,
    /// Its specular fraction (0: diffuse).
    pub specularity: f64,
    /// Its internal heat source, W/m².
    pub internal_power_w_m2: f64,
    /// The library it was read from.
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
    /// The materials with specularity > 0.
    pub specular_materials: Vec<String>,
    /// Materials with an internal heat source.
    pub heated_materials: Vec<String>,
    /// Spectral samples in the band at the render's step.
    pub spectral_samples: usize,
    /// Thermal steps of the history and shadow-history samples per pixel.
    pub thermal_steps: usize,
    /// Shadow-history samples per pixel sample.
    pub shadow_samples: usize,
}

/// One object (an `[[object]]` entry, each of its instances, or a
/// `[[terrain]]`) as `irsig check` lists it: where it stands and how big
/// it is, in the scene frame and on the map.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ObjectSummary {
    /// Object name (`name#k` for instance k).
    pub name: String,
    /// Index of its `[[object]]` (or `[[terrain]]`) entry, and the
    /// instance number within it: `object[i].instance[k - 1]` for
    /// `--set` overrides.
    pub spec_index: usize,
    /// Instance number within the entry (0-based).
    pub instance: usize,
    /// Triangles (zero-area ones left out).
    pub triangles: u32,
    /// Faces (polygons; a terrain's cells).
    pub faces: u32,
    /// Axis-aligned bounds' minimum, scene frame (local ENU of the site), m.
    pub bounds_min_m: [f64; 3],
    /// Axis-aligned bounds' maximum, scene frame, m.
    pub bounds_max_m: [f64; 3],
    /// Footprint (east-west, north-south extent) and height, m.
    pub size_m: [f64; 3],
    /// The centre of the footprint at the object's lowest point, scene
    /// frame, m.
    pub base_centre_m: [f64; 3],
    /// That point's map coordinates (x, y) in the outputs' CRS
    /// (`site.crs`, named in [`SceneSummary::map_crs`]), m.
    pub base_centre_map_m: Option<[f64; 2]>,
    /// That point's latitude and longitude (WGS 84), degrees.
    pub base_centre_lat_lon_deg: Option<[f64; 2]>,
}

/// The summary `irsig check` prints: what a scene holds and what
/// rendering it will need.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SceneSummary {
    /// The scene file.
    pub scene: PathBuf,
    /// The site (latitude, longitude, elevation).
    pub site: super::Site,
    /// Image time, local (as the scene states it).
    pub time_local: String,
    /// Image time, UTC.
    pub time_utc: String,
    /// Number of objects (instances and terrains).
    pub objects: usize,
    /// Each object's bounds, footprint, base and triangle count.
    pub object_list: Vec<ObjectSummary>,
    /// The map CRS of [`ObjectSummary::base_centre_map_m`] (the outputs').
    pub map_crs: String,
    /// Faces of every object.
    pub faces: usize,
    /// Triangles traced.
    pub triangles: usize,
    /// Vertices.
    pub vertices: usize,
    /// Zero-area triangles left out.
    pub degenerate_skipped: usize,
    /// The materials in use.
    pub materials: Vec<MaterialUse>,
    /// Bounds' minimum, world coordinates, m.
    pub bounds_min_m: [f64; 3],
    /// Bounds' maximum, world coordinates, m.
    pub bounds_max_m: [f64; 3],
    /// The tracer's local frame: origin, extent and f32 precision.
    pub local_frame: super::LocalFrame,
    /// Set when the geometry reaches beyond the frame's precise extent.
    pub warning: Option<String>,
    /// Notes on the inputs ([`super::LoadedScene::warnings`]).
    pub warnings: Vec<String>,
    /// The camera (world coordinates).
    pub camera: super::Camera,
    /// Image corners on the plane z = target z (TL, TR, BR, BL); `null`
    /// where a corner ray misses the ground (above the horizon).
    pub footprint_m: [Option<[f64; 3]>; 4],
    /// Ground sample distance at the image centre (across, along), m.
    pub centre_gsd_m: Option<[f64; 2]>,
    /// The band's spectral support, µm.
    pub band_um: (f64, f64),
    /// The weather source, as text.
    pub weather: String,
    /// The atmosphere choice, as text.
    pub atmosphere: String,
    /// What the render will need.
    pub needs: Needs,
}

/// Each object of a loaded scene as [`ObjectSummary`], with the map CRS's
/// name (map coordinates are left out when the site cannot be projected).
pub fn object_list(s: &LoadedScene) -> (Vec<ObjectSummary>, String) {
    let geo = super::georef::Geo::new(&s.scene.site.location, &s.scene.site.crs).ok();
    let crs = geo
        .as_ref()
        .map_or_else(|| "-".to_string(), |g| g.crs.name.clone());
    let list = s
        .objects
        .iter()
        .map(|o| {
            let (lo, hi) = (o.bounds_min_m, o.bounds_max_m);
            let base = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, lo[2]];
            let ll = geo.as_ref().and_then(|g| g.geodetic(base));
            ObjectSummary {
                name: o.name.clone(),
                spec_index: o.spec_index,
                instance: o.instance,
                triangles: o.triangle_count,
                faces: o.face_count,
                bounds_min_m: lo,
                bounds_max_m: hi,
                size_m: std::array::from_fn(|k| hi[k] - lo[k]),
                base_centre_m: base,
                base_centre_map_m: geo.as_ref().and_then(|g| g.scene_to_map(base)),
                base_centre_lat_lon_deg: ll.map(|(lat, lon, _)| [lat, lon]),
            }
        })
        .collect();
    (list, crs)
}

/// Builds the summary of a loaded scene.
pub fn summarize(s: &LoadedScene) -> SceneSummary {
    let sc = &s.scene;
    let (object_list, map_crs) = object_list(s);
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
            internal_power_w_m2: m.construction.internal_power_w_m2,
            library: m.library.clone(),
        })
        .collect();
    let used = |f: &dyn Fn(&super::Material) -> bool| -> Vec<String> {
        s.materials
            .iter()
            .zip(&counts)
            .filter(|(m, n)| **n > 0 && f(m))
            .map(|(m, _)| m.name.clone())
            .collect()
    };
    let specular_materials = used(&|m| m.is_specular());
    let heated_materials = used(&|m| m.construction.internal_power_w_m2 != 0.0);
    let (lo, hi) = s.bounds_m();
    let ground_z = sc.sensor.pose.target_m()[2];
    let band_um = s.response.support_um();
    let t_utc = sc.time.utc(&sc.site);
    let sun_el = crate::sun::approx::approx_sun_elevation_deg(
        t_utc,
        sc.site.location.latitude_deg,
        sc.site.location.longitude_deg,
    );
    // Sun up at any time of the history (sampled every 15 min)?
    let n_hist = (sc.render.history_hours * 4.0).ceil() as i64;
    let solar_heating = (0..=n_hist).any(|k| {
        let t = t_utc - chrono::Duration::minutes(15 * k);
        crate::sun::approx::approx_sun_elevation_deg(
            t,
            sc.site.location.latitude_deg,
            sc.site.location.longitude_deg,
        ) > 0.0
    });
    let (wn_lo, wn_hi) = (1e4 / band_um.1, 1e4 / band_um.0);
    let spectral_samples = ((wn_hi - wn_lo) / sc.render.spectral_step_cm1).floor() as usize + 1;
    let faces = s.objects.iter().map(|o| o.face_count as usize).sum();
    SceneSummary {
        scene: s.path.clone(),
        site: sc.site.clone(),
        time_local: sc.time.local.format("%Y-%m-%d %H:%M:%S").to_string(),
        time_utc: t_utc.to_rfc3339_opts(chrono::SecondsFormat::Secs, true),
        objects: s.objects.len(),
        object_list,
        map_crs,
        faces,
        triangles: s.triangles.len(),
        vertices: s.positions.len(),
        degenerate_skipped: s.degenerate_skipped,
        materials,
        bounds_min_m: lo,
        bounds_max_m: hi,
        local_frame: s.frame,
        warning: s.frame.warning(),
        warnings: s.warnings.clone(),
        camera: s.camera,
        footprint_m: s.camera.footprint(ground_z),
        centre_gsd_m: s.camera.centre_gsd_m(ground_z),
        band_um,
        weather: match &sc.weather {
            WeatherSpec::File {
                path,
                format,
                typical_year,
                stand_in,
            } => format!(
                "{format:?} file {}{}{}",
                s.resolve(path).display(),
                if *typical_year { " (typical year)" } else { "" },
                if *stand_in {
                    stand_in_note(s, path, *typical_year)
                } else {
                    String::new()
                }
            ),
            WeatherSpec::Constant(w) => format!(
                "constant: wind {} m/s, air {}..{} °C, dew point {} °C, cloud {}",
                w.wind_m_s, w.air_min_c, w.air_max_c, w.dew_point_c, w.cloud_fraction
            ),
        },
        atmosphere: format!(
            "{}, visibility {} km",
            sc.atmosphere.model.id(),
            sc.atmosphere.visibility_km
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

/// The weather line's note on a stand-in record: how far it is moved to
/// the site's solar time ([`crate::weather::stand_in_solar_shift`]), or
/// that it is not.
fn stand_in_note(s: &super::LoadedScene, path: &std::path::Path, typical_year: bool) -> String {
    let p = s.resolve(path);
    let shift = s
        .weather_record
        .parsed(&p, &crate::weather::station_options(typical_year))
        .ok()
        .and_then(|f| {
            crate::weather::stand_in_solar_shift(
                f.station.as_ref(),
                "",
                s.scene.site.location.longitude_deg,
            )
            .ok()
        });
    match shift {
        Some(by) => format!(
            " (a stand-in for the site) applied in the site's solar time: moved {:+.1} min",
            by.num_seconds() as f64 / 60.0
        ),
        None => " (a stand-in for the site) applied at its own UTC times (no station named)".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_of_the_airfield() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let s = crate::scene::load(&root.join("scenes/airfield/scene.toml")).unwrap();
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
        // 48 h at 60-min thermal steps and 60-min traced shadow samples
        assert_eq!(
            (sum.needs.thermal_steps, sum.needs.shadow_samples),
            (48, 48)
        );
        // footprint contains the target; JSON serialises
        let fp = sum.footprint_m.map(|p| p.unwrap());
        assert!(fp[0][1] > 20.0 && fp[2][1] < 20.0 && fp[0][0] < 0.0 && fp[1][0] > 0.0);
        let json = serde_json::to_string(&sum).unwrap();
        assert!(json.contains("\"solar_reflection\":true"));
    }
}

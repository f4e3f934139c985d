//! `irsig check <scene> [--json]`: load and validate a scene, then print a
//! summary of what it holds and what rendering it will need
//! ([`crate::scene::summary`]); then refuse what a render would refuse
//! before tracing ([`crate::render::prepare::validate`], the render's own
//! checks: memory limit, band, emissivity tables, atmosphere table and the
//! sensor's paths through it).

use std::path::PathBuf;

use crate::render::memory::{MemoryEstimate, check_report};
use crate::scene;
use crate::scene::summary::SceneSummary;

#[derive(clap::Args, Debug)]
/// `irsig check`: load and validate a scene.
pub struct Args {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// Override a scene key before loading, as for `irsig render`
    /// (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Remove a scene key (a value or a whole table) before the `--set`
    /// overrides, e.g. `--unset sensor.pose.altitude` to switch pose
    /// tables, or `--unset 'object[1]'` (repeatable).
    #[arg(long = "unset", value_name = "KEY")]
    pub unset: Vec<String>,
    /// Refuse what would only be a warning (a weather station more than
    /// 0.5 deg from the site).
    #[arg(long)]
    pub strict: bool,
}

/// Objects listed in the text summary (all of them in the JSON).
const OBJECT_LINES: usize = 50;

fn fmt3(v: [f64; 3]) -> String {
    format!("({:.1}, {:.1}, {:.1})", v[0], v[1], v[2])
}

/// Human-readable summary.
pub fn render_text(s: &SceneSummary) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let _ = writeln!(o, "scene      {}", s.scene.display());
    let _ = writeln!(
        o,
        "site       {} lat {:.4}° lon {:.4}° elevation {} m, UTC{:+}",
        s.site.name.as_deref().unwrap_or("-"),
        s.site.location.latitude_deg,
        s.site.location.longitude_deg,
        s.site.location.elevation_m,
        s.site.utc_offset_h
    );
    let _ = writeln!(o, "time       {} local ({})", s.time_local, s.time_utc);
    let _ = writeln!(
        o,
        "geometry   {} objects, {} faces, {} triangles, {} vertices, {} degenerate triangles skipped",
        s.objects, s.faces, s.triangles, s.vertices, s.degenerate_skipped
    );
    // Each object: where it stands and how big it is (at most
    // OBJECT_LINES; all in --json).
    let _ = writeln!(
        o,
        "objects    (triangles, size E×N×H m, base centre x, y, z m; on the map {})",
        s.map_crs
    );
    for ob in s.object_list.iter().take(OBJECT_LINES) {
        let map = ob
            .base_centre_map_m
            .map_or("-".to_string(), |m| format!("({:.1}, {:.1})", m[0], m[1]));
        let _ = writeln!(
            o,
            "  {:<20} {:>7}  {:.1}×{:.1}×{:.1}  {}  map {}",
            ob.name,
            ob.triangles,
            ob.size_m[0],
            ob.size_m[1],
            ob.size_m[2],
            fmt3(ob.base_centre_m),
            map
        );
    }
    if s.object_list.len() > OBJECT_LINES {
        let _ = writeln!(
            o,
            "  ... and {} more (all in --json)",
            s.object_list.len() - OBJECT_LINES
        );
    }
    let _ = writeln!(
        o,
        "bounds     {} .. {} m",
        fmt3(s.bounds_min_m),
        fmt3(s.bounds_max_m)
    );
    let f = &s.local_frame;
    let _ = writeln!(
        o,
        "frame      tracer origin {} m (camera target); geometry within {:.0} m of it, \
         single-precision positions exact to {:.3} mm (0.5 mm within {:.0} m; refused beyond {:.0} m)",
        fmt3(f.origin_m),
        f.extent_m,
        f.error_m * 1e3,
        f.precise_extent_m,
        f.max_extent_m
    );
    for w in s.warning.iter().chain(&s.warnings) {
        let _ = writeln!(o, "warning    {w}");
    }
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

/// The memory lines of the text summary.
pub fn memory_text(m: &MemoryEstimate) -> String {
    let limit = match m.limit_mib {
        Some(l) if m.total_mib > l => format!(
            "; over the limit of {l:.0} MiB ({}): a render is refused",
            m.limit_from
        ),
        Some(l) => format!(", limit {l:.0} MiB ({})", m.limit_from),
        None => ", no limit".to_string(),
    };
    format!(
        "  memory (estimated peak) {:.0} MiB: {} samples ({} at a time) × {:.0} B = {:.0} MiB, planes {:.0} MiB, \
         geometry {:.0} MiB, spectra {:.0} MiB, base {:.0} MiB{limit}\n",
        m.total_mib,
        m.samples,
        m.samples_held,
        m.bytes_per_sample,
        m.samples_mib,
        m.planes_mib,
        m.geometry_mib,
        m.spectral_mib,
        m.base_mib
    )
}

/// Runs `irsig check`; returns the process exit code (0: the scene loads).
pub fn run(a: Args) -> anyhow::Result<i32> {
    let overrides = super::render::parse_overrides(&a.set)?;
    let s = scene::load_with_edits(&a.scene, &a.unset, &overrides)?;
    // The weather must read and cover the render's history, as a render
    // would need it (a scene whose weather cannot be read fails here).
    let image_time = s.scene.time.utc(&s.scene.site);
    crate::render::weather::frame_weather(&s, image_time)?;
    super::log::warn_or_refuse(&crate::render::weather::weather_warnings(&s)?, a.strict)?;
    let r = check_report(&s);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        print!("{}{}", render_text(&r.summary), memory_text(&r.memory));
    }
    // What a render refuses before tracing, by the render's own checks:
    // the summary is printed first, then the refusal (exit status 1).
    crate::render::prepare::validate(&s)?;
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_of_the_airfield() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let s = scene::load(&root.join("scenes/airfield/scene.toml")).unwrap();
        assert!(
            render_text(&crate::scene::summary::summarize(&s))
                .contains("specular bounce rays    yes")
        );
    }
}

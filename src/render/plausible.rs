//! The plausibility of a render's surface temperatures (issue 33): every
//! input in range can still combine into a surface no real scene has (an
//! in-range `internal_power_w_m2 = -1000` cooled a plate to 16 K in 300 K
//! air). A surface temperature outside [`PLAUSIBLE_K`] is reported with
//! the material of the most extreme pixel and the flux term that dominates
//! its energy balance at the image time; `irsig render` prints it as a
//! warning, or refuses the render with `--strict` (before writing).

use super::planes::Planes;
use super::prepare::{Conditions, Static};
use crate::bounds::Bound;

/// Surface temperatures a real outdoor scene holds: 150 K (below the
/// coldest measured surface, −98 °C on the Antarctic plateau, with margin)
/// to 600 K (hot engine parts and fires aside, above any sunlit surface).
pub const PLAUSIBLE_K: Bound = Bound::new("surface temperature", 150.0, 600.0, "K");

/// The warnings for `planes` (one line each; empty when every surface
/// temperature is plausible). The most extreme pixel is probed (thermal
/// series kept) for its material and dominant flux term.
pub fn surface_temperature_warnings(
    st: &Static,
    cond: &Conditions,
    planes: &Planes,
) -> anyhow::Result<Vec<String>> {
    surface_temperature_warnings_in(st, cond, planes, PLAUSIBLE_K)
}

/// As [`surface_temperature_warnings`], against the range `plausible`.
pub fn surface_temperature_warnings_in(
    st: &Static,
    cond: &Conditions,
    planes: &Planes,
    plausible: Bound,
) -> anyhow::Result<Vec<String>> {
    let Some(p) = planes.get("surface_temperature") else {
        return Ok(Vec::new());
    };
    let w = planes.width.max(1) as usize;
    let mid = 0.5 * (plausible.lo + plausible.hi);
    let mut worst: Option<(usize, f32)> = None;
    let mut n = 0usize;
    for (i, &t) in p.data.iter().enumerate() {
        if t.is_nan() || plausible.contains(t.into()) {
            continue;
        }
        n += 1;
        let far = |v: f32| (f64::from(v) - mid).abs();
        if worst.is_none_or(|(_, b)| far(t) > far(b)) {
            worst = Some((i, t));
        }
    }
    let Some((i, t)) = worst else {
        return Ok(Vec::new());
    };
    let (x, y) = ((i % w) as u32, (i / w) as u32);
    let mut c = super::prepare::prepare_conditions(st, cond.image_time)?;
    c.cache = crate::therm::cache::ThermCache::new(
        *cond.cache.settings(),
        cond.cache.orientation_quantum_deg(),
        true,
    );
    let probe = super::probe::probe(st, &c, (x, y), false)?;
    let hit = probe.samples.iter().find_map(|s| s.hit.as_ref());
    let material = hit.map_or("?".to_string(), |h| h.material.clone());
    let dominant = hit
        .and_then(|h| h.thermal.series.last())
        .map_or(String::new(), |r| {
            let v = serde_json::to_value(r).unwrap_or_default();
            let mut terms: Vec<(String, f64)> = Vec::new();
            collect_fluxes(&v, &mut terms);
            terms
                .into_iter()
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .map_or(String::new(), |(k, f)| {
                    format!("; its largest flux term is {k} = {f:.0} W/m²")
                })
        });
    Ok(vec![format!(
        "{n} pixel(s) have a surface temperature outside the plausible {} to {} K; the most \
         extreme, pixel ({x}, {y}), is {t:.1} K on material `{material}`{dominant}: check the \
         material's properties (e.g. internal_power_w_m2) and the weather",
        plausible.lo, plausible.hi
    )])
}

/// The `*_w_m2` numbers of a JSON record (nested objects included).
fn collect_fluxes(v: &serde_json::Value, out: &mut Vec<(String, f64)>) {
    if let Some(m) = v.as_object() {
        for (k, x) in m {
            if let Some(f) = x.as_f64().filter(|_| k.ends_with("_w_m2")) {
                out.push((k.clone(), f));
            } else if x.is_object() {
                collect_fluxes(x, out);
            }
        }
    }
}

//! The surface water store of a solid (rain in, evaporation out): the
//! wet surface's evaporation cap and the store's update per step, used by
//! the march ([`super::SlabModel::advance`]).

use crate::therm::aero;
use crate::therm::balance::SurfaceDrive;

/// Opens a solid's surface store to evaporation for a step of `h_s`
/// seconds: free evaporation (no surface resistance) while the store holds
/// water or rain falls, at most what the store and the rain supply over the
/// step, `λ·(W/h + P)`.
pub fn wet_drive(d: &mut SurfaceDrive, store_mm: f64, precip_mm_h: f64, air_temp_k: f64, h_s: f64) {
    let supply_kg_m2_s = store_mm.max(0.0) / h_s + precip_mm_h.max(0.0) / 3600.0;
    if supply_kg_m2_s > 0.0 {
        d.conductance_m_s = f64::INFINITY;
        d.evaporation_cap_w_m2 = aero::latent_heat_j_kg(air_temp_k) * supply_kg_m2_s;
    }
}

/// The surface store after a step of `h_s` seconds: rain in, evaporation
/// out (dew in), clipped to `[0, capacity]` (the excess runs off). The
/// evaporated mass is `−λE/λ`, the same λ as [`wet_drive`]'s cap.
pub fn update_store_mm(
    store_mm: f64,
    capacity_mm: f64,
    precip_mm_h: f64,
    latent_w_m2: f64,
    air_temp_k: f64,
    h_s: f64,
) -> f64 {
    let evap_kg_m2_s = -latent_w_m2 / aero::latent_heat_j_kg(air_temp_k);
    (store_mm + (precip_mm_h.max(0.0) / 3600.0 - evap_kg_m2_s) * h_s).clamp(0.0, capacity_mm)
}

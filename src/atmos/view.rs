//! What an atmosphere contributes for one geometry over one band (what
//! `irsig atmos show` prints): the path transmission and radiances, the sky
//! radiances toward one zenith and averaged over the dome, the solar
//! transmission and irradiance, bin by bin and band-integrated.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::Atmosphere;
use crate::radiometry::{Band, SpectralGrid, SpectralResponse};

/// A viewing and sun geometry.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct AtmosGeometry {
    /// Sensor altitude above the target, km.
    pub altitude_km: f64,
    /// View zenith angle at the target, degrees.
    pub view_zenith_deg: f64,
    /// Sky zenith angle for L_DE and L_DS, degrees.
    pub sky_zenith_deg: f64,
    /// Sun zenith angle, degrees.
    pub sun_zenith_deg: f64,
    /// Sun azimuth minus line-of-sight azimuth, degrees.
    pub rel_azimuth_deg: f64,
}

/// The atmosphere's terms over a band, one value per band bin (radiance in
/// W m⁻² sr⁻¹ µm⁻¹, irradiance in W m⁻² µm⁻¹).
#[derive(Clone, Debug, Serialize)]
pub struct AtmosView {
    /// The atmosphere's name.
    pub name: String,
    /// What it is.
    pub description: String,
    /// The table file.
    pub source: PathBuf,
    /// The geometry the terms are for.
    pub geometry: AtmosGeometry,
    /// Band label.
    pub band: String,
    /// Bins of the table's grid inside the band.
    pub grid_bins: usize,
    /// The band's bins, cm⁻¹.
    pub wavenumber_cm1: Vec<f64>,
    /// Band weight of each bin (the weights sum to 1).
    pub weight: Vec<f64>,
    /// Target → sensor transmission.
    pub tau2: Vec<f64>,
    /// Path thermal radiance.
    pub l_ue: Vec<f64>,
    /// Path scattered radiance.
    pub l_us: Vec<f64>,
    /// Sky thermal radiance toward the sky zenith.
    pub l_de: Vec<f64>,
    /// Sky scattered radiance toward the sky zenith.
    pub l_ds: Vec<f64>,
    /// Sky thermal radiance averaged over the sky dome.
    pub l_de_dome: Vec<f64>,
    /// Sky scattered radiance averaged over the sky dome.
    pub l_ds_dome: Vec<f64>,
    /// Sun → ground transmission.
    pub tau1: Vec<f64>,
    /// Exo-atmospheric solar irradiance.
    pub e_sun_exo: Vec<f64>,
    /// τ₁·E_S at the ground.
    pub e_sun_ground: Vec<f64>,
    /// The response-weighted mean of each term over the band, labelled.
    pub band_integrated: Vec<(String, f64)>,
}

/// The response of `band`: a response CSV file (`wavelength_um,response`)
/// when a file of that name exists, else `8-14`, `3-5` or `<lo>-<hi>` µm.
pub fn response_of(band: &str) -> anyhow::Result<SpectralResponse> {
    Ok(if Path::new(band).is_file() {
        SpectralResponse::from_csv(Path::new(band))?
    } else {
        SpectralResponse::parse_band(band)?
    })
}

/// The terms of atmosphere `name` (a shipped table's name or a table file)
/// for geometry `g` over `band` (see [`response_of`]).
pub fn atmos_view(name: &str, band: &str, g: AtmosGeometry) -> anyhow::Result<AtmosView> {
    let atm = Atmosphere::by_name_or_path(name)?;
    let resp = response_of(band)?;
    let grid = SpectralGrid::new(atm.wavenumber_cm1().to_vec())?;
    let band = Band::new(&grid, &resp)?;
    let sa = atm.resample(&band.wavenumber_cm1)?;
    let n = sa.len();
    let path = sa.path(
        g.altitude_km,
        g.view_zenith_deg,
        g.sun_zenith_deg,
        g.rel_azimuth_deg,
    )?;
    let mut l_de = vec![0.0; n];
    let mut l_ds = vec![0.0; n];
    let mut tau1 = vec![0.0; n];
    let mut e_gnd = vec![0.0; n];
    sa.l_de(g.sky_zenith_deg, &mut l_de)?;
    sa.l_ds(
        g.sun_zenith_deg,
        g.rel_azimuth_deg,
        g.sky_zenith_deg,
        &mut l_ds,
    )?;
    sa.tau_sun(g.sun_zenith_deg, &mut tau1)?;
    sa.sun_irradiance_ground(g.sun_zenith_deg, &mut e_gnd)?;
    let dome_de = sa.sky_dome_l_de().to_vec();
    let dome_ds = sa.sky_dome_l_ds(g.sun_zenith_deg)?;
    let e_exo = sa.e_sun_exo().to_vec();
    let rows: [(&str, &[f64]); 10] = [
        ("tau2 (target->sensor)", &path.tau2),
        ("L_UE path thermal", &path.l_ue_w_m2_sr_um),
        ("L_US path scattered", &path.l_us_w_m2_sr_um),
        ("L_DE sky thermal", &l_de),
        ("L_DS sky scattered", &l_ds),
        ("L_DE sky dome average", &dome_de),
        ("L_DS sky dome average", &dome_ds),
        ("tau1 (sun->ground)", &tau1),
        ("E_S exo-atmospheric", &e_exo),
        ("tau1*E_S at ground", &e_gnd),
    ];
    let band_integrated = rows
        .iter()
        .map(|(label, v)| (label.to_string(), band.integrate(v)))
        .collect();
    let t = &atm.table;
    Ok(AtmosView {
        name: t.name.clone(),
        description: t.description.clone(),
        source: t.source.clone(),
        geometry: g,
        band: band.label.clone(),
        grid_bins: grid.wavenumber_cm1.len(),
        wavenumber_cm1: band.wavenumber_cm1.clone(),
        weight: band.weights.clone(),
        tau2: path.tau2,
        l_ue: path.l_ue_w_m2_sr_um,
        l_us: path.l_us_w_m2_sr_um,
        l_de,
        l_ds,
        l_de_dome: dome_de,
        l_ds_dome: dome_ds,
        tau1,
        e_sun_exo: e_exo,
        e_sun_ground: e_gnd,
        band_integrated,
    })
}

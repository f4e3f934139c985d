//! `irsig atmos`: list the shipped atmosphere tables and show what a scene
//! would use (τ, path and sky radiance, band-integrated and spectral).

use anyhow::Context;
use clap::{Args as ClapArgs, Subcommand};

use crate::atmos::{Atmosphere, list_builtin};
use crate::radiometry::{Band, SpectralGrid, SpectralResponse};

#[derive(ClapArgs, Debug)]
pub struct Args {
    #[command(subcommand)]
    pub cmd: AtmosCmd,
}

#[derive(Subcommand, Debug)]
pub enum AtmosCmd {
    /// List the shipped atmosphere tables.
    List,
    /// Show τ₂, path and sky radiance for a geometry, band-integrated and spectral.
    Show(ShowArgs),
}

#[derive(ClapArgs, Debug)]
pub struct ShowArgs {
    /// Atmosphere name (see `irsig atmos list`) or path to a table file.
    pub name: String,
    /// Sensor altitude above the target, km.
    #[arg(long)]
    pub altitude: f64,
    /// View zenith angle at the target, degrees (also the sky zenith unless --sky-zenith).
    #[arg(long)]
    pub zenith: f64,
    /// Sky zenith angle for L_DE, L_DS, degrees (default: --zenith).
    #[arg(long)]
    pub sky_zenith: Option<f64>,
    /// Sun zenith angle, degrees.
    #[arg(long, default_value_t = 45.0)]
    pub sun_zenith: f64,
    /// Sun azimuth minus line-of-sight azimuth, degrees.
    #[arg(long, default_value_t = 90.0)]
    pub rel_azimuth: f64,
    /// Band: 8-14, 3-5, <lo>-<hi> in µm, or a response CSV file (wavelength_um,response).
    #[arg(long, default_value = "8-14")]
    pub band: String,
    /// Print the spectral values as CSV.
    #[arg(long)]
    pub csv: bool,
}

pub fn run(a: Args) -> anyhow::Result<i32> {
    match a.cmd {
        AtmosCmd::List => {
            let list = list_builtin().context("listing atmosphere tables")?;
            if list.is_empty() {
                println!("no tables in {}", crate::atmos::atmos_dir().display());
            }
            for (name, path, desc) in list {
                println!("{name:<10} {desc}\n{:<10} {}", "", path.display());
            }
            Ok(0)
        }
        AtmosCmd::Show(s) => show(s),
    }
}

fn show(s: ShowArgs) -> anyhow::Result<i32> {
    let atm = Atmosphere::by_name_or_path(&s.name)?;
    let resp = if std::path::Path::new(&s.band).is_file() {
        SpectralResponse::from_csv(std::path::Path::new(&s.band))?
    } else {
        SpectralResponse::parse_band(&s.band)?
    };
    let grid = SpectralGrid::new(atm.wavenumber_cm1().to_vec())?;
    let band = Band::new(&grid, &resp)?;
    let sa = atm.resample(&band.wavenumber_cm1)?;
    let n = sa.len();
    let sky_zen = s.sky_zenith.unwrap_or(s.zenith);
    let path = sa.path(s.altitude, s.zenith, s.sun_zenith, s.rel_azimuth)?;
    let mut l_de = vec![0.0; n];
    let mut l_ds = vec![0.0; n];
    let mut tau1 = vec![0.0; n];
    let mut e_gnd = vec![0.0; n];
    sa.l_de(sky_zen, &mut l_de)?;
    sa.l_ds(s.sun_zenith, s.rel_azimuth, sky_zen, &mut l_ds)?;
    sa.tau_sun(s.sun_zenith, &mut tau1)?;
    sa.sun_irradiance_ground(s.sun_zenith, &mut e_gnd)?;
    let dome_de = sa.sky_dome_l_de().to_vec();
    let dome_ds = sa.sky_dome_l_ds(s.sun_zenith)?;
    if s.csv {
        println!(
            "wavenumber_cm1,wavelength_um,weight,tau2,l_ue,l_us,l_de,l_ds,l_de_dome,l_ds_dome,tau1,e_sun_ground"
        );
        for i in 0..n {
            let nu = band.wavenumber_cm1[i];
            println!(
                "{nu},{:.6},{:.6e},{:.6},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6},{:.6e}",
                1e4 / nu,
                band.weights[i],
                path.tau2[i],
                path.l_ue_w_m2_sr_um[i],
                path.l_us_w_m2_sr_um[i],
                l_de[i],
                l_ds[i],
                dome_de[i],
                dome_ds[i],
                tau1[i],
                e_gnd[i]
            );
        }
        return Ok(0);
    }
    let t = &atm.table;
    println!("atmosphere   {} — {}", t.name, t.description);
    println!("table        {}", t.source.display());
    println!(
        "geometry     sensor {} km, view zenith {}°, sky zenith {}°, sun zenith {}°, relative azimuth {}°",
        s.altitude, s.zenith, sky_zen, s.sun_zenith, s.rel_azimuth
    );
    println!(
        "band         {} ({} bins of {} cm-1 grid)",
        band.label,
        band.len(),
        grid.wavenumber_cm1.len()
    );
    println!(
        "band-integrated (response-weighted mean over the band; radiance W m-2 sr-1 um-1, irradiance W m-2 um-1):"
    );
    let rows: [(&str, &[f64]); 10] = [
        ("tau2 (target->sensor)", &path.tau2),
        ("L_UE path thermal", &path.l_ue_w_m2_sr_um),
        ("L_US path scattered", &path.l_us_w_m2_sr_um),
        ("L_DE sky thermal", &l_de),
        ("L_DS sky scattered", &l_ds),
        ("L_DE sky dome average", &dome_de),
        ("L_DS sky dome average", &dome_ds),
        ("tau1 (sun->ground)", &tau1),
        ("E_S exo-atmospheric", sa.e_sun_exo()),
        ("tau1*E_S at ground", &e_gnd),
    ];
    for (label, v) in rows {
        println!("  {label:<24} {:>12.5e}", band.integrate(v));
    }
    println!("spectral:");
    println!(
        "  {:>8} {:>8} {:>8} {:>11} {:>11} {:>11} {:>11} {:>8} {:>11}",
        "cm-1", "um", "tau2", "L_UE", "L_US", "L_DE", "L_DS", "tau1", "tau1*E_S"
    );
    for i in 0..n {
        let nu = band.wavenumber_cm1[i];
        println!(
            "  {:>8.1} {:>8.4} {:>8.5} {:>11.4e} {:>11.4e} {:>11.4e} {:>11.4e} {:>8.5} {:>11.4e}",
            nu,
            1e4 / nu,
            path.tau2[i],
            path.l_ue_w_m2_sr_um[i],
            path.l_us_w_m2_sr_um[i],
            l_de[i],
            l_ds[i],
            tau1[i],
            e_gnd[i]
        );
    }
    Ok(0)
}

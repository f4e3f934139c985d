//! `irsig atmos`: list the shipped atmosphere tables and show what a scene
//! would use (τ, path and sky radiance, band-integrated and spectral;
//! [`crate::atmos::view`]).

use anyhow::Context;
use clap::{Args as ClapArgs, Subcommand};

use crate::atmos::list_builtin;
use crate::atmos::view::{AtmosGeometry, atmos_view};

#[derive(ClapArgs, Debug)]
/// `irsig atmos`: the atmosphere tables.
pub struct Args {
    #[command(subcommand)]
    /// Which of the table commands.
    pub cmd: AtmosCmd,
}

#[derive(Subcommand, Debug)]
/// The `irsig atmos` subcommands.
pub enum AtmosCmd {
    /// List the shipped atmosphere tables.
    List,
    /// Show τ₂, path and sky radiance for a geometry, band-integrated and spectral.
    Show(ShowArgs),
}

#[derive(ClapArgs, Debug)]
/// `irsig atmos show`: what a geometry's path reads from a table.
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

/// Runs `irsig atmos`; returns the process exit code.
pub fn run(a: Args) -> anyhow::Result<i32> {
    match a.cmd {
        AtmosCmd::List => {
            let list = list_builtin().context("listing atmosphere tables")?;
            for (name, source, desc) in list {
                println!("{name:<10} {desc}\n{:<10} {source}", "");
            }
            Ok(0)
        }
        AtmosCmd::Show(s) => show(s),
    }
}

fn show(s: ShowArgs) -> anyhow::Result<i32> {
    let g = AtmosGeometry {
        altitude_km: s.altitude,
        view_zenith_deg: s.zenith,
        sky_zenith_deg: s.sky_zenith.unwrap_or(s.zenith),
        sun_zenith_deg: s.sun_zenith,
        rel_azimuth_deg: s.rel_azimuth,
    };
    let v = atmos_view(&s.name, &s.band, g)?;
    let n = v.wavenumber_cm1.len();
    if s.csv {
        println!(
            "wavenumber_cm1,wavelength_um,weight,tau2,l_ue,l_us,l_de,l_ds,l_de_dome,l_ds_dome,tau1,e_sun_ground"
        );
        for i in 0..n {
            let nu = v.wavenumber_cm1[i];
            println!(
                "{nu},{:.6},{:.6e},{:.6},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6},{:.6e}",
                1e4 / nu,
                v.weight[i],
                v.tau2[i],
                v.l_ue[i],
                v.l_us[i],
                v.l_de[i],
                v.l_ds[i],
                v.l_de_dome[i],
                v.l_ds_dome[i],
                v.tau1[i],
                v.e_sun_ground[i]
            );
        }
        return Ok(0);
    }
    println!("atmosphere   {} — {}", v.name, v.description);
    println!("table        {}", v.source.display());
    println!(
        "geometry     sensor {} km, view zenith {}°, sky zenith {}°, sun zenith {}°, relative azimuth {}°",
        g.altitude_km, g.view_zenith_deg, g.sky_zenith_deg, g.sun_zenith_deg, g.rel_azimuth_deg
    );
    println!(
        "band         {} ({} bins of {} cm-1 grid)",
        v.band, n, v.grid_bins
    );
    println!(
        "band-integrated (response-weighted mean over the band; radiance W m-2 sr-1 um-1, irradiance W m-2 um-1):"
    );
    for (label, x) in &v.band_integrated {
        println!("  {label:<24} {x:>12.5e}");
    }
    println!("spectral:");
    println!(
        "  {:>8} {:>8} {:>8} {:>11} {:>11} {:>11} {:>11} {:>8} {:>11}",
        "cm-1", "um", "tau2", "L_UE", "L_US", "L_DE", "L_DS", "tau1", "tau1*E_S"
    );
    for i in 0..n {
        let nu = v.wavenumber_cm1[i];
        println!(
            "  {:>8.1} {:>8.4} {:>8.5} {:>11.4e} {:>11.4e} {:>11.4e} {:>11.4e} {:>8.5} {:>11.4e}",
            nu,
            1e4 / nu,
            v.tau2[i],
            v.l_ue[i],
            v.l_us[i],
            v.l_de[i],
            v.l_ds[i],
            v.tau1[i],
            v.e_sun_ground[i]
        );
    }
    Ok(0)
}

//! `irsig therm`: surface temperature and every flux term of one material
//! and facet over time (the seed paper's Fig. 6 use).
//!
//! The computation is [`crate::therm::series::facet_series`]; this file
//! parses the flags and prints its rows (table, CSV or JSON).
//!
//! ```text
//! irsig therm --materials mats.toml --material concrete
//!             (--weather <TMY3|EPW|CSV> | --forcing <forcing.csv>)
//!             --lat 36.1 --lon -79.95 [--elevation 273]
//!             --slope 0 --aspect 180 --from 2021-05-05T05:00:00Z --to 2021-05-06T05:00:00Z
//!             --step 15 [--spin-up-h 24] [--spin-up-start mean-forcing|first-sample]
//!             [--shadow RANGES] [--csv | --json]
//! ```
//!
//! * The march starts `--spin-up-h` hours before `--from` (from a steady
//!   state, `--spin-up-start`: under the mean forcing, or the first sample)
//!   and prints one row per forcing sample from `--from` to `--to`.
//! * `--forcing` takes a forcing CSV with the columns
//!   `t_s,air_temp_k,sky_temp_k,wind_speed_m_s,dni_w_m2,dhi_w_m2,ghi_w_m2,sun_e,sun_n,sun_u`
//!   (lines starting with `#` ignored; `tools/ref_therm.py` writes one);
//!   its `t_s = 0` is the start of the spin-up, `--from − --spin-up-h`.
//!   `--step` is then the CSV's own.
//! * `--shadow`: comma-separated UTC ranges `START/END` (RFC 3339) or
//!   daily UTC time-of-day ranges `HH:MM-HH:MM`; the pixel is shaded
//!   (no direct sun) inside them. The history is sampled at every forcing
//!   time (nearest-sample rule of `SunHistory`).
//! * Materials file: a material library as the scenes use
//!   (`[material.NAME]` tables, docs/scene-format.md), e.g. scenes/materials.toml.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, bail};

use crate::scene::lookup::load_material;
use crate::therm::aero::SurfaceLayer;
use crate::therm::balance::{Convection, Orientation};
use crate::therm::series::{
    FacetRun, ForcingSource, ThermRow, facet_series, parse_shadow_ranges, parse_time,
};
use crate::therm::slab::SpinUpStart;
use crate::units::ZERO_C_K;

/// `--convection`: `surface-layer` (the default) or `mcadams` (see
/// [`Convection`]).
// clap: a doc comment on a value becomes its help and turns the whole
// `irsig therm --help` into the long form; the flag's help describes them.
#[allow(missing_docs)]
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConvectionArg {
    SurfaceLayer,
    Mcadams,
}

/// `--spin-up-start`: `mean-forcing` (the default) or `first-sample` (see
/// [`SpinUpStart`]).
// clap: as for [`ConvectionArg`], the flag's help describes the values.
#[allow(missing_docs)]
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum SpinUpArg {
    MeanForcing,
    FirstSample,
}

#[derive(clap::Args, Debug)]
/// `irsig therm`: one material and facet over time.
pub struct Args {
    /// Material library (TOML, `[material.NAME]` tables, as the scenes use;
    /// e.g. scenes/materials.toml).
    #[arg(long)]
    pub materials: PathBuf,
    /// Material name in the materials file.
    #[arg(long)]
    pub material: String,
    /// Weather file (TMY3, EnergyPlus EPW or plain CSV).
    #[arg(long, conflicts_with = "forcing", required_unless_present = "forcing")]
    pub weather: Option<PathBuf>,
    /// The weather file is a typical year (TMY2/TMY3/EPW/PVGIS...: each
    /// month from a different year): it is laid on every year of the run,
    /// wrapping from 31 December to its own 1 January (the scene key
    /// `typical_year = true` in [weather.file]).
    #[arg(long)]
    pub typical_year: bool,
    /// The weather file's station stands in for the site on purpose (the
    /// scene key `weather.file.stand_in`): no warning about its distance,
    /// and the record is applied in the site's solar time (moved by the
    /// longitude difference / 15 deg h), as a render applies it.
    #[arg(long)]
    pub stand_in: bool,
    /// Refuse what would only be a warning (a weather station more than
    /// 0.5 deg from the site).
    #[arg(long)]
    pub strict: bool,
    /// A ready forcing CSV instead of a weather file (see module docs).
    #[arg(long)]
    pub forcing: Option<PathBuf>,
    /// Site latitude, degrees north.
    #[arg(long, allow_hyphen_values = true)]
    pub lat: f64,
    /// Site longitude, degrees east.
    #[arg(long, allow_hyphen_values = true)]
    pub lon: f64,
    /// Site elevation, m.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub elevation: f64,
    /// Facet slope from horizontal, degrees.
    #[arg(long, default_value_t = 0.0)]
    pub slope: f64,
    /// Facet aspect (azimuth of the downslope direction, clockwise from north), degrees.
    #[arg(long, default_value_t = 180.0)]
    pub aspect: f64,
    /// The facet's sky view factor where the scene hides part of its sky
    /// (the value `irsig probe` prints for a surface point; the rest of the
    /// hemisphere at the ground temperature of the forcing, else the air's);
    /// default: the open sky of its slope, (1 + cos β)/2.
    #[arg(long)]
    pub sky_view: Option<f64>,
    /// First output time (RFC 3339).
    #[arg(long)]
    pub from: String,
    /// Last output time (RFC 3339).
    #[arg(long)]
    pub to: String,
    /// Forcing/output step, minutes.
    #[arg(long, default_value_t = 15.0)]
    pub step: f64,
    /// Hours of spin-up before --from.
    #[arg(long, default_value_t = 24.0)]
    pub spin_up_h: f64,
    /// Initial profile of the spin-up: the steady state under the mean
    /// forcing of the whole run, or under its first sample (THERM's).
    #[arg(long, value_enum, default_value_t = SpinUpArg::MeanForcing)]
    pub spin_up_start: SpinUpArg,
    /// Height of the weather record's anemometer above the ground, m.
    #[arg(long, default_value_t = 10.0)]
    pub wind_height_m: f64,
    /// Height above the surface at which the air temperature and humidity
    /// hold, m (screen height).
    #[arg(long, default_value_t = 2.0)]
    pub air_height_m: f64,
    /// Roughness length of the site's terrain, m (moves the wind from the
    /// anemometer to the facet).
    #[arg(long, default_value_t = 0.03)]
    pub site_roughness_m: f64,
    /// Height of the facet above the ground, m.
    #[arg(long, default_value_t = 0.0)]
    pub facet_height_m: f64,
    /// Convection model: the surface layer (convective only, the default)
    /// or McAdams' 5.7 + 3.8 v (radiation folded in; for comparison with
    /// THERM-era results only).
    #[arg(long, value_enum, default_value_t = ConvectionArg::SurfaceLayer)]
    pub convection: ConvectionArg,
    /// Shadow ranges (see module docs).
    #[arg(long, allow_hyphen_values = true)]
    pub shadow: Option<String>,
    /// Output CSV (default: an aligned table).
    #[arg(long, conflicts_with = "json")]
    pub csv: bool,
    /// Output JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `irsig therm`; returns the process exit code.
pub fn run(a: Args) -> anyhow::Result<i32> {
    use crate::bounds::args;
    for (arg, v) in [
        (args::THERM_STEP_MIN, a.step),
        (args::THERM_SPIN_UP_H, a.spin_up_h),
        (args::THERM_FACET_HEIGHT, a.facet_height_m),
        (args::LAT, a.lat),
        (args::LON, a.lon),
        (args::ELEVATION, a.elevation),
        (args::SLOPE, a.slope),
        (args::ASPECT, a.aspect),
    ] {
        arg.check_flag(v).map_err(anyhow::Error::msg)?;
    }
    if let Some(f) = a.sky_view {
        args::SKY_VIEW.check_flag(f).map_err(anyhow::Error::msg)?;
    }
    let mat = load_material(&a.materials, &a.material)?;
    let from = parse_time(&a.from).context("--from")?;
    let to = parse_time(&a.to).context("--to")?;
    if to < from {
        bail!("--to {} is before --from {}", a.to, a.from);
    }
    if let Some(p) = &a.weather {
        let station = crate::weather::read_station(p, a.typical_year)?;
        let file = p.display().to_string();
        let warning = if a.stand_in {
            crate::weather::stand_in_solar_shift(station.as_ref(), &file, a.lon).err()
        } else {
            station.and_then(|st| crate::weather::station_mismatch(&st, &file, a.lat, a.lon))
        };
        super::log::warn_or_refuse(&warning.into_iter().collect::<Vec<_>>(), a.strict)?;
    }
    let run = FacetRun {
        material_name: a.material.clone(),
        material: mat,
        forcing: match (&a.forcing, &a.weather) {
            (Some(p), _) => ForcingSource::ForcingCsv(p.clone()),
            (None, Some(p)) => ForcingSource::Weather {
                path: p.clone(),
                typical_year: a.typical_year,
                stand_in: a.stand_in,
            },
            (None, None) => bail!("give --weather or --forcing"),
        },
        site: crate::sun::Site {
            latitude_deg: a.lat,
            longitude_deg: a.lon,
            elevation_m: a.elevation,
        },
        orientation: Orientation {
            slope_deg: a.slope,
            aspect_deg: a.aspect,
        },
        from,
        to,
        step_min: a.step,
        spin_up_h: a.spin_up_h,
        spin_up_start: match a.spin_up_start {
            SpinUpArg::MeanForcing => SpinUpStart::MeanForcing,
            SpinUpArg::FirstSample => SpinUpStart::FirstSample,
        },
        convection: match a.convection {
            ConvectionArg::SurfaceLayer => Convection::SurfaceLayer(SurfaceLayer {
                wind_height_m: a.wind_height_m,
                air_height_m: a.air_height_m,
                site_roughness_m: a.site_roughness_m,
            }),
            ConvectionArg::Mcadams => Convection::mcadams(),
        },
        facet_height_m: a.facet_height_m,
        shadow: match &a.shadow {
            Some(s) => parse_shadow_ranges(s)?,
            None => Vec::new(),
        },
        sky_view: a.sky_view,
    };
    let series = facet_series(&run)?;
    for l in &series.estimator_lines {
        eprintln!("{l}");
    }
    let mut out = std::io::stdout().lock();
    if a.json {
        serde_json::to_writer_pretty(&mut out, &series)?;
        writeln!(out)?;
    } else {
        write_table(&mut out, &series.rows, a.csv)?;
    }
    Ok(0)
}

const COLUMNS: [&str; 27] = [
    "time_utc",
    "t_s",
    "surface_temp_k",
    "air_temp_k",
    "sunlit",
    "absorbed_direct_w_m2",
    "absorbed_diffuse_w_m2",
    "absorbed_ground_reflected_w_m2",
    "sky_longwave_in_w_m2",
    "ground_longwave_in_w_m2",
    "emitted_longwave_w_m2",
    "convection_w_m2",
    "latent_w_m2",
    "rain_w_m2",
    "internal_w_m2",
    "net_surface_w_m2",
    "conduction_into_slab_w_m2",
    "back_w_m2",
    "convection_coeff_w_m2k",
    "water_store_mm",
    "sky_view",
    "sunlit_fraction",
    "surface_temp_c",
    "richardson",
    "stability_factor",
    "soil_surface_temp_k",
    "melt_w_m2",
];

fn write_table(out: &mut impl Write, rows: &[ThermRow], csv: bool) -> std::io::Result<()> {
    let sep = if csv { "," } else { " " };
    if csv {
        writeln!(out, "{}", COLUMNS.join(sep))?;
    } else {
        writeln!(out, "# {}", COLUMNS.join(sep))?;
    }
    for r in rows {
        let s = &r.rec.surface;
        let nums = [
            r.rec.surface_temp_k,
            r.rec.air_temp_k,
            if r.rec.sunlit { 1.0 } else { 0.0 },
            s.absorbed_direct_w_m2,
            s.absorbed_diffuse_w_m2,
            s.absorbed_ground_reflected_w_m2,
            s.sky_longwave_in_w_m2,
            s.ground_longwave_in_w_m2,
            s.emitted_longwave_w_m2,
            s.convection_w_m2,
            s.latent_w_m2,
            s.rain_w_m2,
            s.internal_w_m2,
            s.net_w_m2,
            r.rec.conduction_into_slab_w_m2,
            r.rec.back_w_m2,
            s.convection_coeff_w_m2k,
            r.rec.water_store_mm,
            r.rec.sky_view,
            r.rec.sunlit_fraction,
            r.rec.surface_temp_k - ZERO_C_K,
            s.richardson,
            r.stability_factor,
            r.rec.soil_surface_temp_k,
            r.rec.melt_w_m2,
        ];
        let cells: Vec<String> = nums.iter().map(|v| format!("{v:.3}")).collect();
        writeln!(
            out,
            "{}{sep}{}{sep}{}",
            r.time_utc,
            r.rec.t_s,
            cells.join(sep)
        )?;
    }
    Ok(())
}

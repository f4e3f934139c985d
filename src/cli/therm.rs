//! `irsig therm`: surface temperature and every flux term of one material
//! and facet over time (the seed paper's Fig. 6 use).
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
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use chrono::{DateTime, Duration, NaiveTime, Timelike, Utc};
use serde::Serialize;

use crate::therm::aero::SurfaceLayer;
use crate::therm::balance::{Convection, Orientation};
use crate::therm::forcing::Forcing;
use crate::therm::slab::{
    SlabMaterial, SlabModel, SpinUpStart, StepRecord, SunHistory, ThermSettings,
};

/// `--convection`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConvectionArg {
    SurfaceLayer,
    Mcadams,
}

/// `--spin-up-start` (see [`SpinUpStart`]).
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum SpinUpArg {
    MeanForcing,
    FirstSample,
}

#[derive(clap::Args, Debug)]
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
    /// Treat the weather file as a typical year (TMY3/EPW): its records
    /// take the year of the spin-up start.
    #[arg(long)]
    pub typical_year: bool,
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

/// A shadow range: absolute UTC interval or daily UTC time-of-day interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowRange {
    Absolute(DateTime<Utc>, DateTime<Utc>),
    Daily(NaiveTime, NaiveTime),
}

impl ShadowRange {
    pub fn contains(&self, t: DateTime<Utc>) -> bool {
        match *self {
            ShadowRange::Absolute(a, b) => t >= a && t < b,
            ShadowRange::Daily(a, b) => {
                let tod = t.time().with_nanosecond(0).unwrap_or(t.time());
                if a <= b {
                    tod >= a && tod < b
                } else {
                    tod >= a || tod < b
                }
            }
        }
    }
}

/// Parses `--shadow`: `START/END` (RFC 3339) or `HH:MM-HH:MM`, comma-separated.
pub fn parse_shadow_ranges(s: &str) -> anyhow::Result<Vec<ShadowRange>> {
    let mut out = Vec::new();
    for (i, part) in s
        .split(',')
        .map(str::trim)
        .filter(|p| !p.is_empty())
        .enumerate()
    {
        let what = || {
            format!(
                "--shadow range {} '{part}': expected START/END (RFC 3339) or HH:MM-HH:MM",
                i + 1
            )
        };
        if let Some((a, b)) = part.split_once('/') {
            let a = parse_time(a).with_context(what)?;
            let b = parse_time(b).with_context(what)?;
            if b <= a {
                bail!("{}: end is not after start", what());
            }
            out.push(ShadowRange::Absolute(a, b));
        } else if let Some((a, b)) = part.split_once('-') {
            let a = NaiveTime::parse_from_str(a.trim(), "%H:%M").with_context(what)?;
            let b = NaiveTime::parse_from_str(b.trim(), "%H:%M").with_context(what)?;
            out.push(ShadowRange::Daily(a, b));
        } else {
            bail!("{}", what());
        }
    }
    Ok(out)
}

fn parse_time(s: &str) -> anyhow::Result<DateTime<Utc>> {
    Ok(DateTime::parse_from_rfc3339(s.trim())
        .with_context(|| format!("'{s}' is not an RFC 3339 time (e.g. 2021-05-05T12:00:00Z)"))?
        .with_timezone(&Utc))
}

/// Reads a forcing CSV (columns in the module docs). Errors name the file,
/// the line and the column.
pub fn read_forcing_csv(path: &Path) -> anyhow::Result<Vec<Forcing>> {
    let file = path.display();
    let text = std::fs::read_to_string(path).with_context(|| format!("{file}: cannot read"))?;
    const COLS: [&str; 10] = [
        "t_s",
        "air_temp_k",
        "sky_temp_k",
        "wind_speed_m_s",
        "dni_w_m2",
        "dhi_w_m2",
        "ghi_w_m2",
        "sun_e",
        "sun_n",
        "sun_u",
    ];
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.starts_with('#') && !l.trim().is_empty());
    let (hl, header) = lines
        .next()
        .with_context(|| format!("{file}: empty file"))?;
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let idx: Vec<usize> = COLS
        .iter()
        .map(|c| {
            names.iter().position(|n| n == c).with_context(|| {
                format!(
                    "{file}:{}: header lacks column '{c}' (expected {})",
                    hl + 1,
                    COLS.join(",")
                )
            })
        })
        .collect::<anyhow::Result<_>>()?;
    let mut out = Vec::new();
    for (ln, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let mut v = [0.0; 10];
        for (k, &j) in idx.iter().enumerate() {
            let s = fields
                .get(j)
                .with_context(|| format!("{file}:{}: missing column '{}'", ln + 1, COLS[k]))?;
            v[k] = s
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .with_context(|| {
                    format!(
                        "{file}:{}: column '{}': '{s}' is not a finite number",
                        ln + 1,
                        COLS[k]
                    )
                })?;
        }
        out.push(Forcing {
            t_s: v[0],
            air_temp_k: v[1],
            sky_temp_k: v[2],
            wind_speed_m_s: v[3],
            dni_w_m2: v[4],
            dhi_w_m2: v[5],
            ghi_w_m2: v[6],
            sun_dir_enu: [v[7], v[8], v[9]],
            dew_point_k: crate::therm::forcing::DRY_AIR_DEW_POINT_K,
            pressure_pa: 101_325.0,
            precip_mm_h: 0.0,
            ground_temp_k: None,
        });
    }
    crate::therm::slab::validate_forcing(&out).with_context(|| format!("{file}"))?;
    Ok(out)
}

/// Forcing from a weather file: `read_weather_file_with` + `build_forcing`
/// (`n_steps + 1` samples); the estimators used are reported on stderr.
fn forcing_from_weather(
    a: &Args,
    start: DateTime<Utc>,
    step_s: f64,
    n_steps: usize,
) -> anyhow::Result<Vec<Forcing>> {
    use chrono::Datelike;
    let opts = crate::therm::weather::ReadOptions {
        coerce_year: a.typical_year.then(|| start.year()),
        ..Default::default()
    };
    let history =
        crate::therm::weather::read_weather_file_with(a.weather.as_deref().unwrap(), &opts)?
            .history;
    let site = crate::sun::Site {
        lat_deg: a.lat,
        lon_deg: a.lon,
        elevation_m: a.elevation,
    };
    let (forcing, report) =
        crate::therm::forcing::build_forcing(&history, &site, start, step_s, n_steps)?;
    for l in report.lines() {
        eprintln!("{l}");
    }
    Ok(forcing)
}

/// One output row: time, the record, and the flux terms.
#[derive(Serialize)]
struct Row {
    time_utc: String,
    #[serde(flatten)]
    rec: StepRecord,
}

#[derive(Serialize)]
struct Report<'a> {
    material: &'a str,
    properties: SlabMaterial,
    orientation: Orientation,
    settings: ThermSettings,
    nodes: usize,
    rows: Vec<Row>,
}

/// The slab of material `name` in a material library (the scene format).
pub fn load_material(path: &Path, name: &str) -> anyhow::Result<SlabMaterial> {
    let lib = crate::scene::material::load_library(path)?;
    match lib.iter().find(|m| m.name == name) {
        Some(m) => Ok(crate::render::prepare::slab_of(m)),
        None => bail!(
            "{}: no material `{name}`; the library defines: {}",
            path.display(),
            lib.iter()
                .map(|m| m.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

pub fn run(a: Args) -> anyhow::Result<i32> {
    let mat = load_material(&a.materials, &a.material)?;
    let from = parse_time(&a.from).context("--from")?;
    let to = parse_time(&a.to).context("--to")?;
    if to < from {
        bail!("--to {} is before --from {}", a.to, a.from);
    }
    if !(a.step.is_finite() && a.step > 0.0) {
        bail!("--step {}: expected a positive number of minutes", a.step);
    }
    if !(a.spin_up_h.is_finite() && a.spin_up_h >= 0.0) {
        bail!("--spin-up-h {}: expected hours >= 0", a.spin_up_h);
    }
    if !(-90.0..=90.0).contains(&a.lat) || !(-180.0..=360.0).contains(&a.lon) {
        bail!(
            "--lat {} --lon {}: expected latitude in [-90, 90] and longitude in [-180, 360]",
            a.lat,
            a.lon
        );
    }
    let start = from - Duration::milliseconds((a.spin_up_h * 3.6e6).round() as i64);
    let forcing = match &a.forcing {
        Some(p) => {
            let f = read_forcing_csv(p)?;
            let end_s = (to - start).num_milliseconds() as f64 / 1e3;
            let f: Vec<Forcing> = f.into_iter().filter(|x| x.t_s <= end_s + 1e-6).collect();
            if f.is_empty() || f[0].t_s > 0.0 || f.last().unwrap().t_s < end_s - 1e-6 {
                bail!(
                    "{}: the forcing must cover t_s = 0 (= --from − --spin-up-h) to {end_s} s (= --to)",
                    p.display()
                );
            }
            f
        }
        None => {
            let step_s = a.step * 60.0;
            let total_s = (to - start).num_milliseconds() as f64 / 1e3;
            let n_steps = (total_s / step_s).ceil().max(1.0) as usize;
            forcing_from_weather(&a, start, step_s, n_steps)?
        }
    };
    let at = |t_s: f64| start + Duration::milliseconds((t_s * 1e3).round() as i64);
    let shadow = match &a.shadow {
        Some(s) => {
            let ranges = parse_shadow_ranges(s)?;
            // Sampled on a uniform grid of the smallest forcing interval.
            let dt = forcing
                .windows(2)
                .map(|w| w[1].t_s - w[0].t_s)
                .fold(f64::INFINITY, f64::min);
            let dt = if dt.is_finite() {
                dt.round().max(1.0)
            } else {
                60.0
            };
            let n = (forcing.last().unwrap().t_s / dt).ceil() as usize + 1;
            Some(SunHistory {
                start_s: 0,
                interval_s: dt as i64,
                sunlit: (0..n)
                    .map(|i| !ranges.iter().any(|r| r.contains(at(i as f64 * dt))))
                    .collect(),
            })
        }
        None => None,
    };
    let o = Orientation {
        slope_deg: a.slope,
        aspect_deg: a.aspect,
    };
    let settings = ThermSettings {
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
        ..ThermSettings::default()
    };
    if !(a.facet_height_m.is_finite() && (0.0..=1e4).contains(&a.facet_height_m)) {
        bail!(
            "--facet-height-m {}: expected a height above the ground from 0 to 10000 m",
            a.facet_height_m
        );
    }
    let model = SlabModel::new(&mat, o, &settings)
        .with_context(|| format!("material '{}'", a.material))?
        .with_height(a.facet_height_m);
    let sol = model.solve(&forcing, shadow.as_ref(), true)?;
    let from_s = (from - start).num_milliseconds() as f64 / 1e3;
    let rows: Vec<Row> = sol
        .series
        .iter()
        .filter(|r| r.t_s >= from_s - 1e-6)
        .map(|r| Row {
            time_utc: at(r.t_s).to_rfc3339_opts(chrono::SecondsFormat::Secs, true),
            rec: *r,
        })
        .collect();
    let mut out = std::io::stdout().lock();
    if a.json {
        let rep = Report {
            material: &a.material,
            properties: mat,
            orientation: o,
            settings,
            nodes: model.nodes(),
            rows,
        };
        serde_json::to_writer_pretty(&mut out, &rep)?;
        writeln!(out)?;
    } else {
        write_table(&mut out, &rows, a.csv)?;
    }
    Ok(0)
}

const COLUMNS: [&str; 23] = [
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
];

fn write_table(out: &mut impl Write, rows: &[Row], csv: bool) -> std::io::Result<()> {
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
            r.rec.surface_temp_k - 273.15,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shadow_ranges_parse_and_contain() {
        let r =
            parse_shadow_ranges("2021-05-05T18:00:00Z/2021-05-05T20:00:00Z, 22:00-02:00").unwrap();
        assert_eq!(r.len(), 2);
        let t = |s: &str| parse_time(s).unwrap();
        assert!(
            r[0].contains(t("2021-05-05T19:59:00Z")) && !r[0].contains(t("2021-05-05T20:00:00Z"))
        );
        assert!(
            r[1].contains(t("2021-05-06T01:00:00Z")) && r[1].contains(t("2021-05-06T23:00:00Z"))
        );
        assert!(!r[1].contains(t("2021-05-06T12:00:00Z")));
        let e = parse_shadow_ranges("18:00-xx").unwrap_err();
        assert!(format!("{e:#}").contains("--shadow range 1"));
        assert!(parse_shadow_ranges("2021-05-05T20:00:00Z/2021-05-05T18:00:00Z").is_err());
    }
}

//! `irsig sun`: print the solar position (NREL SPA) for a site and an instant
//! ([`crate::sun::report::sun_report`]).

use anyhow::Context;
use chrono::{DateTime, Utc};

use crate::sun::report::parse_time;
use crate::sun::report::sun_report;
use crate::sun::{SolarPosition, SpaOptions};

#[derive(clap::Args, Debug)]
/// `irsig sun`: the solar position at a site and instant.
pub struct Args {
    /// Latitude, degrees north (−90..90).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_lat)]
    pub lat: f64,
    /// Longitude, degrees east (−180..180).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_lon)]
    pub lon: f64,
    /// Site elevation above sea level, metres.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub elevation: f64,
    /// Instant, RFC 3339 with an offset (e.g. 2024-06-21T12:00:00Z).
    #[arg(long, value_parser = parse_time)]
    pub time: DateTime<Utc>,
    /// Air pressure for the refraction correction, hPa.
    #[arg(long, default_value_t = 1013.25)]
    pub pressure_hpa: f64,
    /// Air temperature for the refraction correction, °C.
    #[arg(long, default_value_t = 12.0, allow_negative_numbers = true)]
    pub temp_c: f64,
    /// ΔT = TT − UT in seconds (default: Espenak & Meeus model).
    #[arg(long, allow_negative_numbers = true)]
    pub delta_t: Option<f64>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

fn parse_deg(s: &str, what: &str, limit: f64, dir: &str) -> Result<f64, String> {
    let v: f64 = s.trim().parse().map_err(|_| {
        format!("'{s}' is not a number: expected {what} in degrees, {dir} positive")
    })?;
    if !(-limit..=limit).contains(&v) {
        return Err(format!(
            "{what} {v} is out of range: expected degrees in [-{limit}, {limit}], {dir} positive"
        ));
    }
    Ok(v)
}

fn parse_lat(s: &str) -> Result<f64, String> {
    parse_deg(s, "latitude", 90.0, "north")
}

fn parse_lon(s: &str) -> Result<f64, String> {
    parse_deg(s, "longitude", 180.0, "east")
}

/// The text output of `irsig sun`.
pub fn format_text(time: DateTime<Utc>, p: &SolarPosition) -> String {
    let v = p.sun_dir_enu;
    format!(
        "time_utc               {}\n\
         zenith_deg             {:.5}   (apparent, refraction-corrected)\n\
         true_zenith_deg        {:.5}\n\
         azimuth_deg            {:.5}   (clockwise from north)\n\
         elevation_deg          {:.5}\n\
         earth_sun_distance_au  {:.7}\n\
         sun_dir_enu            {:.6} {:.6} {:.6}   (east, north, up)\n",
        time.to_rfc3339_opts(chrono::SecondsFormat::Secs, true),
        p.zenith_deg,
        p.true_zenith_deg,
        p.azimuth_deg,
        p.elevation_deg,
        p.earth_sun_distance_au,
        v[0],
        v[1],
        v[2]
    )
}

/// Runs `irsig sun`; returns the process exit code.
pub fn run(a: Args) -> anyhow::Result<i32> {
    use crate::bounds::args;
    for (arg, v) in [
        (args::ELEVATION, a.elevation),
        (args::SUN_PRESSURE, a.pressure_hpa),
        (args::SUN_TEMP, a.temp_c),
        (args::SUN_DELTA_T, a.delta_t.unwrap_or(0.0)),
    ] {
        arg.check_flag(v).map_err(anyhow::Error::msg)?;
    }
    let opts = SpaOptions {
        pressure_hpa: a.pressure_hpa,
        temp_c: a.temp_c,
        delta_t_s: a.delta_t,
        ..SpaOptions::default()
    };
    let r = sun_report(a.time, a.lat, a.lon, a.elevation, &opts)?;
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&r).context("serialising the solar position")?
        );
    } else {
        print!("{}", format_text(a.time, &r.position));
    }
    Ok(0)
}

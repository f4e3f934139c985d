//! One facet's surface temperature and every flux term over time (the
//! seed paper's Fig. 6 use; `irsig therm`): a material's slab at a site and
//! orientation, forced by a weather file or a ready forcing CSV, marched
//! from a spin-up start, optionally shaded over time ranges.
//!
//! * The march starts `spin_up_h` hours before `from` (from a steady
//!   state, [`SpinUpStart`]: under the mean forcing, or the first sample)
//!   and reports one row per forcing sample from `from` to `to`.
//! * A forcing CSV ([`super::forcing_csv`]) has its `t_s = 0` at the start
//!   of the spin-up, `from − spin_up_h`; its own step is used.
//! * Shadow ranges ([`ShadowRange`]) shade the facet (no direct sun); the
//!   history is sampled on a uniform grid of the smallest forcing interval.
//! * A material on `deep_ground = {}` sits on the deep-ground temperature
//!   a render uses with `to` as the image time
//!   ([`super::conditions::deep_ground_temp_k`]: the mean air temperature,
//!   trapezoid rule on hourly samples, of the 72 h before `to`, or of the
//!   whole run if longer, clipped to the start of the record); from a
//!   forcing CSV, the same rule on the CSV's own samples
//!   ([`forcing_deep_ground_k`]).

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use chrono::{DateTime, Duration, NaiveTime, Timelike, Utc};
use serde::Serialize;

use super::balance::{Convection, Orientation};
use super::conditions::{
    DEEP_GROUND_WINDOW_H, deep_ground_temp_k, weather_window, with_deep_ground,
};
use super::forcing::Forcing;
use super::forcing_csv::read_forcing_csv;
use super::slab::{SlabMaterial, SlabModel, SpinUpStart, StepRecord, SunHistory, ThermSettings};

/// A shadow range: absolute UTC interval or daily UTC time-of-day interval
/// (start included, end excluded; a daily range may wrap past midnight).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowRange {
    /// From the first instant to the second (UTC).
    Absolute(DateTime<Utc>, DateTime<Utc>),
    /// Every day from the first UTC time of day to the second.
    Daily(NaiveTime, NaiveTime),
}

impl ShadowRange {
    /// Whether `t` lies in the range.
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

/// Parses comma-separated shadow ranges: `START/END` (RFC 3339) or
/// `HH:MM-HH:MM` (daily, UTC).
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

/// Parses an RFC 3339 time into UTC (one parser for every command:
/// [`crate::sun::report::parse_time`]).
pub fn parse_time(s: &str) -> anyhow::Result<DateTime<Utc>> {
    crate::sun::report::parse_time(s).map_err(anyhow::Error::msg)
}

/// Where the forcing comes from.
#[derive(Clone, Debug)]
pub enum ForcingSource {
    /// A weather file (any format of [`crate::weather::read_weather`]);
    /// `typical_year`: a typical year, laid on every year of the run;
    /// `stand_in`: its station stands in for the site, and the record is
    /// applied in the site's solar time
    /// ([`crate::weather::stand_in_solar_shift`], as a render does; a file
    /// without a station is applied at its own times).
    Weather {
        /// The weather file.
        path: PathBuf,
        /// A typical-year file, laid on every year of the run.
        typical_year: bool,
        /// The file's station stands in for the site.
        stand_in: bool,
    },
    /// A ready forcing CSV (see [`super::forcing_csv`]).
    ForcingCsv(PathBuf),
}

/// What [`facet_series`] computes: plain inputs.
#[derive(Clone, Debug)]
pub struct FacetRun {
    /// The material's name (reported) and its slab.
    pub material_name: String,
    /// Its slab.
    pub material: SlabMaterial,
    /// Where the forcing comes from.
    pub forcing: ForcingSource,
    /// Site (latitude, longitude, elevation); used with a weather file.
    pub site: crate::sun::Site,
    /// Orientation of the facet.
    pub orientation: Orientation,
    /// First and last output time.
    pub from: DateTime<Utc>,
    /// Last output time.
    pub to: DateTime<Utc>,
    /// Forcing/output step, minutes (a weather file only; a forcing CSV
    /// has its own).
    pub step_min: f64,
    /// Spin-up before the first output, hours.
    pub spin_up_h: f64,
    /// The spin-up's initial profile.
    pub spin_up_start: SpinUpStart,
    /// The convection model.
    pub convection: Convection,
    /// Height of the facet above the ground, m (0-10000).
    pub facet_height_m: f64,
    /// Time ranges in which the facet is shaded.
    pub shadow: Vec<ShadowRange>,
    /// The facet's sky view factor, when the scene hides part of its sky
    /// (a point beside a wall: the `sky view factor` that `irsig probe`
    /// prints for a render's surface point); `None`: the open sky of its
    /// orientation, (1 + cos β)/2. At most that; the rest of the
    /// hemisphere is taken at the forcing's ground temperature (a forcing
    /// CSV's `ground_temp_k`, else the air temperature; a render takes the
    /// ground material's solved temperature).
    pub sky_view: Option<f64>,
}

/// One output row: the time, then the step's record (flattened), then the
/// stability function in force.
#[derive(Clone, Debug, Serialize)]
pub struct ThermRow {
    /// RFC 3339, whole seconds.
    pub time_utc: String,
    #[serde(flatten)]
    /// The step's record: surface state and every flux term.
    pub rec: StepRecord,
    /// `F(Ri)` of the surface layer at this step
    /// ([`super::balance::SurfaceFluxes::stability_factor`]; 1 = neutral).
    pub stability_factor: f64,
}

/// The facet's series; serialises as `irsig therm --json` prints it.
#[derive(Clone, Debug, Serialize)]
pub struct FacetSeries {
    /// The material's name.
    pub material: String,
    /// Its slab properties.
    pub properties: SlabMaterial,
    /// Orientation of the facet.
    pub orientation: Orientation,
    /// The solver settings used.
    pub settings: ThermSettings,
    /// Nodes of the slab's grid.
    pub nodes: usize,
    /// The deep-ground temperature the slab's back sat on, K (a
    /// `deep_ground = {}` material: the rule of
    /// [`super::conditions::deep_ground_temp_k`] with `to` as the image
    /// time; a fixed `temp_c`: that); `None` for other backs.
    pub deep_ground_k: Option<f64>,
    /// One row per output time.
    pub rows: Vec<ThermRow>,
    /// The weather estimators used, one line each (none for a forcing CSV).
    #[serde(skip)]
    pub estimator_lines: Vec<String>,
}

/// Forcing from a weather file (`n_steps + 1` samples from `start`), the
/// report of the estimators used, and the deep-ground temperature with
/// `image_time` as the image time (the render's rule,
/// [`deep_ground_temp_k`]; the record is read over the render's
/// [`weather_window`]).
fn forcing_from_weather(
    path: &Path,
    (typical_year, stand_in): (bool, bool),
    site: &crate::sun::Site,
    start: DateTime<Utc>,
    step_s: f64,
    n_steps: usize,
    image_time: DateTime<Utc>,
) -> anyhow::Result<(Vec<Forcing>, Vec<String>, f64)> {
    let (w_from, w_to) = weather_window(start, image_time);
    let opts = crate::weather::ReadOptions {
        typical_year: typical_year.then(|| crate::weather::YearSpan::around(w_from, w_to)),
        ..Default::default()
    };
    let file = crate::weather::read_weather_file_with(path, &opts)?;
    let shift = crate::weather::stand_in_solar_shift(
        file.station.as_ref(),
        &path.display().to_string(),
        site.longitude_deg,
    );
    let history = match shift {
        Ok(by) if stand_in => file.history.shifted(by),
        _ => file.history,
    };
    let (forcing, report) = super::forcing::build_forcing(&history, site, start, step_s, n_steps)?;
    let deep_k = deep_ground_temp_k(&history, site, start, image_time)?;
    Ok((forcing, report.lines(), deep_k))
}

/// The deep-ground rule of [`deep_ground_temp_k`] on a ready forcing (a
/// forcing CSV, whose `t_s = 0` is the history's start): the mean air
/// temperature, trapezoid rule, over the [`DEEP_GROUND_WINDOW_H`] hours
/// before `end_s` or over the whole forcing if it starts later, K. The
/// samples are the forcing's own (linear between them), not hourly.
pub fn forcing_deep_ground_k(forcing: &[Forcing], end_s: f64) -> Option<f64> {
    let from_s = end_s - DEEP_GROUND_WINDOW_H as f64 * 3600.0;
    let air_at = |t: f64| {
        let i = forcing
            .partition_point(|f| f.t_s <= t)
            .clamp(1, forcing.len() - 1);
        let (a, b) = (&forcing[i - 1], &forcing[i]);
        let w = if b.t_s > a.t_s {
            ((t - a.t_s) / (b.t_s - a.t_s)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        a.air_temp_k + w * (b.air_temp_k - a.air_temp_k)
    };
    match forcing {
        [] => None,
        [f] => Some(f.air_temp_k),
        _ => {
            let lo = from_s.max(forcing[0].t_s);
            let hi = end_s.min(forcing[forcing.len() - 1].t_s);
            if hi <= lo {
                return Some(air_at(hi));
            }
            // Knots: the window's ends and every sample inside it.
            let mut knots = vec![lo];
            knots.extend(forcing.iter().map(|f| f.t_s).filter(|&t| t > lo && t < hi));
            knots.push(hi);
            let sum: f64 = knots
                .windows(2)
                .map(|k| 0.5 * (air_at(k[0]) + air_at(k[1])) * (k[1] - k[0]))
                .sum();
            Some(sum / (hi - lo))
        }
    }
}

/// Marches the facet of `run` and returns its rows from `run.from` to
/// `run.to`.
pub fn facet_series(run: &FacetRun) -> anyhow::Result<FacetSeries> {
    let (from, to) = (run.from, run.to);
    if to < from {
        bail!(
            "the end {} is before the start {}",
            to.to_rfc3339(),
            from.to_rfc3339()
        );
    }
    use crate::bounds::args;
    let check = |a: &args::Arg, v: f64| a.check(v).map_err(anyhow::Error::msg);
    check(&args::THERM_STEP_MIN, run.step_min)?;
    check(&args::THERM_SPIN_UP_H, run.spin_up_h)?;
    check(&args::THERM_FACET_HEIGHT, run.facet_height_m)?;
    check(&args::LAT, run.site.latitude_deg)?;
    check(&args::LON, run.site.longitude_deg)?;
    check(&args::ELEVATION, run.site.elevation_m)?;
    check(&args::SLOPE, run.orientation.slope_deg)?;
    check(&args::ASPECT, run.orientation.aspect_deg)?;
    let open_sky = run.orientation.sky_view_factor();
    if let Some(f) = run.sky_view {
        check(&args::SKY_VIEW, f)?;
        if f > open_sky + 1e-12 {
            bail!(
                "sky view {}: more than the open sky of a facet of slope {}°, (1 + cos β)/2 = {}",
                crate::bounds::num(f),
                crate::bounds::num(run.orientation.slope_deg),
                crate::bounds::num(open_sky)
            );
        }
    }
    // Every time below is from, to or start plus at most their span: with
    // the years bounded (1900-2200) and the spin-up a year at most, none
    // overflows; the step count is bounded before the forcing is built.
    let steps = ((to - from).num_seconds() as f64 + run.spin_up_h * 3600.0) / (run.step_min * 60.0);
    if let ForcingSource::Weather { .. } = run.forcing
        && steps > args::THERM_MAX_STEPS
    {
        bail!(
            "{} steps of {} min from {} h before {} to {}: more than the {} a run may take \
             (about 0.5 GB of forcing); take a longer step or a shorter span",
            crate::bounds::num(steps.ceil()),
            crate::bounds::num(run.step_min),
            crate::bounds::num(run.spin_up_h),
            from.to_rfc3339(),
            to.to_rfc3339(),
            crate::bounds::num(args::THERM_MAX_STEPS)
        );
    }
    let start = from - Duration::milliseconds((run.spin_up_h * 3.6e6).round() as i64);
    let (forcing, estimator_lines, deep_k) = match &run.forcing {
        ForcingSource::ForcingCsv(p) => {
            let f = read_forcing_csv(p)?;
            let end_s = (to - start).num_milliseconds() as f64 / 1e3;
            let f: Vec<Forcing> = f.into_iter().filter(|x| x.t_s <= end_s + 1e-6).collect();
            if f.is_empty() || f[0].t_s > 0.0 || f[f.len() - 1].t_s < end_s - 1e-6 {
                bail!(
                    "{}: the forcing must cover t_s = 0 (the start less the spin-up) to {end_s} s (the end)",
                    p.display()
                );
            }
            let deep_k = forcing_deep_ground_k(&f, end_s);
            (f, Vec::new(), deep_k)
        }
        ForcingSource::Weather {
            path,
            typical_year,
            stand_in,
        } => {
            let step_s = run.step_min * 60.0;
            let total_s = (to - start).num_milliseconds() as f64 / 1e3;
            let n_steps = (total_s / step_s).ceil().max(1.0) as usize;
            let (f, lines, deep_k) = forcing_from_weather(
                path,
                (*typical_year, *stand_in),
                &run.site,
                start,
                step_s,
                n_steps,
                to,
            )?;
            (f, lines, Some(deep_k))
        }
    };
    let at = |t_s: f64| start + Duration::milliseconds((t_s * 1e3).round() as i64);
    let shadow = (!run.shadow.is_empty()).then(|| {
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
        let last = forcing.last().map_or(0.0, |f| f.t_s);
        let n = (last / dt).ceil() + 1.0;
        if n > 10.0 * args::THERM_MAX_STEPS {
            bail!(
                "the shadow history would need {} samples of {dt} s (the forcing's smallest \
                 interval): more than {}; give the forcing a longer step",
                crate::bounds::num(n),
                crate::bounds::num(10.0 * args::THERM_MAX_STEPS)
            );
        }
        let n = n as usize;
        Ok(SunHistory {
            start_s: 0,
            interval_s: dt as i64,
            sunlit: (0..n)
                .map(|i| !run.shadow.iter().any(|r| r.contains(at(i as f64 * dt))))
                .collect(),
        })
    });
    let shadow = shadow.transpose()?;
    let settings = ThermSettings {
        spin_up_h: run.spin_up_h,
        spin_up_start: run.spin_up_start,
        convection: run.convection,
        ..ThermSettings::default()
    };
    // One deep-ground rule for `irsig therm` and a render: resolve
    // `deep_ground = {}` here rather than leave it to the slab's fallback
    // (the plain mean of the forcing it is given).
    let material = match deep_k {
        Some(k) => with_deep_ground(std::slice::from_ref(&run.material), k)[0],
        None => run.material,
    };
    let deep_ground_k = match material.back {
        super::slab::BackBoundary::DeepGround { temp_k } => temp_k,
        _ => None,
    };
    let model = SlabModel::new(&material, run.orientation, &settings)
        .with_context(|| format!("material '{}'", run.material_name))?
        .with_height(run.facet_height_m)
        .with_blocked_sky(run.sky_view.map_or(0.0, |f| open_sky - f));
    let sol = model.solve(&forcing, shadow.as_ref(), true)?;
    let from_s = (from - start).num_milliseconds() as f64 / 1e3;
    let rows = sol
        .series
        .iter()
        .filter(|r| r.t_s >= from_s - 1e-6)
        .map(|r| ThermRow {
            time_utc: at(r.t_s).to_rfc3339_opts(chrono::SecondsFormat::Secs, true),
            rec: *r,
            stability_factor: r.surface.stability_factor(),
        })
        .collect();
    Ok(FacetSeries {
        material: run.material_name.clone(),
        properties: run.material,
        orientation: run.orientation,
        settings,
        nodes: model.nodes(),
        deep_ground_k,
        rows,
        estimator_lines,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(hours: usize, step_h: f64) -> Vec<Forcing> {
        let base = Forcing {
            t_s: 0.0,
            air_temp_k: 0.0,
            sky_temp_k: 260.0,
            wind_speed_m_s: 2.0,
            dni_w_m2: 0.0,
            dhi_w_m2: 0.0,
            ghi_w_m2: 0.0,
            sun_dir_enu: [0.0, 0.0, -1.0],
            dew_point_k: 270.0,
            pressure_pa: 101_325.0,
            precip_mm_h: 0.0,
            ground_temp_k: None,
        };
        (0..=(hours as f64 / step_h) as usize)
            .map(|i| {
                let t_h = i as f64 * step_h;
                Forcing {
                    t_s: t_h * 3600.0,
                    // 1 K/h: the trapezoid mean of a line is exact.
                    air_temp_k: 280.0 + t_h,
                    ..base
                }
            })
            .collect()
    }

    /// The deep-ground rule on a forcing CSV: the mean air temperature of
    /// the 72 h before the end, or of the whole forcing if shorter. On a
    /// 1 K/h ramp the exact means are the window's mid-point values.
    #[test]
    fn forcing_deep_ground_is_the_72_h_mean_air_temperature() {
        // 100 h of forcing, end at 100 h: window 28-100 h, mean at 64 h.
        let f = ramp(100, 0.25);
        let k = forcing_deep_ground_k(&f, 100.0 * 3600.0).unwrap();
        assert!((k - 344.0).abs() < 1e-9, "{k}");
        // End at 90 h (the forcing goes on): window 18-90 h, mean at 54 h.
        let k = forcing_deep_ground_k(&f, 90.0 * 3600.0).unwrap();
        assert!((k - 334.0).abs() < 1e-9, "{k}");
        // 48 h of forcing: the whole of it, mean at 24 h; uneven steps.
        let f = ramp(48, 1.5);
        let k = forcing_deep_ground_k(&f, 48.0 * 3600.0).unwrap();
        assert!((k - 304.0).abs() < 1e-9, "{k}");
        assert_eq!(forcing_deep_ground_k(&[], 0.0), None);
    }

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

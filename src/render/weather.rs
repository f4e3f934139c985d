//! The scene's weather for a render: its record over a window (a file, a
//! stand-in moved to the site's solar time, or constant weather), the
//! warnings about it, and the forcing of one frame's history
//! ([`frame_weather`]). What [`super::prepare::prepare_conditions`]
//! assembles a frame from. This file only unpacks the loaded scene (which
//! sits above `therm` and `weather`): the physics — the thermal steps, the
//! forcing, the deep-ground rule, window means, the ground solve — is in
//! [`crate::therm::conditions`], plain data in and out.

use anyhow::Context;
use chrono::{DateTime, Utc};

use crate::scene::LoadedScene;
use crate::scene::spec::WeatherSpec;
use crate::sun::Site;
use crate::therm::conditions::{FrameForcing, frame_forcing, history_steps, weather_window};
use crate::weather::{ReadOptions, WeatherHistory, YearSpan};

/// The scene's weather record: its file (whole), or its constant weather
/// generated every 15 min from `from` to `to`. A stand-in record
/// (`weather.file.stand_in`) whose file names its station is applied in
/// the site's solar time: its times are moved by
/// [`crate::weather::stand_in_solar_shift`] (one without a station is
/// applied at its own times, and [`weather_warnings`] says why).
pub fn scene_weather(
    scene: &LoadedScene,
    from: DateTime<Utc>,
    to: DateTime<Utc>,
) -> anyhow::Result<WeatherHistory> {
    let sc = &scene.scene;
    Ok(match &sc.weather {
        WeatherSpec::File {
            path,
            typical_year,
            stand_in,
            ..
        } => {
            // The reader recognises TMY3/EPW/CSV from the file itself; the
            // scene's `format` key is not cross-checked (yet).
            let p = scene.resolve(path);
            let opts = ReadOptions {
                typical_year: typical_year.then(|| YearSpan::around(from, to)),
                ..ReadOptions::default()
            };
            let parsed = scene
                .weather_record
                .parsed(&p, &opts)
                .with_context(|| format!("weather file of {}", scene.path.display()))?;
            let history = parsed.history.clone();
            match crate::weather::stand_in_solar_shift(
                parsed.station.as_ref(),
                &p.display().to_string(),
                sc.site.location.longitude_deg,
            ) {
                Ok(by) if *stand_in => history.shifted(by),
                _ => history,
            }
        }
        WeatherSpec::Constant(c) => crate::weather::constant_weather(
            c,
            sc.site.location.latitude_deg,
            sc.site.location.longitude_deg,
            from,
            to,
            900.0,
        )?,
    })
}

/// Warnings about the scene's weather: its file's station more than
/// [`crate::weather::MAX_STATION_OFFSET_DEG`] from the site
/// ([`crate::weather::station_mismatch`]), unless the scene says the
/// file stands in for the site (`weather.file.stand_in`); and, stand-in or
/// not, the hours of the image's history whose measured sunlight disagrees
/// with the site's sun ([`crate::weather::sunlight_mismatch`]).
pub fn weather_warnings(scene: &LoadedScene) -> anyhow::Result<Vec<String>> {
    let mut out = station_warnings(scene)?;
    let sc = &scene.scene;
    if let WeatherSpec::File {
        path,
        typical_year,
        stand_in,
        ..
    } = &sc.weather
    {
        // A stand-in that cannot be moved to the site's solar time says why.
        if *stand_in {
            let p = scene.resolve(path);
            if let Ok(parsed) = scene
                .weather_record
                .parsed(&p, &crate::weather::station_options(*typical_year))
                && let Err(why) = crate::weather::stand_in_solar_shift(
                    parsed.station.as_ref(),
                    &p.display().to_string(),
                    sc.site.location.longitude_deg,
                )
            {
                out.push(why);
            }
        }
        let to = sc.time.utc(&sc.site);
        let from = to - chrono::Duration::seconds((sc.render.history_hours * 3600.0) as i64);
        // A window the file does not cover is the render's error to report.
        if let Ok(h) = scene_weather(scene, from, to) {
            out.extend(crate::weather::sunlight_mismatch(
                &h,
                sc.site.location.latitude_deg,
                sc.site.location.longitude_deg,
                from,
                to,
            ));
        }
    }
    Ok(out)
}

/// The station-distance part of [`weather_warnings`].
fn station_warnings(scene: &LoadedScene) -> anyhow::Result<Vec<String>> {
    let sc = &scene.scene;
    let WeatherSpec::File {
        path,
        typical_year,
        stand_in: false,
        ..
    } = &sc.weather
    else {
        return Ok(Vec::new());
    };
    let p = scene.resolve(path);
    let station = scene
        .weather_record
        .parsed(&p, &crate::weather::station_options(*typical_year))
        .with_context(|| format!("weather file of {}", scene.path.display()))?
        .station
        .clone();
    Ok(station
        .and_then(|st| {
            crate::weather::station_mismatch(
                &st,
                &p.display().to_string(),
                sc.site.location.latitude_deg,
                sc.site.location.longitude_deg,
            )
        })
        .map(|w| {
            format!(
                "{w} (or set weather.file.stand_in = true if the file stands in for the site \
                 on purpose)"
            )
        })
        .into_iter()
        .collect())
}

/// The thermal forcing of a frame at `image_time` (UTC): the scene's
/// weather read over the window the frame needs, the forcing of its
/// history and the deep-ground temperature.
pub struct FrameWeather {
    /// The scene's site (latitude, longitude, elevation).
    pub site: Site,
    /// Start of the history (UTC), its time resolution (the interval of
    /// the fine sample grid the transitions are found on) and the number
    /// of fine intervals.
    pub start: DateTime<Utc>,
    /// Interval of the fine sample grid, s.
    pub interval_s: i64,
    /// Number of fine intervals in the history.
    pub n_sun: i64,
    /// Fine intervals per traced (coarse) sample: the sun is traced every
    /// `coarse_every` fine samples, and between two traced samples that
    /// differ the transition is found by bisection (1: every sample is
    /// traced).
    pub coarse_every: i64,
    /// Thermal step, s.
    pub step_s: f64,
    /// The forcing at `n_steps + 1` times `step_s` apart from `start`.
    pub forcing: Vec<crate::therm::forcing::Forcing>,
    /// Which weather estimators built it.
    pub estimators: crate::therm::forcing::EstimatorReport,
    /// The deep-ground temperature of the frame ([`crate::therm::conditions::deep_ground_temp_k`]), K.
    pub deep_ground_k: f64,
}

/// The shadow-history grid of a traced interval `coarse_s` and an optional
/// transition resolution, minutes: (traced interval, fine interval, fine
/// intervals per traced one), s. The fine interval is a whole number of
/// seconds that divides the traced interval (which is rounded down to a
/// multiple of it when the two do not divide); without a resolution, or
/// one at least the traced interval, the fine grid is the traced one.
pub fn shadow_grid_s(coarse_s: i64, resolution_min: Option<f64>) -> (i64, i64, i64) {
    let coarse_s = coarse_s.max(1);
    let every = match resolution_min {
        Some(r) if r.is_finite() && r > 0.0 => {
            ((coarse_s as f64 / (r * 60.0)).round() as i64).clamp(1, coarse_s)
        }
        _ => 1,
    };
    let fine_s = coarse_s / every;
    (fine_s * every, fine_s, every)
}

/// The fine samples within `recent_h` hours of the image time, rounded up
/// to a power of two (at least 2).
pub fn key_recent_samples(recent_h: f64, interval_s: i64) -> usize {
    let n = (recent_h * 3600.0 / interval_s.max(1) as f64).ceil();
    (n.clamp(2.0, 1e9) as usize).next_power_of_two()
}

/// Reads the scene's weather and builds the forcing of a frame at
/// `image_time` (what [`super::prepare::prepare_conditions`] starts from, and what
/// `irsig check` validates).
pub fn frame_weather(
    scene: &LoadedScene,
    image_time: DateTime<Utc>,
) -> anyhow::Result<FrameWeather> {
    let sc = &scene.scene;
    let opts = &sc.render;
    let site = sc.site.location;
    let coarse_s = (opts.shadow_interval_min * 60.0).round() as i64;
    let (coarse_s, interval_s, coarse_every) = shadow_grid_s(coarse_s, opts.shadow_resolution_min);
    let n_coarse = (opts.history_hours * 3600.0 / coarse_s as f64)
        .round()
        .max(1.0) as i64;
    let n_sun = n_coarse * coarse_every;
    let history_s = n_sun * interval_s;
    let start = image_time - chrono::Duration::seconds(history_s);
    let (n_steps, step_s) = history_steps(history_s as f64, opts.thermal_step_min * 60.0);

    let (from, to) = weather_window(start, image_time);
    let history = scene_weather(scene, from, to)?;
    let FrameForcing {
        forcing,
        estimators,
        deep_ground_k,
    } = frame_forcing(&history, &site, start, step_s, n_steps, image_time)
        .with_context(|| format!("weather for {}", scene.path.display()))?;
    Ok(FrameWeather {
        site,
        start,
        interval_s,
        n_sun,
        coarse_every,
        step_s,
        forcing,
        estimators,
        deep_ground_k,
    })
}

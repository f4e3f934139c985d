//! The thermal conditions of one frame, from its weather record: the
//! history's thermal steps, the forcing of the history, the deep-ground
//! temperature (a multi-day mean of the air), means over a window of the
//! record (the atmosphere's follow-the-weather fit), and the ground that
//! tilted facets see, solved sunlit and horizontal, with the frame's slabs.
//! Plain data in and out (a parsed record, a site, times, slabs): the
//! render only unpacks its loaded scene and calls these
//! ([`crate::render::weather::frame_weather`],
//! [`crate::render::prepare::prepare_conditions`]).

use chrono::{DateTime, Utc};

use super::balance::Orientation;
use super::forcing::{EstimatorReport, Forcing, build_forcing};
use super::slab::{BackBoundary, SlabMaterial, SlabModel, ThermSettings};
use crate::sun::Site;
use crate::weather::WeatherHistory;

/// Hours of air temperature averaged into the deep-ground temperature.
pub const DEEP_GROUND_WINDOW_H: i64 = 72;

/// Start of the deep-ground averaging window (before clipping to the
/// weather record): [`DEEP_GROUND_WINDOW_H`] before the image time, or the
/// history's start if earlier.
pub fn deep_ground_window_start(
    history_start: DateTime<Utc>,
    image_time: DateTime<Utc>,
) -> DateTime<Utc> {
    history_start.min(image_time - chrono::Duration::hours(DEEP_GROUND_WINDOW_H))
}

/// The deep-ground temperature of `deep_ground = {}` materials: the mean air
/// temperature (trapezoid rule on hourly samples) over the
/// [`DEEP_GROUND_WINDOW_H`] hours before the image time, or over the whole
/// history when that is longer, clipped to the start of the weather record.
/// At the depth of the airfield's ground slabs (0.3-0.5 m, two to four
/// diurnal damping depths) the soil follows the multi-day mean, not the
/// day's. The window does not depend on the history length, so the
/// `history_hours` knob changes the spin-up only, not the boundary.
pub fn deep_ground_temp_k(
    history: &WeatherHistory,
    site: &Site,
    history_start: DateTime<Utc>,
    image_time: DateTime<Utc>,
) -> anyhow::Result<f64> {
    let from = deep_ground_window_start(history_start, image_time);
    Ok(window_means(history, site, from, image_time, [|f| f.air_temp_k])?[0])
}

/// Means of each of `fs` over the weather's forcing from `from` (or the
/// start of the record, if later) to `to`: samples at most an hour apart,
/// trapezoid rule.
pub fn window_means<const N: usize>(
    history: &WeatherHistory,
    site: &Site,
    from: DateTime<Utc>,
    to: DateTime<Utc>,
    fs: [fn(&Forcing) -> f64; N],
) -> anyhow::Result<[f64; N]> {
    let mut from = from;
    if let Some(&first) = history.times.first() {
        from = from.max(first);
    }
    let span_s = (to - from).num_milliseconds() as f64 / 1e3;
    if span_s <= 0.0 {
        anyhow::bail!("the weather record starts after the image time");
    }
    let n = (span_s / 3600.0).ceil().max(1.0) as usize;
    let (f, _) = build_forcing(history, site, from, span_s / n as f64, n)?;
    Ok(fs.map(|g| {
        let sum: f64 = f.windows(2).map(|w| 0.5 * (g(&w[0]) + g(&w[1]))).sum();
        sum / n as f64
    }))
}

/// The span of weather record a frame at `image_time` whose history starts
/// at `history_start` reads: the deep-ground window (and the history) with
/// two hours' margin either side for the forcing's interpolation.
pub fn weather_window(
    history_start: DateTime<Utc>,
    image_time: DateTime<Utc>,
) -> (DateTime<Utc>, DateTime<Utc>) {
    (
        deep_ground_window_start(history_start, image_time) - chrono::Duration::hours(2),
        image_time + chrono::Duration::hours(2),
    )
}

/// The thermal steps of a history `history_s` long, with steps of at
/// most `step_s`: (number of steps, at least one; their length, s), the
/// history cut into equal whole steps.
pub fn history_steps(history_s: f64, step_s: f64) -> (usize, f64) {
    let n_steps = (history_s / step_s).ceil().max(1.0) as usize;
    (n_steps, history_s / n_steps as f64)
}

/// The forcing of a frame's thermal history and its deep-ground
/// temperature.
pub struct FrameForcing {
    /// The forcing at `n_steps + 1` times `step_s` apart from the history's
    /// start.
    pub forcing: Vec<Forcing>,
    /// Which weather estimators built the forcing.
    pub estimators: EstimatorReport,
    /// [`deep_ground_temp_k`] at the image time, K.
    pub deep_ground_k: f64,
}

/// The forcing of `n_steps` steps of `step_s` from `start` and the
/// deep-ground temperature at `image_time`, from `history` at `site`.
pub fn frame_forcing(
    history: &WeatherHistory,
    site: &Site,
    start: DateTime<Utc>,
    step_s: f64,
    n_steps: usize,
    image_time: DateTime<Utc>,
) -> anyhow::Result<FrameForcing> {
    let (forcing, estimators) = build_forcing(history, site, start, step_s, n_steps)?;
    let deep_ground_k = deep_ground_temp_k(history, site, start, image_time)?;
    Ok(FrameForcing {
        forcing,
        estimators,
        deep_ground_k,
    })
}

/// `slabs` with `deep_ground = {}` (no temperature given) set to
/// `deep_ground_k`.
pub fn with_deep_ground(slabs: &[SlabMaterial], deep_ground_k: f64) -> Vec<SlabMaterial> {
    slabs
        .iter()
        .map(|m| match m.back {
            BackBoundary::DeepGround { temp_k: None } => SlabMaterial {
                back: BackBoundary::DeepGround {
                    temp_k: Some(deep_ground_k),
                },
                ..*m
            },
            _ => *m,
        })
        .collect()
}

/// The ground tilted facets see: `ground` solved sunlit and horizontal over
/// `forcing` with `settings`; its temperature series goes into the
/// forcing (`ground_temp_k`, for every facet's F_gnd = (1 − cos β)/2 term)
/// and its solar albedo into every one of `slabs`. Returns its surface
/// temperature at the last step, K.
pub fn solve_ground(
    ground: &SlabMaterial,
    settings: &ThermSettings,
    forcing: &mut [Forcing],
    slabs: &mut [SlabMaterial],
) -> anyhow::Result<f64> {
    let sol = SlabModel::new(ground, Orientation::HORIZONTAL, settings)
        .and_then(|model| model.solve(forcing, None, true))?;
    for (f, r) in forcing.iter_mut().zip(&sol.series) {
        f.ground_temp_k = Some(r.surface_temp_k);
    }
    let albedo = 1.0 - ground.solar_absorptivity;
    for s in slabs {
        s.ground_albedo = Some(albedo);
    }
    Ok(sol.surface_temp_k)
}

/// A frame's slabs and the temperature of the ground its tilted facets
/// see: `slabs` with `deep_ground = {}` set to `deep_ground_k`
/// ([`with_deep_ground`]); with a `ground` material (an index into
/// `slabs`), that material solved sunlit and horizontal ([`solve_ground`]:
/// its series into `forcing`, its albedo into every slab) and its surface
/// temperature at the last step; without one, the air temperature at the
/// last step (288.15 K with no forcing). Returns (slabs, ground
/// temperature, K).
pub fn frame_ground(
    slabs: &[SlabMaterial],
    deep_ground_k: f64,
    ground: Option<usize>,
    settings: &ThermSettings,
    forcing: &mut [Forcing],
) -> anyhow::Result<(Vec<SlabMaterial>, f64)> {
    let mut slabs = with_deep_ground(slabs, deep_ground_k);
    let mut ground_temp_k = forcing.last().map(|f| f.air_temp_k).unwrap_or(288.15);
    if let Some(g) = ground {
        let m = slabs[g];
        ground_temp_k = solve_ground(&m, settings, forcing, &mut slabs)?;
    }
    Ok((slabs, ground_temp_k))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weather::WeatherSample;
    use chrono::TimeZone;

    /// An hourly record from `t0` with air temperature `f(hour)` °C.
    fn record(t0: DateTime<Utc>, hours: i64, f: impl Fn(f64) -> f64) -> WeatherHistory {
        let times: Vec<_> = (0..=hours)
            .map(|h| t0 + chrono::Duration::hours(h))
            .collect();
        let samples = (0..=hours)
            .map(|h| WeatherSample {
                air_temp_k: f(h as f64) + 273.15,
                dew_point_k: 273.15,
                wind_speed_m_s: 2.0,
                pressure_pa: 101_325.0,
                cloud_fraction: Some(0.0),
                ghi_w_m2: None,
                dni_w_m2: None,
                dhi_w_m2: None,
                sky_temp_k: None,
                precip_mm_h: 0.0,
            })
            .collect();
        WeatherHistory {
            times,
            samples,
            source: "test".into(),
        }
    }

    const SITE: Site = Site {
        latitude_deg: 36.1,
        longitude_deg: -79.95,
        elevation_m: 273.0,
    };

    /// Reference: the analytic mean of the record's piecewise-linear air
    /// temperature, i.e. the trapezoid rule over its own hourly samples
    /// (exact for a linear trend; a whole-day sinusoid adds nothing). A
    /// trend of 0.1 K/h plus a 5-K diurnal wave over 72 h has the mean of
    /// the trend at the window's midpoint. Tolerance 1e-9 K (rounding).
    #[test]
    fn deep_ground_is_the_72_h_mean_air_temperature() {
        let t0 = Utc.with_ymd_and_hms(2001, 8, 1, 0, 0, 0).unwrap();
        let trend = |h: f64| 20.0 + 0.1 * h;
        let w = record(t0, 200, |h| {
            trend(h) + 5.0 * (2.0 * std::f64::consts::PI * h / 24.0).sin()
        });
        let image = t0 + chrono::Duration::hours(150);
        // Sinusoid sampled hourly over whole days: its trapezoid sum is 0.
        let expect = trend(150.0 - 36.0) + 273.15;
        // A 24-h history: the window is still 72 h.
        let hist_start = image - chrono::Duration::hours(24);
        let got = deep_ground_temp_k(&w, &SITE, hist_start, image).unwrap();
        assert!((got - expect).abs() < 1e-9, "{got} vs {expect}");
        // A 96-h history: the window is the history.
        let hist_start = image - chrono::Duration::hours(96);
        let got = deep_ground_temp_k(&w, &SITE, hist_start, image).unwrap();
        let expect = trend(150.0 - 48.0) + 273.15;
        assert!((got - expect).abs() < 1e-9, "{got} vs {expect}");
    }

    /// The history cut into equal whole steps of at most the step asked
    /// for (worked by hand): 72 h at 15 min is 288 steps of 900 s; 1 h at
    /// 7 min is ⌈8.57⌉ = 9 steps of 400 s; a history shorter than one step
    /// is one step.
    #[test]
    fn history_steps_are_whole_and_at_most_the_step() {
        assert_eq!(history_steps(72.0 * 3600.0, 900.0), (288, 900.0));
        assert_eq!(history_steps(3600.0, 420.0), (9, 400.0));
        assert_eq!(history_steps(600.0, 900.0), (1, 600.0));
    }

    /// A record shorter than the window: the mean over what there is.
    #[test]
    fn deep_ground_window_is_clipped_to_the_record() {
        let t0 = Utc.with_ymd_and_hms(2001, 8, 1, 0, 0, 0).unwrap();
        let w = record(t0, 30, |h| 10.0 + 0.2 * h);
        let image = t0 + chrono::Duration::hours(24);
        let got = deep_ground_temp_k(&w, &SITE, t0, image).unwrap();
        let expect = 10.0 + 0.2 * 12.0 + 273.15;
        assert!((got - expect).abs() < 1e-9, "{got} vs {expect}");
        let before = t0 - chrono::Duration::hours(1);
        let e = deep_ground_temp_k(&w, &SITE, before, before).unwrap_err();
        assert!(e.to_string().contains("starts after the image time"), "{e}");
    }
}

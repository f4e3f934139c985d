//! The seed paper's phenomena (Figs. 12 and 14) on rendered outputs of the
//! airfield scene, found through the planes (material, sun_now,
//! hours_sunlit), not pixel snapshots. Small images (128 px) keep it fast.
//!
//! * MWIR, early afternoon: the current shadow is sharp (the radiance drops
//!   across the one pixel where sun_now flips, part of it the reflected
//!   sunlight that vanishes at once); ground shaded earlier but sunlit now is
//!   cooler than ground sunlit all day, the more so the more recent the
//!   shade, and it lies west of the current shadow (the "blurred thermal
//!   shadow").
//! * LWIR: the same thermal shadow, but reflected sunlight is < 1 % of the
//!   emission (vs. > 5 % in MWIR).
//! * LWIR at a fixed 10 km slant range (Fig. 14): contrast falls with view
//!   zenith, and the specular hangar roof loses its contrast against its
//!   surroundings at 75°: its emissivity falls and it mirrors the sky.
//! * The atmosphere follows the weather: the path's thermal radiance at
//!   15:00 exceeds that at 03:00 (9 K warmer air).

mod common;

use common::{Img, airfield, material_index, render};

const SIZE: [&str; 2] = ["sensor.width_px=128", "sensor.height_px=128"];

fn with(kv: &[&str]) -> Vec<String> {
    SIZE.iter().chain(kv).map(|s| s.to_string()).collect()
}

fn render_kv(dir: &std::path::Path, name: &str, kv: &[String]) -> Img {
    let kv: Vec<&str> = kv.iter().map(String::as_str).collect();
    render(dir, &airfield(), name, &kv)
}

/// Mean of `plane` over `mask`.
fn mean(img: &Img, plane: &str, mask: &[bool]) -> f64 {
    let p = img.plane(plane);
    let (s, n) = p
        .iter()
        .zip(mask)
        .filter(|(_, m)| **m)
        .fold((0.0, 0usize), |(s, n), (v, _)| (s + *v as f64, n + 1));
    assert!(n > 0, "empty mask for {plane}");
    s / n as f64
}

/// Mean column (x, growing eastwards: the sensor is south, looking north).
fn mean_x(img: &Img, mask: &[bool]) -> f64 {
    let (s, n) = mask
        .iter()
        .enumerate()
        .filter(|(_, m)| **m)
        .fold((0.0, 0usize), |(s, n), (k, _)| {
            (s + (k as u32 % img.w) as f64, n + 1)
        });
    s / n as f64
}

fn count(mask: &[bool]) -> usize {
    mask.iter().filter(|m| **m).count()
}

/// Pixels within `r` pixels (Chebyshev) of a pixel of `mask`.
fn dilate(img: &Img, mask: &[bool], r: i64) -> Vec<bool> {
    let (w, h) = (img.w as i64, img.h as i64);
    (0..w * h)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            (-r..=r).any(|dy| {
                (-r..=r).any(|dx| {
                    let (xx, yy) = (x + dx, y + dy);
                    xx >= 0 && yy >= 0 && xx < w && yy < h && mask[(yy * w + xx) as usize]
                })
            })
        })
        .collect()
}

/// Standard deviation of `plane` over `mask`.
fn std(img: &Img, plane: &str, mask: &[bool]) -> f64 {
    let m = mean(img, plane, mask);
    let p = img.plane(plane);
    let (s, n) = p
        .iter()
        .zip(mask)
        .filter(|(_, k)| **k)
        .fold((0.0, 0usize), |(s, n), (v, _)| {
            (s + (*v as f64 - m).powi(2), n + 1)
        });
    (s / n as f64).sqrt()
}

#[test]
fn mwir_sharp_shadow_and_blurred_thermal_shadow_lwir_little_sun() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let now = "time.local=2001-08-08T13:30:00";
    // (1 sample per pixel: a shadow edge lies between a sunlit and a
    // shaded pixel, not inside a refined mixed one)
    let one = "render.supersample=1";
    let mwir = render_kv(d, "mwir", &with(&[now, one]));
    let lwir = render_kv(d, "lwir", &with(&[now, one, "sensor.band=lwir"]));
    // Where the shadows were at 10:00 and 12:00 (sun_now does not depend
    // on the history length: 1 h keeps these renders cheap).
    let shadows_at = |t: &str| {
        render_kv(
            d,
            &format!("at{}", &t[..2]),
            &with(&[
                &format!("time.local=2001-08-08T{t}:00"),
                "render.history_hours=1",
                "sensor.band=lwir",
                one,
            ]),
        )
    };
    let (e10, e12) = (shadows_at("10:00"), shadows_at("12:00"));
    let scene = airfield();
    let concrete = material_index(&scene, "concrete");
    let n = (mwir.w * mwir.h) as usize;
    let is = |img: &Img, plane: &str, k: usize, v: f32| img.plane(plane)[k] == v;
    // The apron under the aircraft in all four renders.
    let apron: Vec<bool> = (0..n)
        .map(|k| {
            [&mwir, &lwir, &e10, &e12]
                .iter()
                .all(|i| is(i, "material", k, concrete))
        })
        .collect();

    // 1. The current shadow is sharp: across every edge where sun_now flips
    //    from 1 to 0 between neighbouring apron pixels the radiance drops,
    //    on average by most of the full sunlit-shadow contrast.
    let lit_now: Vec<bool> = (0..n)
        .map(|k| apron[k] && is(&mwir, "sun_now", k, 1.0))
        .collect();
    let shade_now: Vec<bool> = (0..n)
        .map(|k| apron[k] && is(&mwir, "sun_now", k, 0.0))
        .collect();
    let (w, h) = (mwir.w as usize, mwir.h as usize);
    let full =
        |img: &Img| mean(img, "band_radiance", &lit_now) - mean(img, "band_radiance", &shade_now);
    for (img, band) in [(&mwir, "MWIR"), (&lwir, "LWIR")] {
        let l = img.plane("band_radiance");
        let rs = img.plane("reflected_solar");
        let (mut drops, mut solar) = (Vec::new(), Vec::new());
        for y in 0..h {
            for x in 0..w {
                let k = y * w + x;
                if !lit_now[k] {
                    continue;
                }
                let nb = [
                    (x > 0).then(|| k - 1),
                    (x + 1 < w).then(|| k + 1),
                    (y > 0).then(|| k - w),
                    (y + 1 < h).then(|| k + w),
                ];
                for j in nb.into_iter().flatten().filter(|&j| shade_now[j]) {
                    drops.push((l[k] - l[j]) as f64);
                    solar.push(rs[k] as f64);
                }
            }
        }
        assert!(
            drops.len() >= 10,
            "{band}: shadow edges on the apron: {}",
            drops.len()
        );
        let min = drops.iter().cloned().fold(f64::INFINITY, f64::min);
        let avg = drops.iter().sum::<f64>() / drops.len() as f64;
        let solar_avg = solar.iter().sum::<f64>() / solar.len() as f64;
        eprintln!(
            "{band}: {} edge pairs, drop min {min:.4} mean {avg:.4} of full contrast {:.4} W m-2 sr-1 um-1; reflected solar on the lit side {solar_avg:.4} ({:.1} % of the drop)",
            drops.len(),
            full(img),
            100.0 * solar_avg / avg
        );
        assert!(
            min > 0.0,
            "{band}: the radiance drops across every shadow edge"
        );
        assert!(avg > 0.5 * full(img), "{band}: the edge is sharp");
        if band == "MWIR" {
            // The instantaneous part: sunlight reflected on the lit side.
            assert!(
                solar_avg > 0.2 * avg,
                "MWIR: reflected sunlight makes the edge"
            );
        } else {
            assert!(solar_avg < 0.02 * avg, "LWIR: the edge is thermal");
        }
    }

    // 2. The blurred thermal shadow: apron sunlit now but shaded at 12:00
    //    (recent) or at 10:00 only (older) is cooler than nearby apron sunlit
    //    all day, the recent shade more so, and it lies west of the current
    //    shadow, the older shade further west.
    let s = |img: &Img, k: usize| is(img, "sun_now", k, 1.0);
    let recent: Vec<bool> = (0..n).map(|k| lit_now[k] && !s(&e12, k)).collect();
    let older: Vec<bool> = (0..n)
        .map(|k| lit_now[k] && !s(&e10, k) && s(&e12, k))
        .collect();
    let ever: Vec<bool> = (0..n).map(|k| recent[k] || older[k]).collect();
    let near = dilate(&mwir, &ever, 6);
    let max_h = (0..n)
        .filter(|&k| apron[k])
        .map(|k| mwir.plane("hours_sunlit")[k])
        .fold(0.0f32, f32::max);
    let all_day: Vec<bool> = (0..n)
        .map(|k| {
            lit_now[k]
                && near[k]
                && s(&e10, k)
                && s(&e12, k)
                && mwir.plane("hours_sunlit")[k] == max_h
        })
        .collect();
    assert!(count(&recent) >= 5 && count(&older) >= 5 && count(&all_day) >= 20);
    let (x_recent, x_older, x_now) = (
        mean_x(&mwir, &recent),
        mean_x(&mwir, &older),
        mean_x(&mwir, &shade_now),
    );
    eprintln!(
        "pixels: recent shade {}, older shade {}, sunlit all day (near) {}, shaded now {}; mean column older {x_older:.1}, recent {x_recent:.1}, now {x_now:.1}",
        count(&recent),
        count(&older),
        count(&all_day),
        count(&shade_now)
    );
    for (img, band) in [(&mwir, "MWIR"), (&lwir, "LWIR")] {
        let t = |plane: &str, m: &[bool]| mean(img, plane, m);
        let ts = [&recent, &older, &all_day].map(|m| t("surface_temperature", m));
        let ta = [&recent, &older, &all_day].map(|m| t("apparent_temperature", m));
        eprintln!(
            "{band}: surface temperature recent/older/all-day {:.2} {:.2} {:.2} K, apparent {:.2} {:.2} {:.2} K",
            ts[0], ts[1], ts[2], ta[0], ta[1], ta[2]
        );
        assert!(
            ts[0] < ts[1] - 1.0 && ts[1] < ts[2],
            "{band}: thermal shadow fades with time"
        );
        // The older shade is only ~0.2 K cooler at the surface (asserted
        // above); in apparent temperature the groups also differ by how
        // much of their sky the buildings hide (the apron nearer the hangar
        // reflects the warm ground instead of the sky: LWIR 0.3 K), which
        // masks so small a difference: the recent shade is asserted.
        assert!(
            ta[0] < ta[2] - 0.5 && ta[0] < ta[1] - 0.5,
            "{band}: the thermal shadow is seen"
        );
    }
    assert!(
        x_older < x_recent && x_recent <= x_now + 0.5,
        "the thermal shadow lies west"
    );
    assert!(x_older < x_now - 2.0);

    // 3. Reflected sunlight vs emission on sunlit ground.
    let ground: Vec<f32> = ["concrete", "asphalt", "grass_irrigated"]
        .iter()
        .map(|m| material_index(&scene, m))
        .collect();
    let sunlit_ground: Vec<bool> = (0..n)
        .map(|k| ground.contains(&mwir.plane("material")[k]) && is(&mwir, "sun_now", k, 1.0))
        .collect();
    let ratio = |img: &Img| {
        mean(img, "reflected_solar", &sunlit_ground) / mean(img, "emitted", &sunlit_ground)
    };
    let (rm, rl) = (ratio(&mwir), ratio(&lwir));
    eprintln!(
        "reflected solar / emitted on sunlit ground: MWIR {:.2} %, LWIR {:.3} %",
        100.0 * rm,
        100.0 * rl
    );
    assert!(rl < 0.01, "LWIR: little solar reflection");
    assert!(rm > 0.05, "MWIR: solar reflection comparable to emission");
}

#[test]
fn view_zenith_contrast_falls_and_specular_roof_turns_dark() {
    let dir = tempfile::tempdir().unwrap();
    let scene = airfield();
    let roof_m = material_index(&scene, "painted_steel_roof");
    let (grass_m, concrete_m) = (
        material_index(&scene, "grass_irrigated"),
        material_index(&scene, "concrete"),
    );
    let ground: Vec<f32> = ["concrete", "asphalt", "grass_irrigated", "soil_bare"]
        .iter()
        .map(|m| material_index(&scene, m))
        .collect();
    let mut rows = Vec::new();
    for vz in [0, 45, 75] {
        // Fig. 14: LWIR from a fixed 10 km slant range; a 2.5° field of
        // view spans ~440 m across, like the near-nadir scene.
        let pose = format!(
            "sensor.pose={{slant_range={{slant_range_m=10000.0,view_zenith_deg={vz}.0,azimuth_deg=180.0,target_m=[0.0,20.0,0.0]}}}}"
        );
        let img = render_kv(
            dir.path(),
            &format!("vz{vz}"),
            &with(&["sensor.band=lwir", "sensor.fov_h_deg=2.5", &pose]),
        );
        let m = img.plane("material");
        let scene_px: Vec<bool> = m.iter().map(|&v| v >= 0.0).collect();
        let roof: Vec<bool> = m.iter().map(|&v| v == roof_m).collect();
        let ring = dilate(&img, &roof, 6);
        let ring: Vec<bool> = (0..m.len())
            .map(|k| ring[k] && !roof[k] && ground.contains(&m[k]))
            .collect();
        let of = |mat: f32| -> Vec<bool> { m.iter().map(|&v| v == mat).collect() };
        let t = |mask: &[bool]| mean(&img, "apparent_temperature", mask);
        let row = (
            vz,
            std(&img, "apparent_temperature", &scene_px),
            t(&of(grass_m)) - t(&of(concrete_m)),
            t(&roof) - t(&ring),
            mean(&img, "reflected_sky", &roof)
                / (mean(&img, "reflected_sky", &roof) + mean(&img, "emitted", &roof)),
            count(&roof),
        );
        eprintln!(
            "view zenith {vz}°: std of apparent temperature over the scene {:.3} K, grass - concrete {:.2} K, roof - surroundings {:.2} K, roof reflected sky / (emitted + reflected sky) {:.3} ({} roof px)",
            row.1, row.2, row.3, row.4, row.5
        );
        assert!(row.5 >= 20, "the roof is in view");
        rows.push(row);
    }
    let (a, b, c) = (&rows[0], &rows[1], &rows[2]);
    // Contrast falls with view zenith: over the whole scene and between
    // materials.
    assert!(a.1 > b.1 && b.1 > c.1, "std falls with view zenith");
    assert!(a.2.abs() > b.2.abs() && b.2.abs() > c.2.abs());
    assert!(c.1 < 0.7 * a.1);
    // The roof loses its contrast against its surroundings at 75°,
    // mirroring the sky far more than at nadir. (With the table's own
    // mid-latitude-summer sky it turned just dark, −0.25 K from +3.6 K at
    // nadir; the sky now follows the weather, a humid 32 °C noon whose sky
    // irradiance is 418 W/m² against the table's 354, so the mirrored sky
    // is warmer: +0.37 K from +3.1 K. Since the grass is a canopy skin
    // over its soil (issue #30) the grass in the roof's surroundings is
    // warmer at noon: +0.29 K from +2.76 K.)
    assert!(
        c.3 < a.3 - 2.0 && c.3 < 0.2 * a.3,
        "the roof loses its contrast at 75°"
    );
    assert!(c.4 > 3.0 * a.4, "the roof mirrors the sky at grazing view");
}

/// The surfaces that fill the airfield, against the world (issue: a lawn
/// at 52 °C, a pond at 55 °C): at 15:00 EDT the irrigated grass is cooler
/// than asphalt and concrete and within 10 K of the air (33.3 °C in the
/// record, 14:00 EST); at 03:00 it is at or below the air (25.0 °C) and the asphalt
/// is warmer than it; the pond's apparent temperature is below the
/// pavement's by day.
#[test]
fn grass_pond_and_pavement_against_the_air_day_and_night() {
    let dir = tempfile::tempdir().unwrap();
    let scene = airfield();
    let (grass, asphalt, concrete, pond) = (
        material_index(&scene, "grass_irrigated"),
        material_index(&scene, "asphalt"),
        material_index(&scene, "concrete"),
        material_index(&scene, "pond"),
    );
    let mat_mean = |img: &Img, plane: &str, m: f32| {
        let mask: Vec<bool> = img.plane("material").iter().map(|&v| v == m).collect();
        mean(img, plane, &mask)
    };
    // Air temperature of the record at those hours (TMY3, Greensboro, Aug 8 2001).
    let day = render_kv(
        dir.path(),
        "d15",
        &with(&["sensor.band=lwir", "time.local=2001-08-08T15:00:00"]),
    );
    let night = render_kv(
        dir.path(),
        "n03",
        &with(&["sensor.band=lwir", "time.local=2001-08-08T03:00:00"]),
    );
    let t = |img: &Img, m| mat_mean(img, "surface_temperature", m) - 273.15;
    let (g, a, c) = (t(&day, grass), t(&day, asphalt), t(&day, concrete));
    eprintln!("15:00: grass {g:.1} °C, asphalt {a:.1} °C, concrete {c:.1} °C");
    assert!(g < a && g < c, "grass cooler than the pavements by day");
    assert!((g - 33.3).abs() < 10.0, "grass within 10 K of the air");
    let (gn, an) = (t(&night, grass), t(&night, asphalt));
    eprintln!("03:00: grass {gn:.1} °C, asphalt {an:.1} °C");
    assert!(gn <= 25.0 + 0.3, "grass at or below the air at night");
    assert!(an > gn, "asphalt warmer than grass at night");
    let at = |m| mat_mean(&day, "apparent_temperature", m);
    eprintln!(
        "15:00 apparent: pond {:.1} K, asphalt {:.1} K, concrete {:.1} K",
        at(pond),
        at(asphalt),
        at(concrete)
    );
    assert!(at(pond) < at(asphalt) && at(pond) < at(concrete));
    // Issue: path radiance at 03:00 and 15:00 was identical while the air
    // swung 9 K. The path to the sensor at 1.5 km takes g = 0.57 of it
    // (5 K: +8 % at 10 µm), and the night's moister air (vapour pressure
    // 2.5 vs 2.3 kPa) makes the night path 7 % more opaque, so it emits
    // more: measured +2.8 %; more than 2 % asserted (0 % before).
    let all: Vec<bool> = day.plane("material").iter().map(|&v| v >= 0.0).collect();
    let (pd, pn) = (
        mean(&day, "path_thermal", &all),
        mean(&night, "path_thermal", &all),
    );
    eprintln!("path thermal radiance: 15:00 {pd:.4}, 03:00 {pn:.4} W m-2 sr-1");
    assert!(pd > 1.02 * pn, "the path follows the air temperature");
}

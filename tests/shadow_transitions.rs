//! Sun/shadow transitions found by bisection (`render.shadow_resolution_min`)
//! against every fine sample traced, and the thermal key's coarsening of old
//! transitions (`render.shadow_key_recent_h`) against the exact key.

use irsig::render::{Frame, Sample, prepare_conditions, prepare_static, render};

/// The airfield at 32² (1 sample per pixel, 48-h history), with `kv`.
fn frame(kv: &[(&str, &str)]) -> Frame {
    let mut ov: Vec<(String, String)> = [
        ("sensor.width_px", "32"),
        ("sensor.height_px", "32"),
        ("render.supersample", "1"),
        ("render.history_hours", "48"),
    ]
    .iter()
    .chain(kv)
    .map(|(k, v)| (k.to_string(), v.to_string()))
    .collect();
    ov.push(("time.local".into(), "2001-08-08T18:00:00".into()));
    let scene =
        irsig::scene::load_with_overrides(std::path::Path::new("scenes/airfield/scene.toml"), &ov)
            .unwrap();
    let mut st = prepare_static(scene, None).unwrap();
    st.keep_samples = true;
    let cond = prepare_conditions(&st, st.scene.scene.time.utc(&st.scene.scene.site)).unwrap();
    render(&st, &cond).unwrap()
}

fn histories(f: &Frame) -> Vec<Option<Vec<bool>>> {
    (f.samples.iter())
        .map(|s: &Sample| s.surface.as_ref().map(|s| s.history.iter().collect()))
        .collect()
}

/// Tracing every 20 min and bisecting each change to 5 min gives the
/// histories that tracing every 5 min gives, except within a 20-min
/// interval that holds two or more transitions of the fine trace (a shadow
/// shorter than the interval, or several, missed or half-found by its two
/// traced samples); with fewer shadow rays.
#[test]
fn bisection_finds_the_transitions_of_the_fine_trace() {
    let fine = frame(&[("render.shadow_interval_min", "5")]);
    let bis = frame(&[
        ("render.shadow_interval_min", "20"),
        ("render.shadow_resolution_min", "5"),
    ]);
    let (hf, hb) = (histories(&fine), histories(&bis));
    assert_eq!(hf.len(), hb.len());
    let (mut same, mut hit, mut intervals, mut multi) = (0, 0, 0, 0);
    for (a, b) in hf.iter().zip(&hb) {
        match (a, b) {
            (Some(a), Some(b)) => {
                hit += 1;
                assert_eq!(a.len(), b.len(), "both on the 5-min grid");
                same += usize::from(a == b);
                for k in (0..a.len() - 1).step_by(4) {
                    let end = (k + 4).min(a.len() - 1);
                    let flips = (k + 1..=end).filter(|&i| a[i] != a[i - 1]).count();
                    intervals += usize::from(flips > 0);
                    multi += usize::from(flips > 1);
                    assert_eq!(a[k], b[k], "traced sample {k} differs");
                    if a[k..=end] != b[k..=end] {
                        assert!(
                            flips > 1,
                            "samples {k}-{end}: the fine trace has one transition there, \
                             bisection found another"
                        );
                    }
                }
            }
            (None, None) => {}
            _ => panic!("the primary rays differ"),
        }
    }
    assert!(hit > 500, "{hit} surface samples");
    // Most intervals with a transition hold just one (then bisection finds
    // it exactly); most histories come out the same.
    assert!(
        multi * 5 < intervals,
        "{multi} of {intervals} intervals with several"
    );
    assert!(
        same * 5 > hit * 4,
        "{same} of {hit} histories as the fine trace's"
    );
    assert!(
        bis.stats.solar_rays * 2 < fine.stats.solar_rays,
        "bisection {} rays, fine trace {}",
        bis.stats.solar_rays,
        fine.stats.solar_rays
    );
}

/// Coarsening the key of transitions older than 2 h changes the surface
/// temperature by little (the old shadows' timing hardly matters at the
/// image time) and shares solves; transitions in the last 2 h keep their
/// timing, so the sunlit flag at the image time is unchanged.
#[test]
fn old_transitions_share_a_key() {
    // (at a uniform-enough 0.1 K step tolerance: a looser one lets two different
    // histories' marches differ by their own step control)
    let base = [
        ("render.shadow_interval_min", "20"),
        ("render.shadow_resolution_min", "2.5"),
        ("render.thermal_tol_k", "0.1"),
    ];
    // (240 h: every transition of the 48-h history at full resolution)
    let exact = frame(&[
        base[0],
        base[1],
        base[2],
        ("render.shadow_key_recent_h", "240"),
    ]);
    let keyed = frame(&[
        base[0],
        base[1],
        base[2],
        ("render.shadow_key_recent_h", "2"),
    ]);
    assert!(
        keyed.stats.thermal_solves < exact.stats.thermal_solves,
        "{} solves keyed, {} exact",
        keyed.stats.thermal_solves,
        exact.stats.thermal_solves
    );
    let t = |f: &Frame| f.planes.get("surface_temperature").unwrap().data.clone();
    let (te, tk) = (t(&exact), t(&keyed));
    let mut worst = 0f32;
    for (a, b) in te.iter().zip(&tk) {
        if a.is_finite() {
            worst = worst.max((a - b).abs());
        }
    }
    assert!(worst < 0.5, "largest change {worst} K");
}

/// Bisection, keyed histories and adaptive histories together: the same
/// bits on one thread and on two.
#[test]
fn same_bits_for_one_and_two_threads() {
    let kv = [
        ("render.supersample", "4"),
        ("render.sampling", "uniform"),
        ("render.shadow_interval_min", "60"),
        ("render.shadow_resolution_min", "2.5"),
        ("render.shadow_key_recent_h", "2"),
        ("render.adaptive_histories", "true"),
    ];
    let planes = |threads: u32| {
        let pool = irsig::render::thread_pool(Some(threads)).unwrap();
        let f = pool.install(|| frame(&kv));
        assert!(f.stats.history_pixels_corners > 0 && f.stats.history_pixels_refined > 0);
        f.planes
    };
    let (a, b) = (planes(1), planes(2));
    for name in [
        "apparent_temperature",
        "surface_temperature",
        "hours_sunlit",
    ] {
        let (pa, pb) = (a.get(name).unwrap(), b.get(name).unwrap());
        let same = pa
            .data
            .iter()
            .zip(&pb.data)
            .all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "plane {name} differs between 1 and 2 threads");
    }
}

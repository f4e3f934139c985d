//! Adaptive image sampling (`render.sampling = "adaptive"`) against the
//! uniform render of the same density (every pixel at n×n), and its
//! determinism across thread counts.

use irsig::output::Planes;
use irsig::render::{Frame, prepare_conditions, prepare_static, render};

/// The airfield at 32², LWIR, 18:00 (cheap history: 60-min samples, 24 h),
/// with `kv`.
fn frame(kv: &[(&str, &str)]) -> Frame {
    let ov: Vec<(String, String)> = [
        ("sensor.width_px", "32"),
        ("sensor.height_px", "32"),
        ("sensor.band", "lwir"),
        ("render.shadow_interval_min", "60"),
        ("render.history_hours", "24"),
        ("time.local", "2001-08-08T18:00:00"),
    ]
    .iter()
    .chain(kv)
    .map(|(k, v)| (k.to_string(), v.to_string()))
    .collect();
    let scene =
        irsig::scene::load_with_overrides(std::path::Path::new("scenes/airfield/scene.toml"), &ov)
            .unwrap();
    let st = prepare_static(scene, None).unwrap();
    let cond = prepare_conditions(&st, st.scene.scene.time.utc(&st.scene.scene.site)).unwrap();
    render(&st, &cond).unwrap()
}

fn plane<'a>(p: &'a Planes, name: &str) -> &'a [f32] {
    &p.get(name).unwrap().data
}

/// |a − b| per pixel of the apparent temperature, K (sorted).
fn errors(a: &Planes, b: &Planes) -> Vec<f64> {
    let name = "apparent_temperature";
    let mut e: Vec<f64> = (plane(a, name).iter().zip(plane(b, name)))
        .map(|(x, y)| (*x as f64 - *y as f64).abs())
        .collect();
    e.sort_by(f64::total_cmp);
    e
}

/// An adaptive 8×8 render against the uniform 8×8 render (its converged
/// value at that density): the refined pixels' refined cells are the
/// uniform render's samples, their other cells one sample each and the
/// unrefined pixels one sample, within the refinement threshold's reach — far closer
/// than a 1-sample render, with a fraction of the samples.
#[test]
fn adaptive_approaches_uniform_at_the_same_density() {
    let uniform = frame(&[("render.supersample", "8"), ("render.sampling", "uniform")]);
    let one = frame(&[("render.supersample", "1")]);
    let adaptive = frame(&[
        ("render.supersample", "8"),
        ("render.sampling", "adaptive"),
        ("render.refine_threshold_k", "0.05"),
    ]);
    let s = &adaptive.stats;
    assert_eq!(
        s.adaptive_pixels_coarse + s.adaptive_pixels_refined,
        32 * 32
    );
    assert!(s.adaptive_pixels_refined > 0 && s.adaptive_pixels_coarse > 0);
    assert_eq!(s.adaptive_refined_density, 8);
    // (8×8 in 4×4 cells of 2×2: 16 first-level samples per refined pixel,
    // 3 more per refined cell, the coarse sample reused where it lies)
    assert_eq!(
        s.adaptive_cells_refined + s.adaptive_cells_coarse,
        16 * s.adaptive_pixels_refined
    );
    assert!(s.adaptive_cells_refined > 0 && s.adaptive_cells_coarse > 0);
    let (lo, hi) = (
        32 * 32 + s.adaptive_pixels_refined * 16 + s.adaptive_cells_refined * 2,
        32 * 32 + s.adaptive_pixels_refined * 16 + s.adaptive_cells_refined * 3,
    );
    assert!(
        (lo..=hi).contains(&s.samples),
        "one coarse sample per pixel, 16 per refined pixel, 2-3 per refined cell: {} not in {lo}..={hi}",
        s.samples
    );
    // (at 32², over half the pixels are edge or border pixels)
    assert!(s.samples * 10 < uniform.stats.samples * 6, "{}", s.samples);
    let (ea, e1) = (
        errors(&adaptive.planes, &uniform.planes),
        errors(&one.planes, &uniform.planes),
    );
    let rms = |e: &[f64]| (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt();
    let max = |e: &[f64]| *e.last().unwrap();
    eprintln!(
        "adaptive: rms {:.4} max {:.4} K; 1 spp: rms {:.4} max {:.4} K; refined {}",
        rms(&ea),
        max(&ea),
        rms(&e1),
        max(&e1),
        s.adaptive_pixels_refined
    );
    assert!(rms(&ea) < 0.05 && max(&ea) < 1.0, "adaptive vs uniform");
    assert!(rms(&ea) < rms(&e1) / 4.0, "much closer than 1 spp");
    // Uniform sampling (no adaptive counters).
    assert_eq!(uniform.stats.adaptive_pixels_refined, 0);
    assert_eq!(uniform.stats.adaptive_refined_density, 0);
}

/// The same bits on one thread and on two.
#[test]
fn adaptive_same_bits_for_one_and_two_threads() {
    let kv = [
        ("render.supersample", "6"),
        ("render.sampling", "adaptive"),
        ("render.refine_threshold_k", "0.02"),
    ];
    let planes = |threads: u32| {
        let pool = irsig::render::thread_pool(Some(threads)).unwrap();
        pool.install(|| frame(&kv)).planes
    };
    let (a, b) = (planes(1), planes(2));
    for p in &a.planes {
        let q = b.get(&p.name).unwrap();
        let same = (p.data.iter().zip(&q.data)).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "plane {} differs between 1 and 2 threads", p.name);
    }
}

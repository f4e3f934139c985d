//! `irsig bench rays`: ray throughput of the tracer backends on the
//! ~5,000-triangle benchmark scene, primary and shadow rays, single rays vs
//! 16-wide packets, Embree vs obvhs. Reports Mrays/s (best of `--repeat`).

use std::sync::Arc;
use std::time::Instant;

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use crate::sensor::camera::Camera;
use crate::trace::bvh::BvhTracer;
use crate::trace::embree::{EmbreeTracer, set_thread_ftz_daz};
use crate::trace::offset::offset_origin;
use crate::trace::{Geometry, Hit, QueryMode, Ray, Tracer, meshgen};

#[derive(clap::Subcommand, Debug)]
pub enum BenchCommand {
    /// Mrays/s for primary and shadow rays, per backend and query mode.
    Rays(RaysArgs),
    /// Run time against error for each knob (thermal step, shadow sampling,
    /// spectral step, supersampling, spin-up) against a converged reference.
    Accuracy(super::accuracy::AccuracyArgs),
    /// Render stage times, Mrays/s and the ratio to the pure-Embree ray
    /// floor, peak memory, over image sizes and facet counts.
    Speed(SpeedArgs),
}

#[derive(clap::Args, Debug)]
pub struct SpeedArgs {
    /// The scene file.
    pub scene: std::path::PathBuf,
    /// Image sizes (square), pixels.
    #[arg(long, value_delimiter = ',', default_value = "256,512,1024,2048")]
    pub sizes: Vec<u32>,
    /// Facet multipliers: each triangle split into n² (1, 9 ≈ 10x, 100).
    #[arg(long, value_delimiter = ',', default_value = "1,3,10")]
    pub subdivide: Vec<u32>,
    /// Image size used for the facet-count rows.
    #[arg(long, default_value_t = 512)]
    pub facet_size: u32,
    /// Override scene keys (as `irsig render --set`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<u32>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

#[derive(clap::Args, Debug)]
pub struct RaysArgs {
    /// Image width and height, pixels.
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub size: u32,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Timed repetitions per row (the best is reported).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub repeat: u32,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// One row of the table.
#[derive(Debug, serde::Serialize)]
pub struct Row {
    pub workload: String,
    pub backend: String,
    pub mode: String,
    pub rays: usize,
    pub best_s: f64,
    pub mrays_per_s: f64,
}

pub fn run(cmd: BenchCommand) -> anyhow::Result<i32> {
    match cmd {
        BenchCommand::Rays(a) => rays(a),
        BenchCommand::Speed(a) => speed(a),
        BenchCommand::Accuracy(a) => super::accuracy::run(a),
    }
}

/// Rays per rayon task: 16 packets of one 4x4 tile each.
const TASK: usize = 256;

fn time_best(repeat: u32, mut f: impl FnMut()) -> f64 {
    (0..repeat)
        .map(|_| {
            let t0 = Instant::now();
            f();
            t0.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn rays(a: RaysArgs) -> anyhow::Result<i32> {
    let mut pool = rayon::ThreadPoolBuilder::new().start_handler(|_| set_thread_ftz_daz());
    if let Some(n) = a.threads {
        pool = pool.num_threads(n);
    }
    let pool = pool.build()?;
    let (p, t) = meshgen::bench_scene().finish();
    let g = Arc::new(Geometry::new(p, t)?);
    let packet = EmbreeTracer::new(g.clone(), QueryMode::Packet16)?;
    let single = EmbreeTracer::new(g.clone(), QueryMode::Single)?;
    let bvh = BvhTracer::new(g.clone());
    let cam = Camera::look_at(
        DVec3::new(0.0, -160.0, 230.0),
        DVec3::ZERO,
        60.0,
        a.size,
        a.size,
    );
    let primary: Vec<Ray> = cam
        .tile_order()
        .iter()
        .map(|&(x, y)| cam.ray(x as f64 + 0.5, y as f64 + 0.5))
        .collect();
    let mut hits = vec![None; primary.len()];
    pool.install(|| {
        primary
            .par_chunks(TASK)
            .zip(hits.par_chunks_mut(TASK))
            .for_each(|(r, h)| packet.intersect(r, h))
    });
    // Shadow rays: one sun direction for the whole image, from each hit,
    // kept in tile order so packets stay coherent.
    let sun = Vec3::new(0.35, -0.45, 0.82).normalize();
    let shadow: Vec<Ray> = primary
        .iter()
        .zip(&hits)
        .map(|(r, h): (&Ray, &Option<Hit>)| match h {
            Some(h) => {
                let n = g.normals[h.prim as usize];
                let n = if n.dot(r.dir) > 0.0 { -n } else { n };
                Ray::new(offset_origin(g.point(h.prim, h.u, h.v), n), sun)
            }
            // Misses still cast a (trivially unoccluded) ray, as a render would not.
            None => Ray::new(r.org, sun),
        })
        .collect();
    let tracers: [(&dyn Tracer, &str); 3] =
        [(&single, "single"), (&packet, "packet16"), (&bvh, "single")];
    let mut rows = Vec::new();
    for (name, set) in [("primary", &primary), ("shadow", &shadow)] {
        for (tracer, mode) in tracers {
            let best = pool.install(|| {
                time_best(a.repeat, || {
                    if name == "primary" {
                        let mut out = vec![None; set.len()];
                        set.par_chunks(TASK)
                            .zip(out.par_chunks_mut(TASK))
                            .for_each(|(r, h)| tracer.intersect(r, h));
                    } else {
                        let mut out = vec![false; set.len()];
                        set.par_chunks(TASK)
                            .zip(out.par_chunks_mut(TASK))
                            .for_each(|(r, o)| tracer.occluded(r, o));
                    }
                })
            });
            rows.push(Row {
                workload: name.into(),
                backend: tracer.backend().to_string(),
                mode: mode.into(),
                rays: set.len(),
                best_s: best,
                mrays_per_s: set.len() as f64 / best / 1e6,
            });
        }
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        println!(
            "bench rays: {} triangles, {}x{} px, {} threads, Embree {}, best of {}",
            g.triangles.len(),
            a.size,
            a.size,
            pool.current_num_threads(),
            EmbreeTracer::version_string(),
            a.repeat
        );
        println!(
            "| workload | backend | mode | rays | best ms | Mrays/s |\n|---|---|---|---|---|---|"
        );
        for r in &rows {
            println!(
                "| {} | {} | {} | {} | {:.1} | {:.1} |",
                r.workload,
                r.backend,
                r.mode,
                r.rays,
                r.best_s * 1e3,
                r.mrays_per_s
            );
        }
    }
    Ok(0)
}

/// One row of `bench speed`.
#[derive(Debug, serde::Serialize)]
pub struct SpeedRow {
    pub size: u32,
    pub triangles: usize,
    pub load_bvh_s: f64,
    pub conditions_s: f64,
    pub trace_s: f64,
    pub thermal_s: f64,
    pub radiometry_s: f64,
    pub sensor_s: f64,
    pub total_s: f64,
    pub rays: u64,
    pub mrays_per_s: f64,
    /// Time of the same numbers of primary and shadow rays at the
    /// pure-Embree packet rate measured on this scene and camera.
    pub embree_floor_s: f64,
    pub ratio_to_floor: f64,
    pub thermal_solves: u64,
    pub peak_rss_mib: f64,
}

/// Peak resident memory of this process (VmHWM), MiB; 0 where unknown.
pub fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<f64>().ok())
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

/// Splits every triangle into n² (midpoint grid), keeping its material,
/// object and facet.
fn subdivide(s: &mut crate::scene::LoadedScene, n: u32) {
    if n <= 1 {
        return;
    }
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    let (mut mat, mut obj, mut fac) = (Vec::new(), Vec::new(), Vec::new());
    let nf = n as f32;
    for (t, tri) in s.triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|k| Vec3::from(s.positions[k as usize]));
        // Vertices (i, j) with i + j <= n: a + (b−a)·i/n + (c−a)·j/n.
        let mut id = vec![vec![0u32; (n + 1) as usize]; (n + 1) as usize];
        for i in 0..=n {
            for j in 0..=(n - i) {
                id[i as usize][j as usize] = pos.len() as u32;
                pos.push((a + (b - a) * (i as f32 / nf) + (c - a) * (j as f32 / nf)).to_array());
            }
        }
        for i in 0..n as usize {
            for j in 0..(n as usize - i) {
                let mut push = |q: [u32; 3]| {
                    tris.push(q);
                    mat.push(s.tri_material[t]);
                    obj.push(s.tri_object[t]);
                    fac.push(s.tri_facet[t]);
                };
                push([id[i][j], id[i + 1][j], id[i][j + 1]]);
                if j + 1 < n as usize - i {
                    push([id[i + 1][j], id[i + 1][j + 1], id[i][j + 1]]);
                }
            }
        }
    }
    s.positions = pos;
    s.triangles = tris;
    s.tri_material = mat;
    s.tri_object = obj;
    s.tri_facet = fac;
}

/// Pure-Embree packet throughput (primary, shadow) in rays/s for the
/// scene's geometry and a camera, tile-ordered as the render traces.
fn embree_rates(g: &Arc<Geometry>, cam: &Camera, sun: Vec3) -> anyhow::Result<(f64, f64)> {
    let packet = EmbreeTracer::new(g.clone(), QueryMode::Packet16)?;
    let primary: Vec<Ray> = cam
        .tile_order()
        .iter()
        .map(|&(x, y)| cam.ray(x as f64 + 0.5, y as f64 + 0.5))
        .collect();
    let mut hits = vec![None; primary.len()];
    primary
        .par_chunks(TASK)
        .zip(hits.par_chunks_mut(TASK))
        .for_each(|(r, h)| packet.intersect(r, h));
    let shadow: Vec<Ray> = primary
        .iter()
        .zip(&hits)
        .filter_map(|(r, h)| {
            h.map(|h| {
                let n = g.normals[h.prim as usize];
                let n = if n.dot(r.dir) > 0.0 { -n } else { n };
                Ray::new(offset_origin(g.point(h.prim, h.u, h.v), n), sun)
            })
        })
        .collect();
    let tp = time_best(3, || {
        let mut out = vec![None; primary.len()];
        primary
            .par_chunks(TASK)
            .zip(out.par_chunks_mut(TASK))
            .for_each(|(r, h)| packet.intersect(r, h));
    });
    let ts = time_best(3, || {
        let mut out = vec![false; shadow.len()];
        shadow
            .par_chunks(TASK)
            .zip(out.par_chunks_mut(TASK))
            .for_each(|(r, o)| packet.occluded(r, o));
    });
    Ok((primary.len() as f64 / tp, shadow.len().max(1) as f64 / ts))
}

fn speed(a: SpeedArgs) -> anyhow::Result<i32> {
    use crate::render::{prepare_conditions, prepare_static, render};
    let overrides = super::render::parse_overrides(&a.set)?;
    let pool = super::render::thread_pool(a.threads)?;
    let mut jobs: Vec<(u32, u32)> = a.sizes.iter().map(|&s| (s, 1)).collect();
    jobs.extend(
        a.subdivide
            .iter()
            .filter(|&&n| n > 1)
            .map(|&n| (a.facet_size, n)),
    );
    let mut rows = Vec::new();
    for (size, n) in jobs {
        let mut ov = overrides.clone();
        ov.push(("sensor.width_px".into(), size.to_string()));
        ov.push(("sensor.height_px".into(), size.to_string()));
        // Reset the peak-RSS mark so that each row reports its own peak
        // (Linux: writing 5 to clear_refs resets VmHWM).
        let _ = std::fs::write("/proc/self/clear_refs", "5");
        let row = pool.install(|| -> anyhow::Result<SpeedRow> {
            let t0 = Instant::now();
            let mut scene = crate::scene::load_with_overrides(&a.scene, &ov)?;
            subdivide(&mut scene, n);
            let st = prepare_static(scene, None)?;
            let load = t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            let t = st.scene.scene.time.utc(&st.scene.scene.site);
            let cond = prepare_conditions(&st, t)?;
            let conditions = t1.elapsed().as_secs_f64();
            let frame = render(&st, &cond)?;
            let s = &frame.stats;
            let cam = Camera::from_geometry(&st.scene.camera);
            let sun = glam::DVec3::from(cond.sun_now.sun_dir_enu).as_vec3();
            let (rp, rs) = embree_rates(&st.geometry, &cam, sun)?;
            let floor = s.primary_rays as f64 / rp + (s.solar_rays + s.specular_rays) as f64 / rs;
            let stages =
                s.seconds.trace + s.seconds.thermal + s.seconds.radiometry + s.seconds.sensor;
            let total = load + conditions + stages;
            let rays = s.primary_rays + s.solar_rays + s.specular_rays;
            Ok(SpeedRow {
                size,
                triangles: st.geometry.triangles.len(),
                load_bvh_s: load,
                conditions_s: conditions,
                trace_s: s.seconds.trace,
                thermal_s: s.seconds.thermal,
                radiometry_s: s.seconds.radiometry,
                sensor_s: s.seconds.sensor,
                total_s: total,
                rays,
                mrays_per_s: rays as f64 / s.seconds.trace / 1e6,
                embree_floor_s: floor,
                ratio_to_floor: stages / floor,
                thermal_solves: s.thermal_solves,
                peak_rss_mib: peak_rss_mib(),
            })
        })?;
        if !a.json {
            eprintln!(
                "bench speed: {size}² px, {} triangles: {:.2} s",
                row.triangles, row.total_s
            );
        }
        rows.push(row);
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        println!(
            "| px | triangles | load+BVH s | weather+sun s | trace s | thermal s | radiometry s | sensor s | total s | Mrays/s (trace) | Embree floor s | render/floor | solves | peak MiB |"
        );
        println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
        for r in &rows {
            println!(
                "| {0}² | {1} | {2:.2} | {3:.2} | {4:.2} | {5:.2} | {6:.2} | {7:.2} | {8:.2} | {9:.1} | {10:.3} | {11:.0}x | {12} | {13:.0} |",
                r.size,
                r.triangles,
                r.load_bvh_s,
                r.conditions_s,
                r.trace_s,
                r.thermal_s,
                r.radiometry_s,
                r.sensor_s,
                r.total_s,
                r.mrays_per_s,
                r.embree_floor_s,
                r.ratio_to_floor,
                r.thermal_solves,
                r.peak_rss_mib
            );
        }
    }
    Ok(0)
}

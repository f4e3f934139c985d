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

//! Benchmarks as library calls (`irsig bench rays|speed|accuracy` are thin
//! shells over them): ray throughput of the tracer backends ([`rays`]),
//! stage times against the pure-Embree ray floor ([`speed`]) and run time
//! against error, knob by knob ([`accuracy`]). Each takes plain-data
//! options and returns rows (serde-serialisable); [`report`] writes
//! accuracy's files. The Embree-vs-obvhs cross-check ([`crosscheck`], and
//! [`crosscheck_file`] for a scene or mesh file: `irsig crosscheck`) lives
//! here too. A harness above `render` and `output` (it renders and times
//! the writing), as `batch` is.

use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

use crate::sensor::camera::Camera;
use crate::trace::offset::offset_origin;
use crate::trace::{Geometry, Hit, Ray, Tracer};

pub mod accuracy;
pub mod crosscheck;
pub mod crosscheck_file;
pub mod rays;
pub mod report;
pub mod speed;

pub use accuracy::{AccuracyOptions, AccuracyRow, accuracy};
pub use rays::{RayRow, RaysOptions, RaysReport, rays};
pub use speed::{SpeedOptions, SpeedRow, speed};

/// Rays per rayon task: 16 packets of one 4x4 tile each.
const TASK: usize = 256;

/// One ray through each pixel centre of `cam`, in 4x4 tile order (as a
/// render traces them, so packets stay coherent).
fn tile_rays(cam: &Camera) -> Vec<Ray> {
    cam.tile_order()
        .iter()
        .map(|&(x, y)| cam.ray(x as f64 + 0.5, y as f64 + 0.5))
        .collect()
}

/// The closest hits of `rays`, traced in parallel in tasks of [`TASK`] rays
/// (in the current rayon pool).
fn intersect_all(t: &dyn Tracer, rays: &[Ray]) -> Vec<Option<Hit>> {
    let mut hits = vec![None; rays.len()];
    rays.par_chunks(TASK)
        .zip(hits.par_chunks_mut(TASK))
        .for_each(|(r, h)| t.intersect(r, h));
    hits
}

/// Whether each of `rays` is occluded, traced as [`intersect_all`].
fn occluded_all(t: &dyn Tracer, rays: &[Ray]) -> Vec<bool> {
    let mut out = vec![false; rays.len()];
    rays.par_chunks(TASK)
        .zip(out.par_chunks_mut(TASK))
        .for_each(|(r, o)| t.occluded(r, o));
    out
}

/// The ray toward `sun` from the hit `h` of `r`, offset off the surface on
/// the side `r` came from.
fn shadow_ray(g: &Geometry, r: &Ray, h: &Hit, sun: Vec3) -> Ray {
    let n = g.normals[h.prim as usize];
    let n = if n.dot(r.dir) > 0.0 { -n } else { n };
    Ray::new(offset_origin(g.point(h.prim, h.u, h.v), n), sun)
}

/// The shortest of `repeat` timed runs of `f`, s.
fn time_best(repeat: u32, mut f: impl FnMut()) -> f64 {
    (0..repeat)
        .map(|_| {
            let t0 = Instant::now();
            f();
            t0.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// CPU time (user + system, all threads) this process has used so far, s,
/// from /proc/self/stat (clock ticks of USER_HZ = 100); NaN where unknown.
pub fn process_cpu_s() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // Fields after the command name's closing parenthesis start at field 3
    // (state); utime and stime are fields 14 and 15.
    let after = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = after.split_whitespace().collect();
    match (
        f.get(11).and_then(|v| v.parse::<f64>().ok()),
        f.get(12).and_then(|v| v.parse::<f64>().ok()),
    ) {
        (Some(u), Some(s)) => (u + s) / 100.0,
        _ => f64::NAN,
    }
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

/// Resets the peak-RSS mark so that the next [`peak_rss_mib`] reports the
/// peak from now on (Linux: writing 5 to /proc/self/clear_refs resets
/// VmHWM); does nothing where that is not possible.
pub fn reset_peak_rss() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn process_cpu_time_grows_with_work() {
        // Busy-wait until the process has used 30 ms more CPU time; a
        // clock that did not move would hit the 10-s wall limit.
        let c0 = process_cpu_s();
        assert!(c0.is_finite() && c0 >= 0.0, "{c0}");
        let (t, mut x) = (Instant::now(), 0u64);
        while process_cpu_s() - c0 < 0.03 && t.elapsed().as_secs_f64() < 10.0 {
            for _ in 0..100_000 {
                x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
            }
        }
        let c1 = process_cpu_s();
        assert!(c1 - c0 >= 0.03, "{c0} -> {c1} s after {:?}", t.elapsed());
    }

    #[test]
    fn peak_memory_covers_a_touched_allocation() {
        // 64 MiB written page by page must show in the peak mark.
        let before = peak_rss_mib();
        let v = std::hint::black_box(vec![1u8; 64 << 20]);
        let after = peak_rss_mib();
        assert!(v.iter().step_by(4096).all(|&b| b == 1));
        assert!(after >= 64.0 && after >= before, "{before} -> {after} MiB");
    }
}

//! Step 2 of adaptive sampling, the refinement criterion ([`super`]'s
//! module docs): whether two samples differ ([`differ`]), and the side
//! test that refines only the pixel whose half an edge crosses
//! ([`edge_in`], [`Midpoints`]).

use glam::Vec3;

use crate::render::frame::Counters;
use crate::render::prepare::{Conditions, Static};
use crate::render::sample::{Sample, Surface};
use crate::render::sunflags::SunFlags;
use crate::render::tracing::{sun_flags_at, trace_geometry};
use crate::sensor::camera::Camera;

/// The 8 neighbours of a pixel.
pub(super) const NEIGHBOURS: [(i64, i64); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// Two normals more than about 1° apart are two planes.
pub(super) const SAME_PLANE_COS: f32 = 0.99985;
/// Two parallel planes farther apart than this (m) plus [`PLANE_TOL_REL`]
/// of the range are two planes.
pub(super) const PLANE_TOL_M: f32 = 0.05;
pub(super) const PLANE_TOL_REL: f32 = 1e-4;

/// Whether two surfaces lie on one plane of one material: the same
/// material, normals within 1° ([`SAME_PLANE_COS`]) and each point within
/// [`PLANE_TOL_M`] + [`PLANE_TOL_REL`] of the range of the other's plane
/// (module docs of `adaptive`, step 2). What is not is an object edge: a
/// silhouette against a background, a step, a crease or a change of
/// material.
pub fn same_plane(a: &Surface, b: &Surface) -> bool {
    a.material == b.material
        && a.normal.dot(b.normal) >= SAME_PLANE_COS
        && a.normal.dot(b.point - a.point).abs()
            <= PLANE_TOL_M + PLANE_TOL_REL * a.range_m.max(b.range_m)
}

/// Whether two surfaces (or their absence) may differ in value between
/// them: see the module docs, step 2. `threshold_k` `None` leaves the
/// temperatures out (geometry and sun state only).
fn surfaces_differ(a: Option<&Surface>, b: Option<&Surface>, threshold_k: Option<f64>) -> bool {
    match (a, b) {
        (None, None) => false,
        (Some(a), Some(b)) => {
            !same_plane(a, b)
                || a.sun_now() != b.sun_now()
                // (NaN-safe: a NaN temperature differs)
                || threshold_k.is_some_and(|t| {
                    (a.temp_k - b.temp_k).abs().partial_cmp(&t) != Some(std::cmp::Ordering::Less)
                })
        }
        _ => true,
    }
}

/// [`differ`], the temperatures compared against `threshold_k` or (`None`)
/// left out.
fn differ_by(a: &Sample, b: &Sample, threshold_k: Option<f64>) -> bool {
    surfaces_differ(a.surface.as_ref(), b.surface.as_ref(), threshold_k)
        || match (a.bounce.as_deref(), b.bounce.as_deref()) {
            (None, None) => false,
            (Some((da, x)), Some((db, y))) => {
                // (a mirror ray that leaves the scene: sky above, ground below)
                let up = |d: &Vec3| d.z > 0.0;
                (x.is_none() && y.is_none() && up(da) != up(db))
                    || surfaces_differ(x.as_ref(), y.as_ref(), threshold_k)
            }
            _ => true,
        }
}

/// The refinement criterion between the coarse samples of two
/// neighbouring pixels (module docs, step 2).
pub fn differ(a: &Sample, b: &Sample, threshold_k: f64) -> bool {
    differ_by(a, b, Some(threshold_k))
}

/// The sample of output pixel (`x`, `y`)'s `n`×`n` grid nearest its
/// centre, in sample-image coordinates.
pub(super) fn centre(x: u32, y: u32, n: u32) -> (u32, u32) {
    (x * n + n / 2, y * n + n / 2)
}

/// The grid position halfway between the centre samples of pixel (`x`,
/// `y`) and its neighbour (`x + dx`, `y + dy`) (the pixels' shared edge
/// midpoint or corner), in sample-image coordinates; `None` for an odd `n`
/// (no grid position lies there).
fn midpoint(x: u32, y: u32, (dx, dy): (i64, i64), n: u32) -> Option<(u32, u32)> {
    if n % 2 == 1 {
        return None;
    }
    let (cx, cy) = centre(x, y, n);
    let half = i64::from(n / 2);
    let mx = u32::try_from(i64::from(cx) + dx * half).ok()?;
    let my = u32::try_from(i64::from(cy) + dy * half).ok()?;
    Some((mx, my))
}

/// Whether the coarse samples of two neighbouring pixels differ in what a
/// sample halfway between them can place on one side (module docs, step
/// 2): the surface, its plane or material, the sun state now, a specular
/// background — everything but the temperature.
fn differ_in_geometry(a: &Sample, b: &Sample) -> bool {
    differ_by(a, b, None)
}

/// The samples halfway between neighbouring pixels (sorted by grid
/// position) for the side test ([`edge_in`]): primary and specular rays
/// and the sun flag now of each surface (a one-sample history), no
/// temperature.
pub(super) struct Midpoints {
    at: Vec<(u32, u32)>,
    samples: Vec<Sample>,
}

impl Midpoints {
    pub(super) fn trace(
        st: &Static,
        cond: &Conditions,
        cam: &Camera,
        mut at: Vec<(u32, u32)>,
        c: &Counters,
    ) -> Self {
        at.sort_unstable();
        at.dedup();
        let mut samples = trace_geometry(st, cam, &at, c);
        let now = cond.suns.len().saturating_sub(1);
        let lit = {
            let points: Vec<&Surface> = samples
                .iter()
                .flat_map(|s| {
                    let bg = s.bounce.as_deref().and_then(|(_, b)| b.as_ref());
                    s.surface.iter().chain(bg)
                })
                .collect();
            sun_flags_at(st, cond, &points, &[now], c)
        };
        let mut lit = lit.into_iter();
        for s in &mut samples {
            let bg = s.bounce.as_deref_mut().and_then(|(_, b)| b.as_mut());
            for surf in s.surface.iter_mut().chain(bg) {
                let flag = lit.next().unwrap_or(false);
                surf.history = SunFlags::from_switches(flag, &[], 1);
            }
        }
        Midpoints { at, samples }
    }

    fn get(&self, pos: (u32, u32)) -> Option<&Sample> {
        self.at.binary_search(&pos).ok().map(|k| &self.samples[k])
    }
}

/// The refinement criterion for pixel `me` against one neighbour `other`
/// (module docs, step 2): their coarse samples [`differ`], and the edge
/// between them may cross `me`'s half. Where they differ in geometry or sun
/// state and the sample `mid()` halfway between them is known (looked up
/// only then), the edge lies
/// on the side whose centre `mid` differs from; when `mid` differs from
/// neither (or from both), both pixels are refined, as they are for a
/// difference in temperature alone.
fn edge_in<'a>(
    me: &Sample,
    other: &Sample,
    mid: impl FnOnce() -> Option<&'a Sample>,
    threshold_k: f64,
) -> bool {
    if !differ(me, other, threshold_k) {
        return false;
    }
    match mid() {
        Some(m) if differ_in_geometry(me, other) => {
            differ_in_geometry(me, m) || !differ_in_geometry(m, other)
        }
        _ => true,
    }
}

/// The midpoints ([`midpoint`]) the side test of pixel (`x`, `y`) needs:
/// towards each of its [`NEIGHBOURS`] (`nb`, `None` outside the image)
/// whose coarse sample differs from its own (`me`) in geometry or sun
/// state.
pub(super) fn wanted_midpoints<'a>(
    (x, y): (u32, u32),
    n: u32,
    me: &'a Sample,
    nb: [Option<&'a Sample>; 8],
) -> impl Iterator<Item = (u32, u32)> + 'a {
    (NEIGHBOURS.into_iter().zip(nb))
        .filter_map(move |(d, o)| differ_in_geometry(me, o?).then(|| midpoint(x, y, d, n))?)
}

/// Whether pixel (`x`, `y`) of a `w`×`h` image (refined grid `n`) is
/// refined (module docs, step 2): a border pixel (no neighbour sees the
/// part of the pixel between its centre and the image's edge), or one whose
/// coarse sample `me` and a neighbour's in `nb` ([`NEIGHBOURS`] order)
/// differ with the edge in its half ([`edge_in`], the midpoints `mids`
/// traced from [`wanted_midpoints`]).
pub(super) fn pixel_refined(
    ((x, y), (w, h, n)): ((u32, u32), (u32, u32, u32)),
    me: &Sample,
    nb: &[Option<&Sample>; 8],
    mids: &Midpoints,
    threshold_k: f64,
) -> bool {
    let border = x == 0 || y == 0 || x + 1 == w || y + 1 == h;
    border
        || (NEIGHBOURS.iter().zip(nb)).any(|(&d, o)| {
            o.is_some_and(|o| {
                let mid = || midpoint(x, y, d, n).and_then(|p| mids.get(p));
                edge_in(me, o, mid, threshold_k)
            })
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ground(material: u32, x: f32, lit: bool, temp_k: f64) -> Sample {
        Sample {
            dir: Vec3::new(0.0, 0.0, -1.0),
            surface: Some(Surface {
                material,
                point: Vec3::new(x, 0.0, 0.0),
                normal: Vec3::Z,
                range_m: 1000.0,
                history: SunFlags::from_switches(lit, &[], 4),
                temp_k,
                ..Default::default()
            }),
            bounce: None,
        }
    }

    /// The sample halfway between two pixel centres is their shared edge
    /// midpoint or corner on the n-grid (none for an odd n or off the
    /// sample image).
    #[test]
    fn midpoint_lies_on_the_shared_edge_or_corner() {
        assert_eq!(centre(3, 5, 16), (56, 88));
        assert_eq!(midpoint(3, 5, (1, 0), 16), Some((64, 88)));
        assert_eq!(midpoint(3, 5, (-1, 0), 16), Some((48, 88)));
        assert_eq!(midpoint(3, 5, (1, 1), 16), Some((64, 96)));
        assert_eq!(midpoint(3, 5, (-1, -1), 16), Some((48, 80)));
        assert_eq!(midpoint(0, 0, (-1, 0), 16), Some((0, 8)));
        assert_eq!(midpoint(3, 5, (1, 0), 3), None);
    }

    /// An edge between two pixels refines the pixel whose half it crosses
    /// (the midpoint differs from that pixel's centre); a midpoint like
    /// neither side, an unknown midpoint and a temperature difference alone
    /// refine both; equal samples refine neither.
    #[test]
    fn edge_in_refines_the_half_the_edge_crosses() {
        let grass = ground(1, 0.0, true, 300.0);
        let asphalt = ground(2, 1.0, true, 310.0);
        let (mid_grass, mid_asphalt) = (ground(1, 0.5, true, 0.0), ground(2, 0.5, true, 0.0));
        // Edge between the midpoint and the asphalt centre: the asphalt
        // pixel's half.
        assert!(!edge_in(&grass, &asphalt, || Some(&mid_grass), 0.05));
        assert!(edge_in(&asphalt, &grass, || Some(&mid_grass), 0.05));
        assert!(edge_in(&grass, &asphalt, || Some(&mid_asphalt), 0.05));
        assert!(!edge_in(&asphalt, &grass, || Some(&mid_asphalt), 0.05));
        // A shadow edge (sun flag now) is placed the same way.
        let shaded = ground(1, 1.0, false, 300.0);
        assert!(!edge_in(&grass, &shaded, || Some(&mid_grass), 0.05));
        assert!(edge_in(&shaded, &grass, || Some(&mid_grass), 0.05));
        // A midpoint like neither side, or none: both.
        let other = ground(3, 0.5, true, 0.0);
        assert!(edge_in(&grass, &asphalt, || Some(&other), 0.05));
        assert!(edge_in(&asphalt, &grass, || Some(&other), 0.05));
        assert!(edge_in(&grass, &asphalt, || None, 0.05));
        // Temperature alone: both, whatever the midpoint.
        let warm = ground(1, 1.0, true, 301.0);
        assert!(edge_in(&grass, &warm, || Some(&mid_grass), 0.05));
        assert!(edge_in(&warm, &grass, || Some(&mid_grass), 0.05));
        // Alike: neither.
        let near = ground(1, 1.0, true, 300.01);
        assert!(!edge_in(&grass, &near, || Some(&mid_asphalt), 0.05));
    }
}
